#!/usr/bin/env python3
"""rosrun tb3_sim_nav odom_out_and_back.py, as the tutorial runs it, judged by ground truth.

Closed loop on tf odom->base_footprint: out 1 m at 0.15 m/s, turn pi at
0.5 rad/s, back, turn again. With odometry that does not drift it must end
within 5 cm and 5 deg of where it started, after driving about 1 m ahead.
"""
import rostest

from script_test_case import ScriptTestCase
from tb3_test_utils import init_test_node


class OdomOutAndBack(ScriptTestCase):
    script = 'odom_out_and_back.py'
    script_sim_seconds = 35.0

    def test_script_exits_with_code_0(self):
        self.check_exit_code_0()

    def test_drives_about_1m_straight_ahead_and_back(self):
        self.check_out_and_back_path()

    def test_turns_360deg_left_in_all(self):
        self.check_total_turn(360.0, 10.0)

    def test_ends_within_5cm_and_5deg_of_start(self):
        self.check_back_at_start(0.05, 5.0)


if __name__ == '__main__':
    init_test_node('test_odom_out_and_back')
    rostest.rosrun('tb3_sim_nav', 'odom_out_and_back', OdomOutAndBack)
