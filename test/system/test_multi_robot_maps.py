"""Robots of multi_tb3.launch, each with its own SLAM, explorer and navigation stack, in namespaces.

    roslaunch tb3_sim_bringup multi_tb3.launch profile:=realistic real_time_factor:=0
    ROS_NAMESPACE=tb3_0 roslaunch tb3_sim_bringup tb3_slam.launch explore:=true open_rviz:=false
    (the same for tb3_1 and tb3_2)

Each robot maps its own part of turtlebot3_house on its own `/tb3_N/map`, in
its own frames (`tb3_N/map` -> `tb3_N/odom`), driven by its own
`/tb3_N/move_base`: after a minute of sim time each map holds free floor
round its robot's spawn, its walls on the house's, and no robot touched
anything. Then one robot navigates with its own stack on the shipped map:

    ROS_NAMESPACE=tb3_2 roslaunch tb3_sim_bringup tb3_navigation.launch map_file:=... open_rviz:=false
"""
import json
import math
import os

import pytest
import rosgraph
import rospkg
import yaml

from tb3_common.map_files import load_map
from tb3_harness import exploring
from tb3_harness.map_quality import measure
from tb3_harness.navigating import BURGER_FOOTPRINT, clearance
from tb3_harness.processes import Process, start_master, wait_until
from tb3_harness.report import figure
from tb3_sim_nav.world_file import load_world

from tb3_system_utils import ROBOTS

EXPLORE_SIM_SECONDS = 60.0   # of exploration each robot gets (sim time of its explorer's goals)
TIMEOUT = 900.0              # wall s for that (3 robots, 9 of our nodes and the simulator on 2 cores)
MIN_FREE = 8.0               # m2 of free floor each robot must have mapped round its spawn
NAV_GOAL = (1.0, 4.3, math.pi / 2)  # tb3_2's room, north of its spawn


def _read(path):
    with open(path, errors='replace') as stream:
        return stream.read()


def _sim_time(log):
    """The latest sim time the explorer wrote in its log (its goal lines), 0 if none."""
    goals = exploring.GOAL.findall(_read(log))
    return float(goals[-1][0]) if goals else 0.0


@pytest.fixture
def house(tmp_path):
    folder = str(tmp_path)
    master = start_master(folder)
    started = []

    def start(name, argv, namespace=None):
        env = dict(os.environ, TURTLEBOT3_MODEL='burger')
        if namespace:
            env['ROS_NAMESPACE'] = namespace
        process = Process(name, argv, folder, die_with_parent=True, env=env)
        started.append(process)
        return process
    start('sim', ['roslaunch', 'tb3_sim_bringup', 'multi_tb3.launch', 'profile:=realistic', 'real_time_factor:=0'])
    yield folder, start, started
    for process in reversed(started):
        process.stop()
    master.stop()


def test_three_robots_each_map_their_own_part_of_the_house(house):
    folder, start, started = house
    slams = {name: start('slam_' + name, ['roslaunch', 'tb3_sim_bringup', 'tb3_slam.launch', 'explore:=true',
                                           'open_rviz:=false'], namespace=name) for name in ROBOTS}
    recorders = [start('recorder_' + name, ['python3', '-m', 'tb3_harness.pose_recorder', '--out',
                                            os.path.join(folder, name + '_path.json'), '--map-frame', name + '/map',
                                            '--base-frame', name + '/base_footprint'], namespace=name)
                 for name in ROBOTS]
    wait_until(lambda: all(_sim_time(slam.log) >= EXPLORE_SIM_SECONDS or exploring.progress(_read(slam.log))[2]
                           for slam in slams.values()), TIMEOUT, 'a minute of exploration for each robot',
               poll=2.0, watch=started)
    for name in ROBOTS:
        saver = start('saver_' + name, ['rosrun', 'map_server', 'map_saver', '-f', os.path.join(folder, name),
                                        'map:=/%s/map' % name])
        assert saver.wait(60.0) == 0, _read(saver.log)
    for recorder in recorders:
        recorder.stop()
    obstacles = load_world('turtlebot3_house', os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'),
                                                             'worlds')).obstacles
    for name, spawn in sorted(ROBOTS.items()):
        with open(os.path.join(folder, name + '_path.json')) as stream:
            path = json.load(stream)
        log = _read(slams[name].log)
        assert '%s/map -> %s/odom' % (name, name) in log or 'frames %s/map' % name in log, log[-3000:]
        goals, last, _ = exploring.progress(log)
        saved = load_map(os.path.join(folder, name + '.yaml'))
        quality = measure(saved.grid, saved.values, obstacles, spawn)
        free = float((saved.values == 0).sum()) * saved.grid.resolution ** 2
        least = clearance(path['truth'], obstacles, BURGER_FOOTPRINT)
        print('MEASURED %s: %d goals in %.0f s of sim time, %.1f m2 free mapped, occupied near a surface %.1f %%, '
              'footprint at least %.3f m from the house' % (name, goals, last, free,
                                                           100 * quality.occupied_near_surface, least))
        figure('robot_goals', goals, 'min')
        figure('robot_free_mapped', free, 'min', 'm2')
        figure('robot_occupied_near_surface', 100 * quality.occupied_near_surface, 'min', '%')
        figure('robot_clearance', least, 'min', 'm')
        assert len(path['map']) > 100  # its pose in its own map, tb3_N/map -> tb3_N/base_footprint
        assert goals >= 2 and free >= MIN_FREE
        assert quality.occupied_near_surface >= 0.95, quality.summary()
        assert least > 0.0


def test_a_namespaced_robot_navigates_with_its_own_stack(house):
    folder, start, started = house
    map_file = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'maps', 'turtlebot3_house.yaml')
    spawn = ROBOTS['tb3_2']
    nav = start('nav_tb3_2', ['roslaunch', 'tb3_sim_bringup', 'tb3_navigation.launch', 'map_file:=%s' % map_file,
                              'open_rviz:=false', 'initial_pose_x:=%g' % spawn[0], 'initial_pose_y:=%g' % spawn[1]],
                namespace='tb3_2')
    wait_until(lambda: _read(nav.log).count('map of') >= 2, 120.0, 'the map in amcl and move_base', watch=started)
    result = start('result', ['rostopic', 'echo', '-n', '1', '/tb3_2/move_base/result'])
    goal = start('goal', ['rostopic', 'pub', '-1', '/tb3_2/move_base_simple/goal', 'geometry_msgs/PoseStamped',
                          '{header: {frame_id: tb3_2/map}, pose: {position: {x: %g, y: %g}, orientation: '
                          '{z: %r, w: %r}}}' % (NAV_GOAL[0], NAV_GOAL[1], math.sin(NAV_GOAL[2] / 2),
                                                 math.cos(NAV_GOAL[2] / 2))])
    assert goal.wait(60.0) == 0, _read(goal.log)
    wait_until(lambda: not result.running(), 300.0, 'a result on /tb3_2/move_base/result', watch=(started[0], nav))
    echoed = _read(result.log)  # rostopic may warn first ("Is /clock being published?")
    outcome = yaml.safe_load(echoed[echoed.index('header:'):].split('---')[0])['status']
    print('MEASURED tb3_2 navigating in its namespace: status %s, %s' % (outcome['status'], outcome['text']))
    assert outcome['status'] == 3, echoed
    log = _read(nav.log)
    assert 'frames tb3_2/map and tb3_2/odom, robot tb3_2/base_footprint' in log, log[-3000:]
    publishers = dict(rosgraph.Master('/test').getSystemState()[0])
    assert publishers.get('/tb3_2/cmd_vel') == ['/tb3_2/move_base'], publishers.get('/tb3_2/cmd_vel')
    assert '/tb3_2/move_base/global_costmap/costmap' in publishers and '/tb3_2/amcl_pose' in publishers
