"""tb3_navigation.occupancy: hit and visit counts from scans, out as gmapping's OccupancyGrid data."""
import math

import numpy as np
import pytest

from tb3_common.grid import Grid
from tb3_navigation.occupancy import OccupancyGrid
from tb3_navigation.scan import Scan

RANGE_MIN, RANGE_MAX = 0.12, 3.5  # the LDS-01's
MAX_URANGE = 3.0  # turtlebot3_slam's maxUrange


def one_beam(range_, angle=0.0):
    return Scan(angle, 0.1, [range_], RANGE_MIN, RANGE_MAX)


def cell(grid_map, x, y):
    """(row, column) of the cell holding (x, y)."""
    ix, iy = grid_map.grid.to_cells(np.array([x, y]))
    return iy, ix


def value_at(grid_map, x, y, **kwargs):
    return int(grid_map.values(**kwargs)[cell(grid_map, x, y)])


@pytest.fixture
def grid_map():
    return OccupancyGrid.around(0.05, -5.0, -5.0, 5.0, 5.0)


def test_the_grid_spans_xmin_to_xmax_from_origin_xmin_ymin():
    grid_map = OccupancyGrid.around(0.05, -10.0, -10.0, 10.0, 10.0)  # turtlebot3_slam's extent
    assert grid_map.grid == Grid(0.05, 400, 400, (-10.0, -10.0, 0.0))
    assert grid_map.values().dtype == np.int8
    assert np.all(grid_map.values() == -1)


def test_a_hit_frees_the_cells_before_it_and_occupies_its_own(grid_map):
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(2.0), MAX_URANGE, RANGE_MAX)
    assert value_at(grid_map, 2.02, 0.02) == 100
    for x in np.arange(0.05, 1.95, 0.05):
        assert value_at(grid_map, x + 0.02, 0.02) == 0
    assert value_at(grid_map, 2.12, 0.02) == -1  # behind the wall: not seen
    assert value_at(grid_map, 1.0, 0.3) == -1  # beside the beam: not seen
    assert grid_map.hit_means()[cell(grid_map, 2.02, 0.02)] == pytest.approx([2.02, 0.02])


@pytest.mark.parametrize('range_', [3.2, math.inf, RANGE_MAX])
def test_a_beam_past_max_urange_only_clears_up_to_it(grid_map, range_):
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(range_), MAX_URANGE, RANGE_MAX)
    assert value_at(grid_map, 2.92, 0.02) == 0
    assert value_at(grid_map, 3.12, 0.02) == -1
    assert not np.any(grid_map.values() == 100)


@pytest.mark.parametrize('range_', [math.nan, -math.inf, 0.05, 0.0])
def test_a_beam_with_no_reading_changes_nothing(grid_map, range_):
    assert grid_map.add_scan((0.02, 0.02, 0.0), one_beam(range_), MAX_URANGE, RANGE_MAX) == 0
    assert np.all(grid_map.values() == -1)


def test_a_hit_past_max_range_is_dropped_whole(grid_map):
    """gmapping's maxRange: a reading longer than it does not even clear."""
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(3.2), MAX_URANGE, 3.1)
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(math.inf, angle=1.0), MAX_URANGE, 3.1)
    assert np.all(grid_map.values() == -1)


def test_occupied_above_occ_thresh_of_the_scans_that_saw_the_cell(grid_map):
    """gmapping's rule: hits / visits > occ_thresh (0.25) is 100, else 0."""
    wall = (1.02, 0.02)
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(1.0), MAX_URANGE, RANGE_MAX)
    for _ in range(3):  # the wall cell seen through three times: 1 hit in 4
        grid_map.add_scan((0.02, 0.02, 0.0), one_beam(2.0), MAX_URANGE, RANGE_MAX)
    assert value_at(grid_map, *wall) == 0
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(1.0), MAX_URANGE, RANGE_MAX)  # 2 in 5
    assert value_at(grid_map, *wall) == 100
    assert value_at(grid_map, *wall, occ_thresh=0.5) == 0


def test_a_scan_counts_once_per_cell_and_a_hit_wins_over_a_grazing_beam(grid_map):
    """Two beams end in the same cell, a third passes through it to end farther:
    the cell counts one visit and one hit from the scan."""
    sensor = (0.0, 0.0, 0.0)
    wall_cell = cell(grid_map, 1.02, 0.02)
    angles = np.array([math.atan2(0.02, 1.02), math.atan2(0.04, 1.04), math.atan2(0.03, 1.4)])
    ranges = [math.hypot(1.02, 0.02), math.hypot(1.04, 0.04), math.hypot(1.4, 0.03)]
    scan = Scan(0.0, 1.0, ranges, RANGE_MIN, RANGE_MAX)
    scan.angles = angles  # three beams aimed by hand, not evenly spread
    grid_map.add_scan(sensor, scan, MAX_URANGE, RANGE_MAX)
    assert grid_map.visits[wall_cell] == 1
    assert grid_map.hits[wall_cell] == 1
    assert grid_map.hit_means()[wall_cell] == pytest.approx([1.03, 0.03])


def test_clear_forgets_everything(grid_map):
    grid_map.add_scan((0.02, 0.02, 0.0), one_beam(2.0), MAX_URANGE, RANGE_MAX)
    grid_map.clear()
    assert np.all(grid_map.values() == -1) and grid_map.scans == 0
    assert np.all(np.isnan(grid_map.hit_means()))
