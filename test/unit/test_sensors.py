"""Lidar and IMU on a real pybullet world (DIRECT): ranges, REP 117 limits, noise, rates. test_world_rays.py
checks the world's rays against pybullet's."""
import math

import numpy as np
import pytest

from tb3_sim_nav.diff_drive import wheel_speeds
from tb3_sim_nav.robot_model import read_drive_geometry
from tb3_sim_nav.sensors import Imu, Lidar
from tb3_sim_nav.world_file import Obstacle

STEP = 1.0 / 200
SCAN_X = -0.032  # base_scan in base_footprint
SIGMA = 0.01
WALL = 0.1       # wall thickness
# Distances from the scan origin to the room's inner faces.
FRONT, LEFT, BACK, RIGHT = 1.0, 1.5, 2.0, 0.8


def box(x, y, size_x, size_y, height=0.4):
    return Obstacle('box', (size_x, size_y, height), (x, y, height / 2), 0.0, (1, 1, 1, 1))


def pillar(x, y, radius=0.01, height=0.4):
    return Obstacle('cylinder', (radius, height), (x, y, height / 2), 0.0, (1, 1, 1, 1))


#: Four 6 m walls, overlapping at the corners, around the scan origin.
ROOM = [box(SCAN_X + FRONT + WALL / 2, 0.0, WALL, 6.0),
        box(0.0, LEFT + WALL / 2, 6.0, WALL),
        box(SCAN_X - BACK - WALL / 2, 0.0, WALL, 6.0),
        box(0.0, -RIGHT - WALL / 2, 6.0, WALL)]


@pytest.fixture
def make_world(world_factory):
    """make_world(obstacles): a robot in a world settled for 0.5 s; closed after the test."""
    return lambda obstacles=(): world_factory(STEP, 0.5, obstacles=obstacles)


def run(robot, seconds):
    for _ in range(int(round(seconds / STEP))):
        robot.world.step()


def expected_room_ranges(robot, samples, scan_pose=None):
    """Per beam, the distance from the scan origin (`scan_pose`, else where the
    robot says its base_scan is) to the room's wall it points at."""
    (ox, oy, _oz), (qx, qy, qz, qw) = scan_pose or robot.link_pose('base_scan')
    yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
    front, back = SCAN_X + FRONT, SCAN_X - BACK
    ranges = []
    for k in range(samples):
        angle = yaw + k * 2 * math.pi / samples
        c, s = math.cos(angle), math.sin(angle)
        candidates = []
        if c > 1e-12:
            candidates.append((front - ox) / c)
        if c < -1e-12:
            candidates.append((back - ox) / c)
        if s > 1e-12:
            candidates.append((LEFT - oy) / s)
        if s < -1e-12:
            candidates.append((-RIGHT - oy) / s)
        ranges.append(min(candidates))
    return np.array(ranges)


# --- lidar ---------------------------------------------------------------------------

def test_four_beams_read_front_left_back_right_counter_clockwise(make_world):
    robot = make_world(ROOM)
    ranges = Lidar(robot, 'base_scan', samples=4, noise_stddev=0.0).read()
    assert ranges == pytest.approx([FRONT, LEFT, BACK, RIGHT], abs=0.001)


def test_noiseless_room_scan_is_exact_to_1_mm_at_every_angle(make_world):
    robot = make_world(ROOM)
    ranges = Lidar(robot, 'base_scan', noise_stddev=0.0).read()
    assert len(ranges) == 360
    assert np.abs(ranges - expected_room_ranges(robot, 360)).max() < 0.001


def test_noisy_room_scan_is_true_range_plus_sigma_noise(make_world):
    robot = make_world(ROOM)
    lidar = Lidar(robot, 'base_scan', noise_stddev=SIGMA, rng=np.random.default_rng(11))
    errors = lidar.read() - expected_room_ranges(robot, 360)
    # 360 Gaussian draws: about one beyond 3 sigma is expected, none beyond 5 sigma.
    assert np.abs(errors).max() < 5 * SIGMA
    assert np.mean(np.abs(errors) < 3 * SIGMA) >= 0.99
    assert np.std(errors) == pytest.approx(SIGMA, rel=0.15)
    assert abs(np.mean(errors)) < 3 * SIGMA / math.sqrt(360)


def test_beam_with_nothing_within_range_max_reads_plus_inf(make_world):
    robot = make_world([box(SCAN_X + 3.6 + WALL / 2, 0.0, WALL, 1.0)])  # 3.6 m ahead
    assert Lidar(robot, 'base_scan', range_max=3.5, noise_stddev=0.0).read()[0] == math.inf
    assert Lidar(robot, 'base_scan', range_max=4.0, noise_stddev=0.0).read()[0] == \
        pytest.approx(3.6, abs=0.001)


def test_beams_pointing_away_from_a_single_wall_read_plus_inf(make_world):
    robot = make_world([box(SCAN_X + FRONT + WALL / 2, 0.0, WALL, 20.0)])
    ranges = Lidar(robot, 'base_scan', samples=360, noise_stddev=SIGMA).read()
    angles = np.arange(360) * 2 * math.pi / 360
    # the wall's face along each beam: FRONT / cos(angle), when the beam points at it
    cosines = np.cos(angles)
    reaches = cosines > FRONT / 3.4   # wall within 3.4 m
    misses = cosines < FRONT / 3.6    # wall beyond 3.6 m, or behind
    assert reaches.sum() > 100 and misses.sum() > 200
    assert np.all(np.isfinite(ranges[reaches]))
    assert np.all(ranges[misses] == math.inf)


def test_pillar_closer_than_range_min_reads_minus_inf(make_world):
    # 0.1 m behind the scan origin: clear of the base (it ends 0.07 m behind), within 0.12 m.
    robot = make_world([pillar(SCAN_X - 0.10 - 0.01, 0.0)])
    # Without noise: with the LDS's 1 cm, a 0.10 m hit reads past 0.12 m one
    # scan in 40, as a real one would (the limit applies to what is measured).
    near = Lidar(robot, 'base_scan', range_min=0.12, noise_stddev=0.0).read()
    assert near[180] == -math.inf
    # ...and it is a real hit at 0.10 m, not the robot itself:
    assert Lidar(robot, 'base_scan', range_min=0.0, noise_stddev=0.0).read()[180] == \
        pytest.approx(0.10, abs=0.001)
    assert np.all(near[:90] == math.inf)


def test_robot_never_sees_itself(make_world):
    robot = make_world()
    for range_min in (0.0, 0.12):
        ranges = Lidar(robot, 'base_scan', range_min=range_min, noise_stddev=SIGMA).read()
        assert np.all(ranges == math.inf)


def test_a_turning_robots_scan_is_taken_from_where_its_base_is_now(make_world, burger_urdf):
    """pybullet keeps a link's pose from before the step moved its base unless
    asked to recompute it: at the Burger's 2.84 rad/s that put the scan 1.6
    degrees (a step at 100 Hz) behind the base, and the odometry stamped with it."""
    from tb3_sim_nav.frames import compose, relative, yaw_of
    robot = make_world(ROOM)
    mount = relative(robot.base_pose(), robot.link_pose('base_scan'))  # at rest: the URDF's fixed joints
    assert mount[0] == pytest.approx((SCAN_X, 0.0, 0.182), abs=1e-3)
    robot.set_wheel_speeds(*wheel_speeds(0.0, 2.84, *read_drive_geometry(str(burger_urdf))))
    lidar = Lidar(robot, 'base_scan', noise_stddev=0.0)
    run(robot, 0.5)  # spun up
    previous = compose(robot.base_pose(), mount)
    errors, stale = [], []
    for _ in range(10):
        robot.world.step()
        now = compose(robot.base_pose(), mount)
        ranges = lidar.read()
        errors.append(np.abs(ranges - expected_room_ranges(robot, 360, now)).max())
        stale.append(np.abs(ranges - expected_room_ranges(robot, 360, previous)).max())
        turned = yaw_of(now[1]) - yaw_of(previous[1])
        previous = now
    assert robot.base_velocity()[1][2] > 2.5 and turned > 2.5 * STEP  # it turns, a step at a time
    assert max(errors) < 0.001
    assert min(stale) > 0.01  # the scan of a pose a step old reads centimetres off: this test can tell


@pytest.mark.parametrize('samples', [3, 90, 360, 720])
def test_beam_count_and_increment_follow_samples(make_world, samples):
    robot = make_world(ROOM)
    lidar = Lidar(robot, 'base_scan', samples=samples, noise_stddev=0.0)
    assert lidar.angle_increment == pytest.approx(2 * math.pi / samples)
    ranges = lidar.read()
    assert ranges.shape == (samples,)
    assert np.abs(ranges - expected_room_ranges(robot, samples)).max() < 0.001


def test_seeded_lidars_give_identical_noisy_scans(make_world):
    robot = make_world(ROOM)
    first = Lidar(robot, 'base_scan', rng=np.random.default_rng(7)).read()
    second = Lidar(robot, 'base_scan', rng=np.random.default_rng(7)).read()
    other = Lidar(robot, 'base_scan', rng=np.random.default_rng(8)).read()
    assert np.array_equal(first, second)
    assert not np.array_equal(first, other)


# --- IMU -----------------------------------------------------------------------------

def readings(robot, imu, seconds, start=0.0):
    result = []
    for step in range(int(round(seconds / STEP))):
        robot.world.step()
        result.append(imu.read(round((start + (step + 1) * STEP) * 1e9)))
    return result


def test_imu_at_rest_reads_gravity_up_and_no_rotation(make_world):
    robot = make_world()
    for reading in readings(robot, Imu(robot), 0.5):
        assert reading.linear_acceleration == pytest.approx((0.0, 0.0, 9.81), abs=0.05)
        assert reading.angular_velocity == pytest.approx((0.0, 0.0, 0.0), abs=1e-3)


def test_imu_orientation_is_the_base_orientation(make_world, burger_urdf):
    robot = make_world()
    robot.set_wheel_speeds(*wheel_speeds(0.1, 0.8, *read_drive_geometry(str(burger_urdf))))
    imu = Imu(robot)
    run(robot, 1.0)
    reading = imu.read(1000000000)
    orientation = robot.base_pose()[1]
    assert abs(orientation[2]) > 0.3  # it has turned
    assert reading.orientation == pytest.approx(orientation, abs=1e-9)


def test_imu_reads_yaw_rate_turning_in_place(make_world, burger_urdf):
    robot = make_world()
    robot.set_wheel_speeds(*wheel_speeds(0.0, 1.0, *read_drive_geometry(str(burger_urdf))))
    imu = Imu(robot)
    late = readings(robot, imu, 1.5)[-50:]  # past the spin-up
    for reading in late:
        assert reading.angular_velocity[2] == pytest.approx(1.0, rel=0.05)
        assert reading.angular_velocity[:2] == pytest.approx((0.0, 0.0), abs=0.01)


def test_imu_noise_has_the_requested_standard_deviation(make_world):
    robot = make_world()
    imu = Imu(robot, gyro_noise=0.02, accel_noise=0.1, rng=np.random.default_rng(5))
    got = readings(robot, imu, 2000 * STEP)
    rates = np.array([reading.angular_velocity for reading in got])
    forces = np.array([reading.linear_acceleration for reading in got])
    assert np.std(rates, axis=0) == pytest.approx([0.02] * 3, rel=0.15)
    assert np.std(forces, axis=0) == pytest.approx([0.1] * 3, rel=0.15)
    assert np.mean(forces, axis=0) == pytest.approx((0.0, 0.0, 9.81), abs=0.01)


def test_imu_without_noise_parameters_is_noiseless(make_world):
    robot = make_world()
    got = readings(robot, Imu(robot), 0.5)
    rates = np.array([reading.angular_velocity for reading in got])
    assert np.std(rates, axis=0).max() < 1e-5
