"""Frontiers of a map and explore_lite's rule for choosing one (hrnr/m-explore, noetic). No ROS here.

A frontier cell is a free cell (value 0) with an unknown one (< 0) among
its four neighbours; frontier cells that touch, diagonals included, form
one frontier. explore_lite groups its cells the same way (4-neighbour test,
8-neighbour grouping) but takes the unknown side of the border; the free
side is taken here so that every point a goal may go to is floor the map
knows to be free. Cells off the grid are not unknown: a map's edge is no
frontier.

Each frontier has its size (cells x resolution, m, as explore_lite counts
it), centroid and goal. The goal is the frontier's cell that the global
planner reaches most cheaply, among those where the footprint fits
whichever way the robot turns, with a cell to spare (TURN_MARGIN: cost at most
that 0.213 m from a wall has for the Burger) and outside the blacklist: explore_lite's
"middle" (the nearest point), but nearest along the plan, not in a straight
line. Not its centroid (explore_lite's goal since 2.1): the centroid of a
curved frontier, or of one wrapped round a corner, lies in unknown space or
in a wall, a goal move_base aborts or reaches to see nothing new; and not
its "initial" cell, the first one its search happened on.

The rule, explore_lite's frontierCost with its parameters:

    cost = potential_scale * distance + orientation_scale * turn - gain_scale * size

- distance: the length (m) of the planner's cheapest path from the robot
  to the goal. One search of the planner's potential over the costmap
  (tb3_navigation.planner.GlobalPlanner.spread) gives every frontier's at
  once, and says which ones no plan reaches. explore_lite takes the straight
  line to the nearest cell, which ranks a frontier behind a wall first,
  and multiplies metres by the resolution again (its potential_scale 3 then
  weighs a metre as 0.15 here would); here it is metres, as size is.
- turn: |angle| (rad) between the robot's heading and the direction to the
  goal. explore_lite reads orientation_scale and does nothing with it (its
  documentation says so); the default 0 keeps it so.
- size: the frontier's, m.

A frontier smaller than min_frontier_size (m) is not worth visiting; one
with no cell where the footprint fits has no room (a wall the map shows
with gaps, seen at a grazing angle, borders unknown space all along); one
whose roomy cells no plan reaches is unreachable; one whose reachable cells
all lie farther than max_wall_distance from every wall of the map is in the
open; one whose remaining cells all lie outside explore_bounds (ours, as
frontier_exploration's boundary polygon, a box here) is outside; one
whose remaining cells all lie within blacklist_radius of a
blacklisted goal is blacklisted. The rest are candidates, cheapest first;
none left: exploration is done.

max_wall_distance is not explore_lite's. The SLAM keeps its pose by
matching walls within maxUrange (3.0 m); on open ground it runs on
odometry alone. turtlebot3_house is open to its yard, and the SLAM's map
reaches 10 m out: without the limit the robot went out to the map's edge,
the pose in the map drifted 0.25 m, then 2.5 m, off the truth and the map
doubled its walls (measured: occupied cells near a real surface fell to
50 %). A goal within 2.5 m of a known wall keeps one within the lidar's
reach from there.
"""
import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from tb3_common.grid import Grid
from tb3_common.params import Checked, non_negative, parameter, positive

from .costmap import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, Costmap, CostmapConfig, inflation_costs
from .grid_graph import path_to
from .planner import GlobalPlanner, PlannerConfig

CANDIDATE, TOO_SMALL, NO_ROOM, UNREACHABLE, IN_THE_OPEN, OUTSIDE, BLACKLISTED = (
    'candidate', 'too small', 'no room', 'unreachable', 'in the open', 'outside', 'blacklisted')
FOUR = ndimage.generate_binary_structure(2, 1)
EIGHT = ndimage.generate_binary_structure(2, 2)
HEADING_BACK = 0.3  # m: the goal faces the way the path comes in over its last 0.3 m
WINDOW_MARGIN = 0.5  # m: of unknown space kept around the known part, beyond the inflation radius


def _bounds(value):
    if value == () or (len(value) == 4 and all(isinstance(bound, (int, float)) and not isinstance(bound, bool)
                                               and math.isfinite(bound) for bound in value)
                       and value[0] < value[2] and value[1] < value[3]):
        return None
    return 'must be [] or [xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax'


@dataclass(frozen=True)
class ExploreConfig(Checked):
    """explore_lite's parameters, with explore_lite's explore.launch values (TurtleBot3 has none
    of its own); blacklist_radius (explore_lite: a square of +-5 cells) and max_wall_distance (0:
    no limit) are this rule's."""
    planner_frequency: float = parameter(0.33, 'how often a new frontier is chosen', positive, 'Hz')
    progress_timeout: float = parameter(30.0, 'a goal the robot makes no progress towards for this long is '
                                              'blacklisted', non_negative, 's')
    potential_scale: float = parameter(3.0, "weight of the frontier's distance in its cost", non_negative)
    orientation_scale: float = parameter(0.0, "weight of the turn towards it", non_negative)
    gain_scale: float = parameter(1.0, "weight of the frontier's size", non_negative)
    min_frontier_size: float = parameter(0.5, 'smaller frontiers are left out', non_negative, 'm')
    blacklist_radius: float = parameter(0.25, 'frontiers this near a blacklisted goal are left out', non_negative,
                                        'm')
    max_wall_distance: float = parameter(2.5, 'no goal farther than this from every known wall; 0: no limit',
                                         non_negative, 'm')
    explore_bounds: tuple = parameter((), 'no goal outside [xmin, ymin, xmax, ymax] in the map; []: anywhere',
                                      _bounds, 'm')


@dataclass(frozen=True)
class Frontier:
    """One frontier: its cells' centres (n, 2), size (m), centroid (x, y), status (CANDIDATE,
    NO_ROOM, UNREACHABLE, IN_THE_OPEN, BLACKLISTED); for a candidate its goal (x, y, yaw), the path's
    distance (m) to it, the turn (rad) towards it and its cost (inf for the others)."""
    points: np.ndarray
    size: float
    centroid: tuple
    status: str
    goal: tuple = None
    distance: float = math.inf
    turn: float = math.inf
    cost: float = math.inf


@dataclass(frozen=True)
class Search:
    """One search's frontiers, candidates first (cheapest first), then the others."""
    frontiers: tuple

    @property
    def candidates(self):
        return [frontier for frontier in self.frontiers if frontier.status == CANDIDATE]

    @property
    def best(self):
        """The frontier to visit, or None: none left worth visiting."""
        candidates = self.candidates
        return candidates[0] if candidates else None

    def count(self, status):
        return sum(1 for frontier in self.frontiers if frontier.status == status)

    def why_none(self):
        """Why no frontier is left worth visiting, in words."""
        if not self.frontiers:
            return 'no frontier left: the map is closed (no free cell borders unknown space)'
        parts = []
        for status, words in ((UNREACHABLE, 'out of the planner\'s reach'), (BLACKLISTED, 'blacklisted'),
                              (IN_THE_OPEN, 'in the open, farther than max_wall_distance from any wall'),
                              (OUTSIDE, 'outside explore_bounds'),
                              (NO_ROOM, 'with no cell where the robot fits'),
                              (TOO_SMALL, 'smaller than min_frontier_size')):
            frontiers = [frontier for frontier in self.frontiers if frontier.status == status]
            if frontiers:
                parts.append('%d %s (%.1f m)' % (len(frontiers), words, sum(f.size for f in frontiers)))
        text = 'no frontier worth visiting: %s' % ', '.join(parts)
        if self.count(UNREACHABLE) and not self.count(BLACKLISTED):
            text += '; the robot is boxed in: no plan leads from it to any frontier it fits at'
        return text


def frontier_cells(values):
    """True (H, W) at the free cells (0) with an unknown one (< 0) among their 4 neighbours."""
    values = np.asarray(values)
    return (values == 0) & ndimage.binary_dilation(values < 0, structure=FOUR)


def label_frontiers(values):
    """(labels (H, W) int: 0 off any frontier, 1..count on one; count) of the map's frontiers."""
    return ndimage.label(frontier_cells(values), structure=EIGHT)


#: Cells a goal lies farther from the walls than the circumscribed radius. Move_base's costmap, made
#: from the live scans, draws a wall a cell nearer than the map the goal was chosen on as often as not
#: (a wall's face on a cell's edge), and a robot at a goal it cannot turn at stays there: DWA with
#: TurtleBot3's values cannot start a turn in place, and rotate_recovery checks the turn on the costmap.
#: (In turtlebot3_house goals 0.17 m from a wall's face left the robot in a corner for good; the margin
#: alone did not keep it out where the map had only the wall's near face: see controller._face_the_plan.)
TURN_MARGIN = 1
#: The search's planner: navfn's plain costs. With move_base's obstacle_clearance the cheapest frontier
#: cell of a partial map was the one reached through a wall not seen yet rather than past a door frame.
NAVFN = PlannerConfig(obstacle_clearance=0.0)


class FrontierSearch(object):
    """Frontiers of an OccupancyGrid's values, weighed by the rule, on a costmap made from that map
    as move_base's global costmap makes it (costmap_config: the robot's footprint and inflation)."""

    def __init__(self, config=ExploreConfig(), costmap_config=CostmapConfig(), planner_config=NAVFN):
        self.config = config
        self.costmap_config = costmap_config
        self.planner = GlobalPlanner(planner_config)
        self.costmap = None  # the last search's

    def admissible_cost(self, costmap):
        """The highest cost where the footprint fits whichever way the robot turns, with a cell to
        spare: the cost a cell beyond the circumscribed radius (costmap_2d's circumscribed cost's)."""
        at = np.array(costmap.circumscribed_radius / costmap.grid.resolution + TURN_MARGIN)
        cost = inflation_costs(at, costmap.grid.resolution, costmap.inscribed_radius,
                               self.costmap_config.inflation_radius, self.costmap_config.cost_scaling_factor)
        return min(int(cost), INSCRIBED_INFLATED_OBSTACLE - 1)

    def near_walls(self, costmap):
        """True (H, W) within max_wall_distance of a lethal cell (everywhere if it is 0)."""
        if not self.config.max_wall_distance:
            return np.ones(costmap.grid.shape, dtype=bool)
        walls = costmap.costs == LETHAL_OBSTACLE
        if not walls.any():
            return np.zeros(costmap.grid.shape, dtype=bool)
        distance = ndimage.distance_transform_edt(~walls) * costmap.grid.resolution
        return distance <= self.config.max_wall_distance

    def within_bounds(self, points):
        """True at the points (n, 2) inside explore_bounds (all, without bounds)."""
        if not self.config.explore_bounds:
            return np.ones(len(points), dtype=bool)
        xmin, ymin, xmax, ymax = self.config.explore_bounds
        return (points[:, 0] >= xmin) & (points[:, 0] <= xmax) & (points[:, 1] >= ymin) & (points[:, 1] <= ymax)

    def search(self, grid, values, robot_pose, blacklist=()):
        """The Search of the map `values` [iy, ix] on `grid` for a robot at `robot_pose` (x, y, yaw),
        goals within blacklist_radius of a point of `blacklist` [(x, y)] ruled out."""
        config = self.config
        grid, values = known_window(grid, np.asarray(values).reshape(grid.shape), robot_pose,
                                    self.costmap_config.inflation_radius + WINDOW_MARGIN)
        labels, _ = label_frontiers(values)
        self.costmap = costmap = Costmap(grid, self.costmap_config, static=values)
        spread = self.planner.spread(costmap, robot_pose)
        if spread is None:
            potential, predecessors = np.full(grid.shape, np.inf), None
        else:
            potential, predecessors = spread
        costs, room = costmap.costs, self.admissible_cost(costmap)
        walled = self.near_walls(costmap)
        blacklist = np.asarray(blacklist, dtype=float).reshape(-1, 2)
        frontiers = []
        for index, rows_cols in enumerate(ndimage.find_objects(labels), start=1):
            mine = labels[rows_cols] == index
            iy, ix = np.nonzero(mine)
            cells = np.stack((ix + rows_cols[1].start, iy + rows_cols[0].start), axis=-1)
            points = grid.centres(cells)
            size = len(cells) * grid.resolution
            centroid = tuple(float(value) for value in points.mean(axis=0))
            if size < config.min_frontier_size - 1e-9:
                frontiers.append(Frontier(points, size, centroid, TOO_SMALL))
                continue
            roomy = costs[cells[:, 1], cells[:, 0]] <= room
            reachable = roomy & np.isfinite(potential[cells[:, 1], cells[:, 0]])
            near = reachable & walled[cells[:, 1], cells[:, 0]]
            in_view = near & self.within_bounds(points)
            allowed = in_view & _away_from(points, blacklist, config.blacklist_radius)
            open_cells = cells[allowed]
            if not len(open_cells):
                status = (BLACKLISTED if in_view.any() else OUTSIDE if near.any() else
                          IN_THE_OPEN if reachable.any() else UNREACHABLE if roomy.any() else NO_ROOM)
                frontiers.append(Frontier(points, size, centroid, status))
                continue
            best = open_cells[np.argmin(potential[open_cells[:, 1], open_cells[:, 0]])]
            goal, distance = self._goal(grid, predecessors, best, robot_pose)
            turn = abs(_wrap(math.atan2(goal[1] - robot_pose[1], goal[0] - robot_pose[0]) - robot_pose[2])) \
                if distance > 0 else 0.0
            cost = config.potential_scale * distance + config.orientation_scale * turn - config.gain_scale * size
            frontiers.append(Frontier(points, size, centroid, CANDIDATE, goal, distance, turn, cost))
        order = sorted(range(len(frontiers)), key=lambda i: (frontiers[i].status != CANDIDATE, frontiers[i].cost,
                                                            frontiers[i].distance, -frontiers[i].size))
        return Search(tuple(frontiers[i] for i in order))

    @staticmethod
    def _goal(grid, predecessors, cell, robot_pose):
        """((x, y, yaw), path length in m) of the goal at `cell`: facing the way the path
        comes in over its last HEADING_BACK m (the robot arrives looking on into the unknown)."""
        path = path_to(predecessors, int(cell[1] * grid.width + cell[0]))
        cells = np.stack((np.array(path) % grid.width, np.array(path) // grid.width), axis=-1)
        points = grid.centres(cells)
        steps = np.hypot(*np.diff(points, axis=0).T) if len(points) > 1 else np.zeros(0)
        back = points[max(0, len(points) - 1 - int(round(HEADING_BACK / grid.resolution)))]
        end = points[-1]
        yaw = math.atan2(end[1] - back[1], end[0] - back[0]) if len(points) > 1 else float(robot_pose[2])
        return (float(end[0]), float(end[1]), yaw), float(steps.sum())


def known_window(grid, values, robot_pose, margin):
    """(grid, values) of the part of a map that holds its known cells and the robot, and `margin`
    m around them. The SLAM's map is 20 x 20 m (gmapping's xmin..ymax, 160000 cells) while
    turtlebot3_world fills 5 x 5 m of it: the planner's search over the window is what costs,
    about in proportion to its cells (the whole map took 0.25 s on a quiet core). A plan that
    leaves the window would run through unknown space beyond the walls; the inflation inside
    it is the same as on the whole map, its obstacles being known cells, inflation_radius away
    at most."""
    known = np.asarray(values) >= 0
    rows, cols = np.nonzero(known)
    robot = grid.to_cells(np.asarray(robot_pose[:2], dtype=float))
    if grid.inside(robot):
        rows, cols = np.append(rows, robot[1]), np.append(cols, robot[0])
    if not len(rows):
        return grid, values
    pad = int(math.ceil(margin / grid.resolution))
    r0, r1 = max(0, rows.min() - pad), min(grid.height, rows.max() + pad + 1)
    c0, c1 = max(0, cols.min() - pad), min(grid.width, cols.max() + pad + 1)
    corner = grid.centres(np.array([c0 - 0.5, r0 - 0.5]))
    window = Grid(grid.resolution, c1 - c0, r1 - r0, (float(corner[0]), float(corner[1]), grid.origin[2]))
    return window, values[r0:r1, c0:c1]


def _away_from(points, blacklist, radius):
    """True for the points (n, 2) farther than `radius` from every point of `blacklist` (m, 2)."""
    if not len(blacklist):
        return np.ones(len(points), dtype=bool)
    gaps = np.hypot(points[:, None, 0] - blacklist[None, :, 0], points[:, None, 1] - blacklist[None, :, 1])
    return np.all(gaps > radius, axis=1)


def _wrap(angle):
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def explored_area(grid, values):
    """(m^2 known free, m^2 known occupied, share of the known cells' bounding box that is
    known) of a map: what an exploration logs when it ends. Free 0..25 and occupied >= 65 as
    map_saver classes them."""
    values = np.asarray(values).reshape(grid.shape)
    cell = grid.resolution ** 2
    known = values >= 0
    free = known & (values <= 25)
    occupied = values >= 65
    if not known.any():
        return 0.0, 0.0, 0.0
    rows, cols = np.nonzero(known)
    box = (rows.max() - rows.min() + 1) * (cols.max() - cols.min() + 1)
    return float(free.sum() * cell), float(occupied.sum() * cell), float(known.sum()) / box
