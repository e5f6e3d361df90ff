"""The cells a beam crosses on a grid, for every beam of a scan at once. No ROS here.

Mapping marks the cells a beam crossed as free and its end cell as
occupied; a costmap clears what a beam crossed. Each segment is sampled at
`step` (a share of a cell; a quarter by default, so that a beam misses no
cell it crosses by more than a corner) and the cells are listed once per
scan, as costmap_2d clears a cell once per scan (gmapping counts a visit
per beam instead; tb3_navigation.occupancy says why we do not).
"""
import numpy as np

STEP = 0.25  # of a cell, between two samples of a beam


def crossed_cells(grid, origin, ends, step=STEP):
    """Flat indices (into a grid.shape array) of the cells on the grid crossed by
    the segments from `origin` (x, y) to each of `ends` (n, 2), their end cells
    left out; each listed once, in increasing order."""
    ends = np.asarray(ends, dtype=float).reshape(-1, 2)
    if not len(ends):
        return np.zeros(0, dtype=np.intp)
    start = grid.to_cells_float(np.asarray(origin, dtype=float))
    stops = grid.to_cells_float(ends)
    span = stops - start
    lengths = np.hypot(span[:, 0], span[:, 1])
    samples = max(1, int(np.ceil(lengths.max() / step)))
    fractions = np.arange(samples) / float(samples)
    # (n, samples) cells along each segment, each stopping short of its end; x and y
    # apart, not as (n, samples, 2): the same work on half the memory traffic.
    ix = np.floor(start[0] + span[:, 0:1] * fractions).astype(np.intp)
    iy = np.floor(start[1] + span[:, 1:2] * fractions).astype(np.intp)
    end_x, end_y = np.floor(stops[:, 0:1]).astype(np.intp), np.floor(stops[:, 1:2]).astype(np.intp)
    keep = ((ix != end_x) | (iy != end_y)) & (ix >= 0) & (ix < grid.width) & (iy >= 0) & (iy < grid.height)
    if lengths.min() <= 1e-9:
        keep &= (lengths > 1e-9)[:, None]  # a segment of no length crosses nothing
    # Marking a grid-sized mask lists each cell once, sorted, without np.unique's sort.
    crossed = np.zeros(grid.width * grid.height, dtype=bool)
    crossed[iy[keep] * grid.width + ix[keep]] = True
    return np.flatnonzero(crossed)


def end_cells(grid, ends):
    """Flat indices of the cells on the grid that hold `ends` (n, 2), each listed once."""
    cells = grid.to_cells(np.asarray(ends, dtype=float).reshape(-1, 2))
    cells = cells[grid.inside(cells)]
    return np.unique(cells[:, 1] * grid.width + cells[:, 0])
