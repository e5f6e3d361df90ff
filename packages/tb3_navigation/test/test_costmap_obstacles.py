"""tb3_navigation.costmap's obstacle layer against costmap_2d's rules: marks from a scan within
obstacle_range, beams that clear what they cross (an empty beam only if inf_is_valid), the footprint
cleared, static obstacles kept; the rolling window following the robot in whole cells; clearing outside
a square and the reset; an observation source marking and clearing only as it says; and the tests'
lidar, world_map.ray_cast (no ROS)."""
import math

import numpy as np
import pytest
from costmap_maps import box, empty_map

from tb3_common.pose2d import compose
from tb3_harness.nav_sim import SCAN_POSE, Lidar
from tb3_navigation.costmap import FREE_SPACE, LETHAL_OBSTACLE, Costmap, CostmapConfig

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


# --- what move_base's parameters add: observation sources ------------------------------------

class Source(object):
    """An observation source as move_base's costmap_params makes one."""

    def __init__(self, marking=True, clearing=True, obstacle_range=3.0, raytrace_range=3.5, inf_is_valid=False):
        self.marking, self.clearing, self.inf_is_valid = marking, clearing, inf_is_valid
        self.obstacle_range, self.raytrace_range = obstacle_range, raytrace_range


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
