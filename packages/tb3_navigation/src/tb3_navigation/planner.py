"""The global planner: navfn's plan on a costmap, as move_base runs it for TurtleBot3. No ROS here.

TurtleBot3's move_base keeps the default global planner, navfn/NavfnROS,
with its defaults (allow_unknown true, default_tolerance 0). navfn turns
each cost c of the costmap into a step cost neutral_cost + cost_factor * c
(50 + 0.8 c: 50 in the open, 246 next to a wall), blocks lethal and
inscribed cells (>= 253) and lets unknown ones (255) cost 253 when
allow_unknown; spreads a potential from the robot's cell (whose own cost
never counts: navfn clears it, the robot stands there); and walks down the
potential from the goal. Here the potential is an exact shortest-path cost
over the 8 neighbours of each cell (no diagonal step between two blocked
cells), found by a compiled Dijkstra (tb3_navigation.grid_graph),
and the walk follows its predecessors, so each step of the plan goes to
the neighbour the cheapest path came from. Orientations are those of global_planner's orientation
filter (forward by default): each pose faces the next, the last one is the goal's.

One addition of ours, obstacle_clearance (0.12 m, as the controller's):
a step into a cell whose centre is nearer than the footprint's inscribed
radius plus obstacle_clearance to an obstacle costs CLOSE_STEP more, so
a plan passes a door or a corner that near only where no way round is
shorter than 1 m a cell. navfn's plans hugged door frames and corners 10-13 cm
from the Burger's centre (it refuses only cells within the inscribed radius,
5.1 cm to the padded footprint's front edge), where DWA with
TurtleBot3's values cannot make the turn (min_vel_theta 1.37 rad/s is out
of its window from rest) and rocked forward and back until the recoveries
gave up: see doc/speed.md. 0: navfn's plans.

global_planner/GlobalPlanner is the same search with its own step cost
(getCost: lethal_cost blocks, steps capped one below it; its defaults
neutral 50, factor 3.0, lethal 253) and its orientation modes. Its other
ways of finding a plan (use_dijkstra false: A*, use_quadratic,
use_grid_path false: gradient descent) end on the same cheapest path here.

make_plan's tolerance is navfn's: when it is > 0, the plan goes to the
reachable point nearest to the goal within the square goal +- tolerance,
sampled at the costmap's resolution.
"""
import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tb3_common.params import Checked, fail, non_negative, number, parameter
from tb3_common.pose2d import normalize_angle
from tb3_navigation.costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION
from tb3_navigation.grid_graph import UNREACHED, GridGraph, neighbours, path_cost, path_to, shortest_paths

COST_OBS = 254  # navfn: the step cost of a cell it must not enter (and one below: the dearest it may)
#: Added to the step into a cell nearer than obstacle_clearance: 20 steps in the open (1 m at 0.05 m cells).
CLOSE_STEP = 20.0 * 50.0


@dataclass(frozen=True)
class PlannerConfig(Checked):
    """navfn's parameters, and global_planner's where it has more (neutral_cost and cost_factor are
    global_planner's names for navfn's fixed COST_NEUTRAL 50 and COST_FACTOR 0.8)."""
    allow_unknown: bool = parameter(True, 'plans may cross unknown cells')
    default_tolerance: float = parameter(0.0, 'm: how far from an unreachable goal a plan may end', non_negative, 'm')
    neutral_cost: float = parameter(50.0, "a free cell's step cost (navfn's COST_NEUTRAL)", number(1.0, 255.0))
    cost_factor: float = parameter(0.8, "each unit of a cell's cost adds this to its step cost (navfn's COST_FACTOR)",
                                   non_negative)
    lethal_cost: Optional[int] = parameter(None, "global_planner's: cells this dear are blocked, steps cost at most "
                                                 "one less; unset: navfn's rule (253 blocked, steps up to 253)",
                                           number(1, 255))
    orientation_mode: int = parameter(1, "global_planner's: the plan's headings: 0 none, 1 forward, 2 interpolate, "
                                         '3 forward then interpolate, 4 backward, 5 leftward, 6 rightward',
                                  number(0, 6))
    obstacle_clearance: float = parameter(0.12, 'm (ours): plans keep this far from obstacles (beyond the '
                                                "footprint's inscribed radius) where a way round costs under "
                                                '1 m a cell; 0: navfn\'s plans', non_negative, 'm')
    orientation_window_size: Optional[int] = parameter(None, "global_planner's: a pose heads from this many poses "
                                                             'before it to as many after it; unset: to the next one',
                                                       number(1))

    def check_together(self):
        highest = COST_OBS - 1 if self.lethal_cost is None else self.lethal_cost - 1
        if self.neutral_cost > highest:
            fail('neutral_cost', self.neutral_cost, 'must be <= %d (a step costs at most that)' % highest)


class GlobalPlanner(object):
    """Plans on a tb3_navigation.costmap.Costmap (or anything with `grid` and `costs`)."""

    def __init__(self, config=PlannerConfig()):
        self.config = config
        self.potential = None  # (H, W): the last search's cost from the robot to each cell it reached, else inf
        self._costs = self._steps = self._close = None
        self._graphs = {}  # GridGraphs of the step costs: None: plain; a goal's cell: reweighted toward it (A*)
        self._last = None  # the cells of the last plan that ended at its goal's cell

    def step_costs(self, costs, close=None):
        """navfn's setCostmap (global_planner's getCost with a lethal_cost): the cost (float (H, W)) of
        stepping into each cell, inf if it is blocked; CLOSE_STEP more into a known, unblocked cell
        costing `close` or more (None: none)."""
        config = self.config
        costs = np.asarray(costs)
        steps = config.neutral_cost + config.cost_factor * costs.astype(float)
        if config.lethal_cost is None:
            steps, unknown = np.minimum(steps, COST_OBS - 1), COST_OBS - 1
            blocked = costs >= INSCRIBED_INFLATED_OBSTACLE
        else:
            lethal = config.lethal_cost
            steps = np.where(costs < lethal - 1, np.minimum(steps, lethal - 1), lethal)
            blocked = costs >= lethal
            unknown = min(config.neutral_cost + config.cost_factor * NO_INFORMATION, lethal - 1)
        if close is not None:
            steps = np.where((costs >= close) & (costs < INSCRIBED_INFLATED_OBSTACLE), steps + CLOSE_STEP, steps)
        if config.allow_unknown:
            steps = np.where(costs == NO_INFORMATION, unknown, steps)
            blocked &= costs != NO_INFORMATION
        return np.where(blocked, np.inf, steps)

    def close_cost(self, costmap):
        """The cost from which a cell of `costmap` is too close for a plan (None: obstacle_clearance 0)."""
        clearance = self.config.obstacle_clearance
        return costmap.distance_cost(costmap.inscribed_radius + clearance) if clearance > 0 else None

    def make_plan(self, costmap, start, goal, tolerance=None):
        """The plan [(x, y, yaw), ...] from `start` to `goal` (x, y, yaw, in the
        costmap's frame), or None: start off the map, goal off the map (with no
        tolerance), or nothing reachable within `tolerance` (default_tolerance if None)."""
        tolerance = self.config.default_tolerance if tolerance is None else float(tolerance)
        if not (np.all(np.isfinite(np.asarray(start, dtype=float)[:2])) and
                np.all(np.isfinite(np.asarray(goal, dtype=float)[:3])) and math.isfinite(tolerance)):
            return None
        grid = costmap.grid
        start_cell = grid.to_cells(np.asarray(start[:2], dtype=float))
        if not grid.inside(start_cell):
            return None
        self._use(costmap)
        distances, predecessors = self._search(grid, int(start_cell[1] * grid.width + start_cell[0]), goal, tolerance)
        self.potential = distances
        target = self._target(grid, distances, goal, tolerance)
        if target is None:
            return None
        end, index = target
        path = path_to(predecessors, index)
        self._last = np.array(path)
        cells = np.array(path[1:-1], dtype=int)
        middle = grid.centres(np.stack((cells % grid.width, cells // grid.width), axis=-1)).reshape(-1, 2)
        start_yaw = float(start[2]) if len(start) > 2 else 0.0
        return orient([tuple(start[:2])] + [tuple(point) for point in middle] + [end], goal[2],
                      self.config.orientation_mode, self.config.orientation_window_size, start_yaw)

    def spread(self, costmap, start):
        """navfn's computePotential from the robot at `start` (x, y) over the whole costmap:
        (potential, predecessors), each (H, W), the cheapest path's cost from the robot's
        cell to every cell (inf where no plan reaches) and the cell each path came from
        (grid_graph.UNREACHED for the robot's cell and unreached ones); None if `start`
        is off the map. One search answers "can a plan reach it, and how long is it"
        for every cell at once (frontier exploration asks it of every frontier)."""
        grid = costmap.grid
        if not np.all(np.isfinite(np.asarray(start, dtype=float)[:2])):
            return None
        start_cell = grid.to_cells(np.asarray(start[:2], dtype=float))
        if not grid.inside(start_cell):
            return None
        self._use(costmap)
        distances, predecessors = shortest_paths(self._graph(None), [int(start_cell[1] * grid.width + start_cell[0])])
        self.potential = distances
        return distances, predecessors

    def _use(self, costmap):
        """Step costs of `costmap`'s costs, which the graphs read: mended where cells changed (a global
        costmap's update changes a few hundred, nearly every replan while a map grows)."""
        costs, close = np.asarray(costmap.costs), self.close_cost(costmap)
        if self._costs is not None and self._costs.shape == costs.shape and close == self._close:
            changed = np.flatnonzero(self._costs != costs)
            self._costs.ravel()[changed] = costs.ravel()[changed]
            self._steps.ravel()[changed] = self.step_costs(costs.ravel()[changed], close)
            return
        if self._costs is None or self._costs.shape != costs.shape:
            self._last = None  # its cells are another grid's
        self._costs, self._close = np.array(costs, copy=True), close
        self._steps = self.step_costs(costs, close)
        self._graphs = {}

    def _search(self, grid, start_index, goal, tolerance):
        """(potential, predecessors) from the robot's cell: everywhere when a tolerance asks
        for the nearest reachable point; else an A* toward the goal's cell, bounded by what
        the rest of the last plan to it costs now (_known_limit), else at twice, then four
        times, the heuristic's estimate plus 1 m of open travel, then unbounded. Each gives
        the same plan; the A* visits a fraction of the map (for the plan across
        turtlebot3_house's 400 x 260 cells, a third of them at first)."""
        goal_cell = grid.to_cells(np.asarray(goal[:2], dtype=float))
        if tolerance > 0 or not grid.inside(goal_cell):
            return shortest_paths(self._graph(None), [start_index])
        goal_index = int(goal_cell[1] * grid.width + goal_cell[0])
        if not np.isfinite(self._steps.ravel()[goal_index]) and goal_index != start_index:
            return np.full(grid.shape, np.inf), np.full(grid.shape, UNREACHED)  # a blocked goal
        if goal_index not in self._graphs:
            self._graphs = {key: kept for key, kept in self._graphs.items() if key is None}  # one goal kept
            # The heuristic: navfn's cheapest step (neutral_cost) times the 8-neighbour distance.
            iy, ix = np.mgrid[0:grid.height, 0:grid.width]
            dx, dy = np.abs(ix - goal_cell[0]), np.abs(iy - goal_cell[1])
            self._graph(goal_index, self.config.neutral_cost * (np.maximum(dx, dy)
                                                                + (math.sqrt(2) - 1) * np.minimum(dx, dy)))
        graph = self._graphs[goal_index]
        heuristic = graph.heuristic
        ahead = heuristic.ravel()[start_index]
        estimate = ahead + self.config.neutral_cost / grid.resolution
        known = self._known_limit(graph, start_index, goal_index)
        for limit in ([] if known is None else [known]) + [2.0 * estimate - ahead, 4.0 * estimate - ahead, np.inf]:
            distances, predecessors = shortest_paths(graph, [start_index], limit=limit)
            if np.isfinite(distances.ravel()[goal_index]):
                break
        return distances + ahead - heuristic, predecessors

    def _known_limit(self, graph, start_index, goal_index):
        """A bound on the A*'s search from the last plan to the same goal: what the rest of it costs now
        from where the robot is on it (or a step off it), in `graph`'s reweighted costs; None if there
        is no such plan or it is blocked now. A bound the cheapest path's cost meets at once
        searches only what the cheapest path's cost reaches (a replan across the house: 22 k cells
        where the first plan's bound reached 34 k), and a goal behind walls is searched once, not
        three times (bounds of twice and four times the estimate, then the whole map)."""
        last = self._last
        if last is None or last[-1] != goal_index:
            return None
        on = np.flatnonzero(last == start_index)
        if len(on):
            rest = path_cost(graph, last[on[-1]:])
        else:  # a step off it: onto the nearest of its cells beside the robot's
            beside = np.flatnonzero(np.isin(last, neighbours(graph, start_index)))
            if not len(beside):
                return None
            rest = path_cost(graph, np.concatenate(([start_index], last[beside[-1]:])))
        if not np.isfinite(rest):
            return None
        return rest * (1.0 + 1e-9) + 1e-6  # Dijkstra's sums may round otherwise

    def _graph(self, key, heuristic=None):
        """The graph of the step costs, kept under `key` (None: plain; a goal's cell: A*'s toward it,
        reweighted by `heuristic`)."""
        if key not in self._graphs:
            self._graphs[key] = GridGraph(self._steps, heuristic=heuristic)
        return self._graphs[key]

    @staticmethod
    def _target(grid, distances, goal, tolerance):
        """((x, y), flat index) of the point the plan ends at: the goal if reachable, else
        the reachable sample nearest to it within +- tolerance (navfn's search); None."""
        offsets = np.arange(-int(math.floor(tolerance / grid.resolution + 1e-9)),
                            int(math.floor(tolerance / grid.resolution + 1e-9)) + 1) * grid.resolution
        dx, dy = np.meshgrid(offsets, offsets)
        points = np.stack((goal[0] + dx.ravel(), goal[1] + dy.ravel()), axis=-1)
        cells = grid.to_cells(points)
        inside = grid.inside(cells)
        points, cells = points[inside], cells[inside]
        if not len(points):
            return None
        reachable = np.isfinite(distances[cells[:, 1], cells[:, 0]])
        if not reachable.any():
            return None
        squared = np.where(reachable, np.sum((points - goal[:2]) ** 2, axis=1), np.inf)
        best = int(np.argmin(squared))
        return tuple(points[best]), int(cells[best, 1] * grid.width + cells[best, 0])


#: global_planner's orientation modes beyond forward: the turn from the heading along the plan.
TURNED = {4: math.pi, 5: -math.pi / 2, 6: math.pi / 2}


def orient(points, goal_yaw, mode=1, window=None, start_yaw=0.0):
    """Poses [(x, y, yaw)] of points [(x, y)] as global_planner's OrientationFilter heads them (`mode`
    its orientation_mode, `window` its orientation_window_size): forward, each faces along the plan
    (from `window` points before it to as many after; None: to the next), the last has `goal_yaw`. Interpolation runs
    from `start_yaw` (the robot's) to the goal's, or, in mode 3, from the last turn over 0.35 rad
    onwards: back from the third last pose while the headings stay within 0.35 rad of its
    (global_planner adds the start index to every interpolated yaw once too often; not here)."""
    points = np.asarray(points, dtype=float)
    count = len(points)
    yaws = np.zeros(count) if mode == 0 else np.full(count, float(goal_yaw))
    if count > 1 and mode != 0:
        index = np.arange(count - 1)
        before = index if window is None else np.maximum(0, index - window)
        after = index + 1 if window is None else np.minimum(count - 1, index + window)
        yaws[:-1] = np.arctan2(points[after, 1] - points[before, 1], points[after, 0] - points[before, 0])
        yaws[:-1] = normalize_angle(yaws[:-1] + TURNED.get(mode, 0.0))
        first = 0
        if mode == 3:
            first = last = max(count - 3, 0)
            while first > 0 and abs(normalize_angle(yaws[first - 1] - yaws[last])) <= 0.35:
                first -= 1
        if mode in (2, 3):
            yaws[0] = start_yaw
            span = normalize_angle(goal_yaw - yaws[first]) / max(count - 1 - first, 1)
            yaws[first:] = normalize_angle(yaws[first] + span * np.arange(count - first))
    yaws[-1] = goal_yaw
    return [(float(x), float(y), float(yaw)) for (x, y), yaw in zip(points, yaws)]


def plan_length(plan):
    """Length (m) of a plan's polyline."""
    points = np.asarray(plan, dtype=float)[:, :2]
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T))) if len(points) > 1 else 0.0
