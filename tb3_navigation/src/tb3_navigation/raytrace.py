"""The cells a beam crosses on a grid, for every beam of a scan at once. No ROS here.

Mapping marks the cells a beam crossed as free and its end cell as
occupied; a costmap clears what a beam crossed. Each segment is sampled at
`step` (a share of a cell; a quarter by default, so that a beam misses no
cell it crosses by more than a corner) and the cells are listed once per
scan, as gmapping and costmap_2d count a scan once per cell.
"""
import numpy as np

STEP = 0.25  # of a cell, between two samples of a beam


def crossed_cells(grid, origin, ends, step=STEP):
    """Flat indices (into a grid.shape array) of the cells on the grid crossed by
    the segments from `origin` (x, y) to each of `ends` (n, 2), their end cells
    left out; each listed once."""
    ends = np.asarray(ends, dtype=float).reshape(-1, 2)
    if not len(ends):
        return np.zeros(0, dtype=np.intp)
    start = grid.to_cells_float(np.asarray(origin, dtype=float))
    stops = grid.to_cells_float(ends)
    lengths = np.hypot(*(stops - start).T)
    samples = max(1, int(np.ceil(lengths.max() / step)))
    fractions = np.arange(samples) / float(samples)
    # (n, samples, 2) points along each segment, each stopping short of its end.
    points = start + (stops - start)[:, None, :] * fractions[None, :, None]
    along = fractions[None, :] * lengths[:, None]
    cells = np.floor(points).astype(np.intp)
    end_cells = np.floor(stops).astype(np.intp)
    keep = (along < lengths[:, None] - 1e-9) & grid.inside(cells) & np.any(cells != end_cells[:, None, :], axis=-1)
    return np.unique(cells[keep][:, 1] * grid.width + cells[keep][:, 0])


def end_cells(grid, ends):
    """Flat indices of the cells on the grid that hold `ends` (n, 2), each listed once."""
    cells = grid.to_cells(np.asarray(ends, dtype=float).reshape(-1, 2))
    cells = cells[grid.inside(cells)]
    return np.unique(cells[:, 1] * grid.width + cells[:, 0])
