"""The measures of a map against its world (tb3_harness.map_quality): a perfect map scores perfectly,
a map made from lidar scans at the true poses meets the issue's goals, and each way of spoiling a map
(doubled, shifted, thickened or missing walls, unexplored floor) lowers the figure that names it."""
import math

import numpy as np
import pytest
from scipy import ndimage

from tb3_common.grid import Grid
from tb3_common.map_files import load_map
from tb3_harness.exploring import ExplorationRun, stood_still
from tb3_harness.map_quality import QualityConfig, measure, render_png
from tb3_navigation.raytrace import crossed_cells, end_cells
from tb3_navigation.scan import Scan
from tb3_sim_nav.world import World
from tb3_sim_nav.world_file import load_world
from tb3_sim_nav.world_map import BURGER_SCAN_HEIGHT

from conftest import REPO

START = (-2.0, -0.5)  # tb3_world.launch's spawn
# The drives.py loop around turtlebot3_world's pillars, a pose every ~0.35 m (x, y, yaw).
LOOP = [(-2.0, -0.5), (-1.65, -0.5), (-1.65, 1.65), (0.55, 1.65), (1.65, 1.65), (1.65, -1.65), (-0.55, -1.65),
        (-1.65, -1.65), (-1.65, -0.5)]


@pytest.fixture(scope='module')
def world():
    return load_world('turtlebot3_world', str(REPO / 'worlds')).obstacles


@pytest.fixture(scope='module')
def perfect():
    loaded = load_map(str(REPO / 'maps' / 'turtlebot3_world.yaml'))
    return loaded.grid, loaded.values


def _poses(step=0.35):
    poses = []
    for (x0, y0), (x1, y1) in zip(LOOP, LOOP[1:]):
        count = max(1, int(math.hypot(x1 - x0, y1 - y0) / step))
        heading = math.atan2(y1 - y0, x1 - x0)
        poses += [(x0 + (x1 - x0) * k / count, y0 + (y1 - y0) * k / count, heading) for k in range(count)]
    return poses


def lidar_map(obstacles, poses, believed=None, seed=1):
    """A map made as a mapper would at `believed` poses (default: the true ones) from the scans
    pybullet's lidar ray cast (360 beams, 0.12-3.5 m, sigma 0.01 m) takes at the true `poses`:
    per cell, occupied when more than a quarter of the beams that reached it ended there (gmapping's occ_thresh)."""
    rng = np.random.default_rng(seed)
    grid = Grid.around(0.05, -3.5, -3.5, 3.5, 3.5)
    hits, visits = np.zeros(grid.shape).ravel(), np.zeros(grid.shape).ravel()
    angles = np.arange(360) * 2 * math.pi / 360
    simulated = World(0.01, obstacles)
    try:
        for (x, y, yaw), (bx, by, byaw) in zip(poses, believed or poses):
            origin = np.array([x, y, BURGER_SCAN_HEIGHT])
            ends = origin + np.stack((3.5 * np.cos(yaw + angles), 3.5 * np.sin(yaw + angles), np.zeros(360)), -1)
            ranges = simulated.rays.cast([origin], [(ends - origin) / 3.5], 3.5, [None])[0] + rng.normal(0.0, 0.01, 360)
            scan = Scan(0.0, angles[1], ranges, 0.12, 3.5)
            stops, hit = scan.rays((bx, by, byaw), 3.5)
            crossed = crossed_cells(grid, (bx, by), stops)
            ended = end_cells(grid, stops[hit])
            visits[crossed] += 1
            visits[ended] += 1
            hits[ended] += 1
    finally:
        simulated.close()
    values = np.where(visits == 0, -1, np.where(hits > 0.25 * visits, 100, 0)).astype(np.int8)
    return grid, values.reshape(grid.shape)


def shifted(values, cells_x, cells_y=0):
    """The occupied cells moved by (cells_x, cells_y); where they were, free."""
    moved = np.roll(np.roll(values == 100, cells_y, axis=0), cells_x, axis=1)
    return np.where(moved, 100, np.where(values == 100, 0, values)).astype(np.int8)


def test_a_perfect_map_scores_perfectly(world, perfect):
    quality = measure(perfect[0], perfect[1], world, START)
    print('MEASURED perfect map (world_to_map):', quality.summary())
    assert quality.occupied_near_surface == 1.0 and quality.surface_covered == 1.0
    # Thicker than two cells only at the hexagon's corners, where a normal runs along the other wall.
    assert quality.wall_thickness == 1.0 and quality.doubled_wall_share == 0.0 and quality.thick_wall_share < 0.005
    assert quality.free_floor_mapped == 1.0 and quality.failures() == []
    # The inner faces only: the hexagon's (6 x 2.89 m) and the nine pillars' (9 x 0.94 m), every 0.02 m.
    assert quality.surface_points == pytest.approx((6 * 5.0 / math.sqrt(3) + 9 * 2 * math.pi * 0.15) / 0.02, rel=0.05)


def test_a_map_made_of_lidar_scans_at_the_true_poses_meets_the_goals(world):
    grid, values = lidar_map(world, _poses())
    quality = measure(grid, values, world, START)
    print('MEASURED lidar map, true poses:', quality.summary())
    assert quality.failures() == [], quality.summary()
    assert quality.doubled_wall_share < 0.05 and quality.free_floor_mapped > 0.9


def test_a_jump_in_the_pose_doubles_the_walls(world):
    poses = _poses()
    half = len(poses) // 2
    # From halfway on the mapper believes it is 0.25 m further east and 0.1 m north than it is.
    believed = poses[:half] + [(x + 0.25, y + 0.1, yaw) for x, y, yaw in poses[half:]]
    good = measure(*lidar_map(world, poses), world, START)
    jumped = measure(*lidar_map(world, poses, believed), world, START)
    print('MEASURED lidar map, a 0.27 m jump halfway:', jumped.summary())
    assert jumped.doubled_wall_share > good.doubled_wall_share + 0.05
    assert jumped.occupied_near_surface < 0.9 < good.occupied_near_surface
    assert jumped.failures()


def test_doubled_walls_raise_the_doubled_share_and_lower_the_occupied_near_surface(world, perfect):
    grid, values = perfect
    # A copy of the map shrunk to 90 % about the middle: each hexagon wall again 0.25 m further in.
    cells = grid.to_cells(grid.all_centres() / 0.9)
    inside = grid.inside(cells)
    copy = np.zeros(grid.shape, dtype=bool)
    copy[inside] = values[cells[inside][:, 1], cells[inside][:, 0]] == 100
    doubled = np.where(copy, 100, values).astype(np.int8)
    quality = measure(grid, doubled, world, START)
    print('MEASURED perfect map plus a copy shrunk to 90 %:', quality.summary())
    hexagon_share = 6 * 5.0 / math.sqrt(3) / (6 * 5.0 / math.sqrt(3) + 9 * 2 * math.pi * 0.15)  # 67 %
    assert quality.doubled_wall_share > 0.8 * hexagon_share
    assert quality.occupied_near_surface < 0.8
    assert quality.surface_covered == 1.0  # every true wall is still there


def test_shifted_walls_lower_both_shares(world, perfect):
    grid, values = perfect
    quality = measure(grid, shifted(values, 4), world, START)  # 0.2 m east
    print('MEASURED perfect map shifted 0.2 m east:', quality.summary())
    assert quality.occupied_near_surface < 0.7 and quality.surface_covered < 0.7
    assert quality.failures()


def test_missing_walls_lower_the_covered_surface_only(world, perfect):
    grid, values = perfect
    spoiled = values.copy()
    centres = grid.all_centres()
    spoiled[(centres[..., 0] > 2.3) & (values == 100)] = 0  # the east wall, gone
    spoiled[(np.hypot(centres[..., 0], centres[..., 1]) < 0.3) & (values == 100)] = 0  # the middle pillar
    quality = measure(grid, spoiled, world, START)
    print('MEASURED perfect map without its east wall and middle pillar:', quality.summary())
    east_and_pillar = (5.0 / math.sqrt(3) + 2 * math.pi * 0.15) / (6 * 5.0 / math.sqrt(3) + 9 * 2 * math.pi * 0.15)
    assert quality.surface_covered == pytest.approx(1.0 - east_and_pillar, abs=0.03)
    assert quality.occupied_near_surface == 1.0 and quality.doubled_wall_share == 0.0


def test_thick_walls_raise_the_thickness(world, perfect):
    grid, values = perfect
    thick = np.where(ndimage.binary_dilation(values == 100, iterations=2), 100, values).astype(np.int8)
    quality = measure(grid, thick, world, START)
    print('MEASURED perfect map, walls two cells thicker all round:', quality.summary())
    assert quality.wall_thickness >= 3 and quality.thick_wall_share > 0.8
    assert quality.surface_covered == 1.0 and quality.doubled_wall_share == 0.0
    assert [line for line in quality.failures() if line.startswith('wall_thickness')]


def test_unexplored_floor_lowers_the_free_floor_mapped(world, perfect):
    grid, values = perfect
    half = values.copy()
    half[:, :grid.width // 2][half[:, :grid.width // 2] == 0] = -1  # the west half never seen
    quality = measure(grid, half, world, START)
    print('MEASURED perfect map, west half unknown:', quality.summary())
    assert 0.4 < quality.free_floor_mapped < 0.6
    assert quality.occupied_near_surface == 1.0 and quality.surface_covered == 1.0


def test_a_start_outside_the_reachable_floor_and_bad_settings_are_refused(world, perfect):
    with pytest.raises(ValueError, match=r'start point \(0.00, 0.00\) is not in the free space'):
        measure(perfect[0], perfect[1], world, (0.0, 0.0))  # the middle pillar
    with pytest.raises(ValueError, match='values of shape'):
        measure(perfect[0], perfect[1][1:], world, START)
    with pytest.raises(ValueError, match=r'QualityConfig.tolerance = -0.1: must be a finite number > 0'):
        QualityConfig(tolerance=-0.1)


def test_the_png_shows_the_map_the_outline_and_the_paths(world, perfect, tmp_path):
    from PIL import Image
    grid, values = perfect
    render_png(str(tmp_path / 'plain.png'), grid, values)
    render_png(str(tmp_path / 'drawn.png'), grid, values, world, {'truth': [p[:2] for p in _poses()]}, title='t')
    plain = np.asarray(Image.open(str(tmp_path / 'plain.png')).convert('RGB')).astype(int)
    drawn = np.asarray(Image.open(str(tmp_path / 'drawn.png')).convert('RGB')).astype(int)
    assert plain.shape == drawn.shape and plain.shape[0] > 400
    grey = (plain[..., 0] == plain[..., 1]) & (plain[..., 1] == plain[..., 2])
    assert grey.mean() > 0.99 and (plain.sum(-1) < 100).sum() > 1000  # grey, with black walls
    red = (drawn[..., 0] > 150) & (drawn[..., 1] < 100) & (drawn[..., 2] < 100)  # the outline
    blue = (drawn[..., 2] > 150) & (drawn[..., 0] < 100)  # the path
    assert red.sum() > 1000 and blue.sum() > 500


def test_bounds_keep_the_free_floor_measure_to_a_box(world, perfect):
    """The floor outside `bounds` does not count: the east half of the map known, the west half
    not, measured in the east half only the floor is all mapped."""
    grid, values = perfect
    west = grid.all_centres()[..., 0] < 0.0
    half = np.where(west, -1, values).astype(np.int8)
    whole = measure(grid, half, world, (1.65, -0.55))
    east = measure(grid, half, world, (1.65, -0.55), bounds=(0.0, -5.0, 5.0, 5.0))
    print('MEASURED the east half mapped: free floor %.3f of the whole, %.3f of the east half'
          % (whole.free_floor_mapped, east.free_floor_mapped))
    assert 0.4 < whole.free_floor_mapped < 0.6
    assert east.free_floor_mapped == 1.0 and east.reachable_cells < 0.6 * whole.reachable_cells


def test_stood_still_finds_the_spells_a_path_stayed_put_and_only_those():
    # 10 s driving, 30 s within 5 cm (a robot rocking on its recoveries), 10 s driving, 15 s still (too short).
    path = [[t, 0.1 * t, 0.0] for t in range(10)]
    path += [[10 + t, 1.0 + 0.05 * (t % 2), 0.0] for t in range(31)]
    path += [[41 + t, 1.1 + 0.1 * t, 0.0] for t in range(1, 11)]
    path += [[51 + t, 2.1, 0.0] for t in range(16)]
    spells = stood_still(path)
    assert len(spells) == 1
    start, seconds, where = spells[0]
    assert 9 <= start <= 10 and 30 <= seconds <= 32 and abs(where[0] - 1.0) < 0.11, spells


def test_an_exploration_stands_still_only_until_it_is_done():
    # 30 s driving, the explorer done at 30 s, then 40 s standing while the map is saved and the launches stop.
    path = [[t, 0.1 * t, 0.0, 0.0] for t in range(31)] + [[30 + t, 3.0, 0.0, 0.0] for t in range(1, 41)]
    run = ExplorationRun('turtlebot3_world', 0.0, 'no frontier left', 9, 0, 30.0, 12.0, path, 'map.yaml', None,
                         0.1, {}, done_at=30.0)
    assert run.still_spells() == []
    assert len(stood_still(path)) == 1  # the whole recording has the stand after the end
