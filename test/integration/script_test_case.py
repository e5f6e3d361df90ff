"""A base TestCase that runs one tutorial script with rosrun, exactly as the
user does, and measures its path and end pose against ground truth.

The script runs once (setUpClass); each test method asserts one thing about
that run, so a failure says which promise was broken.
"""
import math
import unittest

import rospy

from tb3_test_utils import Child, GroundTruth, in_frame_of, report, unwrapped_turn, wall_budget, wrap


class ScriptTestCase(unittest.TestCase):
    script = None            # the file name the user gives rosrun
    script_sim_seconds = None  # about how long the script drives (sim s)

    @classmethod
    def setUpClass(cls):
        cls.truth = GroundTruth()
        cls.setup_error = None
        cls.child = None
        try:
            cls._run_script()
        except Exception as error:  # reported by every test, with its cause
            cls.setup_error = '%s: %s' % (type(error).__name__, error)
        finally:
            if cls.child is not None:
                cls.child.stop()

    @classmethod
    def _run_script(cls):
        if not cls.truth.wait_first(timeout=60.0):
            raise AssertionError('no %s within 60 s' % 'base_pose_ground_truth')
        cls.start = cls.truth.wait_at_rest(timeout=30.0)
        if cls.start is None:
            raise AssertionError('the robot did not come to rest after spawning')
        cls.child = Child(['rosrun', 'tb3_sim_nav', cls.script])
        budget = wall_budget(cls.script_sim_seconds)
        cls.exit_code = cls.child.wait(budget)
        cls.output = cls.child.output()
        if rospy.is_shutdown():
            raise AssertionError('the test node was shut down (time limit?) while %s ran; %s'
                                 % (cls.script, cls.child.describe()))
        if cls.exit_code is None:
            raise AssertionError('%s still running after %.0f wall s; %s'
                                 % (cls.script, budget, cls.child.describe()))
        # The script stops the robot before it exits: it must already be at rest.
        cls.end = cls.truth.wait_at_rest(window=0.5, timeout=wall_budget(3.0))
        if cls.end is None:
            raise AssertionError('the robot was still moving 3 s (sim) after %s exited' % cls.script)
        cls.path = cls.truth.samples(start=cls.start.t, end=cls.end.t)
        cls.position_error = math.hypot(cls.end.x - cls.start.x, cls.end.y - cls.start.y)
        cls.heading_error = math.degrees(abs(wrap(cls.end.yaw - cls.start.yaw)))
        local = [in_frame_of(cls.start, sample) for sample in cls.path]
        cls.local_path = local
        cls.max_excursion = max(math.hypot(x, y) for x, y in local)
        cls.bounding_box = (min(x for x, _ in local), max(x for x, _ in local),
                            min(y for _, y in local), max(y for _, y in local))
        cls.total_turn = math.degrees(unwrapped_turn(cls.path))
        report(cls.script, exit_code=cls.exit_code, sim_seconds=cls.end.t - cls.start.t,
               position_error_m=cls.position_error, heading_error_deg=cls.heading_error,
               max_excursion_m=cls.max_excursion, total_turn_deg=cls.total_turn,
               bbox='x[%.3f, %.3f] y[%.3f, %.3f]' % cls.bounding_box)

    def setUp(self):
        if self.setup_error:
            self.fail('running %s failed: %s' % (self.script, self.setup_error))

    # --- assertions shared by the three scripts --------------------------------
    def check_exit_code_0(self):
        self.assertEqual(self.exit_code, 0, 'rosrun tb3_sim_nav %s exited with %r; output:\n%s'
                         % (self.script, self.exit_code, self.output))

    def check_back_at_start(self, position_tolerance, heading_tolerance_deg):
        self.assertLessEqual(self.position_error, position_tolerance,
                             'ended %.3f m from its start (tolerance %.3f m)'
                             % (self.position_error, position_tolerance))
        self.assertLessEqual(self.heading_error, heading_tolerance_deg,
                             'ended heading %.2f deg off its start (tolerance %.1f deg)'
                             % (self.heading_error, heading_tolerance_deg))

    def check_total_turn(self, expected_deg, tolerance_deg):
        self.assertAlmostEqual(self.total_turn, expected_deg, delta=tolerance_deg,
                               msg='turned %.1f deg in all, expected %.0f' % (self.total_turn, expected_deg))

    def check_out_and_back_path(self):
        """Out 1 m straight ahead and back: a robot that never moved cannot pass."""
        self.assertGreaterEqual(self.max_excursion, 0.9,
                                'went at most %.3f m from its start, expected about 1 m'
                                % self.max_excursion)
        far_x, far_y = max(self.local_path, key=lambda p: math.hypot(*p))
        self.assertGreater(far_x, 0.85, 'the farthest point (%.3f, %.3f) in the start frame is '
                           'not straight ahead' % (far_x, far_y))
        self.assertLess(abs(far_y), 0.15, 'the farthest point (%.3f, %.3f) in the start frame is '
                        'off to the side' % (far_x, far_y))
