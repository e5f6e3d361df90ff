"""Loop closure for the SLAM (tb3_navigation.slam), as Karto's and slam_toolbox's: the scans added to the
map are the nodes of a pose graph; one that comes back near scans taken long ago is matched against a
map of those alone, and a good match ties the two together. No ROS here.

Why: the SLAM matches each scan against the map it has built. Where no wall is in range (the house's
yard: 3 m of usable range) its pose drifts with the odometry, and what it draws meanwhile is drawn
drifted; when old walls come back in range, the pose snaps back onto them over a few scans. The map
keeps the drifted walls, a second time (doc/design.md).

So the chain of the graph does not take the SLAM's step between two scans when it snapped (differs by
more than SNAP from the odometry's step, which knows no walls), nor when it relocated after a failed
match: it takes the step matched against the scans added just before (Karto's running scans), or else
the odometry's. The chain then still holds the drift, and a closure, which says where the robot really
came back, disagrees with it: the graph spreads the correction over the poses since the loop began,
and the map is drawn anew from every scan at its corrected pose.
"""
import math
from collections import namedtuple

import numpy as np

from tb3_common.pose2d import compose, normalize_angle, relative

from . import matcher
from .occupancy import OccupancyGrid
from .pose_graph import PoseGraph
from .wall_shapes import WallShapes

#: Standard deviations (m, m, rad) of a constraint the scans' matches made, between two scans in a row
#: or closing a loop: 2 cm and 0.6 degree. Where the pose followed the odometry between two scans (no
#: match, or a snap left out), gmapping's odometry error model adds its own (information()), so that a
#: closure's correction goes where the drift came from: on the drive round the outside of the house, 5
#: of the 58 unmatched steps, turns in the yard, held as much yaw error as the 803 matched ones.
MATCHED = (0.02, 0.02, 0.01)
#: The SLAM's step between two scans added to the map (about 0.5 s apart) that differs this much (m, rad)
#: from the odometry's is taken for a snap back onto old walls: the chain takes the odometry's step.
#: (Its steps while the SLAM holds the pose by walls differ by a few mm.)
SNAP = (0.02, 0.01)
#: A closing match must score this much more per point than the pose as it is: along a corridor, where
#: a slide scores the same, a match is no evidence.
CLEARER = 0.05
#: m driven between two searches for a loop (a search costs a few tens of ms).
SEARCH_EVERY = 0.5
#: A scan is old enough to close a loop with when the robot has driven this many times
#: loop_search_maximum_distance since it: it left that place and came back.
LEFT_AND_BACK = 2.0
#: The old scans of the map a scan is matched against: at most this many, at least SPACING m of
#: driving apart (a robot standing still adds the same scan again and again).
SUBMAP_SCANS = 15
SPACING = 0.2
#: A scan added after a snap, a relocation or a jump of the odometry is chained by a match against this many
#: scans added before it (Karto's running scans), where RUNNING_SHARE of its points land on their walls.
RUNNING_SCANS = 10
RUNNING_SHARE = 0.75
#: A closing match this near the pose (m, rad) agrees with it; a graph whose constraints all hold this
#: well is not worth optimising and redrawing the map for.
NEGLIGIBLE = (0.025, 0.01)

#: One scan of the graph: the scan, the scanner's pose in the base frame, the range beyond which its hits
#: are dropped (maxRange or its range_max), the odometry's pose of the base when it was taken.
Node = namedtuple('Node', 'scan sensor_pose max_range odom')


class LoopCloser(object):
    """The pose graph of the scans added to a map, and the search for loops among them. `config` is
    the SLAM's (tb3_navigation.slam_config.SlamConfig)."""

    def __init__(self, config, grid):
        """`grid`: the map's (tb3_common.grid.Grid)."""
        self.config = config
        self._grid = grid
        self.graph = PoseGraph()
        self._nodes = []
        self._travelled = []  # m driven, along the chain of scans, to each scan
        self._searched_at = -math.inf  # m driven at the last search
        self.closures = 0  # loops closed that moved the poses
        self.moved = 0.0  # m or rad the last of them moved a pose at most

    def add(self, pose, points, node, walls, jumped=False, search=True, followed=(0.0, 0.0)):
        """Adds the scan just added to the map at `pose`, `points` its end points (base frame);
        `walls()` gives the map's occupied cells (called only when a loop is searched for); `jumped`: the
        odometry jumped or went astray since the last scan added (its step is then no measure);
        `search`: False while the map is being drawn anew (its walls are not where the graph now puts
        them); `followed`: (m, rad) of odometry the pose followed unmatched since the last scan added.
        Returns the pose corrected by a loop closure (and then draws nothing: see draw), or None."""
        index = self.graph.add_pose(pose)
        self._nodes.append(node)
        if index == 0:
            self._travelled.append(0.0)
            return None
        c = self.config
        previous = self.graph.poses[index - 1]
        front = relative(previous, pose)
        odometry = relative(self._nodes[index - 1].odom, node.odom)
        # The SLAM's step differs from the odometry's by more than SNAP: a snap back onto old walls.
        snapped = not jumped and _differ(front, odometry, SNAP)
        self._travelled.append(self._travelled[-1] + math.hypot(pose[0] - previous[0], pose[1] - previous[1]))
        due = snapped or self._travelled[-1] - self._searched_at >= SEARCH_EVERY
        closure = self._match_old(index, points, walls) if c.do_loop_closing and search and due else None
        if due and not snapped:
            self._searched_at = self._travelled[-1]
        # A snap back onto old walls, or a relocation, stays out of the chain: closures say where the robot
        # came back. The step is measured on the scans added just before, or else taken from the odometry
        # (after a snap) or the SLAM (after a jump: the odometry's step is no measure then).
        step = self._running_step(index, points, odometry) if snapped or jumped else front
        if step is None and snapped:
            step, followed = odometry, (math.hypot(odometry[0], odometry[1]), abs(odometry[2]))
        self.graph.add_edge(index - 1, index, front if step is None else step, information(self.config, *followed))
        if closure is None:
            return None
        old, matched = closure
        self.graph.add_edge(old, index, relative(self.graph.poses[old], matched), information(self.config))
        if not _differ(np.abs(self.graph.errors()).max(axis=0), (0.0, 0.0, 0.0), NEGLIGIBLE):
            return None
        self.moved = self.graph.optimize()
        self.closures += 1
        return tuple(self.graph.poses[index])

    def _field_of(self, indices, pose, search):
        """The likelihood field of the scans `indices` at their poses, around `pose` (None if empty)."""
        c = self.config
        reach = c.maxUrange + search + 0.5
        submap = OccupancyGrid.around(c.delta, pose[0] - reach, pose[1] - reach, pose[0] + reach, pose[1] + reach)
        for i in indices:
            self._draw(submap, i)
        field = matcher.WallField(WallShapes.of_map(submap.grid, *submap.walls(c.occ_thresh)), c.sigma)
        return None if field.empty else field

    def _running_step(self, index, points, odometry):
        """The step from scan `index` - 1 to scan `index` (`points`: its end points, base frame) matched
        against the RUNNING_SCANS scans added before it, at their poses in the graph, searched around
        the `odometry`'s step as the SLAM's own match searches (Karto's running scans); None where
        less than RUNNING_SHARE of the points land on their walls (the scans before saw nothing, or
        the odometry's step is no measure: the wheels turned on a robot held still, a reset)."""
        c = self.config
        previous = self.graph.poses[index - 1]
        prior = tuple(compose(previous, odometry))
        field = self._field_of(range(max(0, index - RUNNING_SCANS), index), prior, c.search_linear)
        if field is None:
            return None
        start, _ = matcher.search(field, points, prior, c.search_linear, c.search_angular, c.lstep, c.astep)
        matched, score = matcher.refine(field, points, start, c.iterations)
        if score < RUNNING_SHARE * len(points):
            return None
        return relative(previous, matched)

    def _old_scans_near(self, index, walls):
        """Indices of the old scans (see LEFT_AND_BACK) within loop_search_maximum_distance of scan
        `index` and in its sight (no wall of the map between: scans of a wall's other face would pull
        the pose by the wall's thickness), nearest first, SPACING apart, at most SUBMAP_SCANS."""
        c = self.config
        travelled = np.array(self._travelled)
        poses = self.graph.poses
        distance = np.hypot(*(poses[:index, :2] - poses[index, :2]).T)
        old = np.flatnonzero((travelled[index] - travelled[:index] > LEFT_AND_BACK * c.loop_search_maximum_distance)
                             & (distance < c.loop_search_maximum_distance))
        old = old[in_sight(self._grid, walls, poses[index, :2], poses[old, :2])]
        chosen, bins = [], set()
        for candidate in old[np.argsort(distance[old], kind='stable')]:
            spot = int(travelled[candidate] // SPACING)
            if spot not in bins:
                bins.add(spot)
                chosen.append(candidate)
            if len(chosen) == SUBMAP_SCANS:
                break
        return chosen

    def _match_old(self, index, points, walls):
        """(old scan, pose) of scan `index` matched against the old scans near it, or None: the match
        must agree with the pose (within NEGLIGIBLE) or score CLEARER than it (along a corridor a
        slide scores the same); and the search's best yields to the match nearest the pose (refined
        from it) unless it scores CLEARER than that one too. Why: a pose whose heading drifted 2.6
        degrees scores poorly as it is, so a slide of 36 cm along the house's south hallway, which
        fixed the heading, passed as clearer than it, and the graph took it (seen replaying a recorded
        exploration, doc/speed.md; test_loop_closure's corridor)."""
        c = self.config
        old = self._old_scans_near(index, walls())
        if len(old) < c.loop_match_minimum_chain_size:
            return None
        pose = tuple(self.graph.poses[index])
        field = self._field_of(old, pose, c.loop_search_linear)
        if field is None:
            return None
        start, _ = matcher.search(field, points, pose, c.loop_search_linear, c.loop_search_angular, c.lstep, c.astep)
        matched, score = matcher.refine(field, points, start, 2 * c.iterations)
        near, near_score = matcher.refine(field, points, pose, 2 * c.iterations)
        if near_score >= score - CLEARER * len(points):
            matched, score = near, near_score
        if score < max(c.minimumScore, c.loop_match_minimum_response_fine * len(points)):
            return None  # as the SLAM's own match: no score from a scan of too few points (none: 0 >= 0.6 * 0)
        gain = score - field.score(matcher.place(pose, points))
        if _differ(matched, pose, NEGLIGIBLE) and gain < CLEARER * len(points):
            return None
        return old[0], matched

    def _draw(self, grid, index):
        node = self._nodes[index]
        grid.add_scan(tuple(compose(self.graph.poses[index], node.sensor_pose)), node.scan, self.config.maxUrange,
                      node.max_range)

    def draw(self, grid, indices):
        """Draws the scans `indices` into `grid` (an OccupancyGrid) at their poses in the graph."""
        for index in indices:
            self._draw(grid, index)


def information(config, distance=0.0, rotation=0.0):
    """The information matrix of a constraint matched by scans (MATCHED) with `distance` m and `rotation`
    rad of unmatched odometry in it, whose error has gmapping's model and parameters as standard deviations:
    srr and srt (translation per m, per rad), str and stt (rotation)."""
    translation = config.srr * distance + config.srt * rotation
    turn = config.str * distance + config.stt * rotation
    return np.diag(1.0 / (np.square(MATCHED) + np.square((translation, translation, turn))))


def _differ(a, b, limits):
    """Whether poses (or differences) `a` and `b` are farther apart than `limits` (m, rad)."""
    return math.hypot(a[0] - b[0], a[1] - b[1]) > limits[0] or abs(normalize_angle(a[2] - b[2])) > limits[1]


def in_sight(grid, walls, origin, targets, step=0.25):
    """Whether each of `targets` (n, 2) is seen from `origin` (x, y): no cell of `walls` (bool, the
    grid's shape) on the segment between, sampled every `step` of a cell, their own cells left out."""
    targets = np.asarray(targets, dtype=float).reshape(-1, 2)
    start = grid.to_cells_float(np.asarray(origin, dtype=float))
    span = grid.to_cells_float(targets) - start
    samples = max(2, int(np.ceil(np.hypot(span[:, 0], span[:, 1]).max(initial=0.0) / step)))
    fractions = np.linspace(0.0, 1.0, samples)[1:-1]
    ix = np.floor(start[0] + span[:, 0:1] * fractions).astype(np.intp)
    iy = np.floor(start[1] + span[:, 1:2] * fractions).astype(np.intp)
    inside = (ix >= 0) & (ix < grid.width) & (iy >= 0) & (iy < grid.height)
    blocked = np.zeros(ix.shape, dtype=bool)
    blocked[inside] = walls[iy[inside], ix[inside]]
    return ~blocked.any(axis=1)
