"""turtlebot3_drive's decisions (turtlebot3_gazebo.drive), step by step as ROBOTIS' controlLoop takes them,
and its parameter; no ROS master."""
import math

import pytest

from tb3_common.params import ParameterError
from turtlebot3_gazebo.drive import (
    ANGULAR_VELOCITY,
    GET_TB3_DIRECTION,
    LINEAR_VELOCITY,
    TB3_DRIVE_FORWARD,
    TB3_LEFT_TURN,
    TB3_RIGHT_TURN,
    Drive,
    DriveConfig,
    beam_index,
)

RANGE_MAX = 3.5
FULL_CIRCLE = 2.0 * math.pi / 360  # LDS-01: 360 beams from 0


def scan(center, left, right, samples=360, angle_min=0.0, fill=2.0):
    """A scan of `samples` beams reading `fill`, with the beams at 0, 30 and 330 degrees set."""
    increment = 2.0 * math.pi / samples
    ranges = [fill] * samples
    for degrees, value in ((0, center), (30, left), (330, right)):
        ranges[beam_index(math.radians(degrees), angle_min, increment, samples)] = value
    return ranges, angle_min, increment, RANGE_MAX


def yaw(drive, angle):
    drive.on_odom(0.0, 0.0, math.sin(angle / 2.0), math.cos(angle / 2.0))


def looked(center, left, right, heading=0.0):
    drive = Drive()
    yaw(drive, heading)
    drive.on_scan(*scan(center, left, right))
    return drive


def test_before_the_first_scan_it_turns_right_as_robotis_does():
    drive = Drive()
    assert drive.step() is None and drive.state == TB3_RIGHT_TURN
    assert drive.step() == (0.0, -ANGULAR_VELOCITY)


def test_clear_ahead_it_alternates_a_look_and_a_forward_command():
    drive = looked(2.0, 2.0, 2.0)
    commands = [drive.step() for _ in range(6)]
    assert commands == [None, (LINEAR_VELOCITY, 0.0)] * 3
    assert drive.state == GET_TB3_DIRECTION
    assert LINEAR_VELOCITY == 0.3 and ANGULAR_VELOCITY == 1.5


@pytest.mark.parametrize('center, left, right, state, command', [
    (0.69, 2.0, 2.0, TB3_RIGHT_TURN, (0.0, -1.5)),     # blocked ahead: right, whatever the sides say
    (0.69, 0.1, 2.0, TB3_RIGHT_TURN, (0.0, -1.5)),
    (0.69, 2.0, 0.1, TB3_RIGHT_TURN, (0.0, -1.5)),
    (0.71, 0.59, 2.0, TB3_RIGHT_TURN, (0.0, -1.5)),    # a wall near on the left: away, to the right
    (0.71, 2.0, 0.59, TB3_LEFT_TURN, (0.0, 1.5)),      # near on the right: to the left
    (0.71, 0.59, 0.59, TB3_RIGHT_TURN, (0.0, -1.5)),   # both: the left is looked at first
    (0.71, 0.61, 0.61, TB3_DRIVE_FORWARD, (0.3, 0.0)),
])
def test_robotis_thresholds_decide_the_direction(center, left, right, state, command):
    drive = looked(center, left, right)
    assert drive.step() is None
    assert drive.state == state
    assert drive.step() == command


def test_exactly_at_the_forward_distance_it_looks_again():
    """ROBOTIS tests > 0.7 and < 0.7: at 0.7 neither holds and the state stays."""
    drive = looked(0.7, 2.0, 2.0)
    assert [drive.step() for _ in range(3)] == [None] * 3 and drive.state == GET_TB3_DIRECTION


def test_a_turn_lasts_thirty_degrees_of_odometry():
    drive = looked(0.5, 2.0, 2.0, heading=0.2)
    drive.step()
    for heading in (0.2, 0.0, -0.3):
        yaw(drive, heading)
        assert drive.step() == (0.0, -ANGULAR_VELOCITY)
    yaw(drive, 0.2 - math.radians(30.0) - 1e-6)
    assert drive.step() is None and drive.state == GET_TB3_DIRECTION


def test_a_turn_across_180_degrees_ends_early_and_the_next_look_turns_on():
    """ROBOTIS compares the yaws unwrapped: from 179 to -179 degrees reads as 358."""
    drive = looked(0.5, 2.0, 2.0, heading=math.radians(-179.0))
    drive.step()
    yaw(drive, math.radians(179.0))   # 2 degrees to the right, across the seam
    assert drive.step() is None and drive.state == GET_TB3_DIRECTION
    assert drive.step() is None and drive.state == TB3_RIGHT_TURN   # still blocked: turning on


def test_readings_inf_is_range_max_minus_inf_is_zero_nan_keeps_the_last():
    drive = looked(2.0, 2.0, 2.0)
    drive.on_scan(*scan(math.inf, -math.inf, math.nan))
    assert drive.scan_data == [RANGE_MAX, 0.0, 2.0]


@pytest.mark.parametrize('samples, angle_min, increment', [
    (360, 0.0, FULL_CIRCLE),                   # LDS-01
    (24, 0.0, 2.0 * math.pi / 24),             # the machine-learning chapter's cut
    (720, -math.pi, 2.0 * math.pi / 720),      # a lidar whose first beam points backwards
    (360, 2.0 * math.pi, -FULL_CIRCLE),        # beams numbered clockwise
])
def test_beams_are_picked_by_their_angle(samples, angle_min, increment):
    for degrees in (0.0, 30.0, 330.0):
        index = beam_index(math.radians(degrees), angle_min, increment, samples)
        beam = angle_min + index * increment
        assert math.isclose(math.remainder(beam - math.radians(degrees), 2 * math.pi), 0.0, abs_tol=1e-9)
    assert beam_index(0.0, 0.0, FULL_CIRCLE, 360) == 0 and beam_index(math.radians(330), 0.0, FULL_CIRCLE, 360) == 330
    assert beam_index(math.radians(359.9), 0.0, FULL_CIRCLE, 360) == 0   # the circle wraps


def test_a_beam_outside_the_scans_fan_is_missing_and_keeps_its_reading():
    drive = looked(2.0, 2.0, 2.0)
    front_half = [1.0] * 181   # -90 to +90 degrees: 330 is there, as -30
    drive.on_scan(front_half, -math.pi / 2, math.pi / 180, RANGE_MAX)
    assert drive.missing == [] and drive.scan_data == [1.0, 1.0, 1.0]
    drive.on_scan([0.5] * 10, 0.0, math.pi / 180, RANGE_MAX)   # 0 to 9 degrees
    assert drive.missing == [30.0, 330.0] and drive.scan_data == [0.5, 1.0, 1.0]
    assert beam_index(0.0, math.nan, FULL_CIRCLE, 360) is None and beam_index(0.0, 0.0, 0.0, 360) is None


def test_non_finite_odometry_is_ignored():
    drive = Drive()
    yaw(drive, 1.0)
    assert not drive.on_odom(math.nan, 0.0, 0.0, 1.0)
    assert not drive.on_odom(0.0, 0.0, math.inf, 1.0)
    assert drive.tb3_pose == pytest.approx(1.0)


def test_cmd_vel_topic_name_is_checked():
    assert DriveConfig().cmd_vel_topic_name == 'cmd_vel'
    assert DriveConfig(cmd_vel_topic_name='/tb3_0/cmd_vel').cmd_vel_topic_name == '/tb3_0/cmd_vel'
    for bad in ('', 'cmd vel', 7):
        with pytest.raises(ParameterError, match='cmd_vel_topic_name'):
            DriveConfig(cmd_vel_topic_name=bad)
