#!/usr/bin/env python3
"""rosrun tb3_sim_nav nav_square.py, as the tutorial runs it, judged by ground truth.

Closed loop on tf: four 1 m sides, each followed by a 90 deg left turn. The
path must span a 1 m x 1 m square ahead and to the left of the start, the
robot must turn 360 deg in all and end within 15 cm and 10 deg of its start.
"""
import rostest

from script_test_case import ScriptTestCase
from tb3_test_utils import init_test_node

SIDE = 1.0
SIDE_TOLERANCE = 0.1


class NavSquare(ScriptTestCase):
    script = 'nav_square.py'
    script_sim_seconds = 50.0

    def test_script_exits_with_code_0(self):
        self.check_exit_code_0()

    def test_path_spans_1m_by_1m_square_ahead_and_to_the_left(self):
        x_min, x_max, y_min, y_max = self.bounding_box
        box = 'bounding box in the start frame x[%.3f, %.3f] y[%.3f, %.3f]' % self.bounding_box
        self.assertAlmostEqual(x_max - x_min, SIDE, delta=SIDE_TOLERANCE, msg=box)
        self.assertAlmostEqual(y_max - y_min, SIDE, delta=SIDE_TOLERANCE, msg=box)
        # Left turns: the square lies ahead (x >= 0) and to the left (y >= 0).
        self.assertGreater(x_min, -SIDE_TOLERANCE, box)
        self.assertGreater(y_min, -SIDE_TOLERANCE, box)

    def test_visits_the_far_corner(self):
        # The corner diagonally opposite the start, at (1, 1) in the start frame.
        nearest = min(((x - SIDE) ** 2 + (y - SIDE) ** 2) ** 0.5 for x, y in self.local_path)
        self.assertLess(nearest, 0.15, 'passed %.3f m from the far corner (1, 1)' % nearest)

    def test_turns_360deg_left_in_all(self):
        self.check_total_turn(360.0, 20.0)

    def test_ends_within_15cm_and_10deg_of_start(self):
        self.check_back_at_start(0.15, 10.0)


if __name__ == '__main__':
    init_test_node('test_nav_square')
    rostest.rosrun('tb3_sim_nav', 'nav_square', NavSquare)
