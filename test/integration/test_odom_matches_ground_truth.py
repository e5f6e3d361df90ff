#!/usr/bin/env python3
"""odom and tf odom->base_footprint against base_pose_ground_truth.

While the robot follows a command pattern (turn left to a heading of about
90 deg, drive straight, drive an arc, stop):
- every odom message has a ground-truth message with the same stamp, and the
  two agree within 1 mm and 0.1 deg (TurtleBot3's Gazebo odometry does not drift);
- every odom message has a tf odom->base_footprint with the same stamp and the
  same pose;
- odom's twist is in the base frame: driving straight at a heading of 90 deg,
  twist.linear.x is the commanded speed and linear.y about 0 (in the odom
  frame it would be the other way round);
- frames are 'odom' and 'base_footprint', covariance diagonals are non-zero.
The pattern runs once (setUpClass); each test method checks one promise.
"""
import math
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

from tb3_test_utils import GroundTruth, init_test_node, report, wait_for, wait_for_simulator, wall_budget, wrap

POSITION_TOLERANCE = 0.001            # m
ANGLE_TOLERANCE = math.radians(0.1)   # rad
TURN_SPEED = 0.6                      # rad/s
STRAIGHT_SPEED = 0.15                 # m/s
STRAIGHT_SECONDS = 3.0
ARC = (0.1, -0.5)
ARC_SECONDS = 2.0


def key(stamp):
    return (stamp.secs, stamp.nsecs)


def quaternion_angle(a, b):
    """Angle (rad) of the rotation between two geometry_msgs Quaternions."""
    dot = abs(a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w)
    norm = math.sqrt((a.x ** 2 + a.y ** 2 + a.z ** 2 + a.w ** 2)
                     * (b.x ** 2 + b.y ** 2 + b.z ** 2 + b.w ** 2))
    return 2.0 * math.acos(min(1.0, dot / norm))


class Recorder(object):
    def __init__(self):
        self._lock = threading.Lock()
        self.odom = []
        self.truth = {}
        self.tf = {}
        self.tf_parents = set()
        rospy.Subscriber('/odom', Odometry, self._on_odom, queue_size=None)
        rospy.Subscriber('/base_pose_ground_truth', Odometry, self._on_truth, queue_size=None)
        rospy.Subscriber('/tf', TFMessage, self._on_tf, queue_size=None)

    def _on_odom(self, message):
        with self._lock:
            self.odom.append(message)

    def _on_truth(self, message):
        with self._lock:
            self.truth[key(message.header.stamp)] = message

    def _on_tf(self, message):
        with self._lock:
            for transform in message.transforms:
                if transform.child_frame_id.lstrip('/') == 'base_footprint':
                    self.tf[key(transform.header.stamp)] = transform
                    self.tf_parents.add(transform.header.frame_id)


class OdomMatchesGroundTruth(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.recorder = Recorder()
        cls.truth = GroundTruth()
        cls.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=10)
        cls.setup_error = None
        try:
            cls._drive_pattern()
        except Exception as error:
            cls.setup_error = '%s: %s' % (type(error).__name__, error)
        finally:
            cls.command(0.0, 0.0)

    @classmethod
    def command(cls, v, w):
        twist = Twist()
        twist.linear.x, twist.angular.z = v, w
        cls.cmd_vel.publish(twist)

    @classmethod
    def _drive_pattern(cls):
        truth = cls.truth
        start = wait_for_simulator(truth, cls.cmd_vel)
        # Turn left to about 90 deg: there is no spawn-yaw launch argument.
        cls.command(0.0, TURN_SPEED)
        cls.turn_start = truth.now()
        if not wait_for(lambda: wrap(truth.latest().yaw - start.yaw) >= math.radians(88.0),
                        wall_budget(math.pi / 2 / TURN_SPEED)):
            raise AssertionError('did not turn to 90 deg')
        cls.command(0.0, 0.0)
        turned = truth.wait_at_rest(window=0.3, timeout=wall_budget(3.0))
        if turned is None:
            raise AssertionError('did not stop after turning')
        cls.heading = turned.yaw
        # Straight on at that heading.
        cls.command(STRAIGHT_SPEED, 0.0)
        cls.straight_start = truth.now()
        if not truth.wait_until(cls.straight_start + STRAIGHT_SECONDS, wall_budget(STRAIGHT_SECONDS)):
            raise AssertionError('ground truth stopped while driving straight')
        # An arc.
        cls.command(*ARC)
        cls.arc_start = truth.now()
        if not truth.wait_until(cls.arc_start + ARC_SECONDS, wall_budget(ARC_SECONDS)):
            raise AssertionError('ground truth stopped while driving the arc')
        cls.command(0.0, 0.0)
        cls.end = truth.wait_at_rest(window=0.3, timeout=wall_budget(3.0))
        if cls.end is None:
            raise AssertionError('did not stop at the end of the pattern')
        # Let the last odom, truth and tf messages of the stop arrive.
        latest = truth.now()

        def caught_up():
            with cls.recorder._lock:
                odom, tf = list(cls.recorder.odom), dict(cls.recorder.tf)
            return (odom and tf and odom[-1].header.stamp.to_sec() >= latest
                    and max(tf) >= key(odom[-1].header.stamp))
        wait_for(caught_up, 5.0)

    def setUp(self):
        if self.setup_error:
            self.fail('driving the command pattern failed: ' + self.setup_error)
        with self.recorder._lock:
            self.odom = list(self.recorder.odom)
            self.truth_by_stamp = dict(self.recorder.truth)
            self.tf_by_stamp = dict(self.recorder.tf)
        self.assertGreater(len(self.odom), 200, 'only %d odom messages' % len(self.odom))

    def test_odom_and_ground_truth_with_same_stamp_agree_within_1mm_and_0_1deg(self):
        pairs = [(o, self.truth_by_stamp.get(key(o.header.stamp))) for o in self.odom]
        unmatched = [o.header.stamp.to_sec() for o, t in pairs if t is None]
        pairs = [(o, t) for o, t in pairs if t is not None]
        self.assertLessEqual(len(unmatched), 2, 'odom stamps without a ground-truth message of the '
                             'same stamp: %s' % unmatched[:10])
        worst_position = max(math.sqrt((o.pose.pose.position.x - t.pose.pose.position.x) ** 2
                                       + (o.pose.pose.position.y - t.pose.pose.position.y) ** 2
                                       + (o.pose.pose.position.z - t.pose.pose.position.z) ** 2)
                             for o, t in pairs)
        worst_angle = max(quaternion_angle(o.pose.pose.orientation, t.pose.pose.orientation)
                          for o, t in pairs)
        travelled = math.hypot(self.end.x, self.end.y)
        report('odom_vs_truth', pairs=len(pairs), worst_position_m=worst_position,
               worst_angle_deg=math.degrees(worst_angle), end_distance_from_origin_m=travelled)
        self.assertGreater(travelled, 0.3, 'the robot hardly moved: the comparison proves little')
        self.assertLessEqual(worst_position, POSITION_TOLERANCE)
        self.assertLessEqual(worst_angle, ANGLE_TOLERANCE)

    def test_tf_odom_to_base_footprint_has_odom_stamps_and_poses(self):
        missing = [o.header.stamp.to_sec() for o in self.odom
                   if key(o.header.stamp) not in self.tf_by_stamp]
        self.assertLessEqual(len(missing), 2, 'odom stamps without a tf odom->base_footprint of the '
                             'same stamp: %s' % missing[:10])
        self.assertEqual(self.recorder.tf_parents, {'odom'},
                         'parent frames of base_footprint in /tf')
        worst_position = worst_angle = 0.0
        for o in self.odom:
            transform = self.tf_by_stamp.get(key(o.header.stamp))
            if transform is None:
                continue
            t, p = transform.transform.translation, o.pose.pose.position
            worst_position = max(worst_position, math.sqrt((t.x - p.x) ** 2 + (t.y - p.y) ** 2
                                                           + (t.z - p.z) ** 2))
            worst_angle = max(worst_angle, quaternion_angle(transform.transform.rotation,
                                                            o.pose.pose.orientation))
        report('tf_vs_odom', worst_position_m=worst_position, worst_angle_deg=math.degrees(worst_angle))
        self.assertLess(worst_position, 1e-6)
        self.assertLess(worst_angle, 1e-6)

    def test_odom_twist_is_in_the_base_frame(self):
        heading_deg = math.degrees(self.heading)
        self.assertAlmostEqual(heading_deg, 90.0, delta=10.0,
                               msg='set-up: heading %.1f deg before driving straight' % heading_deg)
        steady = [o for o in self.odom
                  if self.straight_start + 1.0 <= o.header.stamp.to_sec()
                  <= self.straight_start + STRAIGHT_SECONDS]
        self.assertGreater(len(steady), 30)
        forward = [o.twist.twist.linear.x for o in steady]
        sideways = [o.twist.twist.linear.y for o in steady]
        # The truth's own motion: along +y of odom, as a heading of 90 deg means.
        samples = self.truth.samples(start=self.straight_start + 1.0,
                                     end=self.straight_start + STRAIGHT_SECONDS)
        first, last = samples[0], samples[-1]
        world_vx = (last.x - first.x) / (last.t - first.t)
        world_vy = (last.y - first.y) / (last.t - first.t)
        report('odom_twist_straight', heading_deg=heading_deg, min_linear_x=min(forward),
               max_linear_x=max(forward), max_abs_linear_y=max(abs(v) for v in sideways),
               truth_world_velocity='(%.4f, %.4f)' % (world_vx, world_vy))
        self.assertGreater(world_vy, 0.9 * STRAIGHT_SPEED, 'set-up: not driving along +y')
        for v in forward:
            self.assertAlmostEqual(v, STRAIGHT_SPEED, delta=0.05 * STRAIGHT_SPEED,
                                   msg='odom twist.linear.x %.4f while driving straight at %.2f m/s '
                                   'with heading 90 deg' % (v, STRAIGHT_SPEED))
        for v in sideways:
            self.assertLess(abs(v), 0.01, 'odom twist.linear.y %.4f while driving straight ahead: '
                            'twist not in the base frame' % v)

    def test_odom_angular_velocity_follows_the_arc(self):
        steady = [o.twist.twist for o in self.odom
                  if self.arc_start + 0.7 <= o.header.stamp.to_sec() <= self.arc_start + ARC_SECONDS]
        self.assertGreater(len(steady), 20)
        for twist in steady:
            self.assertAlmostEqual(twist.angular.z, ARC[1], delta=0.05 * abs(ARC[1]))
            self.assertAlmostEqual(twist.linear.x, ARC[0], delta=0.05 * ARC[0])

    def test_frame_ids_have_no_leading_slash(self):
        for o in self.odom[:: max(1, len(self.odom) // 20)]:
            self.assertEqual((o.header.frame_id, o.child_frame_id), ('odom', 'base_footprint'))
        for t in list(self.truth_by_stamp.values())[:20]:
            self.assertEqual((t.header.frame_id, t.child_frame_id), ('odom', 'base_footprint'))

    def test_covariance_diagonals_are_non_zero(self):
        for o in (self.odom[0], self.odom[-1]):
            for name, covariance in (('pose', o.pose.covariance), ('twist', o.twist.covariance)):
                diagonal = [covariance[i * 7] for i in range(6)]
                self.assertTrue(all(value > 0.0 for value in diagonal),
                                '%s covariance diagonal %s' % (name, diagonal))


if __name__ == '__main__':
    init_test_node('test_odom_matches_ground_truth')
    rostest.rosrun('tb3_sim_nav', 'odom_matches_ground_truth', OdomMatchesGroundTruth)
