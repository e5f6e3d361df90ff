"""A layered costmap as costmap_2d builds one for TurtleBot3's move_base. No ROS here.

TurtleBot3's costmap_common_params set no `plugins`, so costmap_2d loads its
pre-Hydro layers: a static layer (the global costmap's `static_map: true`),
an obstacle layer from the scan (`map_type: costmap`) and an inflation
layer, combined in that order into one array of costs, [iy, ix] on a
tb3_common.grid.Grid:

- static: map cells >= lethal_cost_threshold (100) are LETHAL_OBSTACLE, other
  known cells FREE_SPACE (trinary_costmap), unknown (-1) NO_INFORMATION;
  written over the master as it is.
- obstacles: a scan marks LETHAL the cell of each hit nearer than
  obstacle_range and clears the cells its beams cross up to raytrace_range
  (laser_geometry drops readings at or past range_max, so these beams clear
  nothing unless inf_is_valid), each as its observation source says
  (marking, clearing, its own ranges); the robot's footprint is cleared. Its cells
  default to FREE_SPACE unless track_unknown_space, and are laid on the master
  with "maximum" where they know something. So with TurtleBot3's values
  (track_unknown_space unset: false) the map's unknown cells end up FREE in
  the master, as in TurtleBot3's rviz; with track_unknown_space they stay
  NO_INFORMATION.
- inflation: cost = 252 exp(-cost_scaling_factor (d - inscribed_radius)) at a
  distance d from the nearest lethal cell's centre up to inflation_radius,
  INSCRIBED_INFLATED_OBSTACLE within the inscribed radius; a cell keeps its
  own cost if higher, an unknown cell stays unknown unless inscribed (or,
  with inflate_unknown, unless the inflation gives it any cost). Its two
  parameters and inflate_unknown may change on a running costmap
  (reconfigure: dynamic_reconfigure's inflation_layer).

The footprint is padded by footprint_padding (costmap_2d's default 0.01 m)
and its radii come from it: the Burger's padded footprint is 0.166 x 0.23 m
with base_footprint 0.051 m behind its front edge, so its inscribed radius
is 0.051 m (a single cell's centre at 0.05 m is already outside it) and its
circumscribed radius 0.163 m. A robot_radius instead of a footprint is
costmap_2d's 16-corner polygon of it (circle_footprint). The footprint's
geometry is tb3_navigation.footprint's.
"""
import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy.ndimage import distance_transform_edt

from tb3_common.grid import Grid
from tb3_common.params import Checked, non_negative, number, parameter, points
from tb3_navigation.footprint import footprint_radii, inside_convex, outline
from tb3_navigation.raytrace import crossed_cells
from tb3_navigation.scan import endpoints

FREE_SPACE, INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, NO_INFORMATION = 0, 253, 254, 255

#: turtlebot3_navigation/param/costmap_common_params_*.yaml (noetic), (x, y) in base_footprint.
BURGER_FOOTPRINT = ((-0.105, -0.105), (-0.105, 0.105), (0.041, 0.105), (0.041, -0.105))
WAFFLE_FOOTPRINT = ((-0.205, -0.155), (-0.205, 0.155), (0.077, 0.155), (0.077, -0.155))

#: costmap_2d's publisher: costs to OccupancyGrid values (0, 1..98, 99 inscribed, 100 lethal, -1 unknown).
TRANSLATION = np.array([0] + [1 + (97 * (cost - 1)) // 251 for cost in range(1, 253)] + [99, 100, -1], dtype=np.int8)


@dataclass(frozen=True)
class CostmapConfig(Checked):
    """costmap_2d's parameters, TurtleBot3's values (the Burger's footprint); `live` ones are the
    inflation layer's (InflationPlugin.cfg): dynamic_reconfigure changes them on a running node."""
    footprint: tuple = parameter(BURGER_FOOTPRINT, "m: the robot's outline in base_footprint (the Burger's)",
                                 points(3), 'm')
    footprint_padding: float = parameter(0.01, 'm added around the footprint', non_negative, 'm')
    obstacle_range: float = parameter(3.0, 'm: scan hits nearer than this are marked', non_negative, 'm')
    raytrace_range: float = parameter(3.5, 'm: space along a beam is cleared up to this', non_negative, 'm')
    inflation_radius: float = parameter(1.0, 'm: costs fall off this far from an obstacle', non_negative, 'm',
                                        live=True)
    cost_scaling_factor: float = parameter(3.0, 'how fast: 252 exp(-factor (d - inscribed radius))', non_negative,
                                           live=True)
    inflate_unknown: bool = parameter(False, 'true: unknown cells take any inflated cost (false: only inscribed)',
                                      live=True)
    track_unknown_space: bool = parameter(False, 'true: unseen cells stay unknown (plans avoid them unless '
                                                 'allow_unknown)')
    lethal_cost_threshold: int = parameter(100, 'map cells this or more are obstacles', number(0, 100))
    inf_is_valid: bool = parameter(False, 'true: beams reading inf clear up to raytrace_range')
    footprint_clearing_enabled: bool = parameter(True, "the robot's own footprint is cleared of obstacles")

    @property
    def padded_footprint(self):
        """The footprint (n, 2) pushed out by footprint_padding in x and y, as costmap_2d's padFootprint."""
        points = np.asarray(self.footprint, dtype=float)
        return points + np.sign(points) * self.footprint_padding


def inflation_costs(distance, resolution, inscribed_radius, inflation_radius, cost_scaling_factor):
    """costmap_2d's InflationLayer::computeCost of distances (cells) to the nearest lethal cell,
    0 beyond the inflation radius (rounded up to whole cells, as cellDistance)."""
    distance = np.asarray(distance, dtype=float)
    metres = distance * resolution
    with np.errstate(over='ignore'):
        falling = (INSCRIBED_INFLATED_OBSTACLE - 1) * np.exp(-cost_scaling_factor * (metres - inscribed_radius))
    costs = np.where(metres <= inscribed_radius, INSCRIBED_INFLATED_OBSTACLE, np.floor(np.minimum(falling, 252)))
    costs = np.where(distance == 0, LETHAL_OBSTACLE, costs)
    return np.where(distance <= math.ceil(inflation_radius / resolution - 1e-9), costs, 0).astype(np.uint8)


def occupancy_values(costs):
    """OccupancyGrid values (int8, same shape) of costs, through costmap_2d's translation table."""
    return TRANSLATION[np.asarray(costs, dtype=np.uint8)]


class Costmap(object):
    """Layers and their combination `costs` (uint8 [iy, ix]) on `grid`.

    A global costmap: Costmap(grid, config, static=map data); a local one:
    Costmap.rolling(...), whose grid follows the robot in update().
    """

    def __init__(self, grid, config=CostmapConfig(), static=None, rolling=False):
        self.grid = grid
        self.rolling_window = rolling
        self._take(config)
        self._default = NO_INFORMATION if config.track_unknown_space else FREE_SPACE
        self.static = None
        if static is not None:
            self.static = self.interpret_map(np.asarray(static).reshape(grid.shape))
        self.obstacles = np.full(grid.shape, self._default, dtype=np.uint8)
        self.costs = np.zeros(grid.shape, dtype=np.uint8)
        self.update_costs()

    @classmethod
    def rolling(cls, config=CostmapConfig(), width=3.0, height=3.0, resolution=0.05, centre=(0.0, 0.0)):
        """A rolling window `width` x `height` m (TurtleBot3's local costmap: 3 x 3 at 0.05) around `centre`."""
        columns, rows = int(round(width / resolution)), int(round(height / resolution))
        origin = (centre[0] - columns * resolution / 2.0, centre[1] - rows * resolution / 2.0, 0.0)
        return cls(Grid(resolution, columns, rows, origin), config, rolling=True)

    def _take(self, config):
        self.config = config
        self._master = None  # the layers combined when the costs were last inflated (new parameters: none)
        self.footprint = config.padded_footprint
        self.inscribed_radius, self.circumscribed_radius = footprint_radii(self.footprint)
        self._outline = outline(self.footprint, self.grid.resolution / 2.0)

    def reconfigure(self, config):
        """New parameters (dynamic_reconfigure's: the inflation's): the costs combined anew with them."""
        self._take(config)
        self.update_costs()

    def interpret_map(self, data):
        """Static layer costs of OccupancyGrid values (StaticLayer::interpretValue, trinary)."""
        raw = np.asarray(data).astype(np.int16) & 0xFF  # as costmap_2d reads them: unsigned char
        costs = np.where(raw >= self.config.lethal_cost_threshold, LETHAL_OBSTACLE, FREE_SPACE)
        return np.where(raw == 255, NO_INFORMATION, costs).astype(np.uint8)

    # --- updates ------------------------------------------------------------------------------

    def update(self, robot_pose, scan=None, sensor_pose=None, source=None):
        """One update cycle: follow the robot (rolling), clear and mark from `scan`
        seen from `sensor_pose` (x, y, yaw in this costmap's frame), clear the
        footprint at `robot_pose`, then combine the layers. `source` (costmap_2d's
        observation source: marking, clearing, obstacle_range, raytrace_range and
        inf_is_valid attributes) says how the scan is used; None: the config's way."""
        if self.rolling_window:
            self._follow(robot_pose)
        if scan is not None:
            self._observe(scan, sensor_pose, source or _Source(self.config))
        if self.config.footprint_clearing_enabled:
            cells = self.footprint_cells(robot_pose)
            self.obstacles.ravel()[cells] = FREE_SPACE
        self.update_costs()

    def _observe(self, scan, sensor_pose, source):
        """Clear along each usable beam up to raytrace_range, then mark hits within obstacle_range."""
        ranges = np.nan_to_num(scan.ranges, nan=np.inf)
        use = scan.hits | (scan.misses if source.inf_is_valid else False)
        length = np.minimum(np.where(scan.hits, ranges, source.raytrace_range), source.raytrace_range)
        ends = self._clipped(sensor_pose[:2], endpoints(sensor_pose, scan.angles[use], length[use]))
        if ends is not None and source.clearing:
            self.obstacles.ravel()[crossed_cells(self.grid, sensor_pose[:2], ends)] = FREE_SPACE
        if not source.marking:
            return
        marked = scan.hits & (ranges < source.obstacle_range)
        cells = self.grid.to_cells(endpoints(sensor_pose, scan.angles[marked], ranges[marked]))
        cells = cells[self.grid.inside(cells)]
        self.obstacles[cells[:, 1], cells[:, 0]] = LETHAL_OBSTACLE

    def _clipped(self, origin, ends):
        """The beams from `origin` to `ends` (n, 2) cut where they leave the grid, as
        raytraceFreespace cuts them (a 3.5 m beam crosses at most 2.1 m of a 3 x 3 m
        window); None if the origin is off the grid (costmap_2d then clears nothing)."""
        grid = self.grid
        start = grid.to_cells_float(np.asarray(origin, dtype=float))
        if not grid.inside(np.floor(start).astype(int)):
            return None
        along = grid.to_cells_float(ends) - start
        share = np.ones(len(along))
        for axis, size in ((0, grid.width), (1, grid.height)):
            with np.errstate(divide='ignore', invalid='ignore'):
                exit_share = np.where(along[:, axis] > 0, (size - 1e-6 - start[axis]) / along[:, axis],
                                      np.where(along[:, axis] < 0, (1e-6 - start[axis]) / along[:, axis], np.inf))
            share = np.minimum(share, exit_share)
        return np.asarray(origin, dtype=float) + (np.asarray(ends, dtype=float) - origin) * share[:, None]

    def _follow(self, robot_pose):
        """Move the window so the robot is at its centre, in whole cells (Costmap2D::updateOrigin)."""
        grid = self.grid
        size = (grid.width * grid.resolution, grid.height * grid.resolution)
        shift = [int((robot_pose[axis] - size[axis] / 2.0 - grid.origin[axis]) / grid.resolution)  # C's truncation
                 for axis in (0, 1)]
        if shift == [0, 0]:
            return
        moved = np.full(grid.shape, self._default, dtype=np.uint8)
        (sx, sy), (height, width) = shift, grid.shape
        if abs(sx) < width and abs(sy) < height:
            moved[max(0, -sy):height - max(0, sy), max(0, -sx):width - max(0, sx)] = \
                self.obstacles[max(0, sy):height - max(0, -sy), max(0, sx):width - max(0, -sx)]
        self.obstacles = moved
        self.grid = Grid(grid.resolution, grid.width, grid.height,
                         (grid.origin[0] + sx * grid.resolution, grid.origin[1] + sy * grid.resolution, 0.0))

    def update_costs(self):
        """The master: static overwritten, obstacles by maximum where known, then inflation, where it
        may have changed: the costs are the master's and the parameters' alone, and a cell's cost
        depends on the master within the inflation radius. So, as costmap_2d inflates within the
        bounds an update touched, only the box round the changed cells is inflated again (from the
        master a radius farther), and nothing when the master is what it was: a global costmap
        updated at 10 Hz gets a scan at 5 Hz. Inflating is the costly part (turtlebot3_house's
        400 x 260 cells: over a hundred times as long as combining the layers)."""
        master = self.static.copy() if self.static is not None else np.full(self.grid.shape, self._default, np.uint8)
        known = self.obstacles != NO_INFORMATION
        take = known & ((master == NO_INFORMATION) | (master < self.obstacles))
        master[take] = self.obstacles[take]
        before, self._master = self._master, master
        if before is None or before.shape != master.shape:
            self.costs = self._inflate(master)
            return
        changed = master != before
        rows, columns = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
        if not len(rows):
            return
        reach = max(0, math.ceil(self.config.inflation_radius / self.grid.resolution - 1e-9))
        height, width = master.shape
        box = [max(0, rows[0] - reach), min(height, rows[-1] + 1 + reach),
               max(0, columns[0] - reach), min(width, columns[-1] + 1 + reach)]
        read = [max(0, box[0] - reach), min(height, box[1] + reach),
                max(0, box[2] - reach), min(width, box[3] + reach)]
        inflated = self._inflate(master[read[0]:read[1], read[2]:read[3]])
        costs = self.costs.copy()
        costs[box[0]:box[1], box[2]:box[3]] = inflated[box[0] - read[0]:box[1] - read[0],
                                                       box[2] - read[2]:box[3] - read[2]]
        self.costs = costs

    def _inflate(self, master):
        config = self.config
        lethal = master == LETHAL_OBSTACLE
        if not lethal.any() or math.ceil(config.inflation_radius / self.grid.resolution - 1e-9) == 0:
            return master
        inflated = inflation_costs(distance_transform_edt(~lethal), self.grid.resolution, self.inscribed_radius,
                                   config.inflation_radius, config.cost_scaling_factor)
        taken = inflated > FREE_SPACE if config.inflate_unknown else inflated >= INSCRIBED_INFLATED_OBSTACLE
        unknown_value = np.where(taken, inflated, NO_INFORMATION)
        return np.where(master == NO_INFORMATION, unknown_value, np.maximum(master, inflated))

    def clear_obstacles(self, centre, size, inside=False):
        """clear_costmap_recovery: forget the obstacle layer's cells outside (or, with
        `inside`, within) a square of `size` m centred on `centre` (x, y), then combine."""
        low = self.grid.to_cells((centre[0] - size / 2.0, centre[1] - size / 2.0))
        high = self.grid.to_cells((centre[0] + size / 2.0, centre[1] + size / 2.0))
        iy, ix = np.mgrid[0:self.grid.height, 0:self.grid.width]
        within = (ix > low[0]) & (ix < high[0]) & (iy > low[1]) & (iy < high[1])
        self.obstacles[within == inside] = NO_INFORMATION
        self.update_costs()

    def reset(self):
        """The clear_costmaps service: the obstacle layer back to its default."""
        self.obstacles[:] = self._default
        self.update_costs()

    # --- queries ------------------------------------------------------------------------------

    def footprint_points(self, poses, scale=1.0):
        """Points (n, k, 2) along the (scaled) footprint's outline at each of `poses` (n, 3)."""
        poses = np.atleast_2d(np.asarray(poses, dtype=float))
        local = self._outline * scale
        cos, sin = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
        return np.stack((poses[:, 0:1] + cos * local[:, 0] - sin * local[:, 1],
                         poses[:, 1:2] + sin * local[:, 0] + cos * local[:, 1]), axis=-1)

    def footprint_cost(self, poses, scale=1.0):
        """Per pose (n, 3) as base_local_planner's CostmapModel::footprintCost: -3
        if the outline leaves the map, -1 if it touches a lethal cell, -2 an
        unknown one, else the highest cost under the outline (float (n,))."""
        poses = np.atleast_2d(np.asarray(poses, dtype=float))
        grid, result = self.grid, np.empty(len(poses))
        _footprint_costs(poses, self._outline * scale, self.costs, grid.origin[0], grid.origin[1],
                         math.cos(grid.origin[2]), math.sin(grid.origin[2]), grid.resolution, result)
        return result

    def footprint_cells(self, pose):
        """Flat indices of the cells the footprint at `pose` covers: its outline's cells and
        every cell whose centre lies inside it (setConvexPolygonCost)."""
        outline_cells = self.grid.to_cells(self.footprint_points(pose)[0])
        low, high = outline_cells.min(axis=0), outline_cells.max(axis=0)
        iy, ix = np.mgrid[low[1]:high[1] + 1, low[0]:high[0] + 1]
        box = np.stack((ix.ravel(), iy.ravel()), axis=-1)
        local = (self.grid.centres(box) - pose[:2]).dot(
            np.array([[math.cos(pose[2]), -math.sin(pose[2])], [math.sin(pose[2]), math.cos(pose[2])]]))
        cells = np.concatenate((outline_cells, box[inside_convex(self.footprint, local)]))
        cells = cells[self.grid.inside(cells)]
        return np.unique(cells[:, 1] * self.grid.width + cells[:, 0])

    def distance_cost(self, metres):
        """The inflation cost of a cell whose centre lies `metres` plus half a cell from the nearest
        obstacle cell's: a cell this dear or dearer is nearer than `metres` to an obstacle."""
        resolution = self.grid.resolution
        return float(inflation_costs(np.array([(metres + resolution / 2.0) / resolution]), resolution,
                                     self.inscribed_radius, self.config.inflation_radius,
                                     self.config.cost_scaling_factor)[0])

    def cost_at(self, xy):
        """Costs at points (..., 2); NO_INFORMATION off the map."""
        cells = self.grid.to_cells(xy)
        inside = self.grid.inside(cells)
        values = self.costs[np.clip(cells[..., 1], 0, self.grid.height - 1),
                            np.clip(cells[..., 0], 0, self.grid.width - 1)]
        return np.where(inside, values, NO_INFORMATION)

    def occupancy_grid(self):
        """The costs as nav_msgs/OccupancyGrid values (int8 [iy, ix]), as costmap_2d publishes them."""
        return occupancy_values(self.costs)


class _Source(object):
    """A scan used as the config says: marked and cleared, with its ranges."""

    def __init__(self, config):
        self.marking = self.clearing = True
        self.obstacle_range, self.raytrace_range = config.obstacle_range, config.raytrace_range
        self.inf_is_valid = config.inf_is_valid


@numba.njit(cache=True, nogil=True)
def _footprint_costs(poses, outline, costs, origin_x, origin_y, cos_grid, sin_grid, resolution,
                     result):  # pragma: no cover
    """Costmap.footprint_cost's values into `result`: the outline's points placed and their cells
    found with the arithmetic of footprint_points and Grid.to_cells, so that each lands in the
    same cell. Why compiled: DWA asks it of every pose of every trajectory it scores, about 15 %
    of move_base's CPU in numpy's temporaries (doc/speed.md)."""
    height, width = costs.shape
    for n in range(len(poses)):
        cos, sin = math.cos(poses[n, 2]), math.sin(poses[n, 2])
        highest, unknown, lethal, outside = 0, False, False, False
        for k in range(len(outline)):
            dx = poses[n, 0] + cos * outline[k, 0] - sin * outline[k, 1] - origin_x
            dy = poses[n, 1] + sin * outline[k, 0] + cos * outline[k, 1] - origin_y
            ix = math.floor((cos_grid * dx + sin_grid * dy) / resolution)
            iy = math.floor((-sin_grid * dx + cos_grid * dy) / resolution)
            if ix < 0 or ix >= width or iy < 0 or iy >= height:
                outside = True
                continue
            value = costs[iy, ix]
            if value == NO_INFORMATION:
                unknown = True
            elif value == LETHAL_OBSTACLE:
                lethal = True
            elif value > highest:
                highest = value
        result[n] = -3.0 if outside else -1.0 if lethal else -2.0 if unknown else float(highest)
