#!/usr/bin/env python3
"""rosrun tb3_sim_nav timed_out_and_back.py, as the tutorial runs it, judged by ground truth.

Open loop (timed at 50 Hz in sim time): out 1 m at 0.2 m/s, turn pi at
1 rad/s, back, turn again. It must drive about 1 m straight ahead, turn
about 360 deg in all, and end within 15 cm and 10 deg of where it started.
"""
import rostest

from script_test_case import ScriptTestCase
from tb3_test_utils import init_test_node


class TimedOutAndBack(ScriptTestCase):
    script = 'timed_out_and_back.py'
    script_sim_seconds = 25.0

    def test_script_exits_with_code_0(self):
        self.check_exit_code_0()

    def test_drives_about_1m_straight_ahead_and_back(self):
        self.check_out_and_back_path()

    def test_turns_360deg_left_in_all(self):
        self.check_total_turn(360.0, 20.0)

    def test_ends_within_15cm_and_10deg_of_start(self):
        self.check_back_at_start(0.15, 10.0)


if __name__ == '__main__':
    init_test_node('test_timed_out_and_back')
    rostest.rosrun('tb3_sim_nav', 'timed_out_and_back', TimedOutAndBack)
