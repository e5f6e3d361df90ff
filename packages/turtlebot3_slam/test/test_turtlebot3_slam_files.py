"""turtlebot3_slam's files against ROBOTIS' (ROBOTIS-GIT/turtlebot3, branch noetic): the launch files'
arguments, the gmapping parameters, the rviz views; and every slam_methods as roslaunch resolves it
(no master: roslaunch's own loader, as `roslaunch --nodes` reads the files)."""
import dataclasses
import os
from xml.etree import ElementTree

import pytest
import yaml

from gmapping.config import METHODS, UNHONOURED
from tb3_navigation.slam_config import SlamConfig

PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROBOTIS_METHODS = ('gmapping', 'cartographer', 'hector', 'karto', 'frontier_exploration')
MODEL = ('model', '$(env TURTLEBOT3_MODEL)')
LUA = ('configuration_basename', 'turtlebot3_lds_2d.lua')
#: Each launch file's arguments and defaults, in ROBOTIS' order.
ROBOTIS_ARGS = {
    'turtlebot3_slam.launch': [MODEL, ('slam_methods', 'gmapping'), LUA, ('open_rviz', 'true')],
    'turtlebot3_gmapping.launch': [MODEL, LUA, ('set_base_frame', 'base_footprint'), ('set_odom_frame', 'odom'),
                                   ('set_map_frame', 'map')],
    'turtlebot3_cartographer.launch': [MODEL, LUA],
    'turtlebot3_hector.launch': [MODEL, LUA, ('odom_frame', 'odom'), ('base_frame', 'base_footprint'),
                                 ('scan_subscriber_queue_size', '5'), ('scan_topic', 'scan'), ('map_size', '2048'),
                                 ('pub_map_odom_transform', 'true'),
                                 ('tf_map_scanmatch_transform_frame_name', 'scanmatcher_frame')],
    'turtlebot3_karto.launch': [MODEL, LUA],
    'turtlebot3_frontier_exploration.launch': [MODEL, LUA, ('sensor_range', '1.0'), ('cmd_vel_topic', '/cmd_vel'),
                                               ('odom_topic', 'odom')],
}
#: config/gmapping_params.yaml, every key.
ROBOTIS_GMAPPING = dict(
    map_update_interval=2.0, maxUrange=3.0, sigma=0.05, kernelSize=1, lstep=0.05, astep=0.05, iterations=5,
    lsigma=0.075, ogain=3.0, lskip=0, minimumScore=50, srr=0.1, srt=0.2, str=0.1, stt=0.2, linearUpdate=1.0,
    angularUpdate=0.2, temporalUpdate=0.5, resampleThreshold=0.5, particles=100, xmin=-10.0, ymin=-10.0, xmax=10.0,
    ymax=10.0, delta=0.05, llsamplerange=0.01, llsamplestep=0.01, lasamplerange=0.005, lasamplestep=0.005)
#: The node names ROBOTIS' launch files give each method's mapper (cartographer's main node).
NODE_OF = {'gmapping': 'turtlebot3_slam_gmapping', 'cartographer': 'cartographer_node', 'hector': 'hector_mapping',
           'karto': 'slam_karto', 'frontier_exploration': 'turtlebot3_slam_gmapping'}


def path(*parts):
    return os.path.join(PACKAGE, *parts)


def launch_root(name):
    return ElementTree.parse(path('launch', name)).getroot()


def test_the_launch_files_are_robotis_and_only_those():
    assert sorted(os.listdir(path('launch'))) == sorted(ROBOTIS_ARGS)
    assert sorted(ROBOTIS_ARGS) == sorted(['turtlebot3_slam.launch'] + ['turtlebot3_%s.launch' % method
                                                                        for method in ROBOTIS_METHODS])


@pytest.mark.parametrize('name', sorted(ROBOTIS_ARGS))
def test_the_arguments_are_robotis_each_with_a_doc(name):
    arguments = launch_root(name).findall('arg')
    assert [(arg.get('name'), arg.get('default')) for arg in arguments] == ROBOTIS_ARGS[name]
    assert all(arg.get('doc') for arg in arguments)  # what roslaunch --ros-args shows


def test_turtlebot3_slam_launch_includes_as_robotis_does():
    root = launch_root('turtlebot3_slam.launch')
    includes = [(include.get('file'), {arg.get('name'): arg.get('value') for arg in include.findall('arg')})
                for include in root.findall('include')]
    assert includes == [('$(find turtlebot3_bringup)/launch/turtlebot3_remote.launch', {'model': '$(arg model)'}),
                        ('$(find turtlebot3_slam)/launch/turtlebot3_$(arg slam_methods).launch',
                         {'model': '$(arg model)', 'configuration_basename': '$(arg configuration_basename)'})]
    rviz = root.find("group[@if='$(arg open_rviz)']/node")
    assert (rviz.get('pkg'), rviz.get('type'), rviz.get('required')) == ('rviz', 'rviz', 'true')
    assert rviz.get('args') == '-d $(find turtlebot3_slam)/rviz/turtlebot3_$(arg slam_methods).rviz'


def test_turtlebot3_gmapping_launch_starts_gmapping_as_robotis_does():
    node = launch_root('turtlebot3_gmapping.launch').find('node')
    assert {key: node.get(key) for key in ('pkg', 'type', 'name', 'output')} == {
        'pkg': 'gmapping', 'type': 'slam_gmapping', 'name': 'turtlebot3_slam_gmapping', 'output': 'screen'}
    assert {param.get('name'): param.get('value') for param in node.findall('param')} == {
        'base_frame': '$(arg set_base_frame)', 'odom_frame': '$(arg set_odom_frame)',
        'map_frame': '$(arg set_map_frame)'}
    loads = [(rosparam.get('command'), rosparam.get('file')) for rosparam in node.findall('rosparam')]
    assert loads == [('load', '$(find turtlebot3_slam)/config/gmapping_params.yaml')]


def test_gmapping_params_are_robotis_every_one_taken_by_the_node():
    with open(path('config', 'gmapping_params.yaml')) as stream:
        values = yaml.safe_load(stream)
    assert values == ROBOTIS_GMAPPING and list(values) == list(ROBOTIS_GMAPPING)
    honoured = {name for name in values if name not in UNHONOURED}
    assert honoured <= {field.name for field in dataclasses.fields(SlamConfig)}
    # ... and they are SlamConfig's defaults: a node started without the file maps the same.
    assert SlamConfig(**{name: values[name] for name in honoured}) == SlamConfig()


def nodes_of(launch, monkeypatch, **arguments):
    """The nodes roslaunch would start for `launch` with `arguments`, and the parameters it would set."""
    import roslaunch.config
    import roslaunch.xmlloader
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')
    config = roslaunch.config.ROSLaunchConfig()
    roslaunch.xmlloader.XmlLoader().load(path('launch', launch), config, verbose=False,
                                         argv=['%s:=%s' % item for item in arguments.items()])
    return {node.name: node for node in config.nodes}, {name: param.value for name, param in config.params.items()}


@pytest.mark.parametrize('method', ROBOTIS_METHODS)
def test_every_slam_method_runs_our_slam_under_robotis_node_name_and_says_which(method, monkeypatch):
    nodes, params = nodes_of('turtlebot3_slam.launch', monkeypatch, slam_methods=method, open_rviz='false')
    slam = nodes[NODE_OF[method]]
    assert (slam.package, slam.type) == ('gmapping', 'slam_gmapping')
    assert nodes['robot_state_publisher'].package == 'robot_state_publisher'  # turtlebot3_remote.launch's
    said = params.get('/%s/slam_methods' % slam.name)
    assert said == (None if method == 'gmapping' else method) and method in METHODS
    assert 'rviz' not in nodes
    if method in ('cartographer', 'frontier_exploration'):  # ROBOTIS' start move_base beside them
        assert nodes['move_base'].package == 'move_base'


def test_rviz_is_started_with_the_methods_view(monkeypatch):
    nodes, _ = nodes_of('turtlebot3_slam.launch', monkeypatch, slam_methods='karto')
    assert nodes['rviz'].args.endswith('/rviz/turtlebot3_karto.rviz')


def rviz_view(name):
    with open(path('rviz', name)) as stream:
        return yaml.safe_load(stream)['Visualization Manager']


def displays(view):
    """(class, topic) of every display, those in groups too."""
    for display in view['Displays']:
        yield display['Class'], display.get('Topic', display.get('Marker Topic'))
        yield from displays(display) if 'Displays' in display else ()


@pytest.mark.parametrize('method', ROBOTIS_METHODS)
def test_each_method_has_a_view_of_the_map_scan_and_robot_that_rviz_can_load(method):
    view = rviz_view('turtlebot3_%s.rviz' % method)
    shown = set(displays(view))
    assert {('rviz/Map', '/map'), ('rviz/LaserScan', '/scan'), ('rviz/RobotModel', None)} <= shown
    assert all(kind.startswith('rviz/') for kind, _ in shown)  # Debian has no cartographer_rviz
    assert view['Global Options']['Fixed Frame'] == 'map'
    assert {'rviz/SetInitialPose', 'rviz/SetGoal'} <= {tool['Class'] for tool in view['Tools']}


def test_hector_and_karto_show_what_gmapping_does_as_robotis_views_do():
    assert all(os.path.samefile(path('rviz', 'turtlebot3_gmapping.rviz'), path('rviz', 'turtlebot3_%s.rviz' % method))
               for method in ('hector', 'karto'))
    frontier_exploration = set(displays(rviz_view('turtlebot3_frontier_exploration.rviz')))
    assert ('rviz/MarkerArray', '/explore/frontiers') in frontier_exploration  # explore_lite's, in its place
