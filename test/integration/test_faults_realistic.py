#!/usr/bin/env python3
"""A script killed with SIGKILL in the realistic profile: the firmware's 0.5 s
command timeout stops the robot (test_faults.py has the gazebo profile's case).

`rosrun tb3_sim_nav timed_out_and_back.py` (50 Hz of commands) is sent SIGKILL
3 s (sim) after it starts driving at 0.2 m/s. No command comes any more:
the robot must stand still (< 1 cm/s) from 0.5 s (the timeout) + 0.3 s
(braking at 1 m/s^2 takes 0.2 s, and a margin) after the kill on.
"""
import signal

import rostest
from test_faults import STOPPED_SPEED, FaultsBase

from tb3_test_utils import init_test_node, report, speed, wall_budget

TIMEOUT = 0.5                 # s, ~cmd_vel_timeout of the realistic profile
MARGIN = 0.3                  # s: braking from 0.2 m/s (0.2 s) and the command's age at the kill


class FaultsRealistic(FaultsBase):

    def test_sigkill_to_script_realistic_profile_stops_robot_within_0_5s_plus_margin(self):
        killed, child = self.run_script_and_kill(signal.SIGKILL)
        truth = self.truth
        self.assertTrue(truth.wait_until(killed + 3.0, wall_budget(3.0)), 'ground truth stopped after the SIGKILL')
        window = truth.samples(start=killed + TIMEOUT + MARGIN, end=killed + 3.0)
        stopped = self.stopped_at(killed)
        coasting = truth.samples(start=killed, end=killed + TIMEOUT - 0.1)
        report('sigkill_realistic', stopped_after_s=(stopped - killed) if stopped is not None else None,
               max_speed_in_window=max(speed(s) for s in window),
               min_speed_before_timeout=min(speed(s) for s in coasting), exit_code=child.wait(5.0))
        self.assertGreater(len(window), 40)
        self.assertLess(max(speed(s) for s in window), STOPPED_SPEED,
                        'the robot drives %.3f m/s %.1f s (sim) after the script was killed'
                        % (max(speed(s) for s in window), TIMEOUT + MARGIN))


if __name__ == '__main__':
    init_test_node('test_faults_realistic')
    rostest.rosrun('tb3_sim_nav', 'faults_realistic', FaultsRealistic)
