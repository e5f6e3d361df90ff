"""World files: the shipped worlds load, and every malformed file is refused by name."""
import math

import pytest

from tb3_sim_nav.world_file import DEFAULT_COLOR, RobotSpec, WorldError, load_world

# A valid first obstacle, so that errors must name the second one.
GOOD = '  - cylinder: {radius: 0.1, height: 0.2}\n'


def write(tmp_path, text, name='world.yaml'):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def obstacles_of(world, worlds_folder):
    return load_world(world, worlds_folder).obstacles


def obstacles_file(tmp_path, *entries):
    return write(tmp_path, 'obstacles:\n' + GOOD + ''.join('  - %s\n' % e for e in entries))


# --- the shipped worlds --------------------------------------------------------------

def test_empty_world_has_no_obstacles(worlds_folder):
    assert obstacles_of('empty', str(worlds_folder)) == []


def test_turtlebot3_world_has_6_walls_and_9_pillars(worlds_folder):
    obstacles = obstacles_of('turtlebot3_world', str(worlds_folder))
    kinds = [obstacle.kind for obstacle in obstacles]
    assert kinds.count('box') == 6 and kinds.count('cylinder') == 9 and len(kinds) == 15


def test_turtlebot3_world_obstacles_stand_on_the_ground(worlds_folder):
    for obstacle in obstacles_of('turtlebot3_world', str(worlds_folder)):
        height = obstacle.size[2] if obstacle.kind == 'box' else obstacle.size[1]
        assert obstacle.position[2] == pytest.approx(height / 2.0)


def test_turtlebot3_world_walls_form_a_hexagon_of_inradius_2_5(worlds_folder):
    walls = [o for o in obstacles_of('turtlebot3_world', str(worlds_folder)) if o.kind == 'box']
    for wall in walls:
        x, y, _z = wall.position
        assert math.hypot(x, y) == pytest.approx(2.5 + wall.size[1] / 2, abs=0.01)
        # each wall runs across its radius: yaw is the radius' direction + 90 deg
        assert math.remainder(wall.yaw - math.atan2(y, x) - math.pi / 2, 2 * math.pi) == \
            pytest.approx(0.0, abs=1e-3)


# --- worlds given by path, and defaults ----------------------------------------------

def test_world_given_by_path(tmp_path, worlds_folder):
    path = write(tmp_path, 'obstacles:\n  - box: {size: [1, 2, 0.5], position: [3, -4], yaw: 0.5}\n',
                 name='mine.yaml')
    (box,) = obstacles_of(path, str(worlds_folder))
    assert box.kind == 'box'
    assert box.size == (1.0, 2.0, 0.5)
    assert box.position == (3.0, -4.0, 0.25)
    assert box.yaw == 0.5 and box.color == DEFAULT_COLOR


def test_position_with_z_keeps_z(tmp_path):
    (pillar,) = obstacles_of(write(tmp_path, 'obstacles:\n  - cylinder: {radius: 0.1, height: 0.4, '
                                           'position: [1, 2, 0.05]}\n'), str(tmp_path))
    assert pillar.position == (1.0, 2.0, 0.05)


def test_defaults_centre_a_shape_at_the_origin_on_the_ground(tmp_path):
    (pillar,) = obstacles_of(write(tmp_path, 'obstacles:\n' + GOOD), str(tmp_path))
    assert pillar.size == (0.1, 0.2)
    assert pillar.position == (0.0, 0.0, 0.1)
    assert pillar.yaw == 0.0 and pillar.color == DEFAULT_COLOR


def test_color_is_kept(tmp_path):
    (pillar,) = obstacles_of(write(tmp_path, 'obstacles:\n  - cylinder: {radius: 0.1, height: 0.4, '
                                           'color: [0.1, 0.2, 0.3, 1]}\n'), str(tmp_path))
    assert pillar.color == (0.1, 0.2, 0.3, 1.0)


def test_empty_file_is_an_empty_world(tmp_path):
    assert obstacles_of(write(tmp_path, ''), str(tmp_path)) == []


# --- malformed files -----------------------------------------------------------------

def test_missing_world_by_name_names_the_file(worlds_folder):
    with pytest.raises(WorldError) as error:
        load_world('no_such_world', str(worlds_folder))
    assert str(worlds_folder / 'no_such_world.yaml') in str(error.value)
    assert 'does not exist' in str(error.value)


def test_missing_world_by_path_names_the_file(tmp_path):
    path = str(tmp_path / 'nowhere.yaml')
    with pytest.raises(WorldError) as error:
        load_world(path, str(tmp_path))
    assert path in str(error.value) and 'does not exist' in str(error.value)


@pytest.mark.parametrize('text, problem', [
    ('obstacles: [\n', 'not valid YAML'),
    ('obstacles: {box: {size: [1, 1, 1]}\n', 'not valid YAML'),
    ('- box: {size: [1, 1, 1]}\n', 'top level'),
    ('just a string\n', 'top level'),
    ('obstacles: []\nlights: []\n', 'top level'),
    ('obstacle: []\n', 'top level'),
    ('obstacles: {box: {size: [1, 1, 1]}}\n', '"obstacles" must be a list'),
    ('obstacles: 5\n', '"obstacles" must be a list'),
    ('obstacles: box\n', '"obstacles" must be a list'),
    ('obstacles: 0\n', '"obstacles" must be a list'),
    ('obstacles: false\n', '"obstacles" must be a list'),
])
def test_malformed_top_level_names_file_and_problem(tmp_path, text, problem):
    path = write(tmp_path, text)
    with pytest.raises(WorldError) as error:
        load_world(path, str(tmp_path))
    assert path in str(error.value) and problem in str(error.value)


@pytest.mark.parametrize('entry, problem', [
    # shape and fields
    ('sphere: {radius: 1}', "unknown shape 'sphere'"),
    ('3', 'one key'),
    ('{box: {size: [1, 1, 1]}, cylinder: {radius: 1, height: 1}}', 'one key'),
    ('box: [1, 1, 1]', 'mapping of its fields'),
    ('cylinder: {radius: 0.1}', "missing ['height']"),
    ('box: {position: [0, 0]}', "missing ['size']"),
    ('box: {size: [1, 1, 1], colour: [1, 0, 0, 1]}', "unknown ['colour']"),
    ('cylinder: {radius: 0.1, height: 1, size: [1, 1, 1]}', "unknown ['size']"),
    # sizes
    ('box: {size: [1, 0, 1]}', 'box size must be > 0'),
    ('box: {size: [1, 1, -0.4]}', 'box size must be > 0'),
    ('box: {size: [1, 1]}', 'box size'),
    ('box: {size: 1}', 'box size'),
    ('cylinder: {radius: 0, height: 1}', 'cylinder radius must be > 0'),
    ('cylinder: {radius: -0.1, height: 1}', 'cylinder radius must be > 0'),
    ('cylinder: {radius: 0.1, height: 0.0}', 'cylinder height must be > 0'),
    ('cylinder: {radius: .nan, height: 1}', 'cylinder radius'),
    # positions
    ('box: {size: [1, 1, 1], position: [.nan, 0]}', 'position'),
    ('box: {size: [1, 1, 1], position: [0, .inf]}', 'position'),
    ('box: {size: [1, 1, 1], position: [0, 0, -.inf]}', 'position'),
    ('box: {size: [1, 1, 1], position: [1]}', 'position'),
    ('box: {size: [1, 1, 1], position: [1, 2, 3, 4]}', 'position'),
    ('box: {size: [1, 1, 1], position: "1, 2"}', 'position'),
    ('box: {size: [1, 1, 1], yaw: .nan}', 'yaw'),
    ('box: {size: [1, 1, 1], yaw: "90deg"}', 'yaw'),
    # a bool is never a number
    ('box: {size: [1, true, 1]}', 'box size'),
    ('cylinder: {radius: true, height: 1}', 'cylinder radius'),
    ('box: {size: [1, 1, 1], position: [true, 0]}', 'position'),
    ('box: {size: [1, 1, 1], yaw: false}', 'yaw'),
    # colours
    ('box: {size: [1, 1, 1], color: [1, 0, 0]}', 'color'),
    ('box: {size: [1, 1, 1], color: [1, 0, 0, 1, 1]}', 'color'),
])
def test_malformed_obstacle_names_file_index_and_problem(tmp_path, entry, problem):
    path = obstacles_file(tmp_path, entry)
    with pytest.raises(WorldError) as error:
        load_world(path, str(tmp_path))
    message = str(error.value)
    assert path in message
    assert 'obstacle 2' in message
    assert problem in message


@pytest.mark.parametrize('entry, shown', [
    ('box: {size: [1, true, 1]}', 'True'),
    ('box: {size: [1, 1, 1], position: [.nan, 0]}', 'nan'),
    ('box: {size: [1, 1, 1], color: [1, 0, 0]}', '[1, 0, 0]'),
])
def test_malformed_value_is_shown(tmp_path, entry, shown):
    with pytest.raises(WorldError) as error:
        load_world(obstacles_file(tmp_path, entry), str(tmp_path))
    assert shown in str(error.value)


def test_world_error_is_a_value_error():
    assert issubclass(WorldError, ValueError)


# --- names and robots ------------------------------------------------------------------

def test_obstacles_may_have_names(tmp_path):
    (wall, pillar) = obstacles_of(write(tmp_path, 'obstacles:\n  - box: {size: [1, 1, 1], name: north_wall}\n'
                                        + GOOD), str(tmp_path))
    assert wall.name == 'north_wall' and pillar.name == ''


def test_two_obstacles_with_one_name_are_refused_by_name(tmp_path):
    path = write(tmp_path, 'obstacles:\n  - box: {size: [1, 1, 1], name: w}\n  - box: {size: [1, 1, 1], name: w}\n')
    with pytest.raises(WorldError, match="two obstacles are named 'w'"):
        load_world(path, str(tmp_path))


def test_a_world_lists_robots_with_name_model_and_pose(tmp_path):
    world = load_world(write(tmp_path, 'robots:\n'
                                       '  - {name: tb3_3, model: waffle, position: [1.0, -2.0], yaw: 1.5}\n'
                                       '  - {name: scout, model: burger, position: [0, 0, 0.01]}\n'), str(tmp_path))
    assert world.obstacles == []
    assert world.robots == [RobotSpec('tb3_3', 'waffle', (1.0, -2.0, 0.0), 1.5),
                            RobotSpec('scout', 'burger', (0.0, 0.0, 0.01), 0.0)]


@pytest.mark.parametrize('entry, shown', [
    ('{model: burger, position: [0, 0]}', "missing ['name']"),
    ('{name: a, position: [0, 0]}', "missing ['model']"),
    ('{name: a, model: burger}', "missing ['position']"),
    ('{name: a, model: burger, position: [0, 0], colour: red}', "unknown ['colour']"),
    ('{name: 3a, model: burger, position: [0, 0]}', "name '3a' must be a ROS name"),
    ('{name: a/b, model: burger, position: [0, 0]}', "name 'a/b' must be a ROS name"),
    ('{name: a, model: 5, position: [0, 0]}', 'model must be burger, waffle, waffle_pi or a URDF path'),
    ('{name: a, model: burger, position: [0]}', 'robot a: position must be a list of 2 or 3 finite numbers'),
    ('{name: a, model: burger, position: [0, .nan]}', 'robot a: position must be a list of 2 or 3 finite'),
    ('{name: a, model: burger, position: [0, 0], yaw: up}', 'robot a: yaw must be a list of 1 finite'),
    ('tb3_0', 'must be a mapping of name, model, position and yaw'),
])
def test_a_bad_robot_entry_is_refused_naming_file_entry_and_problem(tmp_path, entry, shown):
    path = write(tmp_path, 'robots:\n  - {name: ok, model: burger, position: [5, 5]}\n  - %s\n' % entry)
    with pytest.raises(WorldError) as error:
        load_world(path, str(tmp_path))
    assert path in str(error.value) and 'robot 2' in str(error.value) and shown in str(error.value)


def test_two_robots_with_one_name_in_a_world_are_refused(tmp_path):
    path = write(tmp_path, 'robots:\n  - {name: a, model: burger, position: [0, 0]}\n'
                           '  - {name: a, model: burger, position: [1, 0]}\n')
    with pytest.raises(WorldError, match="two robots are named 'a'"):
        load_world(path, str(tmp_path))
