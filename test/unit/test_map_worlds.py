"""Worlds from map images (real pybullet, no ROS): a map_server YAML as `world:=`, its occupied
cells walls of ~map_wall_height, merged into few boxes, as Stage builds worlds from bitmaps."""
import math

import numpy as np
import pytest
from PIL import Image

from tb3_common.grid import Grid
from tb3_common.map_files import load_map
from tb3_sim_nav.frames import planar
from tb3_sim_nav.params import ParameterError, resolve
from tb3_sim_nav.robot_model import load_model
from tb3_sim_nav.simulation import build
from tb3_sim_nav.world import World
from tb3_sim_nav.world_file import WorldError, load_world, rectangles
from tb3_sim_nav.world_map import rasterise

from conftest import REPO

TEST_MAP = str(REPO / 'maps' / 'rbx1' / 'test_map.yaml')
WORLDS = str(REPO / 'worlds')
SCAN_OFFSET = (-0.032, 0.182)  # Burger: base_scan's x and height in base_footprint
AGREE = 0.01                   # m: a beam agrees with the march through the image within this
AGREEING_SHARE = 0.95          # of the beams that hit a wall
MAP_OF_WORLD_AGREE = 0.121     # m: a 0.05 m cell plus its diagonal
MAP_OF_WORLD_SHARE = 0.85      # of all beams: the pillars' rings of cells catch beams grazing them
GRAZING = 0.02                 # share of beams that may pass a pixel's corner in one ray cast and not the other


@pytest.fixture
def make(burger_urdf):
    """make(obstacles, pose, **parameters): a Simulation with a Burger at pose (x, y, yaw); closed after."""
    made = []

    def make_simulation(obstacles, pose, **parameters):
        values = dict(scan_noise=0.0, **parameters)
        config = resolve(lambda name, default: values.get(name, default))
        robot = ('', load_model(str(burger_urdf)), planar(pose[0], pose[1], 0.0, pose[2]))
        simulation = build(config, obstacles, [robot])
        made.append(simulation)
        return simulation
    yield make_simulation
    for simulation in made:
        simulation.close()


def _march(values, grid, origin, angles, range_max, step=0.002):
    """Range of each beam to the first occupied cell of the image (inf beyond range_max): the truth."""
    distances = np.arange(0.0, range_max, step)
    points = origin[None, None, :] + distances[None, :, None] * np.stack((np.cos(angles), np.sin(angles)), -1)[:, None]
    cells = grid.to_cells(points)
    inside = grid.inside(cells)
    hit = np.zeros(inside.shape, dtype=bool)
    hit[inside] = values[cells[inside][:, 1], cells[inside][:, 0]] == 100
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
    return np.where(first >= 0, distances[np.maximum(first, 0)], np.inf)


def _lidar_against_image(simulation, loaded, pose):
    robot = simulation.robots['']
    for _ in range(50):
        simulation.step()
    ranges = np.asarray(robot.scan(), dtype=float)
    angles = pose[2] + robot.lidar.angle_increment * np.arange(ranges.size)
    sensor = np.array([pose[0] + SCAN_OFFSET[0] * math.cos(pose[2]), pose[1] + SCAN_OFFSET[0] * math.sin(pose[2])])
    expected = _march(loaded.values, loaded.grid, sensor, angles, robot.lidar.range_max)
    seen = np.isfinite(expected) & np.isfinite(ranges)
    with np.errstate(invalid='ignore'):  # inf - inf
        agree = seen & (np.abs(ranges - expected) <= AGREE)
    return ranges, expected, seen, agree


def test_test_map_loads_as_a_world_of_few_boxes():
    # What loading it and its scans cost: tools/bench_rays.py --map-world (merged boxes are what keeps them cheap).
    world = load_world(TEST_MAP, WORLDS)
    World(0.01, world.obstacles).close()
    occupied = world.map.values == 100
    assert len(world.obstacles) < occupied.sum() / 3  # merged: not one body per pixel
    assert all(o.kind == 'box' and o.size[2] == 0.5 and o.position[2] == 0.25 for o in world.obstacles)
    # The boxes cover exactly the occupied cells: neither unknown (-1) nor free cells are walls.
    assert np.array_equal(rasterise(world.obstacles, world.map.grid), occupied)
    assert len(set(o.name for o in world.obstacles)) == len(world.obstacles)


def test_rectangles_tile_a_mask_exactly_and_merge_runs():
    rng = np.random.default_rng(5)
    mask = rng.random((40, 60)) < 0.3
    mask[5:15, 10:40] = True  # one solid block: one box, not 300
    boxes = rectangles(mask)
    tiled = np.zeros(mask.shape, dtype=int)
    for ix, iy, columns, rows in boxes:
        tiled[iy:iy + rows, ix:ix + columns] += 1
    assert np.array_equal(tiled, mask.astype(int))  # every cell once, no overlaps
    assert rectangles(np.pad(np.ones((10, 30), bool), 2)) == [(2, 2, 30, 10)]


def test_the_lidar_in_test_map_reads_the_image(make):
    loaded = load_map(TEST_MAP)
    pose = (0.0, 0.0, 0.3)  # the launches' default spawn: the book's living room, 1.2 m from a wall
    simulation = make(load_world(TEST_MAP, WORLDS).obstacles, pose)
    ranges, expected, seen, agree = _lidar_against_image(simulation, loaded, pose)
    print('MEASURED test_map lidar at (0, 0): %d beams hit, %d agree within %.3f m; worst %.3f m'
          % (seen.sum(), agree.sum(), AGREE, np.max(np.abs(ranges[seen] - expected[seen]))))
    assert seen.sum() > 60
    assert agree.sum() >= AGREEING_SHARE * seen.sum()
    # No wall the image lacks, none missed, but for beams that graze a pixel's corner.
    assert (np.isfinite(ranges) != np.isfinite(expected)).sum() <= GRAZING * ranges.size


def test_a_saved_map_of_a_world_is_a_world_whose_lidar_reads_as_the_original(make):
    """maps/turtlebot3_world (world_to_map, map_saver's format) driven in as a world, against the world file."""
    pose = (-2.0, -0.5, 0.0)  # tb3_world.launch's spawn
    mapped = make(load_world(str(REPO / 'maps' / 'turtlebot3_world.yaml'), WORLDS).obstacles, pose)
    for _ in range(50):
        mapped.step()
    from_map = np.asarray(mapped.robots[''].scan(), dtype=float)
    original = make(load_world('turtlebot3_world', WORLDS).obstacles, pose)
    for _ in range(50):
        original.step()
    truth = np.asarray(original.robots[''].scan(), dtype=float)
    both = np.isfinite(from_map) & np.isfinite(truth)
    error = from_map[both] - truth[both]
    agree = ~np.isfinite(from_map) & ~np.isfinite(truth)
    agree[both] = np.abs(error) <= MAP_OF_WORLD_AGREE
    print('MEASURED turtlebot3_world map vs world file: %d beams hit in both, median %+.3f m; %d of %d agree '
          'within %.3f m' % (both.sum(), np.median(error), agree.sum(), agree.size, MAP_OF_WORLD_AGREE))
    # The shipped maps are a perfect SLAM's (world_to_map --start): the cells a surface runs through,
    # on the open side, occupied. Built into boxes, those surfaces stand up to a cell in front of the
    # world's (median a cell: walls lie on cell edges), never behind it; beams that pass a round pillar
    # by its ring of cells' corners read that corner.
    assert both.sum() > 300 and error.max() <= 0.002 and np.median(error) >= -0.06
    assert agree.sum() >= MAP_OF_WORLD_SHARE * agree.size


def test_a_spawn_pose_inside_a_wall_gets_the_error_other_worlds_give(make):
    loaded = load_map(TEST_MAP)
    iy, ix = np.argwhere(loaded.values == 100)[0]
    x, y = loaded.grid.centres((ix, iy))
    with pytest.raises(ValueError, match=r'the spawn pose \(%.2f, %.2f\) puts it inside obstacle \d+ of the world '
                                         r'\(wall_\d+\), centred at .*: choose another x_pos/y_pos' % (x, y)):
        make(load_world(TEST_MAP, WORLDS).obstacles, (x, y, 0.0))


def test_map_wall_height_is_a_checked_parameter_and_walls_below_the_lidar_are_not_seen(make):
    assert resolve(lambda name, default: default).map_wall_height == 0.5
    with pytest.raises(ParameterError, match=r'~map_wall_height = -0.2: must be > 0'):
        resolve(lambda name, default: {'map_wall_height': -0.2}.get(name, default))
    low = load_world(TEST_MAP, WORLDS, map_wall_height=0.1)  # under the Burger's lidar (0.182 m)
    assert {o.size[2] for o in low.obstacles} == {0.1}
    ranges = np.asarray(make(low.obstacles, (0.0, 0.0, 0.0)).robots[''].scan(), dtype=float)
    assert not np.isfinite(ranges).any()


def test_a_turned_map_origin_turns_its_walls(tmp_path):
    pixels = np.full((20, 30), 254, dtype=np.uint8)
    pixels[3, 2:25] = 0
    pixels[5:18, 27] = 0
    Image.fromarray(pixels).save(str(tmp_path / 'm.png'))
    (tmp_path / 'm.yaml').write_text('image: m.png\nresolution: 0.1\norigin: [1.0, -2.0, 0.6]\nnegate: 0\n'
                                     'occupied_thresh: 0.65\nfree_thresh: 0.196\n')
    world = load_world(str(tmp_path / 'm.yaml'), WORLDS)
    assert world.map.grid == Grid(0.1, 30, 20, (1.0, -2.0, 0.6)) and len(world.obstacles) == 2
    assert np.array_equal(rasterise(world.obstacles, world.map.grid), world.map.values == 100)
    assert all(o.yaw == 0.6 for o in world.obstacles)


def test_a_bad_map_as_world_names_the_file_and_the_key(tmp_path):
    (tmp_path / 'm.yaml').write_text('image: nowhere.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n'
                                     'occupied_thresh: 0.65\nfree_thresh: 0.196\n')
    with pytest.raises(WorldError, match=r"world file %s is a map, and %s: key 'image': image file .*nowhere.pgm "
                                         r"does not exist" % (tmp_path / 'm.yaml', tmp_path / 'm.yaml')):
        load_world(str(tmp_path / 'm.yaml'), WORLDS)
    (tmp_path / 'n.yaml').write_text('image: m.png\n')
    with pytest.raises(WorldError, match=r"key 'resolution': missing"):
        load_world(str(tmp_path / 'n.yaml'), WORLDS)


# --- world_to_map and the rasterisation behind it ---------------------------------------------
SPAWNS = {'turtlebot3_world': (-2.0, -0.5), 'turtlebot3_house': (-3.0, 1.0), 'turtlebot3_stage_1': (0.0, 0.0),
          'turtlebot3_stage_2': (0.0, 0.0), 'turtlebot3_stage_3': (0.0, 0.0), 'turtlebot3_stage_4': (-0.7, 0.0)}


@pytest.mark.parametrize('world', sorted(SPAWNS))
def test_the_shipped_maps_are_what_world_to_map_makes_today(world, tmp_path, capsys):
    """Each map in maps/ is world_to_map's from its launch's spawn pose (x_pos, y_pos)."""
    from tb3_sim_nav.world_to_map import main
    start = ['%g' % value for value in SPAWNS[world]]
    assert main([world, '-f', str(tmp_path / world), '--start'] + start) == 0
    assert 'world_to_map: %s -> ' % world in capsys.readouterr().out
    for suffix in ('.pgm', '.yaml'):
        assert (tmp_path / (world + suffix)).read_bytes() == (REPO / 'maps' / (world + suffix)).read_bytes()


def test_world_to_map_names_a_missing_world_and_takes_a_resolution(tmp_path, capsys):
    from tb3_sim_nav.world_to_map import main
    assert main(['no_such_world', '-f', str(tmp_path / 'x')]) == 1
    assert "world_to_map: world 'no_such_world': file" in capsys.readouterr().err
    assert main(['turtlebot3_stage_1', '-f', str(tmp_path / 's'), '--resolution', '0.1', '--margin', '0.2']) == 0
    loaded = load_map(str(tmp_path / 's.yaml'))
    assert loaded.grid.resolution == pytest.approx(0.1) and loaded.grid.width == 46  # 4.2 m + 2 x 0.2 m
    with pytest.raises(SystemExit):
        main(['turtlebot3_stage_1', '-f', str(tmp_path / 's'), '--resolution', '0'])


def test_rasterise_marks_every_cell_an_obstacle_covers_and_hardly_more():
    """Against samples in each cell, 16 x 16 (3 mm apart: every obstacle reaching one lies more than
    world_map.OVERLAP, 1 mm, into the cell): no covered cell missed, thin and turned walls included; and
    every cell marked beyond those, a finer grid of samples finds covered."""
    from tb3_sim_nav.world_file import Obstacle
    from tb3_sim_nav.world_map import occupied
    rng = np.random.default_rng(11)
    grid = Grid(0.05, 44, 40, (-1.0, -1.2, 0.0))
    obstacles = [Obstacle('box', (0.01, 1.2, 0.5), (0.3, 0.0, 0.25), 0.3, (1, 1, 1, 1), 'thin'),
                 Obstacle('box', (0.5, 0.05, 0.5), (0.0, 0.575, 0.25), 0.0, (1, 1, 1, 1), 'on_cell_edges')]
    for _ in range(6):
        x, y = rng.uniform(-0.8, 1.0), rng.uniform(-1.0, 0.4)
        obstacles.append(Obstacle('box', (rng.uniform(0.02, 0.6), rng.uniform(0.02, 0.6), 0.5), (x, y, 0.25),
                                  rng.uniform(-3, 3), (1, 1, 1, 1), ''))
        obstacles.append(Obstacle('cylinder', (rng.uniform(0.02, 0.3), 0.5), (y, x, 0.25), 0.0, (1, 1, 1, 1), ''))
    def covered(cells, per_side):
        """True per cell (n, 2) where one of per_side x per_side samples lies in an obstacle."""
        sub = (np.arange(per_side) + 0.5) / per_side - 0.5
        offsets = np.stack(np.meshgrid(sub, sub), -1).reshape(-1, 2) * grid.resolution
        points = grid.centres(cells)[:, None, :] + offsets
        return occupied(obstacles, points.reshape(-1, 2)).reshape(len(cells), -1).any(axis=1)

    cells = np.stack(np.meshgrid(np.arange(grid.width), np.arange(grid.height)), -1).reshape(-1, 2)
    marked = rasterise(obstacles, grid).ravel()
    sampled = covered(cells, 16)
    assert not (sampled & ~marked).any()  # nothing covered is missed
    # What the coarse samples did not see (slivers under 3 mm) a 0.4 mm grid of samples confirms.
    disputed = cells[marked & ~sampled]
    assert covered(disputed, 125).all()
    marked = marked.reshape(grid.shape)
    # The wall 0.05 m thick on cell edges (y 0.55..0.60 on a grid from -1.2) fills one row, not three.
    ix, iy = grid.to_cells((0.0, 0.575))
    assert marked[iy - 1:iy + 2, ix].tolist() == [False, True, False]


def test_signed_distance_is_negative_inside_overlapping_obstacles():
    from tb3_sim_nav.world_file import Obstacle
    from tb3_sim_nav.world_map import signed_distance
    wall = Obstacle('box', (2.0, 0.4, 0.5), (0.0, 0.0, 0.25), 0.0, (1, 1, 1, 1), 'wall')
    post = Obstacle('box', (0.2, 0.2, 0.5), (0.0, 0.25, 0.25), 0.0, (1, 1, 1, 1), 'post')  # overlaps the wall
    # (0, -0.1): 0.1 m inside the wall, 0.05 m outside the post: inside.
    assert signed_distance([wall, post], [(0.0, -0.1)])[0] == pytest.approx(-0.1)
    assert signed_distance([wall, post], [(0.0, 0.4)])[0] == pytest.approx(0.05)
