"""Robots' occupancy grids merged into one grid of the world frame. Numpy only, no ROS.

Each robot's map (a tb3_common.grid.Grid and its int8 values) comes with
its placement: the pose (x, y, yaw) of the map's frame in the world frame.
The merged grid is axis-aligned in the world frame, at the first map's
resolution, its cells on the lattice of the first map's placed origin (so
a first map that is not turned is copied cell for cell), and just large
enough to hold every placed map.

Cells combine as the original's compositor combines them (cv::max over the
warped grids, unknown -1 everywhere else): the highest value wins. Known
beats unknown (0..100 > -1) and occupied beats free (100 > 0): a wall seen
by one robot stays a wall where another saw floor.

Each merged cell takes the value of the source cell its centre falls in
(nearest neighbour, as the original's INTER_NEAREST warp). A source finer
than the merged grid also puts each of its cells into the merged cell its
centre falls in, so that a wall one fine cell thick is not stepped over.

The original (hrnr/m-explore, noetic) places the grids as images: it
ignores each map's origin and resolution, reads the init pose's translation
in cells, not metres, and centres the merged map on the world's origin.
Here every map lies where its metadata and its placement put it.
"""
import math

import numpy as np

from tb3_common import pose2d
from tb3_common.grid import UNKNOWN, Grid

MAX_CELLS = 16000000  # a merged grid larger than this (4000 x 4000) is refused: placements far apart
EDGE = 1e-6           # cells: a map edge this close to a lattice line lies on it (no extra row of cells)


def placed(grid, placement):
    """`grid` as it lies in the world frame when its frame sits at `placement` (x, y, yaw) there."""
    return Grid(grid.resolution, grid.width, grid.height, tuple(pose2d.compose(placement, grid.origin)))


def corners(grid):
    """The four outer corners (4, 2) of `grid` in its frame."""
    width, height = grid.width * grid.resolution, grid.height * grid.resolution
    return pose2d.transform_points(grid.origin, [(0.0, 0.0), (width, 0.0), (width, height), (0.0, height)])


def _cell_box(grid, points):
    """The cells (ix0, iy0, ix1, iy1), end exclusive, of `grid`'s lattice spanning `points` (n, 2)."""
    cells = grid.to_cells_float(points)
    low = np.floor(cells.min(axis=0) + EDGE).astype(int)
    high = np.ceil(cells.max(axis=0) - EDGE).astype(int)
    return low[0], low[1], high[0], high[1]


def merged_grid(grids, max_cells=MAX_CELLS):
    """The axis-aligned Grid holding every placed grid of `grids` (see the module); ValueError if it would
    have more than `max_cells` cells."""
    first = grids[0]
    lattice = Grid(first.resolution, 1, 1, (first.origin[0], first.origin[1], 0.0))
    ix0, iy0, ix1, iy1 = _cell_box(lattice, np.concatenate([corners(grid) for grid in grids]))
    width, height = max(1, ix1 - ix0), max(1, iy1 - iy0)
    if width * height > max_cells:
        raise ValueError('the merged map would be %d x %d cells at %g m (more than %d): the maps are placed '
                         '%.0f m apart' % (width, height, first.resolution, max_cells,
                                           max(width, height) * first.resolution))
    return Grid(first.resolution, width, height,
                (first.origin[0] + ix0 * first.resolution, first.origin[1] + iy0 * first.resolution, 0.0))


def _sample(merged, grid, source, values):
    """Each merged cell within `source`'s box takes the higher of its value and the source cell under its centre."""
    ix0, iy0, ix1, iy1 = _cell_box(grid, corners(source))
    ix0, iy0, ix1, iy1 = max(ix0, 0), max(iy0, 0), min(ix1, grid.width), min(iy1, grid.height)
    if ix0 >= ix1 or iy0 >= iy1:
        return
    iy, ix = np.mgrid[iy0:iy1, ix0:ix1]
    cells = source.to_cells(grid.centres(np.stack((ix, iy), axis=-1)))
    inside = source.inside(cells)
    window = merged[iy0:iy1, ix0:ix1]
    window[inside] = np.maximum(window[inside], values[cells[inside][:, 1], cells[inside][:, 0]])


def _splat(merged, grid, source, values):
    """Each source cell raises the merged cell its centre falls in to its value."""
    cells = grid.to_cells(source.all_centres()).reshape(-1, 2)
    inside = grid.inside(cells)
    np.maximum.at(merged, (cells[inside][:, 1], cells[inside][:, 0]), values.reshape(-1)[inside])


def merge(maps, max_cells=MAX_CELLS):
    """(Grid, int8 values) merged from `maps`, a list of (grid, values [iy, ix], placement (x, y, yaw));
    ValueError if there is none, a placement is not finite or the result would be too large."""
    if not maps:
        raise ValueError('no map to merge')
    sources = []
    for grid, values, placement in maps:
        if not all(math.isfinite(value) for value in placement):
            raise ValueError('placement %s is not finite' % (tuple(placement),))
        values = np.asarray(values, dtype=np.int8)
        if values.shape != grid.shape:
            raise ValueError('values of shape %r on a grid of shape %r' % (values.shape, grid.shape))
        sources.append((placed(grid, placement), values))
    grid = merged_grid([source for source, _ in sources], max_cells)
    merged = np.full(grid.shape, UNKNOWN, dtype=np.int8)
    for source, values in sources:
        _sample(merged, grid, source, values)
        if source.resolution < grid.resolution * (1.0 - EDGE):
            _splat(merged, grid, source, values)
    return grid, merged


def apply_update(values, x, y, width, height, data):
    """A copy of `values` [iy, ix] with the block of an OccupancyGridUpdate (its x, y, width, height and
    row-major data) written in, and whether the block had to be cut to fit; ValueError if it cannot be
    applied (negative corner, data of the wrong size)."""
    if x < 0 or y < 0:
        raise ValueError('negative coordinates, invalid update. x: %d, y: %d' % (x, y))
    block = np.frombuffer(data, dtype=np.int8) if isinstance(data, bytes) else np.asarray(data, dtype=np.int8)
    if block.size != width * height:
        raise ValueError('an update of %d x %d cells with %d values' % (width, height, block.size))
    block = block.reshape(height, width)
    rows, columns = max(0, min(height, values.shape[0] - y)), max(0, min(width, values.shape[1] - x))
    updated = np.array(values, dtype=np.int8, copy=True)
    updated[y:y + rows, x:x + columns] = block[:rows, :columns]
    return updated, (rows, columns) != (height, width)
