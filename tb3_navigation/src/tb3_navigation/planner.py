"""The global planner: navfn's plan on a costmap, as move_base runs it for TurtleBot3. No ROS here.

TurtleBot3's move_base keeps the default global planner, navfn/NavfnROS,
with its defaults (allow_unknown true, default_tolerance 0). navfn turns
each cost c of the costmap into a step cost neutral_cost + cost_factor * c
(50 + 0.8 c: 50 in the open, 246 next to a wall), blocks lethal and
inscribed cells (>= 253) and lets unknown ones (255) cost 253 when
allow_unknown; spreads a potential from the robot's cell (which it clears:
the robot is known to stand there); and walks down the potential from the
goal. Here the potential is an exact Dijkstra over the 8 neighbours of each
cell (tb3_navigation.grid_graph, at C speed), and the walk follows its
predecessors, so each step of the plan goes to the neighbour the cheapest
path came from. Orientations are those of global_planner's orientation
filter (forward): each pose faces the next, the last one is the goal's.

make_plan's tolerance is navfn's: when it is > 0, the plan goes to the
reachable point nearest to the goal within the square goal +- tolerance,
sampled at the costmap's resolution.
"""
import math
from dataclasses import dataclass

import numpy as np

from tb3_navigation.costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION
from tb3_navigation.grid_graph import build, path_to, shortest_paths

COST_OBS = 254  # navfn: the step cost of a cell it must not enter (and one below: the dearest it may)


@dataclass(frozen=True)
class PlannerConfig:
    """navfn's parameters (neutral_cost and cost_factor are global_planner's names for
    navfn's fixed COST_NEUTRAL 50 and COST_FACTOR 0.8)."""
    allow_unknown: bool = True
    default_tolerance: float = 0.0
    neutral_cost: float = 50.0
    cost_factor: float = 0.8

    def __post_init__(self):
        for name in ('default_tolerance', 'cost_factor'):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ValueError('%s must be a finite number >= 0, not %r' % (name, value))
        if not (isinstance(self.neutral_cost, (int, float)) and 1 <= self.neutral_cost < COST_OBS):
            raise ValueError('neutral_cost must be within 1..253, not %r' % (self.neutral_cost,))


class GlobalPlanner(object):
    """Plans on a tb3_navigation.costmap.Costmap (or anything with `grid` and `costs`)."""

    def __init__(self, config=PlannerConfig()):
        self.config = config
        self.potential = None  # (H, W) of the last plan, inf where unreachable: navfn's potential
        self._costs = self._graph_of_costs = None

    def step_costs(self, costs):
        """navfn's setCostmap: the cost (float (H, W)) of stepping into each cell, inf if it is blocked."""
        config = self.config
        costs = np.asarray(costs)
        steps = np.minimum(config.neutral_cost + config.cost_factor * costs.astype(float), COST_OBS - 1)
        blocked = costs >= INSCRIBED_INFLATED_OBSTACLE
        if config.allow_unknown:
            steps = np.where(costs == NO_INFORMATION, COST_OBS - 1, steps)
            blocked &= costs != NO_INFORMATION
        return np.where(blocked, np.inf, steps)

    def _graph(self, costs):
        """The graph of the costs' step costs, kept while the costs stay the same (most
        updates of a global costmap change nothing: the same walls seen again)."""
        if self._costs is None or self._costs.shape != costs.shape or not np.array_equal(self._costs, costs):
            self._costs = np.array(costs, copy=True)
            self._graph_of_costs = build(self.step_costs(costs))
        return self._graph_of_costs

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
        start_index = int(start_cell[1] * grid.width + start_cell[0])
        distances, predecessors = shortest_paths(self._graph(costmap.costs), grid.shape, [start_index])
        self.potential = distances
        target = self._target(grid, distances, goal, tolerance)
        if target is None:
            return None
        end, index = target
        cells = path_to(predecessors, index)[1:-1]
        points = [tuple(start[:2])] + [tuple(p) for p in grid.centres(np.stack(
            (np.array(cells, dtype=int) % grid.width, np.array(cells, dtype=int) // grid.width), axis=-1))] + [end]
        return orient(points, goal[2])

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


def orient(points, goal_yaw):
    """Poses [(x, y, yaw)] of points [(x, y)]: each faces the next, the last has `goal_yaw`."""
    points = np.asarray(points, dtype=float)
    yaws = np.full(len(points), float(goal_yaw))
    if len(points) > 1:
        steps = np.diff(points, axis=0)
        yaws[:-1] = np.arctan2(steps[:, 1], steps[:, 0])
    return [(float(x), float(y), float(yaw)) for (x, y), yaw in zip(points, yaws)]


def plan_length(plan):
    """Length (m) of a plan's polyline."""
    points = np.asarray(plan, dtype=float)[:, :2]
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T))) if len(points) > 1 else 0.0
