#!/usr/bin/env python3
"""The lidar and the IMU against the world they are in (tb3_world.launch).

At the spawn pose (-2, -0.5, yaw 0) of the walled arena (worlds/turtlebot3_world.yaml:
six walls on a hexagon of inradius 2.5 m, 0.1 m thick; nine pillars of radius
0.15 m), this node casts its own 2D rays from base_scan (x -0.032 m of
base_footprint) through the walls and pillars read from the world file, and
compares them with /scan:
- the beam towards the nearest pillar (-1.1, -1.1) and beams towards three
  walls (west, south-west, north-west) read their geometric distance within
  3 sigma + 1 cm (sigma = 0.01 m, the LDS-01's);
- a beam with nothing within 3.5 m (east, between the pillars) reads +inf;
- over every beam whose expected range is unambiguous (not grazing an edge)
  the error is unbiased, about 1 cm wide, never beyond 5 sigma, and no beam
  expected +inf reads anything else;
- the header: frame base_scan, 360 ranges from 0 over 2 pi, 0.12-3.5 m.
At rest /imu reads gravity (+9.81 m/s^2 on z), no rotation, the heading of the
ground truth, in frame imu_link with its covariances filled, and comes at
~imu_rate (this node's private parameter: the simulator's ~imu_rate, 100 Hz
by default) in sim time.
The readings are taken once (setUpClass); each test method checks one promise.
"""
import math
import os
import threading
import unittest

import rospkg
import rospy
import rostest
import yaml
from sensor_msgs.msg import Imu, LaserScan

from tb3_test_utils import GroundTruth, init_test_node, report, wait_for, wall_budget, wrap, yaw_of

SPAWN = (-2.0, -0.5, 0.0)
SCAN_OFFSET_X = -0.032        # base_scan in base_footprint (m), URDF scan_joint + base_joint
SIGMA = 0.01                  # LDS-01 range noise (m)
BEAM_TOLERANCE = 3 * SIGMA + 0.01
SAMPLES = 360
RANGE_MIN, RANGE_MAX = 0.12, 3.5
SCANS = 3
IMU_SECONDS = 1.0             # sim s of IMU readings at rest
GRAVITY = 9.81
PILLAR = (-1.1, -1.1)         # the pillar nearest the spawn pose
WALL_BEAMS = (('west', 180), ('south_west', 270), ('north_west', 90))


# --- the world, as this test reads it -------------------------------------------------
def load_obstacles():
    path = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds', 'turtlebot3_world.yaml')
    with open(path) as stream:
        entries = yaml.safe_load(stream)['obstacles']
    obstacles = []
    for entry in entries:
        (kind, fields), = entry.items()
        x, y = fields['position'][:2]
        if kind == 'box':
            obstacles.append(('box', x, y, fields.get('yaw', 0.0), fields['size'][0] / 2.0,
                              fields['size'][1] / 2.0))
        else:
            obstacles.append(('cylinder', x, y, fields['radius']))
    return obstacles


def ray_box(ox, oy, dx, dy, box):
    """Distance along the unit ray to an oriented rectangle, or inf (slab method)."""
    _, cx, cy, yaw, hx, hy = box
    c, s = math.cos(yaw), math.sin(yaw)
    px, py = c * (ox - cx) + s * (oy - cy), -s * (ox - cx) + c * (oy - cy)
    ux, uy = c * dx + s * dy, -s * dx + c * dy
    near, far = -math.inf, math.inf
    for p, u, h in ((px, ux, hx), (py, uy, hy)):
        if abs(u) < 1e-12:
            if abs(p) > h:
                return math.inf
            continue
        t1, t2 = (-h - p) / u, (h - p) / u
        near, far = max(near, min(t1, t2)), min(far, max(t1, t2))
    if far < max(near, 0.0):
        return math.inf
    return max(near, 0.0)


def ray_cylinder(ox, oy, dx, dy, cylinder):
    _, cx, cy, radius = cylinder
    mx, my = ox - cx, oy - cy
    b = mx * dx + my * dy
    disc = b * b - (mx * mx + my * my - radius * radius)
    if disc < 0.0:
        return math.inf
    t = -b - math.sqrt(disc)
    return t if t >= 0.0 else math.inf


def cast(origin, angle, obstacles):
    """(distance, obstacle index) of the first hit of the ray, or (inf, None)."""
    dx, dy = math.cos(angle), math.sin(angle)
    best = (math.inf, None)
    for index, obstacle in enumerate(obstacles):
        hit = (ray_box if obstacle[0] == 'box' else ray_cylinder)(origin[0], origin[1], dx, dy, obstacle)
        if hit < best[0]:
            best = (hit, index)
    return best


def expected_reading(distance):
    """What an ideal LDS-01 reads for a hit at `distance` (REP 117)."""
    if distance > RANGE_MAX:
        return math.inf
    if distance < RANGE_MIN:
        return -math.inf
    return distance


class Expected(object):
    """Expected reading of every beam from a robot pose, and whether it is unambiguous."""

    def __init__(self, pose, obstacles, spread=math.radians(0.2)):
        self.origin = (pose.x + SCAN_OFFSET_X * math.cos(pose.yaw), pose.y + SCAN_OFFSET_X * math.sin(pose.yaw))
        self.obstacles = obstacles
        self.beams = []
        for i in range(SAMPLES):
            angle = pose.yaw + i * 2.0 * math.pi / SAMPLES
            distance, index = cast(self.origin, angle, obstacles)
            # Neighbouring rays (pose error, beam width) must see the same obstacle,
            # or like it nothing within range: the beam does not graze an edge.
            around = [cast(self.origin, angle + delta, obstacles) for delta in (-spread, spread)]
            reading = expected_reading(distance)
            clear = all(math.isinf(expected_reading(d)) if math.isinf(reading)
                        else (j == index and not math.isinf(expected_reading(d))) for d, j in around)
            # Noise must not carry a hit across range_min or range_max.
            clear = clear and (math.isinf(reading) or RANGE_MIN + 5 * SIGMA < reading < RANGE_MAX - 5 * SIGMA)
            self.beams.append((reading, index, clear))

    def beam_towards(self, point, pose):
        angle = wrap(math.atan2(point[1] - self.origin[1], point[0] - self.origin[0]) - pose.yaw)
        return int(round(angle / (2.0 * math.pi / SAMPLES))) % SAMPLES


class SensorsAndWorld(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.lock = threading.Lock()
        cls.scans, cls.imus = [], []
        cls.truth = GroundTruth()
        rospy.Subscriber('/scan', LaserScan, cls._on_scan, queue_size=None)
        rospy.Subscriber('/imu', Imu, cls._on_imu, queue_size=None)
        cls.setup_error = None
        try:
            cls._collect()
        except AssertionError as error:
            cls.setup_error = str(error)

    @classmethod
    def _on_scan(cls, message):
        with cls.lock:
            cls.scans.append(message)

    @classmethod
    def _on_imu(cls, message):
        with cls.lock:
            cls.imus.append(message)

    @classmethod
    def _collect(cls):
        if not cls.truth.wait_first(60.0):
            raise AssertionError('no base_pose_ground_truth within 60 s')
        cls.pose = cls.truth.wait_at_rest(timeout=30.0)
        if cls.pose is None:
            raise AssertionError('the robot did not come to rest after spawning')
        rest = cls.pose.t
        budget = wall_budget(SCANS / 5.0 + IMU_SECONDS + 1.0)
        if not wait_for(lambda: sum(1 for s in list(cls.scans) if s.header.stamp.to_sec() >= rest) >= SCANS
                        and sum(1 for m in list(cls.imus) if m.header.stamp.to_sec() >= rest + IMU_SECONDS) > 0,
                        budget):
            raise AssertionError('fewer than %d scans or less than %.1f s of imu within %.0f wall s '
                                 '(scans %d, imu %d)' % (SCANS, IMU_SECONDS, budget, len(cls.scans), len(cls.imus)))
        with cls.lock:
            cls.rest_scans = [s for s in cls.scans if s.header.stamp.to_sec() >= rest][:SCANS]
            cls.rest_imus = [m for m in cls.imus if rest <= m.header.stamp.to_sec() <= rest + IMU_SECONDS]
        cls.still = cls.truth.still_since(rest)
        cls.expected = Expected(cls.pose, load_obstacles())

    def setUp(self):
        if self.setup_error:
            self.fail(self.setup_error)

    def check_beam(self, name, beam):
        reading, index, clear = self.expected.beams[beam]
        # By construction: the beams chosen here hit something unambiguous.
        self.assertTrue(clear and not math.isinf(reading),
                        'test construction: beam %d (%s) is not a clean hit: %r' % (beam, name, (reading, index)))
        ranges = [scan.ranges[beam] for scan in self.rest_scans]
        errors = [r - reading for r in ranges]
        report('beam_%s' % name, beam=beam, expected_m=reading, obstacle=index + 1,
               readings=' '.join('%.4f' % r for r in ranges), max_error_m=max(abs(e) for e in errors))
        for r in ranges:
            self.assertAlmostEqual(r, reading, delta=BEAM_TOLERANCE,
                                   msg='beam %d (%s): read %.4f m, geometry gives %.4f m (obstacle %d)'
                                   % (beam, name, r, reading, index + 1))
        return index

    def test_robot_rests_at_the_spawn_pose(self):
        pose = self.pose
        report('rest_pose', x=pose.x, y=pose.y, yaw_deg=math.degrees(pose.yaw))
        self.assertTrue(self.still, 'the robot moved while the sensors were read')
        self.assertLess(math.hypot(pose.x - SPAWN[0], pose.y - SPAWN[1]), 0.01)
        self.assertLess(abs(math.degrees(wrap(pose.yaw - SPAWN[2]))), 1.0)

    def test_scan_header_base_scan_360_beams_over_a_full_turn_lds01_limits(self):
        for scan in self.rest_scans:
            self.assertEqual(scan.header.frame_id, 'base_scan')
            self.assertEqual(len(scan.ranges), SAMPLES)
            self.assertAlmostEqual(scan.angle_min, 0.0, places=9)
            self.assertAlmostEqual(scan.angle_increment, 2.0 * math.pi / SAMPLES, places=6)
            self.assertAlmostEqual(scan.angle_max, (SAMPLES - 1) * 2.0 * math.pi / SAMPLES, places=6)
            self.assertAlmostEqual(scan.range_min, RANGE_MIN, places=6)
            self.assertAlmostEqual(scan.range_max, RANGE_MAX, places=6)

    def test_beam_towards_nearest_pillar_reads_its_distance(self):
        beam = self.expected.beam_towards(PILLAR, self.pose)
        index = self.check_beam('pillar', beam)
        obstacle = self.expected.obstacles[index]
        self.assertEqual((obstacle[0], obstacle[1], obstacle[2]), ('cylinder',) + PILLAR,
                         'test construction: beam %d does not point at the pillar' % beam)

    def test_beam_west_reads_the_west_wall(self):
        self.check_beam(*WALL_BEAMS[0])

    def test_beam_south_west_reads_the_south_west_wall(self):
        self.check_beam(*WALL_BEAMS[1])

    def test_beam_north_west_reads_the_north_west_wall(self):
        self.check_beam(*WALL_BEAMS[2])

    def test_beam_with_nothing_within_3_5m_reads_plus_inf(self):
        # The clear beam nearest to straight ahead (east, between the pillars).
        clear = [i for i, (reading, _, ok) in enumerate(self.expected.beams) if ok and reading == math.inf]
        self.assertTrue(clear, 'test construction: no beam sees nothing within 3.5 m')
        beam = min(clear, key=lambda i: min(i, SAMPLES - i))
        readings = [scan.ranges[beam] for scan in self.rest_scans]
        report('beam_open', beam=beam, readings=readings)
        self.assertEqual(readings, [math.inf] * len(readings), 'beam %d should read +inf' % beam)

    def test_every_clear_beam_agrees_with_geometry_noise_about_1cm_unbiased(self):
        errors, wrong_inf, far = [], [], []
        for scan in self.rest_scans:
            for beam, (reading, _, clear) in enumerate(self.expected.beams):
                if not clear:
                    continue
                value = scan.ranges[beam]
                if math.isinf(reading):
                    if value != reading:
                        wrong_inf.append((beam, value, reading))
                elif math.isinf(value):
                    far.append((beam, value, reading))
                else:
                    errors.append(value - reading)
                    if abs(value - reading) > 5 * SIGMA:
                        far.append((beam, value, reading))
        mean = sum(errors) / len(errors)
        std = math.sqrt(sum((e - mean) ** 2 for e in errors) / (len(errors) - 1))
        report('scan_vs_geometry', beams_compared=len(errors), mean_error_m=mean, std_m=std,
               beyond_5_sigma=len(far), wrong_inf=len(wrong_inf),
               ambiguous_beams=sum(1 for b in self.expected.beams if not b[2]))
        self.assertGreater(len(errors), 200 * len(self.rest_scans), 'test construction: too few clear beams')
        self.assertEqual(wrong_inf, [], 'beams that should read +inf (beam, read, expected)')
        self.assertEqual(far, [], 'beams beyond 5 sigma of the geometry (beam, read, expected)')
        self.assertLess(abs(mean), 0.003, 'the ranges are biased by %.4f m' % mean)
        self.assertAlmostEqual(std, SIGMA, delta=0.002, msg='range noise sigma %.4f m, expected 0.01' % std)

    def test_imu_at_rest_reads_gravity_up_and_no_rotation(self):
        rate = float(rospy.get_param('~imu_rate', 100.0))
        self.assertGreater(len(self.rest_imus), 0.75 * rate * IMU_SECONDS, '%d imu messages in %.1f s of '
                           'sim time, ~imu_rate %g Hz' % (len(self.rest_imus), IMU_SECONDS, rate))
        acc = [m.linear_acceleration for m in self.rest_imus]
        gyro = [m.angular_velocity for m in self.rest_imus]
        report('imu_at_rest', messages=len(acc), min_az=min(a.z for a in acc), max_az=max(a.z for a in acc),
               max_abs_axy=max(max(abs(a.x), abs(a.y)) for a in acc),
               max_abs_gyro=max(max(abs(g.x), abs(g.y), abs(g.z)) for g in gyro))
        for a in acc:
            self.assertAlmostEqual(a.z, GRAVITY, delta=0.1)
            self.assertLess(max(abs(a.x), abs(a.y)), 0.1)
        for g in gyro:
            self.assertLess(max(abs(g.x), abs(g.y), abs(g.z)), 0.01)

    def test_imu_orientation_is_the_ground_truth_heading(self):
        for m in self.rest_imus:
            self.assertLess(abs(math.degrees(wrap(yaw_of(m.orientation) - self.pose.yaw))), 1.0)

    def test_imu_frame_imu_link_and_covariances_filled(self):
        for m in self.rest_imus:
            self.assertEqual(m.header.frame_id, 'imu_link')
            for name in ('orientation_covariance', 'angular_velocity_covariance',
                         'linear_acceleration_covariance'):
                matrix = getattr(m, name)
                self.assertTrue(all(matrix[i] > 0.0 for i in (0, 4, 8)), '%s: %s' % (name, list(matrix)))
                self.assertTrue(all(math.isfinite(v) for v in matrix), '%s: %s' % (name, list(matrix)))


if __name__ == '__main__':
    init_test_node('test_sensors_and_world')
    rostest.rosrun('tb3_sim_nav', 'sensors_and_world', SensorsAndWorld)
