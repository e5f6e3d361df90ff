"""How dwa_local_planner scores a trajectory (its critics), for tb3_navigation.controller. No ROS here.

A velocity sample (v, w) is held for sim_time and stepped as
SimpleTrajectoryGenerator steps it (Euler steps of sim_granularity m or
angular_sim_granularity rad, whichever gives more). Its cost is the sum

    occdist_scale * (highest cost under the footprint along it)
  + path_distance_bias * resolution * (cells from its end to the plan)
  + goal_distance_bias * resolution * (cells from its end to the local goal)
  + the same two at its end's forward point (forward_point_distance ahead),
    to the plan (alignment; dropped within forward_point_distance of the
    local goal) and to the local goal pushed forward_point_distance beyond
    it along the robot's bearing to it (goal front); without
    forward_point_scoring (base_local_planner's TrajectoryPlannerROS) these
    two are left out and a trajectory's end alone is scored, the turns in
    place told apart by the goal distance forward_point_distance ahead of
    where they end (its heading_lookahead);

plus CLOSE if its footprint comes nearer than obstacle_clearance to an
obstacle cell (ours: DWA cut round the pillars with its footprint 6 cm
from them, following a plan that kept 25 cm; a trajectory that keeps the
clearance wins whenever one exists, and one that does not is still allowed,
so that goals near walls stay reachable);
cells counted in 4-neighbour steps around lethal, inscribed and unknown
cells (base_local_planner's MapGrid). It is rejected (cost < 0) if its
footprint, scaled up past scaling_speed, touches a lethal or unknown cell or
leaves the costmap, if a point it is scored at leaves the costmap, or if its
end lies where the plan or the local goal cannot be reached. The footprints,
the dear part, are checked lazily: cheapest trajectories first, since once
the cheapest unchecked one costs more than the best total found, no later
one can win; the winner is the one checking them all would give.
"""
import math

import numpy as np

from tb3_navigation.costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION
from tb3_navigation.grid_graph import step_counter

CHUNK = 64  # trajectories whose footprints are checked together
CLOSE = 1e4  # added to a trajectory nearer to an obstacle than obstacle_clearance: more than any other term
GOAL_ZONE = 0.5  # m from the goal within which the clearance is not asked for
#: Per step of the goal distance ahead of a turn in place (without forward-point scoring): at most
#: 0.0004 on a 600 x 600 costmap, below any difference of the critics (their least is 0.01 of occdist).
HEADING_TIE = 1e-9


def velocity_samples(low, high, count):
    """base_local_planner's VelocityIterator: `count` even samples from low to high, 0 added between."""
    if low == high:
        return np.array([low])
    steps = low + (high - low) * np.arange(max(2, count)) / float(max(1, max(2, count) - 1))
    steps[-1] = high
    if low < 0 < high and not np.any(steps == 0):
        steps = np.sort(np.append(steps, 0.0))
    return steps


class TrajectoryScorer(object):
    """DWA's critics for one controller: `costmap` (the local Costmap), `config` (a DwaConfig; the
    controller replaces it when the parameters change)."""

    def __init__(self, costmap, config):
        self.costmap, self.config = costmap, config

    def maps(self, pose, local):
        """Cells (as step counts) from the plan, from the local goal and from the local goal
        pushed forward_point_distance along the robot's bearing to it, with the scales."""
        config, costmap = self.config, self.costmap
        grid = costmap.grid
        dense = _densify(local[:, :2], grid.resolution)
        goal = local[-1, :2]
        bearing = math.atan2(goal[1] - pose[1], goal[0] - pose[0])
        front = local[:, :2].copy()
        front[-1] += config.forward_point_distance * np.array([math.cos(bearing), math.sin(bearing)])
        front = _densify(front, grid.resolution)
        blocked = costmap.costs >= INSCRIBED_INFLATED_OBSTACLE
        near_goal = np.hypot(*(goal - pose[:2])) <= config.forward_point_distance
        scale_path = config.path_distance_bias * grid.resolution
        scale_goal = config.goal_distance_bias * grid.resolution
        cells = _plan_cells(costmap, dense)
        ahead = config.forward_point_scoring  # false: TrajectoryPlannerROS's critics, the end point alone
        steps_from = _map_grid_steps(blocked)
        return dict(path=steps_from(cells), goal=steps_from(cells[-1:]),
                    front=steps_from(_plan_cells(costmap, front)[-1:]) if ahead else None,
                    scale_path=scale_path, scale_goal=scale_goal, scale_front=scale_goal if ahead else 0.0,
                    scale_alignment=0.0 if near_goal or not ahead else scale_path)

    def trajectories(self, pose, samples):
        """Poses (n, k, 3) along each sample held for sim_time, stepped as DWA steps it (Euler,
        its own step count), padded with its last pose."""
        config = self.config
        counts = np.ceil(np.maximum(np.abs(samples[:, 0]) * config.sim_time / config.sim_granularity,
                                    np.abs(samples[:, 1]) * config.sim_time / config.angular_sim_granularity))
        counts = np.maximum(counts, 1).astype(int)
        dt = config.sim_time / counts
        steps = np.arange(counts.max())
        live = steps[None, :] < (counts[:, None] - 1)
        headings = pose[2] + samples[:, 1:2] * dt[:, None] * np.minimum(steps[None, :], counts[:, None] - 1)
        moves = samples[:, 0:1] * dt[:, None] * live
        x = pose[0] + np.concatenate((np.zeros((len(samples), 1)), np.cumsum(moves * np.cos(headings), 1)[:, :-1]), 1)
        y = pose[1] + np.concatenate((np.zeros((len(samples), 1)), np.cumsum(moves * np.sin(headings), 1)[:, :-1]), 1)
        return np.stack((x, y, headings), axis=-1)

    def score(self, pose, samples, maps, check_all=False, clearance=True):
        """Costs (n,) of the samples' trajectories (< 0: rejected) and the trajectories;
        `clearance` False: obstacle_clearance not asked for (near the goal)."""
        config, costmap = self.config, self.costmap
        trajectories = self.trajectories(pose, samples)
        ends = trajectories[:, -1, :]
        forward = ends[:, :2] + config.forward_point_distance * np.stack((np.cos(ends[:, 2]), np.sin(ends[:, 2])), -1)
        costs = np.zeros(len(samples))
        rejected = np.zeros(len(samples), dtype=bool)
        for name, points, scale, stop in (('front', forward, maps['scale_front'], False),
                                          ('path', forward, maps['scale_alignment'], False),
                                          ('path', ends[:, :2], maps['scale_path'], True),
                                          ('goal', ends[:, :2], maps['scale_goal'], True)):
            if scale == 0:
                continue
            values, off = _lookup(costmap.grid, maps[name], points)
            rejected |= off | (stop & (values >= maps[name].size))
            costs += scale * np.where(off, 0.0, values)
        if not config.forward_point_scoring:
            # TrajectoryPlannerROS's heading_lookahead: of the turns in place, which all end where the robot
            # stands, the one whose point forward_point_distance ahead lies nearest the local goal wins, and a
            # turn wins a tie with a trajectory that drives (base_local_planner prefers turning then).
            values, off = _lookup(costmap.grid, maps['goal'], forward)
            costs += HEADING_TIE * np.where((samples[:, 0] == 0) & ~off, values, maps['goal'].size + 1)
        costs[rejected] = -1.0
        # The footprints last, cheapest trajectories first: the obstacle term is never
        # negative, so once the other terms of the cheapest unchecked trajectory alone
        # cost more than the best total found, no later one can win (an equal one is
        # still checked: among equals the first sampled wins).
        order = np.flatnonzero(~rejected)
        order = order[np.argsort(costs[order], kind='stable')]
        best = math.inf
        close_cost = self.costmap.distance_cost(config.obstacle_clearance) \
            if clearance and config.obstacle_clearance > 0 else 0.0
        for start in range(0, len(order), CHUNK):
            chunk = order[start:start + CHUNK]
            if not check_all and costs[chunk[0]] > best:
                costs[order[start:]] = math.inf  # valid but never better: left unscored
                break
            obstacle = self.obstacle_costs(trajectories[chunk], samples[chunk])
            close = (obstacle >= close_cost) & (close_cost > 0)
            costs[chunk] = np.where(obstacle < 0, -1.0, costs[chunk] + config.occdist_scale * obstacle + CLOSE * close)
            if np.any(obstacle >= 0):
                best = min(best, costs[chunk][obstacle >= 0].min())
        return costs, trajectories

    def obstacle_costs(self, trajectories, samples):
        """ObstacleCostFunction per trajectory: < 0 if any pose's footprint is illegal, else the
        highest footprint or centre cost along it."""
        config, costmap = self.config, self.costmap
        speed = np.abs(samples[:, 0])
        scale = np.where(speed > config.scaling_speed, 1.0 + config.max_scaling_factor * (speed - config.scaling_speed)
                         / max(config.max_vel_trans - config.scaling_speed, 1e-9), 1.0)
        count, steps = trajectories.shape[:2]
        result = np.empty(count)
        for value in np.unique(scale):
            rows = np.flatnonzero(scale == value)
            poses = trajectories[rows].reshape(-1, 3)
            footprint = costmap.footprint_cost(poses, value)
            centre = costmap.cost_at(poses[:, :2]).astype(float)
            per_pose = np.where(footprint < 0, -1.0, np.maximum(footprint, centre)).reshape(len(rows), steps)
            result[rows] = np.where(np.any(per_pose < 0, axis=1), -1.0, per_pose.max(axis=1))
        return result


def _densify(points, resolution):
    """MapGrid::adjustPlanResolution: points inserted so that none is more than `resolution` from the next
    (a segment `steps` long gets steps - 1, at k / steps of it; its end point kept as it is)."""
    points = np.asarray(points, dtype=float)
    if len(points) < 2:
        return points
    deltas = points[1:] - points[:-1]
    gaps = np.fromiter(map(math.hypot, deltas[:, 0], deltas[:, 1]), float, len(deltas))
    steps = np.where(gaps > resolution, np.ceil(gaps / resolution), 1.0).astype(np.intp)
    segment = np.repeat(np.arange(len(deltas)), steps)
    k = np.arange(len(segment)) - np.repeat(np.cumsum(steps) - steps, steps) + 1  # 1 .. steps of its segment
    out = points[segment] + deltas[segment] * (k / steps[segment])[:, None]
    ends = k == steps[segment]
    out[ends] = points[1:]
    return np.concatenate((points[:1], out))


def _plan_cells(costmap, points):
    """Flat indices of the cells of the plan's points on the costmap and known, up to the first
    point after them that is not (MapGrid::setTargetCells)."""
    grid = costmap.grid
    cells = grid.to_cells(points)
    usable = grid.inside(cells)
    usable[usable] = costmap.costs[cells[usable, 1], cells[usable, 0]] != NO_INFORMATION
    if not usable.any():
        return np.zeros(0, dtype=np.intp)
    first = int(np.argmax(usable))
    gaps = np.flatnonzero(~usable[first:])
    cells = cells[first:first + (gaps[0] if len(gaps) else len(cells))]
    return cells[:, 1] * grid.width + cells[:, 0]


def _map_grid_steps(blocked):
    """MapGrid's 4-neighbour step counts (H, W) around `blocked` cells from the nearest of some sources
    (flat indices), as a function of the sources: blocked cells count H * W (its obstacleCosts),
    unreached ones H * W + 1."""
    size, counts = blocked.size, step_counter(blocked)

    def steps_from(sources):
        if not len(sources):
            return np.full(blocked.shape, size + 1.0)
        distances = counts(sources)
        distances[blocked] = np.where(np.isfinite(distances[blocked]), distances[blocked], size)
        return np.where(np.isfinite(distances), distances, size + 1.0)
    return steps_from


def _lookup(grid, values, points):
    """(values at points (n, 2), off the grid (n,))."""
    cells = grid.to_cells(points)
    inside = grid.inside(cells)
    found = values[np.clip(cells[:, 1], 0, grid.height - 1), np.clip(cells[:, 0], 0, grid.width - 1)]
    return found, ~inside
