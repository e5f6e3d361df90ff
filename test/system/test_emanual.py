"""ROBOTIS' e-manual, SLAM and navigation chapters (noetic), typed as it writes them, with rviz (issue 29).

In one terminal each, through bash, in a fresh HOME, with rviz on a screen
of the test's own (the launches open it, as on a desktop):

    export TURTLEBOT3_MODEL=burger
    roslaunch turtlebot3_gazebo turtlebot3_world.launch               (+ real_time_factor:=0, ours)
    roslaunch turtlebot3_slam turtlebot3_slam.launch slam_methods:=gmapping
    (the robot driven round the pillars: tb3_harness.route_driver, where the learner uses the teleop)
    rosrun map_server map_saver -f ~/map
    (Ctrl+C in the SLAM's terminal)
    roslaunch turtlebot3_navigation turtlebot3_navigation.launch map_file:=$HOME/map.yaml
    2D Pose Estimate where the robot stands, then a 2D Nav Goal (published as rviz's tools publish them)

The world runs as fast as possible (lockstep makes that the same as real
time). What rviz shows at each step must be there: the map in the SLAM's
view; the plan, the costmap and the particles in navigation's. The saved map
must lie on the world's walls, and the goal must SUCCEED with the true pose
within DWAPlannerROS's tolerances. The screenshots go to
~/.ros/test_results/tb3_sim_nav/emanual/ (doc/'s pictures are copies).
"""
import glob
import json
import math
import os
import shutil
import signal

import numpy as np
import pytest
import rosgraph
import rospkg
import yaml

from tb3_harness.map_quality import measure
from tb3_harness.report import figure
from tb3_harness.screen import save_png, screenshot
from tb3_harness.waypoints import WORLD_LOOP_START

from tb3_system_utils import run, wait_until

TIMEOUT = 60.0
ROUTE_TIMEOUT = 900.0  # wall s for the loop round the pillars (about 90 s of sim time), rviz drawing beside
EXPORT = 'export TURTLEBOT3_MODEL=burger'
WORLD = 'roslaunch turtlebot3_gazebo turtlebot3_world.launch'  # the e-manual's (the README's)
SHOTS = os.path.join(rospkg.get_ros_home(), 'test_results', 'tb3_sim_nav', 'emanual')
GOAL = (0.55, 0.55, math.pi / 2)
XY_TOLERANCE, YAW_TOLERANCE = 0.05, 0.17  # DWAPlannerROS's, TurtleBot3's
#: Where the loop ends: back at the spawn, facing west (map coordinates are the world's, as odom's are).
END_OF_LOOP = (-2.0, -0.5, math.pi)
INITIAL_POSE = ("rostopic pub -1 /initialpose geometry_msgs/PoseWithCovarianceStamped '{header: {frame_id: map}, "
                "pose: {pose: {position: {x: -2.0, y: -0.5}, orientation: {z: 1.0, w: 0.0}}, covariance: [0.25, 0, 0, "
                "0, 0, "
                "0, 0, 0.25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, "
                "0.06853891945]}}'")
NAV_GOAL = ("rostopic pub -1 /move_base_simple/goal geometry_msgs/PoseStamped '{header: {frame_id: map}, pose: "
            "{position: {x: 0.55, y: 0.55}, orientation: {z: 0.7071068, w: 0.7071068}}}'")


def bash(command):
    return ['bash', '-c', '%s && %s' % (EXPORT, command)]


UNKNOWN = (92, 110, 108)  # rviz's "map" scheme: an unknown cell (-1) on the view's background
FLOOR = (192, 192, 192)   # a free cell (0)
WALL = (14, 14, 14)       # an occupied one (100)
PARTICLES = (0, 192, 0)   # turtlebot3_navigation.rviz's "Amcl Particles" (its LaserScan is (0, 255, 0))


def colour_pixels(image, colour, tolerance=25):
    return int((np.abs(image.astype(int) - np.array(colour)).max(axis=2) <= tolerance).sum())


def map_view(image):
    """The part of a screenshot where rviz draws the map: the box round its unknown cells (the
    desktop round rviz's window is black, and so is the text of its panels)."""
    rows, cols = np.nonzero((np.abs(image.astype(int) - np.array(UNKNOWN)).max(axis=2) <= 3))
    assert rows.size > 1000, 'no map in rviz: %d unknown-cell pixels' % rows.size
    return image[rows.min():rows.max() + 1, cols.min():cols.max() + 1]


def shot(display, name):
    image = screenshot(display)
    os.makedirs(SHOTS, exist_ok=True)
    save_png(image, os.path.join(SHOTS, name))
    return image


def truth_now():
    """(x, y, yaw) of base_pose_ground_truth, read as `rostopic echo` prints it."""
    from tb3_common.pose2d import yaw_of_quaternion
    echoed = run(['rostopic', 'echo', '-n', '1', '/base_pose_ground_truth/pose/pose'], TIMEOUT).stdout
    pose = yaml.safe_load(echoed[echoed.index('position:'):].split('---')[0])
    q = pose['orientation']
    return pose['position']['x'], pose['position']['y'], yaw_of_quaternion(q['x'], q['y'], q['z'], q['w'])


def echoed(output):
    """The first message `rostopic echo` printed (it may warn first: "Is /clock being published?")."""
    return yaml.safe_load(output[output.index('header:'):].split('---')[0])


def rviz_topics(config, kind):
    """The topics of the enabled displays of class `kind` in an rviz config, those in groups too."""
    with open(config) as stream:
        displays = list(yaml.safe_load(stream)['Visualization Manager']['Displays'])
    topics = []
    while displays:
        display = displays.pop(0)
        displays.extend(display.get('Displays', []))
        if display.get('Class') == kind and display.get('Enabled'):
            topics.append(display['Topic'])
    return topics


def node_log(home, node):
    """What `node` wrote to its log file in the run's log folder (ROS_HOME/log/latest)."""
    text = ''
    for path in glob.glob(os.path.join(home, '.ros', 'log', 'latest', node + '-*.log')):
        with open(path, errors='replace') as stream:
            text += stream.read()
    return text


def check_map(yaml_file):
    """The saved map against the world file: its walls where the world's are, one or two cells thick."""
    from tb3_common.map_files import load_map
    from tb3_sim_nav.world_file import load_world
    saved = load_map(yaml_file)
    worlds = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds')
    quality = measure(saved.grid, saved.values, load_world('turtlebot3_world', worlds).obstacles,
                      WORLD_LOOP_START[:2])
    print('MEASURED the map saved from turtlebot3_slam.launch: %s' % quality.summary())
    assert not quality.failures(), quality.summary()


@pytest.fixture
def desktop(screen, tmp_path, monkeypatch):
    """A fresh HOME and a screen: (HOME, DISPLAY)."""
    home = tmp_path / 'home'
    home.mkdir()
    monkeypatch.setenv('HOME', str(home))
    return str(home), screen


def test_map_save_and_navigate_as_the_emanual_does(ros_port, processes, desktop):
    home, display = desktop
    processes.start_master('roscore', ros_port)
    world = processes.start('world', bash(WORLD + ' real_time_factor:=0'))
    # As a learner waits for Gazebo's window: robot_state_publisher (turtlebot3_remote.launch's, in the SLAM's
    # launch) reads /use_sim_time once, at its start.
    master = rosgraph.Master('/emanual_test')
    assert wait_until(lambda: master.hasParam('/use_sim_time'), TIMEOUT), world.describe()
    slam = processes.start('slam', bash('roslaunch turtlebot3_slam turtlebot3_slam.launch slam_methods:=gmapping'))
    assert wait_until(lambda: 'turtlebot3_slam_gmapping parameters' in slam.output(None), TIMEOUT), slam.describe()
    # gmapping_params.yaml sets the particle filter's parameters too: the node takes them and says why not.
    assert '~particles = 100 has no effect here' in slam.output(None), slam.describe()
    route = os.path.join(home, 'route.json')
    driven = run(['python3', '-m', 'tb3_harness.route_driver', 'world_loop', '--out', route], ROUTE_TIMEOUT)
    assert driven.returncode == 0 and world.running() and slam.running(), (driven.stdout[-2000:], slam.describe())
    with open(route) as stream:
        paths = json.load(stream)
    end = paths['truth'][-1][1:]
    # The 2D Pose Estimate below is typed for the loop's end, as a learner clicks where rviz shows the robot.
    assert math.hypot(end[0] - END_OF_LOOP[0], end[1] - END_OF_LOOP[1]) < 0.1, end
    assert abs(math.remainder(end[2] - END_OF_LOOP[2], 2 * math.pi)) < 0.2, end
    assert paths['map'], 'no pose in the map frame while driving: %s' % slam.describe()
    mapping = map_view(shot(display, 'slam.png'))
    # rviz's "map" scheme: occupied cells black, free ones light grey; the scan's flat green.
    walls, floor = colour_pixels(mapping, WALL, 8), colour_pixels(mapping, FLOOR, 8)
    scan = colour_pixels(mapping, (0, 255, 0), 40)
    print('MEASURED rviz during SLAM: %d wall pixels, %d floor pixels, %d scan pixels' % (walls, floor, scan))
    figure('slam_rviz_wall_pixels', walls, 'min', 'px')
    figure('slam_rviz_floor_pixels', floor, 'min', 'px')
    figure('slam_rviz_scan_pixels', scan, 'min', 'px')
    assert walls > 2000 and floor > 20000 and scan > 300

    saved = run(bash('rosrun map_server map_saver -f ~/map'), TIMEOUT)
    assert saved.returncode == 0, saved.stdout
    with open(os.path.join(home, 'map.yaml')) as stream:
        metadata = yaml.safe_load(stream)
    assert metadata['image'] == os.path.join(home, 'map.pgm') and metadata['resolution'] == pytest.approx(0.05)
    check_map(os.path.join(home, 'map.yaml'))
    slam.signal_group(signal.SIGINT)  # Ctrl+C in its terminal
    assert slam.wait(TIMEOUT) is not None, slam.describe()

    nav = processes.start('navigation', bash('roslaunch turtlebot3_navigation turtlebot3_navigation.launch '
                                             'map_file:=$HOME/map.yaml'))
    # The map in move_base (its lines on the screen) and in amcl (ROBOTIS' amcl.launch sends them to its log).
    assert wait_until(lambda: 'map of' in nav.output(None) and 'map of' in node_log(home, 'amcl'), TIMEOUT), \
        (nav.describe(), node_log(home, 'amcl')[-3000:])
    assert run(bash(INITIAL_POSE), TIMEOUT).returncode == 0
    # What rviz draws while navigating: the plans it subscribes to (the Path displays of ROBOTIS' view),
    # each as move_base sends it, and on the screen amcl's particles and the costmaps.
    paths = rviz_topics(os.path.join(rospkg.RosPack().get_path('turtlebot3_navigation'), 'rviz',
                                     'turtlebot3_navigation.rviz'), 'rviz/Path')
    assert {'/move_base/NavfnROS/plan', '/move_base/DWAPlannerROS/global_plan'} <= set(paths), paths
    plans = [processes.start('plan_%d' % number, ['rostopic', 'echo', '-n', '1', topic])
             for number, topic in enumerate(paths)]
    result = processes.start('result', ['rostopic', 'echo', '-n', '1', '/move_base/result'])
    goal = processes.start('goal', bash(NAV_GOAL))
    assert wait_until(lambda: not any(plan.running() for plan in plans), 120), \
        'no plan on %s' % [topic for topic, plan in zip(paths, plans) if plan.running()]
    image = shot(display, 'navigation.png')
    subscribers = dict(master.getSystemState()[1])
    poses = dict((topic, echoed(plan.output(None))['poses']) for topic, plan in zip(paths, plans))
    for topic in paths:
        print('MEASURED %s: %d poses, subscribers %s' % (topic, len(poses[topic]), subscribers.get(topic)))
        assert poses[topic] and '/rviz' in subscribers.get(topic, []), (topic, subscribers.get(topic))
    planned = poses['/move_base/NavfnROS/plan'][-1]['pose']['position']
    assert math.hypot(planned['x'] - GOAL[0], planned['y'] - GOAL[1]) < 0.05, planned
    particles = colour_pixels(image, PARTICLES, 10)
    costmap_cyan = colour_pixels(image, (0, 255, 255), 60)
    print('MEASURED rviz while navigating: %d particle pixels, %d costmap (cyan) pixels' % (particles, costmap_cyan))
    figure('nav_rviz_particle_pixels', particles, 'min', 'px')
    figure('nav_rviz_costmap_pixels', costmap_cyan, 'min', 'px')
    assert particles > 50 and costmap_cyan > 200
    assert goal.wait(TIMEOUT) == 0, goal.describe()
    assert wait_until(lambda: not result.running(), 180), 'no move_base result within 180 s'
    outcome = echoed(result.output(None))
    x, y, yaw = truth_now()
    xy_error, yaw_error = math.hypot(x - GOAL[0], y - GOAL[1]), abs(math.remainder(yaw - GOAL[2], 2 * math.pi))
    print('MEASURED 2D Nav Goal: status %s, %s; truly %.3f m and %.3f rad off'
          % (outcome['status']['status'], outcome['status']['text'], xy_error, yaw_error))
    figure('emanual_goal_xy_error', xy_error, 'max', 'm')
    assert outcome['status']['status'] == 3, outcome
    assert xy_error <= XY_TOLERANCE and yaw_error <= YAW_TOLERANCE, (x, y, yaw)
    shutil.copy(os.path.join(home, 'map.pgm'), os.path.join(SHOTS, 'map.pgm'))
