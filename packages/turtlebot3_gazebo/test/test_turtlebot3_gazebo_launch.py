"""turtlebot3_gazebo's launch files, as roslaunch reads them (no master): ROBOTIS' arguments with ROBOTIS'
defaults (turtlebot3_simulations, noetic-devel), ours beside them with a doc each, and the nodes they start."""
import math
import os

import pytest
import roslaunch.arg_dump
import roslaunch.config
from roslaunch.core import RLException

LAUNCH = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'launch')
MODEL = 'model type [burger, waffle, waffle_pi]'
#: ROBOTIS' spawn pose of each world launch (x_pos, y_pos; z_pos 0).
WORLDS = {'turtlebot3_empty_world': (0.0, 0.0), 'turtlebot3_world': (-2.0, -0.5), 'turtlebot3_house': (-3.0, 1.0),
          'turtlebot3_stage_1': (0.0, 0.0), 'turtlebot3_stage_2': (0.0, 0.0), 'turtlebot3_stage_3': (0.0, 0.0),
          'turtlebot3_stage_4': (-0.7, 0.0)}
#: What the simulator adds to every world launch.
OURS = ('world', 'gui', 'paused', 'use_sim_time', 'real_time_factor', 'profile')
MULTI_POSES = {'first_tb3': ('tb3_0', -7.0, -1.0, 1.57), 'second_tb3': ('tb3_1', 7.0, -1.0, 1.57),
               'third_tb3': ('tb3_2', 0.5, 3.0, 0.0)}
#: ROBOTIS' arguments and defaults of the other launch files.
ROBOTIS = {
    'turtlebot3_simulation': {'cmd_vel': '/cmd_vel', 'name': 'turtlebot3'},
    'turtlebot3_gazebo_rviz': {'model': 'burger'},
    'multi_turtlebot3_slam': {'ns': 'tb3_0'},
    'multi_map_merge': dict(sum([[(robot, name), (robot + '_x_pos', x), (robot + '_y_pos', y), (robot + '_z_pos', 0.0),
                                  (robot + '_yaw', 0.0)] for robot, (name, x, y, _) in MULTI_POSES.items()], [])),
    'multi_turtlebot3': dict([('model', 'burger')] + sum([[(robot, name), (robot + '_x_pos', x), (robot + '_y_pos', y),
                                                           (robot + '_z_pos', 0.0), (robot + '_yaw', yaw)]
                                                          for robot, (name, x, y, yaw) in MULTI_POSES.items()], [])),
}


def path(name):
    return os.path.join(LAUNCH, name + '.launch')


def nodes(name, *args):
    """{namespace + name: node} of the launch file with `args` (NAME:=VALUE), and its parameters."""
    config = roslaunch.config.load_config_default([(path(name), list(args))], None, verbose=False)
    return dict((node.namespace + node.name, node) for node in config.nodes), config.params


def same(value, expected):
    if isinstance(expected, float):
        return math.isclose(float(value), expected)
    return value == expected


@pytest.fixture(autouse=True)
def burger(monkeypatch):
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')


@pytest.mark.parametrize('name', sorted(WORLDS) + sorted(ROBOTIS))
def test_robotis_arguments_and_defaults_and_a_doc_for_each(name):
    args = roslaunch.arg_dump.get_args([path(name)])
    if name in WORLDS:
        expected = dict(model='burger', x_pos=WORLDS[name][0], y_pos=WORLDS[name][1], z_pos=0.0)
    else:
        expected = ROBOTIS[name]
    for arg, default in expected.items():
        assert arg in args and same(args[arg][1], default), (arg, args.get(arg))
    if 'model' in expected:
        assert args['model'][0] == MODEL
    if name in WORLDS or name == 'multi_turtlebot3':
        assert set(OURS) <= set(args), sorted(args)
    assert all(doc for doc, _ in args.values()), [arg for arg, (doc, _) in args.items() if not doc]


@pytest.mark.parametrize('name', sorted(WORLDS))
def test_a_world_launch_starts_the_simulator_where_robotis_spawns_and_no_robot_state_publisher(name):
    started, parameters = nodes(name)
    assert list(started) == ['/tb3_sim'] and started['/tb3_sim'].package == 'tb3_sim_nav'
    assert (parameters['/tb3_sim/x_pos'].value, parameters['/tb3_sim/y_pos'].value) == pytest.approx(WORLDS[name])
    assert parameters['/tb3_sim/world'].value == ('empty' if name == 'turtlebot3_empty_world' else name)
    assert '<robot name="turtlebot3_burger"' in parameters['/robot_description'].value
    assert parameters['/use_sim_time'].value is True


def test_a_world_launch_passes_its_arguments_on():
    """The other world launches include the empty world's with all their arguments."""
    started, parameters = nodes('turtlebot3_empty_world', 'model:=waffle', 'real_time_factor:=0', 'x_pos:=1.5')
    assert parameters['/tb3_sim/model'].value == 'waffle' and parameters['/tb3_sim/real_time_factor'].value == 0
    assert parameters['/tb3_sim/x_pos'].value == 1.5
    assert '<robot name="turtlebot3_waffle"' in parameters['/robot_description'].value


def test_without_turtlebot3_model_a_world_launch_fails_as_robotis_does(monkeypatch):
    monkeypatch.delenv('TURTLEBOT3_MODEL')
    with pytest.raises(RLException, match='TURTLEBOT3_MODEL'):
        nodes('turtlebot3_world')


def test_simulation_starts_turtlebot3_drive_on_the_topic_it_is_given():
    started, parameters = nodes('turtlebot3_simulation')
    drive = started['/turtlebot3_drive']
    assert (drive.package, drive.type, drive.required) == ('turtlebot3_gazebo', 'turtlebot3_drive', True)
    assert parameters['/cmd_vel_topic_name'].value == '/cmd_vel'
    started, parameters = nodes('turtlebot3_simulation', 'name:=tb3_0', 'cmd_vel:=/tb3_0/cmd_vel')
    assert list(started) == ['/tb3_0_drive'] and parameters['/cmd_vel_topic_name'].value == '/tb3_0/cmd_vel'


def test_gazebo_rviz_starts_the_remote_launch_and_rviz_with_its_view():
    started, parameters = nodes('turtlebot3_gazebo_rviz')
    assert sorted(started) == ['/robot_state_publisher', '/rviz']
    assert started['/rviz'].args.endswith('turtlebot3_gazebo/rviz/turtlebot3_gazebo_model.rviz')
    assert os.path.isfile(started['/rviz'].args.split()[-1])
    assert '/robot_description' in parameters


def test_multi_turtlebot3_gives_the_simulator_three_named_robots():
    started, parameters = nodes('multi_turtlebot3')
    assert list(started) == ['/tb3_sim']
    robots = parameters['/tb3_sim/robots'].value
    assert [(robot['name'], robot['position'][:2], robot['yaw']) for robot in robots] == [
        (name, [x, y], yaw) for name, x, y, yaw in MULTI_POSES.values()]
    assert parameters['/tb3_sim/world'].value == 'turtlebot3_house'


def test_multi_slam_starts_gmapping_in_the_namespace_on_its_frames():
    started, parameters = nodes('multi_turtlebot3_slam', 'ns:=tb3_1')
    node = started['/tb3_1/turtlebot3_slam_gmapping']
    assert (node.package, node.type) == ('gmapping', 'slam_gmapping')
    prefix = '/tb3_1/turtlebot3_slam_gmapping/'
    assert [parameters[prefix + name].value for name in ('base_frame', 'odom_frame', 'map_frame')] == [
        'tb3_1/base_footprint', 'tb3_1/odom', 'tb3_1/map']
    assert parameters[prefix + 'maxUrange'].value == 4.0 and parameters[prefix + 'particles'].value == 120


def test_map_merge_and_the_three_static_transforms_as_robotis_has_them():
    started, parameters = nodes('multi_map_merge')
    merge = started['/map_merge']
    assert (merge.package, merge.type) == ('multirobot_map_merge', 'map_merge')
    assert parameters['/map_merge/known_init_poses'].value is True
    assert parameters['/map_merge/robot_namespace'].value == 'tb3'
    for robot, (name, x, y, _) in MULTI_POSES.items():
        transform = started['/world_to_%s_tf_broadcaster' % name]
        assert (transform.package, transform.type) == ('tf', 'static_transform_publisher')
        assert transform.args == '0 0 0 0 0 0 /map /%s/map 100' % name
        assert parameters['/%s/map_merge/init_pose_x' % name].value == x
        assert parameters['/%s/map_merge/init_pose_y' % name].value == y
