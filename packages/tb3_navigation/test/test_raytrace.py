"""tb3_navigation.raytrace against geometry: the cells a scan's beams cross, on plain and turned grids."""
import numpy as np
import pytest

from tb3_common.grid import Grid
from tb3_navigation.raytrace import STEP, crossed_cells, end_cells


def chords(grid, origin, end, samples=4000):
    """{flat cell index: length (cells) of the segment inside it}, measured by dense sampling."""
    start, stop = grid.to_cells_float(np.asarray(origin, dtype=float)), grid.to_cells_float(np.asarray(end))
    fractions = (np.arange(samples) + 0.5) / samples
    cells = np.floor(start + (stop - start) * fractions[:, None]).astype(int)
    inside = grid.inside(cells)
    flat = cells[inside, 1] * grid.width + cells[inside, 0]
    indices, counts = np.unique(flat, return_counts=True)
    return dict(zip(indices.tolist(), (counts * np.hypot(*(stop - start)) / samples).tolist()))


def touches(start, stop, cell):
    """Whether the segment from `start` to `stop` (cell units) meets the closed square of `cell` (ix, iy)
    (Liang-Barsky clipping)."""
    low, high = 0.0, 1.0
    for axis in (0, 1):
        span = stop[axis] - start[axis]
        for p, q in ((-span, start[axis] - cell[axis]), (span, cell[axis] + 1 - start[axis])):
            if p == 0:
                if q < 0:
                    return False
            elif p < 0:
                low = max(low, q / p)
            else:
                high = min(high, q / p)
    return low <= high


@pytest.mark.parametrize('origin', [(0.0, 0.0, 0.0), (-1.3, 0.4, 0.7)])
def test_crossed_cells_are_those_a_beam_passes_through_none_skipped_that_it_crosses_by_more_than_a_step(origin):
    grid = Grid(0.05, 70, 50, origin)
    rng = np.random.default_rng(4)
    sensor = grid.centres(np.array((30, 20))) + rng.uniform(-0.02, 0.02, 2)
    angles = np.linspace(0.0, 2.0 * np.pi, 90, endpoint=False)
    lengths = rng.uniform(0.05, 4.0, len(angles))  # some leave the grid
    ends = sensor + lengths[:, None] * np.column_stack((np.cos(angles), np.sin(angles)))
    found = set(crossed_cells(grid, sensor, ends).tolist())
    must = set()
    for end in ends:
        own_end = end_cells(grid, end[None, :]).tolist()
        # Samples lie at most STEP apart along a beam: a longer chord through a cell holds one.
        must.update(cell for cell, length in chords(grid, sensor, end).items()
                    if length > STEP * 1.01 and cell not in own_end)
    assert must <= found
    assert len(must) > 500
    # Nothing off the beams: each cell listed is met by one of them.
    start, stops = grid.to_cells_float(sensor), grid.to_cells_float(ends)
    for cell in found:
        assert any(touches(start, stop, divmod(cell, grid.width)[::-1]) for stop in stops), cell


def test_crossed_cells_leave_out_end_cells_and_segments_of_no_length_and_list_each_cell_once_in_order():
    grid = Grid(0.05, 20, 20)
    cells = crossed_cells(grid, (0.5, 0.5), [(0.5, 0.5), (0.88, 0.5), (0.88, 0.5)])
    assert cells.tolist() == [10 * 20 + ix for ix in range(10, 17)]  # the end cell, 17, left out
    assert crossed_cells(grid, (0.5, 0.5), [(0.5, 0.5)]).size == 0
    assert crossed_cells(grid, (0.5, 0.5), np.zeros((0, 2))).size == 0
