"""tb3_navigation.costmap's costs against costmap_2d's rules: the footprint's radii, inflation's formula
cell for cell, the static layer, the footprint's cost, the OccupancyGrid translation and the checks of
its parameters; what move_base's parameters add (robot_radius's polygon, inflation changed on a running
costmap, inflate_unknown); and costs inflated again only, and exactly, where the layers changed. The
obstacle layer (marking and clearing from scans, the rolling window, the resets) is
test_costmap_obstacles.py's (no ROS)."""
import math

import numpy as np
import pytest
from costmap_maps import RESOLUTION, box, empty_map

from tb3_common.grid import Grid
from tb3_harness.nav_sim import SCAN_POSE, Lidar
from tb3_navigation.costmap import (
    BURGER_FOOTPRINT,
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    WAFFLE_FOOTPRINT,
    Costmap,
    CostmapConfig,
    occupancy_values,
)
from tb3_navigation.footprint import circle_footprint, footprint_radii


def expected_cost(cells, inscribed, scaling=3.0, radius=1.0):
    """costmap_2d's computeCost, written out from its source, for a distance in cells."""
    if cells == 0:
        return LETHAL_OBSTACLE
    if cells * RESOLUTION <= inscribed:
        return INSCRIBED_INFLATED_OBSTACLE
    if cells > math.ceil(radius / RESOLUTION - 1e-9):
        return 0
    return int(252 * math.exp(-scaling * (cells * RESOLUTION - inscribed)))


# --- footprint and inflation ------------------------------------------------------------

def test_radii_of_turtlebot3_footprints_padded_by_one_centimetre():
    config = CostmapConfig()
    assert config.footprint == BURGER_FOOTPRINT
    inscribed, circumscribed = footprint_radii(config.padded_footprint)
    assert inscribed == pytest.approx(0.041 + 0.01)  # base_footprint to the front edge
    assert circumscribed == pytest.approx(math.hypot(0.115, 0.115))
    inscribed, circumscribed = footprint_radii(CostmapConfig(footprint=WAFFLE_FOOTPRINT).padded_footprint)
    assert inscribed == pytest.approx(0.087)
    assert circumscribed == pytest.approx(math.hypot(0.215, 0.165))


@pytest.mark.parametrize('scaling, radius', [(3.0, 1.0), (10.0, 0.55)])
def test_inflation_follows_costmap_2d_formula_cell_for_cell(scaling, radius):
    grid, data = empty_map()
    data[40, 40] = 100
    costmap = Costmap(grid, CostmapConfig(cost_scaling_factor=scaling, inflation_radius=radius), static=data)
    iy, ix = np.mgrid[0:grid.height, 0:grid.width]
    distances = np.hypot(ix - 40, iy - 40)
    expected = np.vectorize(lambda d: expected_cost(d, costmap.inscribed_radius, scaling, radius))(distances)
    assert np.array_equal(costmap.costs, expected)
    # A few by hand: one cell (0.05 m) is inside the Burger's inscribed 0.051 m; at 20 cells the
    # 1 m inflation radius ends with 252 exp(-3 (1 - 0.051)) = 14.6.
    if scaling == 3.0:
        assert costmap.costs[40, 41] == INSCRIBED_INFLATED_OBSTACLE
        assert costmap.costs[41, 41] == 237
        assert costmap.costs[40, 60] == 14 and costmap.costs[40, 61] == 0


def test_inflation_takes_the_nearest_of_several_obstacles_and_keeps_higher_costs():
    grid, data = empty_map()
    data[40, 30] = data[40, 50] = 100
    costmap = Costmap(grid, CostmapConfig(), static=data)
    for ix in range(31, 50):
        nearest = min(ix - 30, 50 - ix)
        assert costmap.costs[40, ix] == expected_cost(nearest, costmap.inscribed_radius)


# --- the static layer -----------------------------------------------------------------------

def test_static_layer_as_turtlebot3_sets_it_up():
    grid, data = empty_map(width=10, height=1, origin=(0.0, 0.0, 0.0))
    data[0, :] = [100, 99, 65, 0, -1, -1, 0, 0, 0, 0]
    no_inflation = dict(inflation_radius=0.0)
    turtlebot3 = Costmap(grid, CostmapConfig(**no_inflation), static=data)
    assert list(turtlebot3.costs[0, :6]) == [LETHAL_OBSTACLE, 0, 0, 0, 0, 0]  # unknown ends up free
    assert list(turtlebot3.static[0, :6]) == [LETHAL_OBSTACLE, 0, 0, 0, NO_INFORMATION, NO_INFORMATION]
    tracking = Costmap(grid, CostmapConfig(track_unknown_space=True, **no_inflation), static=data)
    assert list(tracking.costs[0, :6]) == [LETHAL_OBSTACLE, 0, 0, 0, NO_INFORMATION, NO_INFORMATION]
    lower = Costmap(grid, CostmapConfig(lethal_cost_threshold=65, **no_inflation), static=data)
    assert list(lower.costs[0, :4]) == [LETHAL_OBSTACLE, LETHAL_OBSTACLE, LETHAL_OBSTACLE, 0]


def test_unknown_cells_stay_unknown_under_inflation_unless_inscribed():
    grid, data = empty_map(width=10, height=1, origin=(0.0, 0.0, 0.0), value=-1)
    data[0, 0] = 100
    costmap = Costmap(grid, CostmapConfig(track_unknown_space=True), static=data)
    assert list(costmap.costs[0, :4]) == [LETHAL_OBSTACLE, INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION,
                                          NO_INFORMATION]


# --- the footprint's cost -------------------------------------------------------------------

def test_footprint_cost_is_the_highest_cost_under_its_outline_and_refuses_lethal_unknown_and_off_map():
    grid, data = empty_map(width=40, height=40, origin=(-1.0, -1.0, 0.0))
    data[20, 26] = 100  # the cell at x 0.30..0.35, y 0.0..0.05
    data[5, 5] = -1
    costmap = Costmap(grid, CostmapConfig(track_unknown_space=True), static=data)
    rng = np.random.default_rng(5)
    poses = np.column_stack((rng.uniform(-0.6, 0.6, 300), rng.uniform(-0.6, 0.6, 300), rng.uniform(-3, 3, 300)))
    costs = costmap.footprint_cost(poses)
    for pose, cost in zip(poses, costs):
        under = costmap.cost_at(costmap.footprint_points(pose)[0])
        if np.any(under == LETHAL_OBSTACLE):
            assert cost == -1
        elif np.any(under == NO_INFORMATION):
            assert cost == -2
        else:
            assert cost == under.max()
    assert np.any(costs == -1) and np.any(costs >= 0)
    # The front edge 0.051 m ahead of base_footprint: touching at 0.26, clear at 0.24 (the cell starts at 0.30).
    assert costmap.footprint_cost([(0.26, 0.025, 0.0)])[0] == -1
    assert costmap.footprint_cost([(0.24, 0.025, 0.0)])[0] >= 0
    assert costmap.footprint_cost([(0.95, 0.0, 0.0)])[0] == -3


def test_footprint_cost_finds_the_cells_footprint_points_and_the_grid_find_on_a_turned_grid_scaled():
    """The compiled cost places each outline point in the cell Grid.to_cells gives footprint_points',
    also on a turned grid, with DWA's scaled footprint, and for poses half off the map."""
    grid = Grid(RESOLUTION, 30, 20, origin=(-0.4, -0.7, 0.6))
    costs = np.random.default_rng(3).integers(0, 253, grid.shape).astype(np.uint8)
    costs[4:6, 10:12], costs[14, 3:9] = LETHAL_OBSTACLE, NO_INFORMATION
    costmap = Costmap(grid, CostmapConfig(track_unknown_space=True), static=np.zeros(grid.shape, dtype=np.int8))
    costmap.costs = costs
    rng = np.random.default_rng(8)
    poses = np.column_stack((rng.uniform(-1.5, 1.5, 4000), rng.uniform(-1.5, 1.5, 4000), rng.uniform(-4, 4, 4000)))
    for scale in (1.0, 1.3):
        cells = grid.to_cells(costmap.footprint_points(poses, scale))
        inside = grid.inside(cells).all(axis=1)
        under = np.where(grid.inside(cells), costmap.cost_at(costmap.footprint_points(poses, scale)), FREE_SPACE)
        expected = np.where(~inside, -3.0, np.where(np.any(under == LETHAL_OBSTACLE, axis=1), -1.0, np.where(
            np.any(under == NO_INFORMATION, axis=1), -2.0, under.max(axis=1))))
        found = costmap.footprint_cost(poses, scale)
        assert np.array_equal(found, expected)
        assert {-3.0, -2.0, -1.0} <= set(found) and np.count_nonzero(found >= 0) > 100


# --- publishing -----------------------------------------------------------------------------

def test_occupancy_grid_translation_table():
    costs = np.arange(256, dtype=np.uint8)
    values = occupancy_values(costs)
    assert values.dtype == np.int8
    assert (values[0], values[1], values[252], values[253], values[254], values[255]) == (0, 1, 98, 99, 100, -1)
    assert values[128] == 1 + 97 * 127 // 251 == 50
    assert np.all(np.diff(values[1:253].astype(int)) >= 0)


def test_config_validation_names_the_parameter():
    with pytest.raises(ValueError, match='inflation_radius'):
        CostmapConfig(inflation_radius=-1.0)
    with pytest.raises(ValueError, match='footprint'):
        CostmapConfig(footprint=((0.0, 0.0), (1.0, 1.0)))
    with pytest.raises(ValueError, match='obstacle_range'):
        CostmapConfig(obstacle_range=float('nan'))
    with pytest.raises(ValueError, match='lethal_cost_threshold'):
        CostmapConfig(lethal_cost_threshold=101)


# --- what move_base's parameters add: robot_radius, live inflation ----------------------------

def test_robot_radius_is_costmap_2ds_16_corner_polygon():
    corners = np.array(circle_footprint(0.2))
    assert corners.shape == (16, 2) and np.allclose(np.hypot(*corners.T), 0.2)
    assert np.allclose(corners[::4], [(0.2, 0.0), (0.0, 0.2), (-0.2, 0.0), (0.0, -0.2)])
    inscribed, circumscribed = footprint_radii(corners)
    assert inscribed == pytest.approx(0.2 * math.cos(math.pi / 16)) and circumscribed == pytest.approx(0.2)


def test_inflation_changes_on_a_running_costmap_and_inflate_unknown():
    grid, data = empty_map()
    data[40, 40] = 100
    data[40, 50:] = -1  # unknown cells east of the wall cell
    config = CostmapConfig(track_unknown_space=True, inflation_radius=0.5)
    costmap = Costmap(grid, config, static=data)
    assert costmap.costs[40, 45] > 0 and costmap.costs[40, 52] == NO_INFORMATION
    costmap.reconfigure(config.replace(inflation_radius=0.2))
    assert costmap.costs[40, 45] == 0 and costmap.costs[40, 43] > 0
    costmap.reconfigure(config.replace(inflate_unknown=True))
    assert FREE_SPACE < costmap.costs[40, 50] < INSCRIBED_INFLATED_OBSTACLE  # 0.5 m from the wall: inflated
    assert costmap.costs[40, 52] == NO_INFORMATION                          # 0.6 m, beyond 0.5 m: unknown


def test_costs_are_inflated_again_only_when_the_layers_or_the_parameters_changed(monkeypatch):
    """An update that leaves the combined layers as they were (no scan, the footprint already free;
    the same scan again) keeps the costs; a new obstacle, a footprint on a mark and new inflation
    parameters inflate anew, to the costs a new costmap with the same layers has."""
    grid, data = empty_map()
    costmap = Costmap(grid, CostmapConfig(), static=data)
    inflated = []
    inflate = Costmap._inflate
    monkeypatch.setattr(costmap, '_inflate', lambda master: inflated.append(1) or inflate(costmap, master))

    def fresh():
        again = Costmap(grid, costmap.config, static=data)
        again.obstacles = costmap.obstacles.copy()
        again.update_costs()
        return again.costs

    pose, boxes = (0.0, 0.0, 0.0), [box(1.0, 0.3, 0.1, 0.4)]
    scan = Lidar(boxes, 1).scan(pose)
    for what, update, inflates in [
            ('a scan marks the box', lambda: costmap.update(pose, scan, SCAN_POSE), True),
            ('no scan, the footprint free', lambda: costmap.update(pose), False),
            ('the same scan again', lambda: costmap.update(pose, scan, SCAN_POSE), False),
            ('the footprint over a mark', lambda: costmap.update((0.95, 0.3, 0.0)), True),
            ('a narrower inflation', lambda: costmap.reconfigure(CostmapConfig(inflation_radius=0.5)), True)]:
        inflated.clear()
        update()
        assert bool(inflated) == inflates, what
        assert np.array_equal(costmap.costs, fresh()), what


@pytest.mark.parametrize('inflate_unknown', (False, True))
def test_costs_inflated_again_round_what_changed_are_those_of_the_whole_map(inflate_unknown):
    """Random layers changed in random boxes (marks, clearings, unknown cells, near the edges too):
    the costs inflated round the change are, bitwise, those of a new costmap with the same layers."""
    rng = np.random.default_rng(7)
    config = CostmapConfig(inflate_unknown=inflate_unknown, inflation_radius=0.3, track_unknown_space=True)
    grid = Grid(0.05, 70, 50, (0.0, 0.0, 0.0))
    static = np.where(rng.random(grid.shape) < 0.02, 100, np.where(rng.random(grid.shape) < 0.1, -1, 0))
    costmap = Costmap(grid, config, static=static.astype(np.int8))
    for _ in range(60):
        y, x = rng.integers(0, grid.height), rng.integers(0, grid.width)
        size = rng.integers(1, 8, 2)
        costmap.obstacles[y:y + size[0], x:x + size[1]] = rng.choice(
            [FREE_SPACE, LETHAL_OBSTACLE, NO_INFORMATION], p=[0.5, 0.3, 0.2])
        costmap.update_costs()
        again = Costmap(grid, config, static=static.astype(np.int8))
        again.obstacles = costmap.obstacles.copy()
        again.update_costs()
        assert np.array_equal(costmap.costs, again.costs)
