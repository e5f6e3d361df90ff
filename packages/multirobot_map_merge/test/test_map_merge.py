"""map_merge's merge, discovery and parameters. No master."""
import math

import numpy as np
import pytest

from multirobot_map_merge import discovery
from multirobot_map_merge.config import MapMergeConfig
from multirobot_map_merge.merge import apply_update, merge, merged_grid, placed
from tb3_common import pose2d
from tb3_common.grid import FREE, OCCUPIED, UNKNOWN, Grid
from tb3_common.params import ParameterError

ROOM = (-1.0, -0.5, 3.0, 2.5)  # the world's room: xmin, ymin, xmax, ymax (m)
RESOLUTION = 0.05


def _to_walls(points):
    """Distance (m) of world points (..., 2) from the room's four walls."""
    xmin, ymin, xmax, ymax = ROOM
    x, y = points[..., 0], points[..., 1]
    outside = np.hypot(np.maximum(np.maximum(xmin - x, x - xmax), 0), np.maximum(np.maximum(ymin - y, y - ymax), 0))
    inside = np.minimum(np.minimum(x - xmin, xmax - x), np.minimum(y - ymin, ymax - y))
    return np.where(outside > 0, outside, np.abs(inside))


def _robot_map(placement, seen, resolution=RESOLUTION):
    """A robot's map of the room in its own frame, its frame at `placement` in the world: walls one cell
    thick, floor free, unknown where seen(world points) is false and outside the room."""
    grid = Grid(resolution, int(6.0 / resolution), int(6.0 / resolution), (-3.0, -3.0, 0.0))
    world = pose2d.transform_points(placement, grid.all_centres().reshape(-1, 2)).reshape(grid.shape + (2,))
    xmin, ymin, xmax, ymax = ROOM
    inside = (world[..., 0] > xmin) & (world[..., 0] < xmax) & (world[..., 1] > ymin) & (world[..., 1] < ymax)
    values = np.full(grid.shape, UNKNOWN, dtype=np.int8)
    values[inside] = FREE
    values[_to_walls(world) <= resolution / 2] = OCCUPIED
    values[~seen(world)] = UNKNOWN
    return grid, values


def _occupied_centres(grid, values):
    return grid.all_centres()[values == OCCUPIED]


WEST = (0.2, 0.4, 0.5)     # robot A's frame in the world
EAST = (2.3, 1.9, -2.0)    # robot B's frame: far off and turned


def _two_robots():
    a = _robot_map(WEST, lambda world: world[..., 0] < 1.2)
    b = _robot_map(EAST, lambda world: world[..., 0] > 0.8)
    return a, b


def test_two_maps_of_one_room_merge_into_one_whose_walls_coincide():
    (grid_a, values_a), (grid_b, values_b) = _two_robots()
    grid, values = merge([(grid_a, values_a, WEST), (grid_b, values_b, EAST)])
    assert grid.resolution == RESOLUTION and grid.origin[2] == 0.0
    walls = _to_walls(_occupied_centres(grid, values))
    assert walls.max() <= 1.5 * RESOLUTION  # a turned source, sampled: within a cell and a half of a wall
    # the whole room is known: the west half from A, the east half from B
    centres = grid.all_centres()
    xmin, ymin, xmax, ymax = ROOM
    floor = ((centres[..., 0] > xmin + 0.1) & (centres[..., 0] < xmax - 0.1) & (centres[..., 1] > ymin + 0.1)
             & (centres[..., 1] < ymax - 0.1))
    assert np.all(values[floor] == FREE)
    # every wall is there: points along the four walls each have an occupied cell near
    occupied = _occupied_centres(grid, values)
    for x, y in [(-1.0, 1.0), (3.0, 1.0), (0.0, -0.5), (2.5, -0.5), (0.0, 2.5), (2.5, 2.5)]:
        assert np.min(np.hypot(occupied[:, 0] - x, occupied[:, 1] - y)) <= 1.5 * RESOLUTION


def test_a_wrong_placement_is_seen():
    """The test has teeth: B placed as if its frame were the world's puts walls off the room's."""
    (grid_a, values_a), (grid_b, values_b) = _two_robots()
    grid, values = merge([(grid_a, values_a, WEST), (grid_b, values_b, (0.0, 0.0, 0.0))])
    assert _to_walls(_occupied_centres(grid, values)).max() > 0.5


def test_an_unturned_first_map_is_copied_cell_for_cell():
    grid_a, values_a = _robot_map((0.0, 0.0, 0.0), lambda world: world[..., 0] < 5)
    grid, values = merge([(grid_a, values_a, (1.0, 2.0, 0.0))])
    assert grid == Grid(RESOLUTION, grid_a.width, grid_a.height, (-2.0, -1.0, 0.0))
    assert np.array_equal(values, values_a)


def test_the_merged_grid_holds_every_placed_map_on_the_first_lattice():
    first = placed(Grid(0.1, 10, 10, (0.05, 0.05, 0.0)), (0.0, 0.0, 0.0))
    second = placed(Grid(0.1, 10, 10), (-2.0, 3.0, math.pi / 4))
    grid = merged_grid([first, second])
    assert (grid.origin[0] - 0.05) / 0.1 == pytest.approx(round((grid.origin[0] - 0.05) / 0.1))
    corners = second.centres(np.array([[0, 0], [9, 0], [9, 9], [0, 9]]))
    assert np.all(grid.inside(grid.to_cells(corners)))


def test_known_beats_unknown_and_occupied_beats_free():
    grid = Grid(1.0, 3, 1)
    a = np.array([[UNKNOWN, FREE, FREE]], dtype=np.int8)
    b = np.array([[FREE, OCCUPIED, UNKNOWN]], dtype=np.int8)
    _, values = merge([(grid, a, (0.0, 0.0, 0.0)), (grid, b, (0.0, 0.0, 0.0))])
    assert values.tolist() == [[FREE, OCCUPIED, FREE]]
    _, values = merge([(grid, b, (0.0, 0.0, 0.0)), (grid, a, (0.0, 0.0, 0.0))])  # in either order
    assert values.tolist() == [[FREE, OCCUPIED, FREE]]


def test_a_finer_map_s_thin_wall_is_kept_on_a_coarser_grid():
    coarse = (Grid(0.1, 10, 10), np.full((10, 10), FREE, dtype=np.int8))
    fine_grid = Grid(0.02, 50, 50)
    fine = np.full(fine_grid.shape, FREE, dtype=np.int8)
    fine[:, 22] = OCCUPIED  # a wall one fine cell thick at x = 0.44..0.46, off every coarse centre
    grid, values = merge([coarse + ((0.0, 0.0, 0.0),), (fine_grid, fine, (0.0, 0.0, 0.0))])
    assert np.all(values[:, 4] == OCCUPIED) and np.count_nonzero(values == OCCUPIED) == 10


def test_what_cannot_be_merged():
    grid = Grid(1.0, 2, 2)
    values = np.zeros((2, 2), dtype=np.int8)
    with pytest.raises(ValueError, match='no map'):
        merge([])
    with pytest.raises(ValueError, match='not finite'):
        merge([(grid, values, (math.nan, 0.0, 0.0))])
    with pytest.raises(ValueError, match='apart'):
        merge([(grid, values, (0.0, 0.0, 0.0)), (grid, values, (1e5, 1e5, 0.0))])
    with pytest.raises(ValueError, match='shape'):
        merge([(grid, np.zeros((3, 2), dtype=np.int8), (0.0, 0.0, 0.0))])


def test_a_map_update_is_written_into_a_copy():
    values = np.full((4, 5), UNKNOWN, dtype=np.int8)
    updated, cut = apply_update(values, 1, 2, 2, 2, [0, 100, 100, 0])
    assert not cut and np.all(values == UNKNOWN)
    assert updated[2:4, 1:3].tolist() == [[0, 100], [100, 0]]
    updated, cut = apply_update(values, 4, 3, 2, 2, bytes([0, 100, 255, 0]))  # data as genpy may give it
    assert cut and updated[3, 4] == 0 and np.count_nonzero(updated != UNKNOWN) == 1
    with pytest.raises(ValueError, match='negative'):
        apply_update(values, -1, 0, 1, 1, [0])
    with pytest.raises(ValueError, match='values'):
        apply_update(values, 0, 0, 2, 2, [0])


# --- discovery ---------------------------------------------------------------------------------
PUBLISHED = [('/tb3_0/map', 'nav_msgs/OccupancyGrid'), ('/tb3_1/map', 'nav_msgs/OccupancyGrid'),
             ('/tb3_0/map_metadata', 'nav_msgs/MapMetaData'), ('/map', 'nav_msgs/OccupancyGrid'),
             ('/tb3_2/move_base/global_costmap/costmap', 'nav_msgs/OccupancyGrid'),
             ('/other/map', 'nav_msgs/OccupancyGrid'), ('/tb3_2/map', 'std_msgs/String'),
             ('/fleet/tb3_5/map', 'nav_msgs/OccupancyGrid')]


def test_robots_are_found_as_the_original_finds_them():
    assert discovery.robot_maps(PUBLISHED, 'map', 'tb3', '/map') == {
        '/tb3_0': '/tb3_0/map', '/tb3_1': '/tb3_1/map', '/fleet/tb3_5': '/fleet/tb3_5/map'}
    # with no robot_namespace every map but the merged one is a robot's, the root's too
    assert set(discovery.robot_maps(PUBLISHED, 'map', '', '/map_merge/map')) == {
        '/tb3_0', '/tb3_1', '/', '/other', '/fleet/tb3_5'}


@pytest.mark.parametrize('name, parent', [('/tb3_0/map', '/tb3_0'), ('/map', '/'), ('/a/b/c', '/a/b'), ('/', '/')])
def test_parent_namespace(name, parent):
    assert discovery.parent_namespace(name) == parent


def test_init_poses_come_from_the_robot_s_namespace():
    params = {'/tb3_0/map_merge/init_pose_x': -7.0, '/tb3_0/map_merge/init_pose_y': -1,
              '/tb3_0/map_merge/init_pose_z': 0.0, '/tb3_0/map_merge/init_pose_yaw': 1.57}
    assert discovery.init_pose('/tb3_0', params.__getitem__) == (-7.0, -1.0, 1.57)
    with pytest.raises(discovery.InitPoseError, match='/tb3_1/map_merge/init_pose_x is not set'):
        discovery.init_pose('/tb3_1', params.__getitem__)
    for bad in (math.nan, True, 'west'):
        with pytest.raises(discovery.InitPoseError, match='init_pose_yaw'):
            discovery.init_pose('/tb3_0', dict(params, **{'/tb3_0/map_merge/init_pose_yaw': bad}).__getitem__)


# --- parameters ---------------------------------------------------------------------------------
def test_the_original_s_defaults():
    config = MapMergeConfig()
    assert (config.robot_map_topic, config.robot_map_updates_topic, config.robot_namespace,
            config.merged_map_topic, config.world_frame) == ('map', 'map_updates', '', 'map', 'world')
    assert (config.known_init_poses, config.merging_rate, config.discovery_rate, config.estimation_rate,
            config.estimation_confidence) == (True, 4.0, 0.05, 0.5, 1.0)


@pytest.mark.parametrize('name, value', [('merging_rate', 0.0), ('discovery_rate', -1), ('world_frame', ''),
                                         ('robot_map_topic', 'a/map'), ('known_init_poses', 'yes'),
                                         ('estimation_confidence', math.inf)])
def test_a_bad_value_names_its_parameter(name, value):
    with pytest.raises(ParameterError, match='~%s' % name):
        MapMergeConfig(**{name: value})
