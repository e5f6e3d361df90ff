#!/usr/bin/env python3
"""What hztest cannot check: the rate of one transform inside /tf, and /clock itself.

- tf odom->base_footprint comes at 30 Hz +- 10 % of sim time: counted by
  header stamp over a sim-time window (robot_state_publisher shares /tf, so
  hztest on /tf would count its wheel transforms too);
- /clock never goes backwards and never publishes zero;
- /clock is fine-grained: at least 95 % of its messages advance exactly one
  physics step (1/100 s), so that a 50 Hz rospy.Rate (timed_out_and_back.py)
  keeps its rate in sim time. (A rospy publisher drops messages when its
  queue overflows on a loaded machine, so the odd larger step is allowed;
  the largest is reported.)
"""
import math
import threading
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from tb3_test_utils import init_test_node, report, wait_for, wall_budget

WINDOW = 10.0  # sim s


class TfRateAndClock(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.lock = threading.Lock()
        cls.clock = []
        cls.tf_stamps = []
        rospy.Subscriber('/clock', Clock, cls._on_clock, queue_size=None)
        rospy.Subscriber('/tf', TFMessage, cls._on_tf, queue_size=None)
        cls.setup_error = None
        if not wait_for(lambda: cls.tf_stamps and cls.clock, 60.0):
            cls.setup_error = 'no /tf odom->base_footprint or no /clock within 60 s'
            return
        # Start the window a little after the first stamp (the publisher may still be connecting).
        cls.window_start = cls.tf_stamps[0] + 1.0
        cls.window_end = cls.window_start + WINDOW
        if not wait_for(lambda: cls.tf_stamps[-1] >= cls.window_end + 0.5,
                        wall_budget(WINDOW + 1.5)):
            cls.setup_error = 'tf odom->base_footprint stopped before the end of the window'

    @classmethod
    def _on_clock(cls, message):
        with cls.lock:
            cls.clock.append(message.clock)

    @classmethod
    def _on_tf(cls, message):
        stamps = [t.header.stamp.to_sec() for t in message.transforms
                  if t.header.frame_id.lstrip('/') == 'odom'
                  and t.child_frame_id.lstrip('/') == 'base_footprint']
        with cls.lock:
            cls.tf_stamps.extend(stamps)

    def setUp(self):
        if self.setup_error:
            self.fail(self.setup_error)
        with self.lock:
            self.clock_values = list(self.clock)
            self.stamps = list(self.tf_stamps)

    def test_tf_odom_to_base_footprint_at_30hz_within_10_percent_of_sim_time(self):
        in_window = [t for t in self.stamps if self.window_start <= t < self.window_end]
        rate = len(in_window) / WINDOW
        duplicates = len(in_window) - len(set(in_window))
        report('tf_odom_base_footprint', rate_hz=rate, messages=len(in_window),
               window_s=WINDOW, duplicate_stamps=duplicates)
        self.assertAlmostEqual(rate, 30.0, delta=3.0)
        self.assertEqual(duplicates, 0, 'the same transform stamp published more than once')

    def test_clock_never_goes_backwards(self):
        backwards = [(a.to_sec(), b.to_sec()) for a, b in zip(self.clock_values, self.clock_values[1:])
                     if b < a]
        self.assertGreater(len(self.clock_values), 500)
        self.assertEqual(backwards, [], '/clock went backwards')

    def test_clock_never_publishes_zero(self):
        zeros = sum(1 for c in self.clock_values if c.is_zero())
        self.assertEqual(zeros, 0, '/clock published zero %d times' % zeros)

    def test_clock_advances_one_physics_step_per_message(self):
        step = 1.0 / 100
        steps = [(b - a).to_sec() for a, b in zip(self.clock_values, self.clock_values[1:])]
        other = [s for s in steps if not math.isclose(s, step, abs_tol=1e-6)]
        report('clock', messages=len(self.clock_values), min_step_s=min(steps),
               max_step_s=max(steps), steps_not_one_step=len(other))
        self.assertLessEqual(len(other), 0.05 * len(steps),
                             '%d of %d /clock steps are not one physics step (%g s): %s'
                             % (len(other), len(steps), step, other[:10]))


if __name__ == '__main__':
    init_test_node('test_tf_rate_and_clock')
    rostest.rosrun('tb3_sim_nav', 'tf_rate_and_clock', TfRateAndClock)
