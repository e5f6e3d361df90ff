#!/usr/bin/env python3
"""The tutorial's two rostopic commands, verbatim, judged by ground truth.

1. `rostopic pub -r 10 /cmd_vel geometry_msgs/Twist '{linear: {x: 0.1, ...},
   angular: {..., z: -0.5}}'` drives a clockwise circle of radius
   0.1 / 0.5 = 0.2 m (one turn in 4 pi = 12.6 s).
2. Ctrl+C on that rostopic: the robot keeps following the last command.
3. `rostopic pub -1 /cmd_vel geometry_msgs/Twist '{}'` stops it within 0.5 s
   (sim) of the empty Twist's arrival.

The steps build on each other, so they run in order in one test method.
"""
import math
import signal
import threading
import unittest

import numpy
import rospy
import rostest
from geometry_msgs.msg import Twist

from tb3_test_utils import (
    Child,
    GroundTruth,
    in_frame_of,
    init_test_node,
    report,
    speed,
    unwrapped_turn,
    wait_for,
    wall_budget,
)

CIRCLE_COMMAND = ['rostopic', 'pub', '-r', '10', '/cmd_vel', 'geometry_msgs/Twist',
                  '{linear: {x: 0.1, y: 0, z: 0}, angular: {x: 0, y: 0, z: -0.5}}']
STOP_COMMAND = ['rostopic', 'pub', '-1', '/cmd_vel', 'geometry_msgs/Twist', '{}']
V, W = 0.1, -0.5
RADIUS = abs(V / W)
PERIOD = 2.0 * math.pi / abs(W)
CIRCLE_SECONDS = 14.0     # sim s of circling: a bit more than one turn
SETTLE = 1.0              # sim s at the start of the circle left out of the fit
COAST_SECONDS = 2.0       # after Ctrl+C the robot must keep going at least this long
STOP_DELAY = 0.5          # sim s from the empty Twist's arrival to standing still
STOPPED_SPEED = 0.01      # m/s
STOPPED_YAW_RATE = 0.02   # rad/s


def fit_circle(points):
    """Least-squares circle through (x, y) points: centre, radius, RMS residual."""
    xy = numpy.asarray(points)
    x, y = xy[:, 0], xy[:, 1]
    # x^2 + y^2 = 2 a x + 2 b y + c, linear in a, b, c (Kasa's fit).
    design = numpy.column_stack((2 * x, 2 * y, numpy.ones_like(x)))
    (a, b, c), _, _, _ = numpy.linalg.lstsq(design, x * x + y * y, rcond=None)
    radius = math.sqrt(c + a * a + b * b)
    residual = numpy.sqrt(numpy.mean((numpy.hypot(x - a, y - b) - radius) ** 2))
    return (a, b), radius, float(residual)


class CmdVelRecorder(object):
    """Every /cmd_vel message with the sim time it arrived here."""

    def __init__(self):
        self._lock = threading.Lock()
        self.arrivals = []
        self._sub = rospy.Subscriber('/cmd_vel', Twist, self._on_twist, queue_size=None)

    def _on_twist(self, twist):
        with self._lock:
            self.arrivals.append((rospy.get_time(), twist))

    def since(self, sim_time=-math.inf):
        with self._lock:
            return [(t, m) for t, m in self.arrivals if t >= sim_time]

    def first(self, predicate, since=-math.inf):
        for t, message in self.since(since):
            if predicate(message):
                return t
        return None


def is_empty(twist):
    return all(value == 0.0 for value in (twist.linear.x, twist.linear.y, twist.linear.z,
                                          twist.angular.x, twist.angular.y, twist.angular.z))


def is_circle_command(twist):
    return twist.linear.x == V and twist.angular.z == W


class TutorialCmdVel(unittest.TestCase):

    def setUp(self):
        self.truth = GroundTruth()
        self.cmd_vel = CmdVelRecorder()
        self.assertTrue(self.truth.wait_first(60.0), 'no base_pose_ground_truth within 60 s')
        self.start = self.truth.wait_at_rest(timeout=30.0)
        self.assertIsNotNone(self.start, 'the robot did not come to rest after spawning')

    def test_circle_then_ctrl_c_keeps_last_command_then_empty_twist_stops_within_half_a_second(self):
        truth, cmd_vel = self.truth, self.cmd_vel

        # --- 1. rostopic pub -r 10: a clockwise circle of radius 0.2 m ----------
        circling = Child(CIRCLE_COMMAND)
        self.addCleanup(circling.stop)
        self.assertTrue(wait_for(lambda: cmd_vel.first(is_circle_command) is not None, 30.0),
                        'the circle command never arrived on /cmd_vel; ' + circling.describe())
        t_first = cmd_vel.first(is_circle_command)
        self.assertTrue(truth.wait_until(t_first + CIRCLE_SECONDS, wall_budget(CIRCLE_SECONDS)),
                        'ground truth stopped before %.0f s of circling' % CIRCLE_SECONDS)
        self.assertTrue(circling.running(), 'rostopic pub -r 10 exited on its own; '
                        + circling.describe())
        circle = truth.samples(start=t_first + SETTLE, end=t_first + CIRCLE_SECONDS)
        local = [in_frame_of(self.start, s) for s in circle]
        (cx, cy), radius, residual = fit_circle(local)
        turn = unwrapped_turn(truth.samples(start=t_first, end=t_first + CIRCLE_SECONDS))
        steady_rate = unwrapped_turn(circle) / (circle[-1].t - circle[0].t)
        report('circle', radius_m=radius, centre_in_start_frame='(%.4f, %.4f)' % (cx, cy),
               rms_residual_m=residual, turn_deg=math.degrees(turn), yaw_rate=steady_rate,
               samples=len(circle))
        self.assertAlmostEqual(radius, RADIUS, delta=0.1 * RADIUS,
                               msg='circle radius %.4f m, expected %.2f m +- 10 %%' % (radius, RADIUS))
        self.assertLess(residual, 0.1 * RADIUS, 'the path is no circle: RMS residual %.4f m' % residual)
        # Clockwise from a start heading along +x: the centre lies to the right (-y).
        self.assertLess(math.hypot(cx - 0.0, cy + RADIUS), 0.05,
                        'circle centre (%.3f, %.3f) in the start frame, expected (0, -0.2): '
                        'not a clockwise circle from the start' % (cx, cy))
        self.assertLess(turn, -2.0 * math.pi,
                        'turned %.0f deg in %.0f s; a full clockwise circle is -360 deg'
                        % (math.degrees(turn), CIRCLE_SECONDS))
        self.assertAlmostEqual(steady_rate, W, delta=0.1 * abs(W),
                               msg='yaw rate %.3f rad/s, commanded %.1f' % (steady_rate, W))

        # --- 2. Ctrl+C: the last command holds ---------------------------------
        circling.signal_group(signal.SIGINT)
        exit_code = circling.wait(10.0)
        self.assertIsNotNone(exit_code, 'rostopic pub ignored Ctrl+C (SIGINT) for 10 s')
        t_interrupted = rospy.get_time()
        last_arrival = cmd_vel.since()[-1][0]
        self.assertTrue(truth.wait_until(t_interrupted + COAST_SECONDS + 0.5,
                                         wall_budget(COAST_SECONDS + 0.5)),
                        'ground truth stopped after Ctrl+C')
        self.assertEqual(len(cmd_vel.since(last_arrival + 1e-9)), 0,
                         'something published on /cmd_vel after rostopic was interrupted')
        coast = truth.samples(start=t_interrupted, end=t_interrupted + COAST_SECONDS)
        self.assertGreater(len(coast), 0.8 * 30 * COAST_SECONDS, 'too few ground-truth samples')
        slowest = min(speed(s) for s in coast)
        weakest_turn = max(s.wz for s in coast)  # W is negative: the largest is the weakest
        report('after_ctrl_c', seconds=coast[-1].t - coast[0].t, min_speed=slowest,
               weakest_yaw_rate=weakest_turn, exit_code=exit_code)
        self.assertGreater(slowest, 0.9 * V, 'the robot slowed to %.3f m/s within %.0f s of '
                           'Ctrl+C: the last command did not hold' % (slowest, COAST_SECONDS))
        self.assertLess(weakest_turn, 0.9 * W, 'the yaw rate fell to %.3f rad/s within %.0f s of '
                        'Ctrl+C: the last command did not hold' % (weakest_turn, COAST_SECONDS))

        # --- 3. rostopic pub -1 '{}': stop within 0.5 s --------------------------
        stopping = Child(STOP_COMMAND)
        self.addCleanup(stopping.stop)
        self.assertTrue(wait_for(lambda: cmd_vel.first(is_empty, last_arrival + 1e-9) is not None,
                                 30.0), 'the empty Twist never arrived; ' + stopping.describe())
        t_empty = cmd_vel.first(is_empty, last_arrival + 1e-9)
        self.assertTrue(truth.wait_until(t_empty + 2.0, wall_budget(2.0)),
                        'ground truth stopped after the empty Twist')
        self.assertEqual(stopping.wait(30.0), 0, 'rostopic pub -1 failed; ' + stopping.describe())
        after = truth.samples(start=t_empty - 0.1, end=t_empty + 2.0)

        def stopped(s):
            return speed(s) < STOPPED_SPEED and abs(s.wz) < STOPPED_YAW_RATE
        # The first instant from which the robot stays stopped.
        t_stopped = None
        for index, sample in enumerate(after):
            if all(stopped(s) for s in after[index:]):
                t_stopped = sample.t
                break
        self.assertIsNotNone(t_stopped, 'still moving 2 s after the empty Twist: '
                             'speed %.3f m/s' % speed(after[-1]))
        delay = t_stopped - t_empty
        rest = truth.samples(start=t_empty + STOP_DELAY, end=t_empty + 2.0)
        drift = math.hypot(rest[-1].x - rest[0].x, rest[-1].y - rest[0].y)
        report('stop', delay_s=delay, drift_after_stop_m=drift,
               speed_at_arrival=speed(after[0]))
        self.assertGreater(speed(after[0]), 0.9 * V, 'the robot was not moving when the empty '
                           'Twist arrived, so its stop proves nothing')
        self.assertLessEqual(delay, STOP_DELAY, 'the robot took %.3f s (sim) to stop, more than '
                             '%.1f s' % (delay, STOP_DELAY))
        self.assertLess(drift, 0.002, 'moved %.4f m over the 1.5 s after stopping' % drift)


if __name__ == '__main__':
    init_test_node('test_tutorial_cmd_vel')
    rostest.rosrun('tb3_sim_nav', 'tutorial_cmd_vel', TutorialCmdVel)
