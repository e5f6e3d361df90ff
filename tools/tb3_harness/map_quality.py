"""How good a map is, measured against the world file it was made in, and a picture of both. No ROS.

For the SLAM system test, the demo and exploration. The truth is the world
cut at the lidar's height (tb3_sim_nav.world_map); every figure is measured
on the map's own grid. A map's cells are classed as map_saver classes them:
occupied >= 65, free 0..25, anything else (and -1) unknown.

- occupied_near_surface: the share of occupied cells whose centre lies within
  `tolerance` (0.10 m) of a real surface, or inside an obstacle. Goal >= 95 %.
- surface_covered: the share of the surface a robot inside can see (the
  outline's points that face the free space connected to the start) with an
  occupied cell's centre within `tolerance`. Goal >= 80 %.
- wall_thickness: the median count of occupied cells a line along the
  surface's normal crosses from the surface outwards (a mapped wall one or
  two cells thick reads 1 or 2); thick_wall_share: the share above 2.
- doubled_wall_share: the share of covered surface points where, beyond that
  wall and a gap, another occupied run stands within `doubled_reach` (0.5 m)
  along the normal, off every real surface by `tolerance` and before any
  other real surface: a wall mapped twice (a jump in the pose).
- free_floor_mapped: the share of the reachable free floor mapped as free;
  reachable: the cells whose centre is more than the robot's radius (Burger
  0.105 m) from any obstacle, connected to the start, and within `bounds`
  if given (the world's own box: turtlebot3_house is open to a yard that
  the SLAM's 20 x 20 m map holds too, and the house is what is explored).
  For exploration.
"""
import dataclasses
import math

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from tb3_sim_nav.world_map import BURGER_SCAN_HEIGHT, in_plane, outline, rasterise, signed_distance

OCCUPIED_AT, FREE_UP_TO = 65, 25  # map_saver's --occ and --free
GOALS = dict(occupied_near_surface=0.95, surface_covered=0.80, wall_thickness=2.0)
FOUR_CONNECTED = ndimage.generate_binary_structure(2, 1)  # diagonal gaps between wall pixels do not connect


@dataclasses.dataclass(frozen=True)
class QualityConfig(object):
    """How the measures look; the defaults are the issue's figures and the Burger's."""
    tolerance: float = 0.10        # m: "near" a surface
    robot_radius: float = 0.105    # m: the Burger's footprint half-width
    scan_height: float = BURGER_SCAN_HEIGHT  # m: where the world is cut
    doubled_reach: float = 0.5     # m: how far out a second wall counts as a double
    outline_spacing: float = 0.02  # m: between surface points

    def __post_init__(self):
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError('QualityConfig.%s = %r: must be a finite number > 0' % (field.name, value))


@dataclasses.dataclass(frozen=True)
class MapQuality(object):
    """The figures of one map (shares in 0..1; NaN where nothing was there to measure)."""
    occupied_near_surface: float
    surface_covered: float
    wall_thickness: float
    thick_wall_share: float
    doubled_wall_share: float
    free_floor_mapped: float
    occupied_cells: int
    surface_points: int
    reachable_cells: int

    def failures(self):
        """What misses the issue's goals, one line each (empty: the map is good)."""
        lines = []
        for name in ('occupied_near_surface', 'surface_covered'):
            value = getattr(self, name)
            if not value >= GOALS[name]:
                lines.append('%s %.1f %% < %.0f %%' % (name, 100 * value, 100 * GOALS[name]))
        if not self.wall_thickness <= GOALS['wall_thickness']:
            lines.append('wall_thickness %.1f cells > %.0f' % (self.wall_thickness, GOALS['wall_thickness']))
        return lines

    def summary(self):
        return ('occupied near a surface %.1f %%, surface covered %.1f %%, walls %.1f cells (%.1f %% thicker than '
                '2, %.1f %% doubled), free floor mapped %.1f %% (%d occupied cells, %d surface points, %d '
                'reachable cells)' % (100 * self.occupied_near_surface, 100 * self.surface_covered,
                                      self.wall_thickness, 100 * self.thick_wall_share, 100 * self.doubled_wall_share,
                                      100 * self.free_floor_mapped, self.occupied_cells, self.surface_points,
                                      self.reachable_cells))


def _share(flags):
    return float(np.mean(flags)) if np.size(flags) else math.nan


def _component(mask, grid, start, what):
    """The 4-connected part of `mask` holding the point `start`, or ValueError."""
    cell = grid.to_cells(np.asarray(start[:2], dtype=float))
    if not grid.inside(cell) or not mask[cell[1], cell[0]]:
        raise ValueError('the start point (%.2f, %.2f) is not in the %s of the map\'s grid %r'
                         % (start[0], start[1], what, grid))
    labels, _ = ndimage.label(mask, structure=FOUR_CONNECTED)
    return labels == labels[cell[1], cell[0]]


def _lookup(grid, table, points, outside=False):
    """table[iy, ix] at the cells holding points (..., 2); `outside` off the grid."""
    cells = grid.to_cells(points)
    inside = grid.inside(cells)
    looked = np.full(inside.shape, outside, dtype=table.dtype)
    looked[inside] = table[cells[inside][:, 1], cells[inside][:, 0]]
    return looked


def _walls_along_normals(grid, occupied, truth_clearance, points, normals, config):
    """(thickness in cells, doubled) at each surface point: samples along its normal from
    -tolerance to doubled_reach. NaN thickness where no occupied cell lies within tolerance."""
    step = grid.resolution / 4.0
    offsets = np.arange(-config.tolerance, config.doubled_reach + step / 2, step)
    samples = points[:, None, :] + offsets[None, :, None] * normals[:, None, :]
    occ = _lookup(grid, occupied, samples)
    # Another real surface nearer than this one (by more than the tolerance and a cell's rounding): the
    # look ends there, so that the next obstacle's own wall is no double of this one.
    clearance = _lookup(grid, truth_clearance, samples, outside=np.inf)
    elsewhere = clearance + grid.resolution < offsets[None, :] - config.tolerance
    away = clearance > config.tolerance  # a double stands off every real surface (a nearer one is a thick wall)
    steps_to_new_cell = np.any(np.diff(grid.to_cells(samples), axis=1) != 0, axis=-1)  # (points, samples - 1)
    near = np.abs(offsets) <= config.tolerance + 1e-9
    thickness = np.full(len(points), np.nan)
    doubled = np.zeros(len(points), dtype=bool)
    for index in range(len(points)):
        hits = np.flatnonzero(occ[index] & near)
        if not len(hits):
            continue
        first = hits[np.argmin(np.abs(offsets[hits]))]  # the wall's sample nearest the true surface
        end = first
        while end + 1 < len(offsets) and occ[index, end + 1]:
            end += 1
        thickness[index] = 1 + np.count_nonzero(steps_to_new_cell[index, first:end])
        blocked = np.flatnonzero(elsewhere[index, end + 1:])
        stop = end + 1 + (blocked[0] if len(blocked) else len(offsets))
        doubled[index] = np.any(occ[index, end + 1:stop] & away[index, end + 1:stop])
    return thickness, doubled


def measure(grid, values, obstacles, start, config=QualityConfig(), bounds=None):
    """The MapQuality of int8 `values` [iy, ix] on `grid` (tb3_common.grid.Grid) against the world's
    `obstacles` (world_file.Obstacle), the robot having started at `start` (x, y) in the reachable space;
    the reachable floor within `bounds` (xmin, ymin, xmax, ymax) if given."""
    values = np.asarray(values)
    if values.shape != grid.shape:
        raise ValueError('values of shape %r on a grid of shape %r' % (values.shape, grid.shape))
    cut = in_plane(obstacles, config.scan_height)
    occupied = values >= OCCUPIED_AT
    free = (values >= 0) & (values <= FREE_UP_TO)
    centres = grid.all_centres()

    occupied_centres = centres[occupied]
    near = signed_distance(cut, occupied_centres) <= config.tolerance

    truth = rasterise(cut, grid)
    open_space = _component(~truth, grid, start, 'free space')
    truth_clearance = ndimage.distance_transform_edt(~truth) * grid.resolution
    points, normals = outline(cut, config.outline_spacing)
    probe = 1.5 * grid.resolution + 1e-3  # beyond the cell the surface itself lies in
    visible = _lookup(grid, open_space, points + probe * normals)
    points, normals = points[visible], normals[visible]
    if len(occupied_centres) and len(points):
        distance, _ = cKDTree(occupied_centres).query(points, distance_upper_bound=config.tolerance + 1e-9)
        covered = np.isfinite(distance)
    else:
        covered = np.zeros(len(points), dtype=bool)
    thickness, doubled = _walls_along_normals(grid, occupied, truth_clearance, points, normals, config)
    measured = np.isfinite(thickness)

    clearance = signed_distance(cut, centres.reshape(-1, 2)).reshape(grid.shape)
    reachable = _component(clearance > config.robot_radius, grid, start, 'reachable floor')
    if bounds is not None:
        xmin, ymin, xmax, ymax = bounds
        reachable &= ((centres[..., 0] >= xmin) & (centres[..., 0] <= xmax) & (centres[..., 1] >= ymin)
                      & (centres[..., 1] <= ymax))
    return MapQuality(
        occupied_near_surface=_share(near), surface_covered=_share(covered),
        wall_thickness=float(np.median(thickness[measured])) if measured.any() else math.nan,
        thick_wall_share=_share(thickness[measured] > 2), doubled_wall_share=_share(doubled[measured]),
        free_floor_mapped=_share(free[reachable]), occupied_cells=int(occupied.sum()),
        surface_points=int(len(points)), reachable_cells=int(reachable.sum()))


# --- the picture ---------------------------------------------------------------
PATH_COLORS = ('tab:blue', 'tab:orange', 'tab:green', 'tab:red', 'tab:purple', 'tab:brown')
CLOUD_COLORS = ('tab:pink', 'tab:olive', 'tab:cyan', 'tab:gray')
PIXELS_PER_METRE = 80  # a 5 m world in 400 px: every 0.05 m cell seen


def _grey(values):
    """Each cell as map_saver's PGM shows it, 0..1: occupied black, free white, unknown 205."""
    values = np.asarray(values).astype(np.int16)
    grey = np.full(values.shape, 205 / 255.0)
    grey[values >= OCCUPIED_AT] = 0.0
    grey[(values >= 0) & (values <= FREE_UP_TO)] = 254 / 255.0
    return grey


def render_png(filename, grid, values, obstacles=(), paths=(), title=None, scan_height=BURGER_SCAN_HEIGHT,
               clouds=()):
    """A PNG of the map in grey with the world's outline (at the lidar's height) in red over it,
    `paths` (a list of [(x, y), ...], or a dict label -> path) in colours, and `clouds` (a dict
    label -> [(x, y), ...]) as dots."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon
    from matplotlib.transforms import Affine2D

    width, height = grid.width * grid.resolution, grid.height * grid.resolution
    figure = Figure(figsize=(max(4.0, width * PIXELS_PER_METRE / 100.0), max(4.0, height * PIXELS_PER_METRE / 100.0)))
    FigureCanvasAgg(figure)
    axis = figure.add_subplot(1, 1, 1)
    x0, y0, yaw = grid.origin
    image = axis.imshow(_grey(values), cmap='gray', vmin=0.0, vmax=1.0, origin='lower', interpolation='nearest',
                        extent=(x0, x0 + width, y0, y0 + height))
    turn = Affine2D().rotate_around(x0, y0, yaw)
    image.set_transform(turn + axis.transData)
    for obstacle in in_plane(obstacles, scan_height):
        style = dict(fill=False, edgecolor='tab:red', linewidth=1.0)
        if obstacle.kind == 'box':
            half = np.array(obstacle.size[:2]) / 2.0
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half
            cos, sin = math.cos(obstacle.yaw), math.sin(obstacle.yaw)
            axis.add_patch(Polygon(corners.dot([[cos, sin], [-sin, cos]]) + obstacle.position[:2], closed=True,
                                   **style))
        else:
            axis.add_patch(Circle(obstacle.position[:2], obstacle.size[0], **style))
    labelled = paths.items() if isinstance(paths, dict) else ((None, path) for path in paths)
    for index, (label, path) in enumerate(labelled):
        path = np.asarray(path, dtype=float).reshape(-1, 2)
        axis.plot(path[:, 0], path[:, 1], color=PATH_COLORS[index % len(PATH_COLORS)], linewidth=1.5, label=label)
    for index, (label, points) in enumerate(dict(clouds).items()):
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        axis.scatter(points[:, 0], points[:, 1], s=1, alpha=0.4, color=CLOUD_COLORS[index % len(CLOUD_COLORS)],
                     label=label)
    if (isinstance(paths, dict) and paths) or clouds:
        axis.legend(loc='upper right', fontsize=8, framealpha=0.9)
    corners = turn.transform([(x0, y0), (x0 + width, y0), (x0 + width, y0 + height), (x0, y0 + height)])
    axis.set_xlim(corners[:, 0].min(), corners[:, 0].max())
    axis.set_ylim(corners[:, 1].min(), corners[:, 1].max())
    axis.set_aspect('equal')
    axis.set_xlabel('x (m)')
    axis.set_ylabel('y (m)')
    if title:
        axis.set_title(title, fontsize=10)
    figure.tight_layout()
    figure.savefig(filename, dpi=100)
