#!/usr/bin/env python3
"""Gazebo's /gazebo/reset_world and /gazebo/reset_simulation, judged by ground truth.

On one simulator (tb3_empty_world.launch, spawn (0, 0), yaw 0), in order:
1. reset_world while the robot drives an arc: ground truth back at the spawn
   pose (1 cm, 1 deg) and at rest, odom back at the spawn pose too, and /clock
   runs on: it never goes back;
2. reset_simulation while the robot drives: /clock jumps back to near zero and
   then increases again, ground truth is at the spawn pose and at rest, and a
   tf2_ros.TransformListener and a tf.TransformListener made before the jump
   give odom -> base_footprint again, with post-jump stamps, within a few
   seconds (they must clear their buffers on the jump);
3. reset_simulation, and once time has run on a step, again (a learning
   agent's set-up, then its first episode), and at once `rosrun tb3_sim_nav
   odom_out_and_back.py`: after each reset a scan comes at the first step, as
   after a start; the script drives 1 m out and back and ends within 5 cm and
   5 deg of where it started.
Each phase (reset_phases.py) runs once (setUpClass); each test method checks one promise of one
phase, and says so if its phase could not run.
"""
import math

import rospy
import rostest
import tf
import tf2_ros
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from reset_phases import (
    AFTER_RESET,
    FIRST_STEP,
    HEADING_TOLERANCE,
    NEAR_ZERO,
    POSITION_TOLERANCE,
    STOPPED_SPEED,
    TF_WITHIN,
    Recorder,
    ResetPhases,
    odom_sample,
    off_spawn,
)
from script_test_case import ScriptTestCase
from tb3_test_utils import GroundTruth, init_test_node, report, speed


class Resets(ResetPhases, ScriptTestCase):
    script = 'odom_out_and_back.py'
    script_sim_seconds = 35.0

    @classmethod
    def setUpClass(cls):
        cls.truth_all = GroundTruth()
        cls.odom = Recorder('/odom', Odometry, odom_sample)
        cls.clock = Recorder('/clock', Clock, lambda message: message.clock.to_sec())
        cls.scan = Recorder('/scan', LaserScan, lambda message: message.header.stamp.to_sec())
        # Made before any reset: they must cope with the jump of sim time.
        cls.tf2_buffer = tf2_ros.Buffer()
        cls.tf2_listener = tf2_ros.TransformListener(cls.tf2_buffer)
        cls.tf_listener = tf.TransformListener()
        cls.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=10)
        cls.errors = {}
        cls.child = None
        for phase in ('reset_world', 'reset_simulation', 'script'):
            try:
                getattr(cls, '_phase_' + phase)()
            except Exception as error:  # reported by the phase's tests, with its cause
                cls.errors[phase] = '%s: %s' % (type(error).__name__, error)
            finally:
                cls.cmd_vel.publish(Twist())
                if cls.child is not None:
                    cls.child.stop()
            if rospy.is_shutdown():
                break

    def setUp(self):
        pass  # each test checks its own phase (need)

    # --- 1. reset_world --------------------------------------------------------------
    def test_reset_world_puts_ground_truth_back_at_spawn(self):
        self.need('reset_world')
        driven = off_spawn(self.world_driven)
        worst = max((off_spawn(s) for s in self.world_after), key=lambda e: e[0])
        worst_heading = max(off_spawn(s)[1] for s in self.world_after)
        report('reset_world_ground_truth', driven_off_m=driven[0], driven_off_deg=driven[1],
               worst_after_m=worst[0], worst_after_deg=worst_heading, samples=len(self.world_after))
        self.assertGreater(driven[0], 0.2, 'set-up: the robot did not drive away before the reset')
        self.assertGreater(len(self.world_after), 30)
        self.assertLessEqual(worst[0], POSITION_TOLERANCE)
        self.assertLessEqual(worst_heading, HEADING_TOLERANCE)

    def test_reset_world_leaves_the_robot_at_rest(self):
        self.need('reset_world')
        fastest = max(speed(s) for s in self.world_after)
        turning = max(abs(s.wz) for s in self.world_after)
        report('reset_world_rest', max_speed=fastest, max_yaw_rate=turning)
        self.assertLess(fastest, STOPPED_SPEED, 'the drive command survived reset_world')
        self.assertLess(turning, 0.02)

    def test_reset_world_puts_odom_back_at_spawn(self):
        self.need('reset_world')
        self.assertGreater(len(self.world_odom_after), 30)
        worst = max(off_spawn(s)[0] for s in self.world_odom_after)
        worst_heading = max(off_spawn(s)[1] for s in self.world_odom_after)
        report('reset_world_odom', worst_after_m=worst, worst_after_deg=worst_heading)
        self.assertLessEqual(worst, POSITION_TOLERANCE)
        self.assertLessEqual(worst_heading, HEADING_TOLERANCE)

    def test_reset_world_clock_runs_on_never_back(self):
        self.need('reset_world')
        values = self.world_clock
        backwards = [(a, b) for a, b in zip(values, values[1:]) if b < a]
        report('reset_world_clock', first=values[0], last=values[-1], messages=len(values),
               backwards=len(backwards))
        self.assertEqual(backwards, [], '/clock went back on reset_world')
        self.assertGreater(values[-1], self.world_called + AFTER_RESET)

    # --- 2. reset_simulation -----------------------------------------------------------
    def test_reset_simulation_clock_jumps_back_near_zero_then_increases(self):
        self.need('reset_simulation')
        values = self.sim_clock_after
        backwards = [(a, b) for a, b in zip(values, values[1:]) if b < a]
        report('reset_simulation_clock', before=self.sim_before, first_after=self.first_after_jump,
               last=values[-1], messages_after=len(values))
        self.assertLess(self.first_after_jump, NEAR_ZERO)
        self.assertGreater(self.first_after_jump, 0.0, '/clock published zero')
        self.assertEqual(backwards, [], '/clock went back again after the jump')
        self.assertGreater(values[-1], self.first_after_jump + AFTER_RESET)

    def test_reset_simulation_puts_ground_truth_back_at_spawn_at_rest(self):
        self.need('reset_simulation')
        after = self.sim_truth_after
        self.assertGreater(len(after), 30, 'ground truth did not jump back with /clock')
        worst = max(off_spawn(s)[0] for s in after)
        worst_heading = max(off_spawn(s)[1] for s in after)
        fastest = max(speed(s) for s in after)
        report('reset_simulation_ground_truth', first_stamp=after[0].t, worst_m=worst,
               worst_deg=worst_heading, max_speed=fastest)
        self.assertLess(after[0].t, NEAR_ZERO)
        self.assertLessEqual(worst, POSITION_TOLERANCE)
        self.assertLessEqual(worst_heading, HEADING_TOLERANCE)
        self.assertLess(fastest, STOPPED_SPEED)

    def test_reset_simulation_puts_odom_back_at_spawn(self):
        self.need('reset_simulation')
        after = self.sim_odom_after
        self.assertGreater(len(after), 30, 'odom did not jump back with /clock')
        worst = max(off_spawn(s)[0] for s in after)
        self.assertLessEqual(worst, POSITION_TOLERANCE)
        self.assertLessEqual(max(off_spawn(s)[1] for s in after), HEADING_TOLERANCE)

    def check_listener(self, name, seen, later):
        self.need('reset_simulation')
        seconds, answer = seen
        report('%s_after_jump' % name, wall_seconds=seconds, answer=answer, later=later)
        self.assertIsNotNone(seconds, '%s gave no post-jump odom -> base_footprint within %.0f wall s of '
                             'the jump; last answer: %s (sim time before the reset %.2f)'
                             % (name, TF_WITHIN, answer, self.sim_before))
        stamp, x, y = answer
        self.assertLess(math.hypot(x, y), POSITION_TOLERANCE, '%s: odom -> base_footprint at %.2f s is '
                        '(%.3f, %.3f), not the spawn pose' % (name, stamp, x, y))
        # And it keeps up afterwards: its latest transform follows /clock.
        self.assertIsInstance(later, tuple, '%s: no transform %.1f s (sim) after the jump: %s'
                              % (name, AFTER_RESET, later))
        self.assertGreater(later[0], self.first_after_jump + AFTER_RESET - 0.5,
                           '%s: latest odom -> base_footprint is stamped %.2f s, /clock is past %.2f s'
                           % (name, later[0], self.first_after_jump + AFTER_RESET))

    def test_reset_simulation_tf2_ros_listener_recovers_within_5s(self):
        self.check_listener('tf2_ros', self.tf2_seen, self.tf2_later)

    def test_reset_simulation_tf_listener_recovers_within_5s(self):
        self.check_listener('tf', self.tf_seen, self.tf_later)

    # --- 3. odom_out_and_back.py right after reset_simulation ----------------------------
    def test_script_after_reset_simulation_starts_at_spawn(self):
        self.need('script')
        self.assertLess(off_spawn(self.start)[0], POSITION_TOLERANCE)
        self.assertLess(self.start.t, NEAR_ZERO + 1.0, 'the path does not start at the jump')

    def test_a_scan_comes_at_the_first_step_after_each_reset_simulation(self):
        self.need('script')
        self.assertEqual(len(self.first_scans), 2, 'scans stamped before %g s after two resets: %s'
                         % (FIRST_STEP, self.first_scans))

    def test_script_after_reset_simulation_exits_with_code_0(self):
        self.need('script')
        self.check_exit_code_0()

    def test_script_after_reset_simulation_drives_about_1m_out_and_back(self):
        self.need('script')
        self.check_out_and_back_path()

    def test_script_after_reset_simulation_ends_within_5cm_and_5deg_of_start(self):
        self.need('script')
        self.check_back_at_start(0.05, 5.0)

if __name__ == '__main__':
    init_test_node('test_resets')
    rostest.rosrun('tb3_sim_nav', 'resets', Resets)
