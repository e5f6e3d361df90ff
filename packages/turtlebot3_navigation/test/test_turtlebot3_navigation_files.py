"""turtlebot3_navigation's files against ROBOTIS' (ROBOTIS-GIT/turtlebot3, branch noetic): the launch
files' arguments, amcl's values, move_base's parameter files, the default map and the rviz view; and
every launch file of the repository that loads one of these parameter files finds it."""
import dataclasses
import glob
import os
import re
from xml.etree import ElementTree

import pytest
import rospkg
import yaml

from tb3_navigation.amcl_config import AmclConfig

PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODEL = ('model', '$(env TURTLEBOT3_MODEL)')
FORWARD = ('move_forward_only', 'false')
#: Each launch file's arguments and defaults, in ROBOTIS' order.
ROBOTIS_ARGS = {
    'turtlebot3_navigation.launch': [MODEL, ('map_file', '$(find turtlebot3_navigation)/maps/map.yaml'),
                                     ('open_rviz', 'true'), FORWARD],
    'amcl.launch': [('scan_topic', 'scan'), ('initial_pose_x', '0.0'), ('initial_pose_y', '0.0'),
                    ('initial_pose_a', '0.0')],
    'move_base.launch': [MODEL, ('cmd_vel_topic', '/cmd_vel'), ('odom_topic', 'odom'), FORWARD],
}
#: amcl.launch's parameters, as written there.
ROBOTIS_AMCL = {
    'min_particles': '500', 'max_particles': '3000', 'kld_err': '0.02', 'update_min_d': '0.20',
    'update_min_a': '0.20', 'resample_interval': '1', 'transform_tolerance': '0.5', 'recovery_alpha_slow': '0.00',
    'recovery_alpha_fast': '0.00', 'initial_pose_x': '$(arg initial_pose_x)', 'initial_pose_y': '$(arg initial_pose_y)',
    'initial_pose_a': '$(arg initial_pose_a)', 'gui_publish_rate': '50.0', 'laser_max_range': '3.5',
    'laser_max_beams': '180', 'laser_z_hit': '0.5', 'laser_z_short': '0.05', 'laser_z_max': '0.05',
    'laser_z_rand': '0.5', 'laser_sigma_hit': '0.2', 'laser_lambda_short': '0.1', 'laser_likelihood_max_dist': '2.0',
    'laser_model_type': 'likelihood_field', 'odom_model_type': 'diff', 'odom_alpha1': '0.1', 'odom_alpha2': '0.1',
    'odom_alpha3': '0.1', 'odom_alpha4': '0.1', 'odom_frame_id': 'odom', 'base_frame_id': 'base_footprint'}


def costmap_common(footprint):
    return {'obstacle_range': 3.0, 'raytrace_range': 3.5, 'footprint': footprint, 'inflation_radius': 1.0,
            'cost_scaling_factor': 3.0, 'map_type': 'costmap', 'observation_sources': 'scan',
            'scan': {'sensor_frame': 'base_scan', 'data_type': 'LaserScan', 'topic': 'scan', 'marking': True,
                     'clearing': True}}


def dwa(speed, turn, sim_time):
    return {'DWAPlannerROS': {
        'max_vel_x': speed, 'min_vel_x': -speed, 'max_vel_y': 0.0, 'min_vel_y': 0.0, 'max_vel_trans': speed,
        'min_vel_trans': speed / 2, 'max_vel_theta': turn[0], 'min_vel_theta': turn[1], 'acc_lim_x': 2.5,
        'acc_lim_y': 0.0, 'acc_lim_theta': 3.2, 'xy_goal_tolerance': 0.05, 'yaw_goal_tolerance': 0.17,
        'latch_xy_goal_tolerance': False, 'sim_time': sim_time, 'vx_samples': 20, 'vy_samples': 0, 'vth_samples': 40,
        'controller_frequency': 10.0, 'path_distance_bias': 32.0, 'goal_distance_bias': 20.0, 'occdist_scale': 0.02,
        'forward_point_distance': 0.325, 'stop_time_buffer': 0.2, 'scaling_speed': 0.25, 'max_scaling_factor': 0.2,
        'oscillation_reset_dist': 0.05, 'publish_traj_pc': True, 'publish_cost_grid_pc': True}}


BURGER = [[-0.105, -0.105], [-0.105, 0.105], [0.041, 0.105], [0.041, -0.105]]
WAFFLE = [[-0.205, -0.155], [-0.205, 0.155], [0.077, 0.155], [0.077, -0.155]]
#: param/, every file and every value.
ROBOTIS_PARAMS = {
    'costmap_common_params_burger.yaml': costmap_common(BURGER),
    'costmap_common_params_waffle.yaml': costmap_common(WAFFLE),
    'costmap_common_params_waffle_pi.yaml': costmap_common(WAFFLE),
    'dwa_local_planner_params_burger.yaml': dwa(0.22, (2.75, 1.37), 1.5),
    'dwa_local_planner_params_waffle.yaml': dwa(0.26, (1.82, 0.9), 2.0),
    'dwa_local_planner_params_waffle_pi.yaml': dwa(0.26, (1.82, 0.9), 2.0),
    'global_costmap_params.yaml': {'global_costmap': {
        'global_frame': 'map', 'robot_base_frame': 'base_footprint', 'update_frequency': 10.0,
        'publish_frequency': 10.0, 'transform_tolerance': 0.5, 'static_map': True}},
    'local_costmap_params.yaml': {'local_costmap': {
        'global_frame': 'odom', 'robot_base_frame': 'base_footprint', 'update_frequency': 10.0,
        'publish_frequency': 10.0, 'transform_tolerance': 0.5, 'static_map': False, 'rolling_window': True,
        'width': 3, 'height': 3, 'resolution': 0.05}},
    'move_base_params.yaml': {
        'shutdown_costmaps': False, 'controller_frequency': 10.0, 'planner_patience': 5.0, 'controller_patience': 15.0,
        'conservative_reset_dist': 3.0, 'planner_frequency': 5.0, 'oscillation_timeout': 10.0,
        'oscillation_distance': 0.2},
    'base_local_planner_params.yaml': {'TrajectoryPlannerROS': {
        'max_vel_x': 0.18, 'min_vel_x': 0.08, 'max_vel_theta': 1.0, 'min_vel_theta': -1.0,
        'min_in_place_vel_theta': 1.0, 'acc_lim_x': 1.0, 'acc_lim_y': 0.0, 'acc_lim_theta': 0.6,
        'xy_goal_tolerance': 0.10, 'yaw_goal_tolerance': 0.05, 'holonomic_robot': False, 'sim_time': 0.8,
        'vx_samples': 18, 'vtheta_samples': 20, 'sim_granularity': 0.05}},
}
#: move_base.launch's rosparam loads, in its order: (file, ns).
ROBOTIS_LOADS = [('costmap_common_params_$(arg model).yaml', 'global_costmap'),
                 ('costmap_common_params_$(arg model).yaml', 'local_costmap'), ('local_costmap_params.yaml', None),
                 ('global_costmap_params.yaml', None), ('move_base_params.yaml', None),
                 ('dwa_local_planner_params_$(arg model).yaml', None)]


def path(*parts):
    return os.path.join(PACKAGE, *parts)


def launch_root(name):
    """The launch file's XML root, once its arguments are checked: ROBOTIS' names and defaults in ROBOTIS'
    order, each with a doc (what roslaunch --ros-args shows)."""
    root = ElementTree.parse(path('launch', name)).getroot()
    assert [(arg.get('name'), arg.get('default'), bool(arg.get('doc'))) for arg in root.findall('arg')] == [
        (argument, default, True) for argument, default in ROBOTIS_ARGS[name]]
    return root


def test_turtlebot3_navigation_launch_starts_what_robotis_does():
    root = launch_root('turtlebot3_navigation.launch')
    assert sorted(os.listdir(path('launch'))) == sorted(ROBOTIS_ARGS)
    assert [include.get('file') for include in root.findall('include')] == [
        '$(find turtlebot3_bringup)/launch/turtlebot3_remote.launch',
        '$(find turtlebot3_navigation)/launch/amcl.launch', '$(find turtlebot3_navigation)/launch/move_base.launch']
    map_server = root.find('node')
    assert [map_server.get(key) for key in ('pkg', 'type', 'name', 'args')] == [
        'map_server', 'map_server', 'map_server', '$(arg map_file)']
    rviz = root.find("group[@if='$(arg open_rviz)']/node")
    assert rviz.get('args') == '-d $(find turtlebot3_navigation)/rviz/turtlebot3_navigation.rviz'


def test_amcl_launch_has_robotis_values_inline_each_one_amcl_takes():
    node = launch_root('amcl.launch').find('node')
    assert [node.get(key) for key in ('pkg', 'type', 'name')] == ['amcl', 'amcl', 'amcl']
    values = {param.get('name'): param.get('value') for param in node.findall('param')}
    assert values == ROBOTIS_AMCL
    assert set(values) <= {field.name for field in dataclasses.fields(AmclConfig)}
    assert [(remap.get('from'), remap.get('to')) for remap in node.findall('remap')] == [('scan', '$(arg scan_topic)')]


def test_move_base_launch_loads_robotis_param_files_with_dwa():
    node = launch_root('move_base.launch').find('node')
    assert [node.get(key) for key in ('pkg', 'type', 'name')] == ['move_base', 'move_base', 'move_base']
    params = [(param.get('name'), param.get('value'), param.get('if')) for param in node.findall('param')]
    assert params == [('base_local_planner', 'dwa_local_planner/DWAPlannerROS', None),
                      ('DWAPlannerROS/min_vel_x', '0.0', '$(arg move_forward_only)')]
    loads = [(rosparam.get('file'), rosparam.get('ns')) for rosparam in node.findall('rosparam')]
    assert loads == [('$(find turtlebot3_navigation)/param/' + name, ns) for name, ns in ROBOTIS_LOADS]
    assert [(remap.get('from'), remap.get('to')) for remap in node.findall('remap')] == [
        ('cmd_vel', '$(arg cmd_vel_topic)'), ('odom', '$(arg odom_topic)')]


@pytest.mark.parametrize('name', sorted(ROBOTIS_PARAMS))
def test_every_param_file_has_robotis_values_and_no_other(name):
    with open(path('param', name)) as stream:
        assert yaml.safe_load(stream) == ROBOTIS_PARAMS[name]
    assert sorted(os.listdir(path('param'))) == sorted(ROBOTIS_PARAMS)


def test_every_launch_file_of_the_repository_finds_the_param_files_it_loads():
    """One copy of the files (moved here from tb3_sim_nav's param/), and every launch file that loads one
    (ours: tb3_navigation.launch, tb3_slam.launch's explore, move_base.launch) names it here."""
    repository = os.path.dirname(os.path.dirname(PACKAGE))
    launches = glob.glob(os.path.join(repository, 'launch', '*.launch')) + glob.glob(
        os.path.join(repository, 'packages', '*', 'launch', '*.launch'))
    found = 0
    for launch in launches:
        with open(launch) as stream:
            text = stream.read()
        assert '$(find tb3_sim_nav)/param/' not in text, launch
        for name in re.findall(r'\$\(find turtlebot3_navigation\)/param/([\w.$() ]+?\.yaml)', text):
            for model in ('burger', 'waffle', 'waffle_pi'):
                assert os.path.exists(path('param', name.replace('$(arg model)', model))), (launch, name)
            found += 1
    assert found >= 14 and not os.path.exists(os.path.join(repository, 'param'))


def test_the_default_map_is_tb3_sim_navs_turtlebot3_world_map():
    """A copy (map_server reads an image relative to its YAML, and ROBOTIS' map.yaml names ./map.pgm):
    the image byte for byte, the YAML but for the image's name. maps/turtlebot3_world is the world file
    cut at the lidar's height, so the default map matches the simulated world."""
    from tb3_common.map_files import load_map
    shipped = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'maps', 'turtlebot3_world')
    with open(path('maps', 'map.pgm'), 'rb') as copy, open(shipped + '.pgm', 'rb') as original:
        assert copy.read() == original.read()
    with open(path('maps', 'map.yaml')) as copy, open(shipped + '.yaml') as original:
        assert copy.read() == original.read().replace('image: turtlebot3_world.pgm', 'image: ./map.pgm')
    loaded, world = load_map(path('maps', 'map.yaml')), load_map(shipped + '.yaml')
    assert loaded.grid == world.grid and (loaded.values == world.values).all()


def test_the_rviz_view_shows_what_robotis_shows():
    with open(path('rviz', 'turtlebot3_navigation.rviz')) as stream:
        view = yaml.safe_load(stream)['Visualization Manager']
    shown, stack = set(), list(view['Displays'])
    while stack:
        display = stack.pop()
        shown.add((display['Class'], display.get('Topic')))
        stack.extend(display.get('Displays', ()))
    assert {('rviz/Map', '/map'), ('rviz/LaserScan', '/scan'), ('rviz/Path', '/move_base/NavfnROS/plan'),
            ('rviz/Map', '/move_base/global_costmap/costmap'), ('rviz/Map', '/move_base/local_costmap/costmap'),
            ('rviz/Polygon', '/move_base/local_costmap/footprint'),
            ('rviz/Path', '/move_base/DWAPlannerROS/local_plan'),
            ('rviz/PoseArray', '/particlecloud'), ('rviz/RobotModel', None)} <= shown
    assert view['Global Options']['Fixed Frame'] == 'map'
    tools = {tool['Class']: tool.get('Topic') for tool in view['Tools']}
    assert tools['rviz/SetInitialPose'] == '/initialpose' and tools['rviz/SetGoal'] == '/move_base_simple/goal'
