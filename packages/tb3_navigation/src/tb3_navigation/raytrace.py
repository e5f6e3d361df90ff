"""The cells a beam crosses on a grid, for every beam of a scan at once. No ROS here.

Mapping marks the cells a beam crossed as free and its end cell as
occupied; a costmap clears what a beam crossed. Each segment is sampled at
`step` (a share of a cell; a quarter by default, so that a beam misses no
cell it crosses by more than a corner) and the cells are listed once per
scan, as costmap_2d clears a cell once per scan (gmapping counts a visit
per beam instead; tb3_navigation.occupancy says why we do not).
"""
import math

import numba
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
    # Marking a grid-sized mask lists each cell once, sorted, without np.unique's sort.
    crossed = np.zeros(grid.width * grid.height, dtype=np.bool_)
    _mark_crossed(float(start[0]), float(start[1]), grid.to_cells_float(ends), step, grid.width, grid.height,
                  crossed)
    return np.flatnonzero(crossed)


@numba.njit(cache=True, nogil=True)
def _mark_crossed(x0, y0, stops, step, width, height, crossed):  # pragma: no cover
    """Marks in `crossed` the cells of the samples along each segment from (x0, y0) to a row of `stops`
    (cell units): every segment sampled at the same fractions k / samples of it, as many as the longest
    needs, so that it steps at most `step`; the end cell and cells off the grid left out. Why compiled:
    numpy's (beams x samples) temporaries were most of the clearing, and each of move_base's costmaps
    clears with every scan (timings in doc/speed.md)."""
    longest = 0.0
    for i in range(len(stops)):
        longest = max(longest, math.hypot(stops[i, 0] - x0, stops[i, 1] - y0))
    samples = max(1, int(math.ceil(longest / step)))
    for i in range(len(stops)):
        span_x, span_y = stops[i, 0] - x0, stops[i, 1] - y0
        if math.hypot(span_x, span_y) <= 1e-9:
            continue  # a segment of no length crosses nothing
        end_x, end_y = math.floor(stops[i, 0]), math.floor(stops[i, 1])
        for k in range(samples):
            fraction = k / samples
            ix, iy = math.floor(x0 + span_x * fraction), math.floor(y0 + span_y * fraction)
            if (ix != end_x or iy != end_y) and 0 <= ix < width and 0 <= iy < height:
                crossed[iy * width + ix] = True


def end_cells(grid, ends):
    """Flat indices of the cells on the grid that hold `ends` (n, 2), each listed once."""
    cells = grid.to_cells(np.asarray(ends, dtype=float).reshape(-1, 2))
    cells = cells[grid.inside(cells)]
    return np.unique(cells[:, 1] * grid.width + cells[:, 0])
