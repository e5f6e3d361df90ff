"""The e-manual's SLAM and navigation chapters under ROBOTIS' own names, typed through bash (issue 29).

Each in a terminal of its own, with ROBOTIS' launch files of this repository's packages
turtlebot3_gazebo, turtlebot3_slam and turtlebot3_navigation:

    export TURTLEBOT3_MODEL=burger
    roslaunch turtlebot3_gazebo turtlebot3_world.launch real_time_factor:=0
    roslaunch turtlebot3_slam turtlebot3_slam.launch slam_methods:=gmapping open_rviz:=false
    (the robot driven round the pillars: tb3_harness.route_driver, where the learner uses the teleop)
    rosrun map_server map_saver -f TMP/map
    (Ctrl+C in the SLAM's terminal)
    roslaunch turtlebot3_navigation turtlebot3_navigation.launch map_file:=TMP/map.yaml open_rviz:=false
    2D Pose Estimate where the robot stands, then two 2D Nav Goals (as rviz's tools send them)

The world runs as fast as possible (lockstep makes that the same as real time). The saved map must lie
on the world's walls, and each goal must SUCCEED with the true pose within DWAPlannerROS's tolerances.
test_emanual.py runs the chapters under the tutorial's names (tb3_sim_bringup), with rviz.
"""
import json
import math
import os
import signal

import rosgraph
import rospkg
import yaml

from tb3_harness.map_quality import measure
from tb3_harness.navigating import Navigation, WORLD_GOALS, say_goal
from tb3_harness.processes import wait_until
from tb3_harness.report import figure
from tb3_harness.waypoints import WORLD_LOOP_START
from tb3_system_utils import run

TIMEOUT = 60.0             # wall s for a launch to be ready, a command to end
ROUTE_TIMEOUT = 300.0      # wall s for the loop round the pillars (about 90 s of sim time)
EXPORT = 'export TURTLEBOT3_MODEL=burger'
#: Where the loop ends: back at the spawn, facing west (the map's coordinates are the world's, as odometry's).
END_OF_LOOP = (-2.0, -0.5, math.pi)
XY_TOLERANCE, YAW_TOLERANCE = 0.05, 0.17  # DWAPlannerROS's, TurtleBot3's


def bash(command):
    return ['bash', '-c', '%s && %s' % (EXPORT, command)]


def test_map_save_and_navigate_with_robotis_launch_files(ros_port, processes, tmp_path):
    processes.start_master('roscore', ros_port)
    world = processes.start('world', bash('roslaunch turtlebot3_gazebo turtlebot3_world.launch real_time_factor:=0'))
    # As a learner waits for Gazebo's window: robot_state_publisher (turtlebot3_remote.launch's, in the SLAM's
    # launch) reads /use_sim_time once, at its start.
    master = rosgraph.Master('/turtlebot3_slam_navigation_test')
    wait_until(lambda: master.hasParam('/use_sim_time'), TIMEOUT, "the world's /use_sim_time", watch=(world,))
    slam = processes.start('slam', bash('roslaunch turtlebot3_slam turtlebot3_slam.launch slam_methods:=gmapping '
                                        'open_rviz:=false'))
    wait_until(lambda: 'turtlebot3_slam_gmapping parameters' in slam.output(20000), TIMEOUT, 'the SLAM node',
               watch=(world, slam))
    # gmapping_params.yaml sets the particle filter's parameters too: the node takes them and says why not.
    assert "~particles = 100 has no effect here" in slam.output(20000), slam.describe()

    route = str(tmp_path / 'route.json')
    driven = run(['python3', '-m', 'tb3_harness.route_driver', 'world_loop', '--out', route], ROUTE_TIMEOUT)
    assert driven.returncode == 0 and world.running() and slam.running(), (driven.stdout[-2000:], slam.describe())
    with open(route) as stream:
        paths = json.load(stream)
    end = paths['truth'][-1][1:]
    assert math.hypot(end[0] - END_OF_LOOP[0], end[1] - END_OF_LOOP[1]) < 0.1, end
    assert paths['map'], 'no pose in the map frame while driving: %s' % slam.describe()

    saved = run(bash('rosrun map_server map_saver -f %s' % (tmp_path / 'map')), TIMEOUT)
    assert saved.returncode == 0, saved.stdout
    with open(str(tmp_path / 'map.yaml')) as stream:
        assert yaml.safe_load(stream)['image'] == str(tmp_path / 'map.pgm')
    check_map(str(tmp_path / 'map.yaml'))
    slam.signal_group(signal.SIGINT)  # Ctrl+C in its terminal
    assert slam.wait(TIMEOUT) is not None, slam.describe()

    navigation = processes.start('navigation', bash('roslaunch turtlebot3_navigation turtlebot3_navigation.launch '
                                                    'map_file:=%s open_rviz:=false' % (tmp_path / 'map.yaml')))
    wait_until(lambda: 'map of' in navigation.output(20000), TIMEOUT, "move_base's map", watch=(world, navigation))
    navigate(navigation)


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


def navigate(navigation):
    """rviz's 2D Pose Estimate where the loop ended, then two goals between the pillars, judged on the truth."""
    import rospy
    rospy.init_node('turtlebot3_navigation_test', anonymous=True, disable_signals=True)
    nav = Navigation()
    try:
        nav.wait_ready(TIMEOUT)
        nav.set_pose(*END_OF_LOOP)
        wait_until(lambda: nav.amcl, TIMEOUT, "amcl's pose after the 2D Pose Estimate", watch=(navigation,))
        for number, goal in enumerate(WORLD_GOALS[:2], 1):
            outcome = nav.go(*goal)
            say_goal(number, outcome)
            figure('turtlebot3_goal_xy_error', outcome.xy_error, 'max', 'm')
            figure('turtlebot3_goal_yaw_error', outcome.yaw_error, 'max', 'rad')
            assert outcome.state == 'SUCCEEDED', (goal, outcome.state, outcome.text, navigation.describe())
            assert outcome.xy_error <= XY_TOLERANCE and outcome.yaw_error <= YAW_TOLERANCE, outcome
    finally:
        nav.close()
        rospy.signal_shutdown('turtlebot3 navigation test done')
