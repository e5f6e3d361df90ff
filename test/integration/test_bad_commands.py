#!/usr/bin/env python3
"""Bad /cmd_vel input: a clear, throttled warning, never a crash or a NaN.

In order, on one simulator:
1. one Twist with NaN in linear.x gets a warning on /rosout from /tb3_sim;
   a burst of 1000 bad Twists in 1 s (each different, so that a throttle keyed
   on the text would not help) gets at most a handful more;
2. from a drive, NaN in linear.x, inf in angular.z, NaN in linear.y alone:
   each stops the robot, and /odom keeps flowing;
3. linear.x 5.0, angular.z -30 is clamped: the robot follows 0.22 m/s and
   -2.84 rad/s and never exceeds them by more than 5 %.
Throughout: no non-finite number in /odom or /tf, and the ground-truth speeds
stay within the limits. The sequence runs once (setUpClass); each test method
checks one promise.
"""
import math
import threading
import time
import unittest

import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from tf2_msgs.msg import TFMessage

from tb3_test_utils import (
    GroundTruth,
    all_finite,
    finite_difference_speeds,
    init_test_node,
    report,
    speed,
    wait_for,
    wall_budget,
)

MAX_V, MAX_W = 0.22, 2.84
SLACK = 1.05
BURST = 1000
HANDFUL = 3
DRIVE = (0.15, 0.5)
STOP_WITHIN = 1.0          # sim s from a non-finite command to standing still
STOPPED_SPEED = 0.01       # m/s
STOPPED_YAW_RATE = 0.02    # rad/s
OVERSIZED = (5.0, -30.0)
OVERSIZED_SECONDS = 3.0
SIM_NODE = '/tb3_sim'


def twist(linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
    message = Twist()
    message.linear.x, message.linear.y, message.linear.z = linear
    message.angular.x, message.angular.y, message.angular.z = angular
    return message


NON_FINITE = [
    ('nan_in_linear_x', twist(linear=(math.nan, 0.0, 0.0), angular=(0.0, 0.0, DRIVE[1]))),
    ('inf_in_angular_z', twist(linear=(DRIVE[0], 0.0, 0.0), angular=(0.0, 0.0, math.inf))),
    ('nan_in_linear_y_only', twist(linear=(DRIVE[0], math.nan, 0.0), angular=(0.0, 0.0, DRIVE[1]))),
]


def burst_message(index):
    """Bad Twists that all differ: non-finite ones and oversized ones, alternately."""
    if index % 2:
        return twist(linear=(1.0 + index * 1e-3, 0.0, 0.0), angular=(0.0, 0.0, -10.0 - index * 1e-3))
    return twist(linear=(math.nan, 0.0, 0.0), angular=(0.0, 0.0, index * 1e-3))


class Watch(object):
    """Non-finite numbers in /odom and /tf, odom arrivals, and /tb3_sim's warnings."""

    def __init__(self):
        self.lock = threading.Lock()
        self.odom_stamps = []
        self.bad_odom = []
        self.bad_tf = []
        self.tf_count = 0
        self.warnings = []   # (wall time received, sim stamp, text)
        rospy.Subscriber('/odom', Odometry, self._on_odom, queue_size=None)
        rospy.Subscriber('/tf', TFMessage, self._on_tf, queue_size=None)
        rospy.Subscriber('/rosout', Log, self._on_log, queue_size=None)

    def _on_odom(self, message):
        with self.lock:
            self.odom_stamps.append(message.header.stamp.to_sec())
            if not all_finite(message):
                self.bad_odom.append(message)

    def _on_tf(self, message):
        with self.lock:
            self.tf_count += 1
            if not all_finite(message):
                self.bad_tf.append(message)

    def _on_log(self, message):
        if message.name == SIM_NODE and message.level == Log.WARN:
            with self.lock:
                self.warnings.append((time.monotonic(), message.header.stamp.to_sec(), message.msg))

    def last_odom(self):
        with self.lock:
            return self.odom_stamps[-1] if self.odom_stamps else -math.inf

    def warnings_since(self, wall_time):
        with self.lock:
            return [w for w in self.warnings if w[0] >= wall_time]


class BadCommands(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.watch = Watch()
        cls.truth = GroundTruth()
        cls.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=BURST)
        cls.results = {}
        cls.setup_error = None
        try:
            cls._run()
        except Exception as error:
            cls.setup_error = '%s: %s' % (type(error).__name__, error)
        finally:
            cls.cmd_vel.publish(Twist())
        cls.end_sim_time = cls.truth.now()

    @classmethod
    def _run(cls):
        truth, watch = cls.truth, cls.watch
        if not truth.wait_first(60.0):
            raise AssertionError('no base_pose_ground_truth within 60 s')
        if not wait_for(lambda: cls.cmd_vel.get_num_connections() > 0, 30.0):
            raise AssertionError('the simulator never subscribed to /cmd_vel')
        if not wait_for(lambda: rospy.get_published_topics() and
                        any(t == '/rosout' for t, _ in rospy.get_published_topics()), 10.0):
            raise AssertionError('/rosout is not published')
        if truth.wait_at_rest(timeout=30.0) is None:
            raise AssertionError('the robot did not come to rest after spawning')

        # 1. One NaN: a warning. Then 1000 different bad Twists in 1 s: a handful at most.
        cls.burst_start_wall = time.monotonic()
        cls.cmd_vel.publish(NON_FINITE[0][1])
        cls.first_warning = wait_for(lambda: watch.warnings_since(cls.burst_start_wall), 15.0)
        start = time.monotonic()
        for index in range(1, BURST):
            cls.cmd_vel.publish(burst_message(index))
            # Pace the burst over 1 s of wall time.
            delay = start + index / float(BURST) - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        cls.burst_wall_seconds = time.monotonic() - start
        cls.cmd_vel.publish(NON_FINITE[0][1])  # end the burst stopped
        cls.burst_end_sim = rospy.get_time()
        truth.wait_until(cls.burst_end_sim + 2.0, wall_budget(2.0))  # let late warnings arrive
        time.sleep(1.0)  # and 1 wall s more: /rosout has no end to wait for
        cls.burst_warnings = watch.warnings_since(cls.burst_start_wall)
        cls.burst_odom_alive = watch.last_odom() > cls.burst_end_sim + 1.0

        # 2. Each non-finite command stops a moving robot.
        for name, bad in NON_FINITE:
            cls.results[name] = cls._stop_on(name, bad)

        # 3. An oversized command is clamped.
        cls.cmd_vel.publish(twist(linear=(OVERSIZED[0], 0.0, 0.0), angular=(0.0, 0.0, OVERSIZED[1])))
        cls.oversized_start = rospy.get_time()
        if not truth.wait_until(cls.oversized_start + OVERSIZED_SECONDS, wall_budget(OVERSIZED_SECONDS)):
            raise AssertionError('ground truth stopped during the oversized command')
        cls.cmd_vel.publish(Twist())
        if truth.wait_at_rest(window=0.3, timeout=wall_budget(3.0)) is None:
            raise AssertionError('did not stop after the oversized command')
        cls.alive_at_end = rosnode.rosnode_ping(SIM_NODE, max_count=1)

    @classmethod
    def _stop_on(cls, name, bad):
        truth, watch = cls.truth, cls.watch
        cls.cmd_vel.publish(twist(linear=(DRIVE[0], 0.0, 0.0), angular=(0.0, 0.0, DRIVE[1])))
        moving = wait_for(lambda: speed(truth.latest()) > 0.9 * DRIVE[0], wall_budget(3.0))
        if not moving:
            raise AssertionError('%s: the robot did not start driving before the bad command' % name)
        truth.wait_sim(0.5)
        speed_before = speed(truth.latest())
        cls.cmd_vel.publish(bad)
        t_bad = rospy.get_time()
        truth.wait_until(t_bad + STOP_WITHIN + 1.0, wall_budget(STOP_WITHIN + 1.0))
        after = truth.samples(start=t_bad + STOP_WITHIN, end=t_bad + STOP_WITHIN + 1.0)
        stopped = bool(after) and all(speed(s) < STOPPED_SPEED and abs(s.wz) < STOPPED_YAW_RATE
                                      for s in after)
        drift = math.hypot(after[-1].x - after[0].x, after[-1].y - after[0].y) if after else math.nan
        result = dict(speed_before=speed_before, stopped=stopped, drift_m=drift,
                      max_speed_after=max((speed(s) for s in after), default=math.nan),
                      odom_alive=watch.last_odom() > t_bad + STOP_WITHIN)
        report(name, **result)
        return result

    def setUp(self):
        if self.setup_error:
            self.fail('the bad-command sequence failed: ' + self.setup_error)

    def test_nan_gets_a_warning_on_rosout_from_tb3_sim(self):
        self.assertTrue(self.first_warning, 'no warning from %s on /rosout within 15 s of a NaN '
                        'command' % SIM_NODE)
        text = self.first_warning[0][2]
        self.assertIn('non-finite', text.lower(), 'the warning does not say what is wrong: %r' % text)

    def test_burst_of_1000_bad_commands_in_1s_gives_at_most_a_handful_of_warnings(self):
        report('burst', messages=BURST, wall_seconds=self.burst_wall_seconds,
               warnings=len(self.burst_warnings))
        self.assertLess(self.burst_wall_seconds, 1.5, 'set-up: the burst took too long')
        self.assertLessEqual(len(self.burst_warnings), HANDFUL, 'warnings: %s'
                             % [w[2][:80] for w in self.burst_warnings[:10]])
        self.assertTrue(self.burst_odom_alive, '/odom stopped during the burst')

    def check_stops(self, name):
        result = self.results[name]
        self.assertGreater(result['speed_before'], 0.9 * DRIVE[0], 'set-up: robot not driving')
        self.assertTrue(result['stopped'], '%s did not stop the robot within %.1f s: %s'
                        % (name, STOP_WITHIN, result))
        self.assertLess(result['drift_m'], 0.002, result)
        self.assertTrue(result['odom_alive'], '/odom stopped after %s' % name)

    def test_nan_in_linear_x_stops_the_robot(self):
        self.check_stops('nan_in_linear_x')

    def test_inf_in_angular_z_stops_the_robot(self):
        self.check_stops('inf_in_angular_z')

    def test_nan_in_linear_y_alone_stops_the_robot(self):
        self.check_stops('nan_in_linear_y_only')

    def test_oversized_command_is_followed_at_the_limits(self):
        steady = self.truth.samples(start=self.oversized_start + 1.0,
                                    end=self.oversized_start + OVERSIZED_SECONDS)
        self.assertGreater(len(steady), 30)
        v = sum(s.vx for s in steady) / len(steady)
        w = sum(s.wz for s in steady) / len(steady)
        report('oversized_steady', linear_x=v, angular_z=w)
        self.assertAlmostEqual(v, MAX_V, delta=0.1 * MAX_V, msg='linear.x 5.0 should give 0.22 m/s')
        self.assertAlmostEqual(w, -MAX_W, delta=0.1 * MAX_W, msg='angular.z -30 should give -2.84 rad/s')

    def test_ground_truth_speeds_never_exceed_the_limits_by_5_percent(self):
        samples = self.truth.samples(end=self.end_sim_time)
        self.assertGreater(len(samples), 300)
        twist_v = max(speed(s) for s in samples)
        twist_w = max(abs(s.wz) for s in samples)
        motion = finite_difference_speeds(samples)
        motion_v = max(v for _, v, _ in motion)
        motion_w = max(abs(w) for _, _, w in motion)
        report('max_ground_truth_speeds', twist_v=twist_v, twist_w=twist_w,
               from_poses_v=motion_v, from_poses_w=motion_w)
        self.assertLessEqual(twist_v, MAX_V * SLACK)
        self.assertLessEqual(twist_w, MAX_W * SLACK)
        self.assertLessEqual(motion_v, MAX_V * SLACK)
        self.assertLessEqual(motion_w, MAX_W * SLACK)

    def test_no_non_finite_number_in_odom_or_tf(self):
        with self.watch.lock:
            odom, tf, bad_odom, bad_tf = (len(self.watch.odom_stamps), self.watch.tf_count,
                                          list(self.watch.bad_odom), list(self.watch.bad_tf))
        self.assertGreater(odom, 300)
        self.assertGreater(tf, 300)
        self.assertEqual(len(bad_odom), 0, 'non-finite /odom: %s' % bad_odom[:1])
        self.assertEqual(len(bad_tf), 0, 'non-finite /tf: %s' % bad_tf[:1])

    def test_simulator_stays_up(self):
        self.assertTrue(self.alive_at_end, '%s does not answer a ping' % SIM_NODE)
        self.assertGreater(self.watch.last_odom(), self.end_sim_time - 0.5, '/odom stopped')


if __name__ == '__main__':
    init_test_node('test_bad_commands')
    rostest.rosrun('tb3_sim_nav', 'bad_commands', BadCommands)
