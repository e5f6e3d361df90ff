"""ROBOTIS' worlds through their launches, started as a user starts them.

For each of tb3_house.launch and tb3_stage_1.launch ... tb3_stage_4.launch,
against a roscore (one for the file, on a free loopback port, its parameters
cleared between launches: conftest.py's shared_master) and with
TURTLEBOT3_MODEL=burger in the environment, as a TurtleBot3 user has it:
`roslaunch tb3_sim_bringup LAUNCH` with no arguments, then `rostopic echo -n 1`
of /base_pose_ground_truth (after REST s of sim time) and of /scan. The robot
must rest where the launch file's defaults put it, and its lidar must see
walls. What the lidar sees, beam for beam, is test/unit/test_known_worlds.py's.
"""
import math
import os
import xml.etree.ElementTree as ElementTree

import pytest
import yaml

from tb3_system_utils import run

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# As a user types them (the README shows the first).
COMMANDS = ['roslaunch tb3_sim_bringup tb3_house.launch', 'roslaunch tb3_sim_bringup tb3_stage_1.launch',
            'roslaunch tb3_sim_bringup tb3_stage_2.launch', 'roslaunch tb3_sim_bringup tb3_stage_3.launch',
            'roslaunch tb3_sim_bringup tb3_stage_4.launch']
REST = 1.0          # sim s after which the robot must rest at its spawn pose
AT_SPAWN = 0.01     # m
TIMEOUT = 60.0      # wall s for a message to come


def spawn_of(launch):
    """(x, y) of a launch file's argument defaults."""
    root = ElementTree.parse(os.path.join(REPO, 'launch', launch)).getroot()
    defaults = {arg.get('name'): arg.get('default') for arg in root.iter('arg')}
    return float(defaults['x_pos']), float(defaults['y_pos'])


def echo(topic, sim):
    """One message of `topic` as `rostopic echo -n 1` prints it, parsed."""
    printed = run(['rostopic', 'echo', '-n', '1', topic], TIMEOUT)
    assert printed.returncode == 0, 'rostopic echo -n 1 %s: %s (exit %r); %s' % (
        topic, printed.stdout[-1000:], printed.returncode, sim.describe())
    return next(yaml.safe_load_all(printed.stdout))


def stamp(message):
    return message['header']['stamp']['secs'] + 1e-9 * message['header']['stamp']['nsecs']


@pytest.mark.parametrize('command', COMMANDS)
def test_the_robot_rests_at_the_launch_spawn_pose_and_its_lidar_sees_walls(command, shared_master, processes):
    launch = command.split()[-1]
    sim = processes.start('roslaunch', command.split(), env=dict(os.environ, TURTLEBOT3_MODEL='burger'))
    truth = echo('/base_pose_ground_truth', sim)
    while stamp(truth) < REST:
        truth = echo('/base_pose_ground_truth', sim)
    scan = echo('/scan', sim)
    position, orientation = truth['pose']['pose']['position'], truth['pose']['pose']['orientation']
    yaw = 2.0 * math.atan2(orientation['z'], orientation['w'])
    ranges = [float(value) for value in scan['ranges']]  # rostopic prints inf, which YAML reads as a string
    seen = [value for value in ranges if math.isfinite(value)]
    x, y = spawn_of(launch)
    print('MEASURED %s: at t %.2f s (x, y, yaw) = (%.4f, %.4f, %.4f), spawn (%.2f, %.2f); '
          'scan at t %.2f s: %d of %d beams hit, %.2f to %.2f m'
          % (launch, stamp(truth), position['x'], position['y'], yaw, x, y, stamp(scan), len(seen), len(ranges),
             min(seen, default=math.nan), max(seen, default=math.nan)))
    assert sim.running(), sim.describe()
    assert math.hypot(position['x'] - x, position['y'] - y) <= AT_SPAWN
    assert abs(yaw) <= 0.01  # ROBOTIS' launches have no yaw: heading 0
    assert scan['header']['frame_id'] == 'base_scan' and len(ranges) == 360
    assert len(seen) >= len(ranges) // 4, ranges  # the lidar sees walls


def test_multi_tb3_launch_puts_three_robots_in_the_house_as_robotis_does(shared_master, processes):
    """`roslaunch tb3_sim_bringup multi_tb3.launch`, no arguments: tb3_0, tb3_1 and tb3_2 rest at the
    launch's default poses in turtlebot3_house (ROBOTIS': (-7, -1) and (7, -1) facing +y, (0.5, 3))."""
    sim = processes.start('roslaunch', ['roslaunch', 'tb3_sim_bringup', 'multi_tb3.launch'],
                          env=dict(os.environ, TURTLEBOT3_MODEL='burger'))
    root = ElementTree.parse(os.path.join(REPO, 'launch', 'multi_tb3.launch')).getroot()
    defaults = {arg.get('name'): arg.get('default') for arg in root.findall('arg')}
    assert defaults['world'] == 'turtlebot3_house'
    for order, name in enumerate(['first', 'second', 'third']):
        truth = echo('/tb3_%d/base_pose_ground_truth' % order, sim)
        while stamp(truth) < REST:
            truth = echo('/tb3_%d/base_pose_ground_truth' % order, sim)
        position, orientation = truth['pose']['pose']['position'], truth['pose']['pose']['orientation']
        yaw = 2.0 * math.atan2(orientation['z'], orientation['w'])
        x, y, heading = (float(defaults['%s_tb3_%s' % (name, key)]) for key in ('x_pos', 'y_pos', 'yaw'))
        print('MEASURED multi_tb3.launch tb3_%d: (x, y, yaw) = (%.4f, %.4f, %.4f), spawn (%.2f, %.2f, %.2f)'
              % (order, position['x'], position['y'], yaw, x, y, heading))
        assert math.hypot(position['x'] - x, position['y'] - y) <= AT_SPAWN
        assert abs(yaw - heading) <= 0.01
    assert sim.running(), sim.describe()
