"""The fake TurtleBot3 (turtlebot3_fake.fake) moved as ROBOTIS' turtlebot3_fake.cpp moves it, its parameters,
and turtlebot3_fake.launch as roslaunch reads it; no ROS master."""
import math
import os

import pytest
import roslaunch.config

from tb3_common.params import ParameterError
from turtlebot3_fake.fake import CMD_VEL_TIMEOUT, WHEEL_RADIUS, WHEEL_SEPARATION, FakeConfig, FakeRobot

RATE = 30.0   # Hz: the node's updates
LAUNCH = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'launch', 'turtlebot3_fake.launch')


def drive(robot, seconds, start=0.0):
    """Updates at RATE for `seconds` from `start`; the time of the last."""
    steps = int(round(seconds * RATE))
    for step in range(1, steps + 1):
        robot.update(start + step / RATE)
    return start + steps / RATE


def test_straight_ahead_for_half_a_second():
    robot = FakeRobot(WHEEL_SEPARATION['burger'])
    robot.update(0.0)
    robot.command(0.2, 0.0, 0.0)
    drive(robot, 0.5)
    assert robot.pose == pytest.approx([0.1, 0.0, 0.0])
    assert robot.velocity == pytest.approx((0.2, 0.0))
    assert robot.wheel_velocity == pytest.approx([0.2 / WHEEL_RADIUS] * 2)
    assert robot.wheel_position == pytest.approx([0.1 / WHEEL_RADIUS] * 2)


def test_an_arc_lands_on_its_circle_and_the_wheels_differ_by_the_separation():
    robot = FakeRobot(WHEEL_SEPARATION['burger'])
    robot.update(0.0)
    robot.command(0.1, 0.5, 0.0)   # radius 0.2 m
    drive(robot, 0.9)              # within the timeout
    x, y, yaw = robot.pose
    assert yaw == pytest.approx(0.45)
    # Each step moves its arc length along the chord: 0.2 um off the circle after 27 steps.
    assert math.hypot(x, y - 0.2) == pytest.approx(0.2, abs=1e-6)
    left, right = robot.wheel_velocity
    assert (right - left) * WHEEL_RADIUS == pytest.approx(0.5 * 0.160)
    assert robot.velocity == pytest.approx((0.1, 0.5))


def test_the_wheels_stop_a_second_after_the_last_cmd_vel():
    robot = FakeRobot(WHEEL_SEPARATION['waffle'])
    robot.update(0.0)
    robot.command(0.2, 0.0, 0.0)
    drive(robot, 3.0)
    assert robot.pose[0] == pytest.approx(0.2 * CMD_VEL_TIMEOUT, abs=0.2 / RATE)
    assert robot.velocity == (0.0, 0.0) and robot.wheel_velocity == [0.0, 0.0]
    assert CMD_VEL_TIMEOUT == 1.0


def test_before_any_cmd_vel_it_stands():
    robot = FakeRobot(WHEEL_SEPARATION['burger'])
    drive(robot, 1.0, start=100.0)
    assert robot.pose == [0.0, 0.0, 0.0]


@pytest.mark.parametrize('linear, angular', [(math.nan, 0.0), (0.1, math.inf), (-math.inf, math.nan)])
def test_a_non_finite_command_stops_the_wheels(linear, angular):
    robot = FakeRobot(WHEEL_SEPARATION['burger'])
    robot.update(0.0)
    robot.command(0.2, 0.3, 0.0)
    end = drive(robot, 0.5)
    assert robot.command(linear, angular, end) is False
    before = list(robot.pose)
    drive(robot, 0.5, start=end)
    assert robot.pose == before and all(math.isfinite(value) for value in robot.pose)
    assert robot.velocity == (0.0, 0.0)


def test_time_going_back_moves_nothing():
    robot = FakeRobot(WHEEL_SEPARATION['burger'])
    robot.update(10.0)
    robot.command(0.2, 0.0, 10.0)
    robot.update(5.0)
    assert robot.pose == [0.0, 0.0, 0.0]
    robot.update(5.5)
    assert robot.pose[0] == pytest.approx(0.1)


def test_parameters_by_robotis_names_and_defaults_checked():
    config = FakeConfig()
    assert (config.tb3_model, config.wheel_left_joint_name, config.wheel_right_joint_name, config.joint_states_frame,
            config.odom_frame, config.base_frame) == ('burger', 'wheel_left_joint', 'wheel_right_joint',
                                                      'base_footprint', 'odom', 'base_footprint')
    assert FakeConfig(odom_frame='/odom').odom_frame == 'odom'
    assert WHEEL_SEPARATION == {'burger': 0.160, 'waffle': 0.287, 'waffle_pi': 0.287}
    with pytest.raises(ParameterError, match=r"tb3_model = 'turtlebot4': must be one of: burger, waffle, waffle_pi"):
        FakeConfig(tb3_model='turtlebot4')
    with pytest.raises(ParameterError, match='wheel_left_joint_name'):
        FakeConfig(wheel_left_joint_name='')


def test_the_launch_starts_the_fake_node_robot_state_publisher_and_rviz(monkeypatch):
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'waffle_pi')
    config = roslaunch.config.load_config_default([LAUNCH], None, verbose=False)
    started = dict((node.name, node) for node in config.nodes)
    assert sorted(started) == ['robot_state_publisher', 'rviz', 'turtlebot3_fake_node']
    assert (started['turtlebot3_fake_node'].package, started['turtlebot3_fake_node'].type) == (
        'turtlebot3_fake', 'turtlebot3_fake_node')
    assert os.path.isfile(started['rviz'].args.split()[-1])
    assert config.params['/tb3_model'].value == 'waffle_pi'
    assert '<robot name="turtlebot3_waffle_pi"' in config.params['/robot_description'].value
