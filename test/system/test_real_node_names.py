"""Launch files written for the real nodes run unchanged (issue 29): tf's static_transform_publisher,
fake_localization and multirobot_map_merge, each started by a launch file as the ROS world writes them.

- A launch file in the style of the ROS wiki's tutorials starts tf's
  static_transform_publisher in both argument forms; tf2 finds the
  transforms, right and future-dated; bad arguments print tf's usage.
- fake_localization beside `roslaunch tb3_sim_bringup tb3_world.launch`,
  with map_server and move_base (a launch of its own, including ours):
  a goal is reached, and amcl_pose is the truth.
- ROBOTIS' multi-robot chapter as the e-manual types it: `roslaunch
  turtlebot3_gazebo multi_turtlebot3.launch`, `roslaunch turtlebot3_gazebo
  multi_turtlebot3_slam.launch ns:=tb3_N` for the three robots, then
  `roslaunch turtlebot3_gazebo multi_map_merge.launch` (map_merge and three
  of tf's static_transform_publishers); each robot turns a little, and the
  merged /map holds every robot's known cells, its walls on the house's.

Every look from ROS's side is a short python process (PROBE below): this
process starts a master per test and cannot be a rospy node of each.
"""
import json
import math
import os
import sys
import time

import numpy as np
import rospkg

from tb3_common.map_files import load_map
from tb3_harness.map_quality import measure
from tb3_harness.screen import save_png, screen_env, screenshot, start_xvfb
from tb3_sim_nav.world_file import load_world

from tb3_system_utils import ROBOTS, registered, wait_until


def _burger(**variables):
    """This process's environment (its master's, set by the ros_port fixture) for a Burger, plus `variables`."""
    return dict(os.environ, TURTLEBOT3_MODEL='burger', **variables)


# The ROS wiki's way (tf tutorials, "static_transform_publisher" in a launch file): leading slashes, both forms.
TUTORIAL_LAUNCH = """<launch>
  <node pkg="tf" type="static_transform_publisher" name="laser_broadcaster"
        args="0.1 0 0.2 0 0 0 /base_link /laser 100" />
  <node pkg="tf" type="static_transform_publisher" name="camera_broadcaster"
        args="0.05 0 0.3 1.5707963 0 0 base_link camera_link 100" />
  <node pkg="tf" type="static_transform_publisher" name="link1_broadcaster"
        args="1 0 0 0 0 0.7071068 0.7071068 link1_parent link1 100" />
</launch>
"""
#: parent, child: translation, rotation (x, y, z, w) the tutorial's launch gives them
TUTORIAL_TRANSFORMS = {
    ('base_link', 'laser'): ((0.1, 0.0, 0.2), (0.0, 0.0, 0.0, 1.0)),
    ('base_link', 'camera_link'): ((0.05, 0.0, 0.3), (0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5))),
    ('link1_parent', 'link1'): ((1.0, 0.0, 0.0), (0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)))}
PERIOD = 0.1  # s: the launch's 100 ms

# A launch file for fake_localization as the wild writes one (frames with a slash), with our move_base.
FAKE_LOCALIZATION_LAUNCH = """<launch>
  <node pkg="map_server" type="map_server" name="map_server" args="$(find tb3_sim_nav)/maps/turtlebot3_world.yaml"/>
  <node pkg="fake_localization" type="fake_localization" name="fake_localization" output="screen">
    <param name="global_frame_id" value="/map"/>
    <param name="base_frame_id" value="/base_footprint"/>
  </node>
  <include file="$(find tb3_sim_nav)/launch/move_base.launch"/>
</launch>
"""
SHOTS = os.path.join(rospkg.get_ros_home(), 'test_results', 'tb3_sim_nav', 'real_node_names')
WORLD_GOAL = (-0.55, -0.55, 0.0)  # test_navigation's first, past the west pillars' row
XY_TOLERANCE = 0.05               # DWAPlannerROS's, TurtleBot3's

#: The e-manual's multi-robot commands, as the README shows them (the world gets real_time_factor:=0, ours).
MULTI_WORLD = 'roslaunch turtlebot3_gazebo multi_turtlebot3.launch'
MULTI_SLAM = {'tb3_0': 'roslaunch turtlebot3_gazebo multi_turtlebot3_slam.launch ns:=tb3_0',
              'tb3_1': 'roslaunch turtlebot3_gazebo multi_turtlebot3_slam.launch ns:=tb3_1',
              'tb3_2': 'roslaunch turtlebot3_gazebo multi_turtlebot3_slam.launch ns:=tb3_2'}
MULTI_MERGE = 'roslaunch turtlebot3_gazebo multi_map_merge.launch'
MULTI_RVIZ = 'rosrun rviz rviz -d `rospack find turtlebot3_gazebo`/rviz/multi_turtlebot3_slam.rviz'
WALL = (14, 14, 14)       # rviz's "map" scheme: an occupied cell
FLOOR = (214, 221, 220)   # a free cell of the merged map under a free cell of a robot's own (both drawn at 0.7)
DRIVE_SECONDS = 12.0      # sim s each robot turns on a small circle: a look all round from its spawn
KNOWN_IN_MERGED = 0.97    # share of each robot's known cells the merged map knows too
NEAR_SURFACE = 0.95       # share of the merged map's occupied cells within 0.10 m of the house's surfaces

# The ROS side's looks, one short python process each: `python3 -c PROBE MODE ARGS...`, one JSON line out.
PROBE = r'''
import json, math, sys
import rospy
mode, args = sys.argv[1], sys.argv[2:]
rospy.init_node('probe', anonymous=True)
if mode == 'tf':  # parent child ...: each transform, and its stamp less now (s)
    import tf2_ros
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    found = {}
    for parent, child in zip(args[::2], args[1::2]):
        t = buffer.lookup_transform(parent, child, rospy.Time(0), rospy.Duration(20.0))
        found[parent + ' ' + child] = dict(
            translation=[t.transform.translation.x, t.transform.translation.y, t.transform.translation.z],
            rotation=[t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w],
            ahead=(t.header.stamp - rospy.Time.now()).to_sec())
    print(json.dumps(found))
elif mode == 'drive':  # seconds linear angular settle namespace...: every robot on a circle, then still
    from geometry_msgs.msg import Twist
    seconds, linear, angular, settle = (float(value) for value in args[:4])
    publishers = [rospy.Publisher(ns + '/cmd_vel', Twist, queue_size=1) for ns in args[4:]]
    while rospy.Time.now().is_zero():
        rospy.sleep(0.01)
    start, rate = rospy.get_time(), rospy.Rate(10)
    twist = Twist()
    twist.linear.x, twist.angular.z = linear, angular
    while rospy.get_time() - start < seconds:
        for publisher in publishers:
            publisher.publish(twist)
        rate.sleep()
    for _ in range(5):
        for publisher in publishers:
            publisher.publish(Twist())
        rate.sleep()
    rospy.sleep(settle)
    print(json.dumps(dict(sim_seconds=rospy.get_time() - start)))
elif mode == 'goal':  # x y yaw: move_base's outcome, the true pose and amcl_pose at the end
    import actionlib
    from geometry_msgs.msg import PoseWithCovarianceStamped
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
    from nav_msgs.msg import Odometry
    x, y, yaw = (float(value) for value in args)
    client = actionlib.SimpleActionClient('move_base', MoveBaseAction)
    assert client.wait_for_server(rospy.Duration(120.0)), 'no move_base'
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id, goal.target_pose.header.stamp = 'map', rospy.Time.now()
    goal.target_pose.pose.position.x, goal.target_pose.pose.position.y = x, y
    goal.target_pose.pose.orientation.z, goal.target_pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    client.send_goal(goal)
    client.wait_for_result(rospy.Duration(120.0))
    rospy.sleep(1.0)
    def pose(message):
        p, q = message.pose.pose.position, message.pose.pose.orientation
        return [p.x, p.y, math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))]
    truth = rospy.wait_for_message('base_pose_ground_truth', Odometry, 10.0)
    estimate = rospy.wait_for_message('amcl_pose', PoseWithCovarianceStamped, 10.0)
    print(json.dumps(dict(state=client.get_state(), truth=pose(truth), amcl=pose(estimate),
                          amcl_frame=estimate.header.frame_id, stamps=[truth.header.stamp.to_sec(),
                                                                       estimate.header.stamp.to_sec()])))
'''


def _probe(processes, name, mode, *args, timeout=120.0):
    """The JSON a PROBE run printed (AssertionError with its output if it failed)."""
    process = processes.start(name, [sys.executable, '-c', PROBE, mode] + [str(arg) for arg in args])
    code = process.wait(timeout)
    output = process.output(None)
    assert code == 0, '%s: exit %r\n%s' % (name, code, output)
    return json.loads(output.strip().splitlines()[-1])


def _launch_file(tmp_path, name, text):
    path = os.path.join(str(tmp_path), name)
    with open(path, 'w') as stream:
        stream.write(text)
    return path


def test_the_tutorial_s_static_transform_publishers(ros_port, processes, tmp_path):
    processes.start_master('roscore', ros_port)
    launch = processes.start('tutorial', ['roslaunch', _launch_file(tmp_path, 'tf_tutorial.launch', TUTORIAL_LAUNCH)])
    found = _probe(processes, 'probe_tf', 'tf', *[frame for pair in TUTORIAL_TRANSFORMS for frame in pair])
    for (parent, child), (translation, rotation) in TUTORIAL_TRANSFORMS.items():
        seen = found[parent + ' ' + child]
        print('MEASURED %s -> %s: %s, %s, stamped %+.3f s from now' % (parent, child, seen['translation'],
                                                                    seen['rotation'], seen['ahead']))
        assert np.allclose(seen['translation'], translation, atol=1e-9)
        assert np.allclose(seen['rotation'], rotation, atol=1e-6)
        # future-dated by the period, as tf's: the latest is never older than now, less a little latency
        assert -0.05 < seen['ahead'] <= PERIOD + 0.01, seen
    assert launch.running(), launch.describe()


def test_static_transform_publisher_refuses_bad_arguments_and_ends_at_once(ros_port, processes):
    bad = processes.start('bad', ['rosrun', 'tf', 'static_transform_publisher', '1', '2', '3'])
    assert bad.wait(30.0) == 255, bad.describe()
    assert 'Usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id' in bad.output()
    processes.start_master('roscore', ros_port)
    node = processes.start('node', ['rosrun', 'tf', 'static_transform_publisher', '0', '0', '0', '0', '0', '0',
                                    'map', 'odom', '100'])
    _probe(processes, 'probe_node', 'tf', 'map', 'odom')
    began = time.monotonic()
    node.stop()
    took = time.monotonic() - began
    print('MEASURED static_transform_publisher ended %.2f s after SIGINT' % took)
    assert took < 2.0


def _world_up(timeout=60.0):
    """Wait, as a learner waits for the world to come up before the next command, until /clock is
    published: /use_sim_time is set then. A node started before it is set keeps wall time for good
    (rospy reads the parameter once): move_base did so once beside make test's other parts, and held
    still, taking every tf stamped in sim time for 1.8e9 s old."""
    import rosgraph
    master = rosgraph.Master('/test_real_node_names')
    assert wait_until(lambda: ['/clock', 'rosgraph_msgs/Clock'] in master.getPublishedTopics('/'), timeout), \
        'no /clock: the world did not come up'


def test_fake_localization_drives_move_base_to_a_goal(ros_port, processes, tmp_path):
    processes.start_master('roscore', ros_port)
    sim = processes.start('sim', ['roslaunch', 'tb3_sim_bringup', 'tb3_world.launch', 'real_time_factor:=0'],
                          env=_burger())
    _world_up()
    nav = processes.start('nav', ['roslaunch', _launch_file(tmp_path, 'fake_nav.launch', FAKE_LOCALIZATION_LAUNCH)],
                          env=_burger())
    outcome = _probe(processes, 'probe_goal', 'goal', *WORLD_GOAL, timeout=240.0)
    truth, estimate = outcome['truth'], outcome['amcl']
    error = math.hypot(truth[0] - WORLD_GOAL[0], truth[1] - WORLD_GOAL[1])
    print('MEASURED fake_localization + move_base: state %d, %.3f m from the goal, amcl_pose %.4f m from the truth'
          % (outcome['state'], error, math.hypot(truth[0] - estimate[0], truth[1] - estimate[1])))
    assert outcome['state'] == 3, (outcome, nav.output())  # SUCCEEDED
    assert error <= XY_TOLERANCE + 0.01
    assert outcome['amcl_frame'] == 'map'
    assert math.hypot(truth[0] - estimate[0], truth[1] - estimate[1]) < 0.01  # the robot stands still: same pose
    log = sim.output(None)
    assert 'fake_localization publishes map -> odom' in log, log[-3000:]  # the simulator gave way


def test_robotis_multi_map_merge_merges_the_three_robots_maps(ros_port, processes, tmp_path):
    processes.start_master('roscore', ros_port)
    folder = str(tmp_path)
    # The e-manual's commands, each in a terminal of its own (+ real_time_factor:=0, ours).
    processes.start('sim', MULTI_WORLD.split() + ['real_time_factor:=0'], env=_burger())
    _world_up()
    for name in ROBOTS:
        processes.start('slam_' + name, MULTI_SLAM[name].split(), env=_burger())
    import rosgraph
    master = rosgraph.Master('/test_real_node_names')
    assert wait_until(lambda: all(['/%s/map' % name, 'nav_msgs/OccupancyGrid'] in master.getPublishedTopics('/')
                                  for name in ROBOTS), 120.0), 'no map topic of each robot'
    merger = processes.start('multi_map_merge', MULTI_MERGE.split(), env=_burger())
    drove = _probe(processes, 'probe_drive', 'drive', DRIVE_SECONDS, 0.05, 0.6, 6.0, *ROBOTS, timeout=240.0)
    # rviz as the e-manual starts it (backticks, through bash), on a screen of the test's own: the merged map
    # and the robots' own maps are drawn.
    xvfb, display = start_xvfb()
    processes.add(xvfb, server=True)
    processes.start('rviz', ['bash', '-c', MULTI_RVIZ], env=_burger(**screen_env(display)))
    drawn = []

    def maps_drawn():
        image = screenshot(display).astype(int)
        drawn[:] = [image] + [int((np.abs(image - np.array(colour)).max(axis=2) <= 8).sum())
                              for colour in (WALL, FLOOR)]
        return drawn[1] > 500 and drawn[2] > 5000
    assert wait_until(maps_drawn, 120.0, poll=1.0), 'rviz draws no map: %s wall and floor pixels' % drawn[1:]
    os.makedirs(SHOTS, exist_ok=True)
    save_png(drawn[0].astype(np.uint8), os.path.join(SHOTS, 'multi_turtlebot3_slam.png'))
    print('MEASURED rviz with multi_turtlebot3_slam.rviz: %d wall and %d floor pixels' % tuple(drawn[1:]))
    maps = {}
    for name, topic in [(name, '/%s/map' % name) for name in ROBOTS] + [('merged', '/map')]:
        saver = processes.start('saver_' + name, ['rosrun', 'map_server', 'map_saver', '-f',
                                                  os.path.join(folder, name), 'map:=' + topic])
        assert saver.wait(60.0) == 0, saver.describe()
        maps[name] = load_map(os.path.join(folder, name + '.yaml'))
    log = merger.output(None)
    for name in ROBOTS:
        assert 'adding robot [/%s]' % name in log, log
        assert 'where tf puts %s/map in map' % name in log, log
    merged = maps['merged']
    obstacles = load_world('turtlebot3_house', os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'),
                                                             'worlds')).obstacles
    quality = measure(merged.grid, merged.values, obstacles, ROBOTS['tb3_0'])
    print('MEASURED merged map after %.1f s of sim time: %d x %d cells at %.3f m, occupied near a surface %.1f %%'
          % (drove['sim_seconds'], merged.grid.width, merged.grid.height, merged.grid.resolution,
             100 * quality.occupied_near_surface))
    assert quality.occupied_near_surface >= NEAR_SURFACE, quality.summary()
    for name in ROBOTS:
        own = maps[name]
        centres = own.grid.all_centres()[own.values >= 0]  # the robot's known cells, in its map (= the world's)
        cells = merged.grid.to_cells(centres)
        inside = merged.grid.inside(cells)
        known = np.zeros(len(centres), dtype=bool)
        known[inside] = merged.values[cells[inside][:, 1], cells[inside][:, 0]] >= 0
        print('MEASURED %s: %d known cells, %.1f %% known in the merged map' % (name, len(centres), 100 * known.mean()))
        assert len(centres) > 1000 and known.mean() >= KNOWN_IN_MERGED


def test_a_node_started_before_the_world_says_it_keeps_wall_time(ros_port, processes):
    """The race _world_up avoids, as a learner may meet it: move_base started on a bare roscore, then the
    world's launch. It cannot switch to sim time; it must say why it will hold still, and how to fix it.
    A node started after the world (on sim time) must not say so."""
    import rosgraph
    processes.start_master('roscore', ros_port)
    master = rosgraph.Master('/test_real_node_names')
    early = processes.start('early', ['rosrun', 'move_base', 'move_base'], env=_burger())
    assert wait_until(lambda: registered(master, '/move_base'), 60.0), early.output()
    processes.start('sim', ['roslaunch', 'tb3_sim_bringup', 'tb3_empty_world.launch'], env=_burger())
    _world_up()
    assert wait_until(lambda: 'started before /use_sim_time was set' in early.output(None), 30.0), early.output()
    late = processes.start('late', ['rosrun', 'fake_localization', 'fake_localization'], env=_burger())
    assert wait_until(lambda: registered(master, '/fake_localization'), 60.0), late.output()
    # rospy registers the node (its /rosout publisher) before it subscribes to /clock: CI once looked in between.
    assert wait_until(lambda: '/fake_localization' in dict(master.getSystemState()[1]).get('/clock', ()), 30.0), \
        'the late node is not on sim time'
    time.sleep(2.0)  # /clock at 100 Hz has reached it 200 times meanwhile
    assert 'use_sim_time' not in late.output(None), late.output()
