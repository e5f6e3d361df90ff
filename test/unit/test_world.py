"""The pybullet world (DIRECT, real physics): the Burger stands, drives and turns as specified."""
import math

import numpy as np
import pybullet
import pytest

from tb3_sim_nav.diff_drive import wheel_speeds
from tb3_sim_nav.frames import yaw_of
from tb3_sim_nav.robot_model import read_drive_geometry

STEP = 1.0 / 200
SETTLE_STEPS = 400  # 2 s for the robot to drop onto the ground and come to rest


@pytest.fixture
def geometry(burger_urdf):
    return read_drive_geometry(str(burger_urdf))


@pytest.fixture
def make_world(world_factory):
    """make_world(x, y, yaw): a robot settled in a world at that spawn pose; closed after the test."""
    return lambda x=0.0, y=0.0, yaw=0.0: world_factory(STEP, SETTLE_STEPS * STEP, (x, y, 0.0, yaw))


def run(robot, seconds):
    for _ in range(int(round(seconds / STEP))):
        robot.world.step()


def drive(robot, geometry, v, w):
    robot.set_wheel_speeds(*wheel_speeds(v, w, *geometry))


def pose(robot):
    """(x, y, z, roll, pitch, yaw) of base_footprint."""
    position, orientation = robot.base_pose()
    roll, pitch, _ = pybullet.getEulerFromQuaternion(orientation)
    return tuple(position) + (roll, pitch, yaw_of(orientation))


def angle_between(a, b):
    return abs(math.remainder(a - b, 2 * math.pi))


def link_index(robot, name):
    for index in range(robot.p.getNumJoints(robot.id)):
        info = robot.p.getJointInfo(robot.id, index)
        if info[12].decode() == name:
            return index
    raise KeyError(name)


def test_robot_settles_level_on_wheels_and_caster(make_world):
    robot = make_world()
    x, y, z, roll, pitch, _yaw = pose(robot)
    assert abs(z) < 0.002
    assert abs(math.degrees(roll)) < 1.0 and abs(math.degrees(pitch)) < 1.0
    contacts = robot.p.getContactPoints(robot.id, robot.world.plane)
    touching = {contact[3] for contact in contacts}
    expected = {link_index(robot, 'wheel_left_link'), link_index(robot, 'wheel_right_link'),
                link_index(robot, 'caster_back_link')}
    assert touching == expected


def test_robot_at_rest_stays_put_for_10_s(make_world):
    robot = make_world()
    before = pose(robot)
    run(robot, 10.0)
    after = pose(robot)
    assert math.dist(before[:3], after[:3]) < 0.001
    assert angle_between(before[5], after[5]) < math.radians(0.1)


def test_straight_drive_covers_one_metre(make_world, geometry):
    robot = make_world()
    drive(robot, geometry, 0.2, 0.0)
    run(robot, 5.0)
    x, y, _z, _roll, _pitch, yaw = pose(robot)
    assert x == pytest.approx(1.0, rel=0.02)
    assert abs(y) < 0.005
    assert angle_between(yaw, 0.0) < math.radians(1.0)


def test_in_place_turn_of_pi_seconds_at_1_rad_s_turns_180_deg(make_world, geometry):
    robot = make_world()
    drive(robot, geometry, 0.0, 1.0)
    run(robot, math.pi)
    drive(robot, geometry, 0.0, 0.0)
    run(robot, 0.5)
    x, y, _z, _roll, _pitch, yaw = pose(robot)
    assert math.degrees(angle_between(yaw, math.pi)) < 2.0
    assert math.hypot(x, y) < 0.005


def test_circle_has_radius_v_over_w_and_turns_clockwise(make_world, geometry):
    robot = make_world()
    drive(robot, geometry, 0.1, -0.5)
    points, turned, last_yaw = [], 0.0, 0.0
    for _ in range(int(round(4 * math.pi / STEP))):  # one full circle
        robot.world.step()
        x, y, _z, _roll, _pitch, yaw = pose(robot)
        points.append((x, y))
        turned += math.remainder(yaw - last_yaw, 2 * math.pi)
        last_yaw = yaw
    xs, ys = np.array(points).T
    # Least-squares circle: x^2 + y^2 = 2 a x + 2 b y + c.
    a, b, c = np.linalg.lstsq(np.c_[2 * xs, 2 * ys, np.ones_like(xs)], xs ** 2 + ys ** 2, rcond=None)[0]
    radius = math.sqrt(c + a * a + b * b)
    assert radius == pytest.approx(0.2, rel=0.05)
    # Clockwise: the centre lies on the right of the start heading (+x), and yaw decreases.
    assert (a, b) == pytest.approx((0.0, -0.2), abs=0.01)
    assert turned == pytest.approx(-2 * math.pi, rel=0.05)


def test_base_twist_is_in_body_frame_whatever_the_heading(make_world, geometry):
    robot = make_world(yaw=math.pi / 2)
    drive(robot, geometry, 0.2, 0.0)
    run(robot, 2.0)
    linear, angular = robot.base_twist()
    assert linear == pytest.approx((0.2, 0.0, 0.0), abs=0.005)
    assert angular == pytest.approx((0.0, 0.0, 0.0), abs=0.01)
    # ...while in the world frame the robot heads along +y.
    x, y, *_ = pose(robot)
    assert abs(x) < 0.005 and y > 0.3


def test_base_twist_reports_yaw_rate_while_turning(make_world, geometry):
    robot = make_world(yaw=-2.0)
    drive(robot, geometry, 0.1, -0.5)
    run(robot, 2.0)
    linear, angular = robot.base_twist()
    assert linear == pytest.approx((0.1, 0.0, 0.0), abs=0.005)
    assert angular[2] == pytest.approx(-0.5, abs=0.02)


@pytest.mark.parametrize('x, y, yaw', [(0.0, 0.0, 0.0), (1.5, -2.0, 2.5), (-3.0, 0.7, -math.pi / 2)])
def test_spawn_pose_is_honoured(make_world, x, y, yaw):
    robot = make_world(x, y, yaw)
    got_x, got_y, _z, _roll, _pitch, got_yaw = pose(robot)
    assert (got_x, got_y) == pytest.approx((x, y), abs=0.001)
    assert angle_between(got_yaw, yaw) < math.radians(0.5)


def test_wheel_angles_grow_at_v_over_r(make_world, geometry):
    robot = make_world()
    drive(robot, geometry, 0.2, 0.0)
    run(robot, 1.0)  # past the spin-up
    angles_before, _ = robot.wheel_states()
    run(robot, 2.0)
    angles_after, speeds = robot.wheel_states()
    expected = 0.2 / geometry.wheel_radius
    for before, after in zip(angles_before, angles_after):
        assert (after - before) / 2.0 == pytest.approx(expected, rel=0.02)
    assert speeds == pytest.approx([expected, expected], rel=0.02)


def test_wheel_speeds_have_opposite_signs_turning_in_place(make_world, geometry):
    robot = make_world()
    drive(robot, geometry, 0.0, 1.0)
    run(robot, 1.0)
    _angles, (left, right) = robot.wheel_states()
    expected = 1.0 * geometry.wheel_separation / 2 / geometry.wheel_radius
    assert (left, right) == pytest.approx((-expected, expected), rel=0.02)
