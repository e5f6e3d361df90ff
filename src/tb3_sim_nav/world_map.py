"""A world file's obstacles as the lidar sees them: a cut at one height, in 2-D. No ROS, no pybullet.

What a planar lidar at `height` above the ground can see of a world is the
cut of its boxes and cylinders at that height: an obstacle whose height range
does not cover it (a table top, the bar above a door, a low step) is not
there for the lidar, nor for a map made from it. From that cut come the maps
shipped for ROBOTIS' worlds (a cell is occupied where an obstacle covers any
part of it, so that a wall thinner than a cell is not lost) and the measures
of a map against the truth (each point's distance to the nearest surface; the
outline of each obstacle).
"""
import math

import numpy as np

from tb3_common.grid import FREE, OCCUPIED, UNKNOWN, Grid

BURGER_SCAN_HEIGHT = 0.182  # m: base_scan above the ground on the Burger (and lower on the Waffles: 0.132)


def in_plane(obstacles, height=BURGER_SCAN_HEIGHT):
    """The obstacles whose height range covers `height`."""
    cut = []
    for obstacle in obstacles:
        tall = obstacle.size[2] if obstacle.kind == 'box' else obstacle.size[1]
        bottom = obstacle.position[2] - tall / 2.0
        if bottom <= height <= bottom + tall:
            cut.append(obstacle)
    return cut


def _local(obstacle, points):
    """Points (n, 2) in the obstacle's own frame (centre, turned by its yaw)."""
    cos, sin = math.cos(obstacle.yaw), math.sin(obstacle.yaw)
    dx, dy = points[:, 0] - obstacle.position[0], points[:, 1] - obstacle.position[1]
    return cos * dx + sin * dy, -sin * dx + cos * dy


def signed_distance(obstacles, points):
    """Distance (n,) from each point (n, 2) to the nearest obstacle's outline in
    the plane, negative inside an obstacle (the smallest of the obstacles' signed
    distances: where obstacles overlap, a point inside one and near another's
    outside is inside); +inf if there is none."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    nearest = np.full(len(points), np.inf)
    for obstacle in obstacles:
        x, y = _local(obstacle, points)
        if obstacle.kind == 'box':
            half_x, half_y = obstacle.size[0] / 2.0, obstacle.size[1] / 2.0
            out_x, out_y = np.abs(x) - half_x, np.abs(y) - half_y
            outside = np.hypot(np.maximum(out_x, 0.0), np.maximum(out_y, 0.0))
            distance = np.where((out_x <= 0) & (out_y <= 0), np.maximum(out_x, out_y), outside)
        else:
            distance = np.hypot(x, y) - obstacle.size[0]
        nearest = np.minimum(nearest, distance)
    return nearest


def occupied(obstacles, points):
    """True (n,) where a point (n, 2) lies inside an obstacle (or on its outline)."""
    return signed_distance(obstacles, points) <= 0.0


def outline(obstacles, spacing=0.02):
    """Points (n, 2) every `spacing` m along each obstacle's outline, and their outward normals (n, 2)."""
    points, normals = [], []
    for obstacle in obstacles:
        cos, sin = math.cos(obstacle.yaw), math.sin(obstacle.yaw)
        if obstacle.kind == 'box':
            half = (obstacle.size[0] / 2.0, obstacle.size[1] / 2.0)
            local, outward = [], []
            for axis in (0, 1):
                other = 1 - axis
                count = max(2, int(math.ceil(2 * half[other] / spacing)) + 1)
                along = np.linspace(-half[other], half[other], count)
                for side in (-1.0, 1.0):
                    face = np.zeros((count, 2))
                    face[:, axis], face[:, other] = side * half[axis], along
                    normal = np.zeros((count, 2))
                    normal[:, axis] = side
                    local.append(face)
                    outward.append(normal)
            local, outward = np.concatenate(local), np.concatenate(outward)
        else:
            count = max(8, int(math.ceil(2 * math.pi * obstacle.size[0] / spacing)))
            angles = np.arange(count) * 2 * math.pi / count
            outward = np.stack((np.cos(angles), np.sin(angles)), axis=-1)
            local = outward * obstacle.size[0]
        rotation = np.array([[cos, -sin], [sin, cos]])
        points.append(local.dot(rotation.T) + obstacle.position[:2])
        normals.append(outward.dot(rotation.T))
    if not points:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.concatenate(points), np.concatenate(normals)


def bounds(obstacles, margin=0.0):
    """(xmin, ymin, xmax, ymax) of the obstacles' outlines, widened by `margin`."""
    points, _ = outline(obstacles, spacing=0.05)
    if not len(points):
        return -margin, -margin, margin, margin
    low, high = points.min(axis=0) - margin, points.max(axis=0) + margin
    return low[0], low[1], high[0], high[1]


# m: an obstacle must reach this far into a cell to cover it. Not merely touching: turtlebot3_world's
# west wall (yaw 4.7124 for 3 pi / 2) leans 3e-5 m over a cell edge along its 3 m and would gain a cell row.
OVERLAP = 1e-3


def rasterise(obstacles, grid):
    """True [iy, ix] where an obstacle covers any part of a cell of `grid` (a tb3_common.grid.Grid):
    exact for boxes (separating axes) and cylinders (the cell's nearest point)."""
    covered = np.zeros(grid.shape, dtype=bool)
    half = grid.resolution / 2.0
    for obstacle in obstacles:
        centre = grid.to_grid_frame(obstacle.position[:2])
        turn = obstacle.yaw - grid.origin[2]
        cos, sin = abs(math.cos(turn)), abs(math.sin(turn))
        if obstacle.kind == 'box':
            a, b = obstacle.size[0] / 2.0, obstacle.size[1] / 2.0
            reach = np.array([cos * a + sin * b, sin * a + cos * b])
        else:
            reach = np.array([obstacle.size[0]] * 2)
        low = np.maximum(np.floor((centre - reach) / grid.resolution).astype(int), 0)
        high = np.minimum(np.floor((centre + reach) / grid.resolution).astype(int), (grid.width - 1, grid.height - 1))
        if np.any(high < low):
            continue  # off the grid
        iy, ix = np.mgrid[low[1]:high[1] + 1, low[0]:high[0] + 1]
        dx = (ix + 0.5) * grid.resolution - centre[0]
        dy = (iy + 0.5) * grid.resolution - centre[1]
        if obstacle.kind == 'box':
            along = math.cos(turn) * dx + math.sin(turn) * dy
            across = -math.sin(turn) * dx + math.cos(turn) * dy
            spread = half * (cos + sin)  # the cell's half-width along the box's axes
            hit = ((np.abs(dx) < half + reach[0] - OVERLAP) & (np.abs(dy) < half + reach[1] - OVERLAP)
                   & (np.abs(along) < a + spread - OVERLAP) & (np.abs(across) < b + spread - OVERLAP))
        else:
            gap_x, gap_y = np.maximum(np.abs(dx) - half, 0.0), np.maximum(np.abs(dy) - half, 0.0)
            hit = np.hypot(gap_x, gap_y) < obstacle.size[0] - OVERLAP
        covered[iy[hit], ix[hit]] = True
    return covered


def map_of_world(obstacles, resolution=0.05, margin=0.5, height=BURGER_SCAN_HEIGHT, start=None):
    """(Grid, int8 values) of the world's cut at `height`: 100 where an obstacle
    covers a cell, 0 elsewhere; the grid spans the cut's outline plus `margin`,
    its corner on a multiple of `resolution` (walls at round coordinates then
    fall on cell edges, not across cells).

    With `start` (x, y), the map a perfect SLAM run from there would make: free
    the cells reachable from it, occupied the covered cells next to those (the
    surfaces a lidar sees, one cell thick, as a SLAM's map has them), unknown
    the rest (obstacles' insides, walls' far sides). Localization needs that:
    matched to a map whose walls are two or more cells thick, a scan was 2 to 4
    cm off the truth; to such a map, as to a SLAM's, under 1.5 cm."""
    cut = in_plane(obstacles, height)
    xmin, ymin, xmax, ymax = bounds(cut, margin)
    # Without start, cell edges on multiples of `resolution`: walls at round coordinates fill whole
    # cells. With start, cell centres there: a surface at a round coordinate then runs through the
    # centres of one row of cells, the cells marked, and nothing is biased. On edges it ran between
    # two rows, the open side's was marked, and every wall stood half a cell (2.5 cm) into the room:
    # amcl sat 2.3 cm off the truth where one wall dominated the scan (2026-11-24).
    shift = resolution / 2.0 if start is not None else 0.0
    xmin, ymin = (round(math.floor(value / resolution) * resolution - shift, 9) for value in (xmin, ymin))
    grid = Grid.around(resolution, xmin, ymin, xmax, ymax)
    covered = rasterise(cut, grid)
    if start is None:
        return grid, np.where(covered, OCCUPIED, FREE).astype(np.int8)
    from scipy import ndimage
    cell = grid.to_cells(np.asarray(start, dtype=float))
    # A lidar's hits mark the cells a surface runs through, not those it merely grazes: the cells
    # whose centre lies within half a cell of a surface (each pillar a ring, not a square).
    distance = signed_distance(cut, grid.all_centres().reshape(-1, 2)).reshape(grid.shape)
    surface = np.abs(distance) <= grid.resolution / 2.0
    open_space = (distance > grid.resolution / 2.0) & ~covered
    if not grid.inside(cell) or not open_space[cell[1], cell[0]]:
        raise ValueError('start (%g, %g) is not in the free space of the map' % tuple(start))
    regions, _ = ndimage.label(open_space)
    reachable = regions == regions[cell[1], cell[0]]
    near = ndimage.binary_dilation(reachable, structure=ndimage.generate_binary_structure(2, 2))
    seen = near & ~reachable & (surface | covered)
    return grid, np.where(reachable, FREE, np.where(seen, OCCUPIED, UNKNOWN)).astype(np.int8)


def ray_cast(obstacles, origin, angles, max_range=math.inf):
    """Distance (n,) along each ray from `origin` (x, y) at `angles` (n,) (rad, in the
    frame) to the first obstacle outline it meets; inf if none within `max_range`.
    What a planar lidar at `origin` would read of the cut, without noise."""
    angles = np.asarray(angles, dtype=float).reshape(-1)
    nearest = np.full(angles.size, np.inf)
    for obstacle in obstacles:
        x, y = _local(obstacle, np.asarray(origin, dtype=float).reshape(1, 2))
        heading = angles - obstacle.yaw
        dx, dy = np.cos(heading), np.sin(heading)
        if obstacle.kind == 'box':
            near, far = np.full(angles.size, -np.inf), np.full(angles.size, np.inf)
            for start, step, half in ((x[0], dx, obstacle.size[0] / 2.0), (y[0], dy, obstacle.size[1] / 2.0)):
                with np.errstate(divide='ignore', invalid='ignore'):
                    first, second = (-half - start) / step, (half - start) / step
                # A ray parallel to this pair of faces is inside the slab all along, or never.
                inside = abs(start) <= half
                parallel = step == 0.0
                near = np.maximum(near, np.where(parallel, -np.inf if inside else np.inf, np.minimum(first, second)))
                far = np.minimum(far, np.where(parallel, np.inf if inside else -np.inf, np.maximum(first, second)))
            hit = np.where((near <= far) & (far >= 0.0), np.maximum(near, 0.0), np.inf)
        else:
            along = -(x[0] * dx + y[0] * dy)
            chord = along * along - (x[0] * x[0] + y[0] * y[0] - obstacle.size[0] ** 2)
            root = np.sqrt(np.maximum(chord, 0.0))
            entry = along - root
            inside = (entry < 0.0) & (along + root >= 0.0)  # the origin within the circle: a hit at once
            hit = np.where(chord < 0.0, np.inf, np.where(entry >= 0.0, entry, np.where(inside, 0.0, np.inf)))
        nearest = np.minimum(nearest, hit)
    return np.where(nearest <= max_range, nearest, np.inf)
