"""tb3_navigation.costmap against costmap_2d's rules: inflation's formula, the static
layer, marking and clearing from a scan, the rolling window, the footprint's cost,
clearing, and the OccupancyGrid translation (no ROS)."""
import math

import numpy as np
import pytest

from tb3_common.grid import Grid
from tb3_common.pose2d import compose
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
from tb3_sim_nav.world_file import Obstacle

RESOLUTION = 0.05


def empty_map(width=80, height=80, origin=(-2.0, -2.0, 0.0), value=0):
    grid = Grid(RESOLUTION, width, height, origin)
    return grid, np.full(grid.shape, value, dtype=np.int8)


def box(x, y, size_x, size_y, yaw=0.0):
    return Obstacle('box', (size_x, size_y, 0.4), (x, y, 0.2), yaw, None)


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


# --- marking and clearing -------------------------------------------------------------------

def scan_update(costmap, pose, obstacles, seed=1):
    costmap.update(pose, Lidar(obstacles, seed).scan(pose), compose(pose, SCAN_POSE))


def lethal_near(costmap, point, radius=0.06):
    """True if a lethal cell's centre lies within `radius` of `point` (a hit lands within
    the lidar's noise of a surface, in one of the cells around it)."""
    lethal = costmap.grid.centres(np.argwhere(costmap.costs == LETHAL_OBSTACLE)[:, ::-1])
    return bool(len(lethal)) and bool(np.any(np.hypot(*(lethal - point).T) <= radius))


def test_scan_marks_hits_within_obstacle_range_and_not_beyond():
    grid, data = empty_map(width=140, height=80, origin=(-2.0, -2.0, 0.0))
    costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0), static=data)
    near, far = box(1.0, 0.3, 0.1, 0.4), box(3.2, -0.7, 0.1, 0.6)  # faces ~1 m and ~3.2 m from the lidar
    scan = Lidar([near, far], 1).scan((0.0, 0.0, 0.0))
    assert np.sum(scan.hits & (scan.ranges > 3.0)) >= 3  # the far face is seen, beyond obstacle_range
    costmap.update((0.0, 0.0, 0.0), scan, SCAN_POSE)
    lethal = costmap.grid.centres(np.argwhere(costmap.costs == LETHAL_OBSTACLE)[:, ::-1])
    assert len(lethal) >= 8
    # Every lethal cell holds the near box's face (noise 0.01 m, cells 0.05 m).
    assert np.all(np.abs(lethal[:, 0] - 0.95) <= 0.06) and np.all(np.abs(lethal[:, 1] - 0.3) <= 0.23)


def test_beams_clear_what_they_cross_and_an_empty_beam_clears_only_if_inf_is_valid():
    grid, data = empty_map(width=160, height=160, origin=(-4.0, -4.0, 0.0))
    for inf_is_valid in (False, True):
        costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0, inf_is_valid=inf_is_valid), static=data)
        spawned = box(1.5, 0.0, 0.3, 0.3)
        wall = box(0.0, 2.0, 3.0, 0.1)
        scan_update(costmap, (0.0, 0.0, 0.0), [spawned, wall])
        assert lethal_near(costmap, (1.35, 0.0)) and lethal_near(costmap, (0.0, 1.95))
        # The box removed, a wall behind where it stood: beams now cross its cells and clear them.
        scan_update(costmap, (0.0, 0.0, 0.0), [box(2.5, 0.0, 0.1, 3.0), wall], seed=2)
        assert not lethal_near(costmap, (1.35, 0.0), 0.1)
        assert lethal_near(costmap, (2.45, 0.0))
        # The wall removed and nothing in range there: those beams are inf.
        scan_update(costmap, (0.0, 0.0, 0.0), [box(2.5, 0.0, 0.1, 3.0)], seed=3)
        assert lethal_near(costmap, (0.0, 1.95), 0.1) == (not inf_is_valid)


def test_the_footprint_is_cleared_of_marks():
    grid, data = empty_map()
    costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0), static=data)
    scan_update(costmap, (0.0, 0.0, 0.0), [box(0.3, 0.0, 0.1, 0.1)])
    assert lethal_near(costmap, (0.25, 0.0))
    costmap.update((0.3, 0.0, 0.0))  # the robot drove onto it: what it covers is free
    assert not lethal_near(costmap, (0.25, 0.0), 0.1)
    assert np.all(costmap.costs.ravel()[costmap.footprint_cells((0.3, 0.0, 0.0))] == FREE_SPACE)


def test_static_obstacles_are_not_cleared_by_beams():
    grid, data = empty_map()
    data[40, 60] = 100  # (1.025, 0.025)
    costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0), static=data)
    scan_update(costmap, (0.0, 0.0, 0.0), [])  # nothing seen at all
    assert costmap.cost_at((1.025, 0.025)) == LETHAL_OBSTACLE


# --- the rolling window ---------------------------------------------------------------------

def test_rolling_window_follows_the_robot_in_whole_cells_and_keeps_marks_in_place():
    costmap = Costmap.rolling(CostmapConfig(inflation_radius=0.0))
    assert costmap.grid.shape == (60, 60) and costmap.grid.origin == (-1.5, -1.5, 0.0)
    scan_update(costmap, (0.0, 0.0, 0.0), [box(1.0, 0.5, 0.1, 0.1)])
    marked = costmap.grid.centres(np.argwhere(costmap.costs == LETHAL_OBSTACLE)[:, ::-1])
    assert len(marked)
    costmap.update((0.52, -0.31, 0.0))
    # Moved by int(0.52 / 0.05) = 10 and int(-0.31 / 0.05) = -6 cells (C's truncation).
    assert costmap.grid.origin[:2] == pytest.approx((-1.5 + 0.5, -1.5 - 0.3))
    assert np.all(costmap.cost_at(marked) == LETHAL_OBSTACLE)
    costmap.update((-3.0, 0.0, 0.0))  # out of the window: forgotten
    costmap.update((0.0, 0.0, 0.0))
    assert np.all(costmap.cost_at(marked) == FREE_SPACE)


def test_rolling_window_clears_beams_up_to_its_edge():
    costmap = Costmap.rolling(CostmapConfig(inflation_radius=0.0))
    # A mark one cell before the window's edge, on the beam ahead (the edge cell itself is the
    # cut beam's end cell, which costmap_2d's raytraceLine leaves as it is too).
    edge = costmap.grid.to_cells(np.array([1.42, 0.01]))
    costmap.obstacles[edge[1], edge[0]] = LETHAL_OBSTACLE
    scan_update(costmap, (0.0, 0.0, 0.0), [box(3.1, 0.0, 0.1, 0.4)])  # a hit 3 m ahead, far outside
    assert costmap.obstacles[edge[1], edge[0]] == FREE_SPACE
    assert not np.any(costmap.costs == LETHAL_OBSTACLE)


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


# --- recovery and reset ---------------------------------------------------------------------

def test_clear_obstacles_outside_a_square_and_reset():
    grid, data = empty_map(width=160, height=160, origin=(-4.0, -4.0, 0.0))
    data[10, 10] = 100  # static: never cleared
    costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0), static=data)
    scan_update(costmap, (0.0, 0.0, 0.0), [box(0.6, 0.0, 0.1, 0.1), box(-2.0, 0.0, 0.1, 0.1)])
    near, far = (0.55, 0.0), (-1.95, 0.0)  # the faces the lidar sees
    assert lethal_near(costmap, near) and lethal_near(costmap, far)
    costmap.clear_obstacles((0.0, 0.0), 3.0)  # conservative_reset: a 3 m square around the robot
    assert lethal_near(costmap, near) and not lethal_near(costmap, far, 0.1)
    costmap.reset()
    assert not lethal_near(costmap, near, 0.1)
    assert costmap.costs[10, 10] == LETHAL_OBSTACLE


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


# --- the tests' lidar: world_map.ray_cast ---------------------------------------------------

def test_ray_cast_ends_on_an_outline_and_misses_cross_nothing():
    from tb3_harness.nav_sim import world_cut
    from tb3_sim_nav import world_map
    obstacles = world_cut() + [box(-1.6, -1.6, 0.3, 0.3, 0.4)]
    rng = np.random.default_rng(11)
    for origin in rng.uniform(-2.0, 2.0, (12, 2)):
        if world_map.signed_distance(obstacles, origin[None, :])[0] <= 0:
            continue
        angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
        ranges = world_map.ray_cast(obstacles, origin, angles, max_range=3.5)
        directions = np.stack((np.cos(angles), np.sin(angles)), axis=-1)
        hit = np.isfinite(ranges)
        ends = origin + directions[hit] * ranges[hit, None]
        assert np.abs(world_map.signed_distance(obstacles, ends)).max() < 1e-9
        # Nothing between the origin and the hit (or 3.5 m): samples along the ray stay outside.
        reach = np.where(hit, ranges, 3.5)
        samples = origin + directions[:, None, :] * (reach[:, None, None] * np.linspace(0, 0.999, 80)[None, :, None])
        assert world_map.signed_distance(obstacles, samples.reshape(-1, 2)).min() > -1e-9


def test_ray_cast_along_a_box_s_axes():
    from tb3_sim_nav import world_map
    beside, ahead = box(1.0, 0.3, 0.1, 0.4), box(1.0, 0.0, 0.1, 0.4)
    assert world_map.ray_cast([beside], (0.0, 0.0), [0.0])[0] == math.inf
    assert world_map.ray_cast([ahead], (0.0, 0.0), [0.0])[0] == pytest.approx(0.95)
    assert world_map.ray_cast([ahead], (1.0, -1.0), [math.pi / 2])[0] == pytest.approx(0.8)
    assert world_map.ray_cast([ahead], (0.0, 0.0), [0.0], max_range=0.9)[0] == math.inf


# --- what move_base's parameters add: robot_radius, observation sources, live inflation ----------

class Source(object):
    """An observation source as move_base's costmap_params makes one."""

    def __init__(self, marking=True, clearing=True, obstacle_range=3.0, raytrace_range=3.5, inf_is_valid=False):
        self.marking, self.clearing, self.inf_is_valid = marking, clearing, inf_is_valid
        self.obstacle_range, self.raytrace_range = obstacle_range, raytrace_range


def test_robot_radius_is_costmap_2ds_16_corner_polygon():
    corners = np.array(circle_footprint(0.2))
    assert corners.shape == (16, 2) and np.allclose(np.hypot(*corners.T), 0.2)
    assert np.allclose(corners[::4], [(0.2, 0.0), (0.0, 0.2), (-0.2, 0.0), (0.0, -0.2)])
    inscribed, circumscribed = footprint_radii(corners)
    assert inscribed == pytest.approx(0.2 * math.cos(math.pi / 16)) and circumscribed == pytest.approx(0.2)


def test_a_source_marks_and_clears_only_as_it_says():
    grid, data = empty_map(width=160, height=160, origin=(-4.0, -4.0, 0.0))
    seen = [box(1.5, 0.0, 0.3, 0.3)]
    costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0), static=data)
    scan = Lidar(seen, 1).scan((0.0, 0.0, 0.0))
    costmap.update((0.0, 0.0, 0.0), scan, SCAN_POSE, Source(marking=False))
    assert not lethal_near(costmap, (1.35, 0.0))
    costmap.update((0.0, 0.0, 0.0), scan, SCAN_POSE, Source(obstacle_range=1.0))  # the box lies beyond
    assert not lethal_near(costmap, (1.35, 0.0))
    costmap.update((0.0, 0.0, 0.0), scan, SCAN_POSE, Source())
    assert lethal_near(costmap, (1.35, 0.0))
    emptied = Lidar([box(2.5, 0.0, 0.1, 3.0)], 2).scan((0.0, 0.0, 0.0))
    costmap.update((0.0, 0.0, 0.0), emptied, SCAN_POSE, Source(clearing=False, marking=False))
    assert lethal_near(costmap, (1.35, 0.0))  # not cleared: the beams through it do not clear
    costmap.update((0.0, 0.0, 0.0), emptied, SCAN_POSE, Source(marking=False))
    assert not lethal_near(costmap, (1.35, 0.0), 0.1)


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
