#!/usr/bin/env python3
"""Faults around /cmd_vel, in the default (gazebo) profile, judged by ground truth.

Each test method stands alone (the robot at rest first, stopped afterwards):
(a) `rostopic pub -r 10 /cmd_vel std_msgs/String "data: hi"`: ROS refuses the
    connection; the simulator stays up (odom flows, /tb3_sim answers a ping),
    the robot does not move, and a Twist sent meanwhile still drives it;
(b) two `rostopic pub -r 20` fighting for 5 s (0.2 m/s forward against
    -0.2 m/s): ground-truth speeds never exceed the limits x 1.05 and the
    simulator and the robot stay up;
(c) `rosrun tb3_sim_nav timed_out_and_back.py` sent SIGINT (Ctrl+C) 3 s (sim)
    after it starts driving: its shutdown hook stops the robot within 2 s;
(d) the same sent SIGKILL: no hook runs and, as in Gazebo, the last command
    holds: the robot drives on at 0.2 m/s.
faults_realistic.test checks (d) in the realistic profile, where the
firmware's 0.5 s command timeout stops the robot.
"""
import math
import signal
import threading
import unittest

import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from tb3_test_utils import (
    Child,
    GroundTruth3D,
    finite_difference_speeds,
    init_test_node,
    report,
    speed,
    wait_for,
    wall_budget,
)

SIM_NODE = '/tb3_sim'
MAX_V, MAX_W = 0.22, 2.84
SLACK = 1.05
STOPPED_SPEED = 0.01          # m/s
SCRIPT = 'timed_out_and_back.py'
SCRIPT_SPEED = 0.2            # m/s, its first leg
KILL_AFTER = 3.0              # sim s after the script starts driving
SIGINT_STOP_WITHIN = 2.0      # sim s
FIGHT_SECONDS = 5.0           # sim s
WRONG_TYPE_SECONDS = 3.0      # sim s


def twist(v=0.0, w=0.0):
    message = Twist()
    message.linear.x, message.angular.z = v, w
    return message


class OdomWatch(object):
    """Stamps of /odom as they arrive: is the simulator still publishing?"""

    def __init__(self):
        self.lock = threading.Lock()
        self.stamps = []
        rospy.Subscriber('/odom', Odometry, self._on_odom, queue_size=None)

    def _on_odom(self, message):
        with self.lock:
            self.stamps.append(message.header.stamp.to_sec())

    def latest(self):
        with self.lock:
            return self.stamps[-1] if self.stamps else -math.inf


class FaultsBase(unittest.TestCase):
    """Shared set-up: ground truth, odom, a /cmd_vel publisher, the robot at rest."""

    @classmethod
    def setUpClass(cls):
        cls.truth = GroundTruth3D()
        cls.odom = OdomWatch()
        cls.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=10)

    def setUp(self):
        self.addCleanup(self.cmd_vel.publish, Twist())
        self.assertTrue(self.truth.wait_first(60.0), 'no base_pose_ground_truth within 60 s')
        self.assertTrue(wait_for(lambda: self.cmd_vel.get_num_connections() > 0, 30.0),
                        'the simulator never subscribed to /cmd_vel')
        self.cmd_vel.publish(Twist())
        self.rest = self.truth.wait_at_rest(timeout=wall_budget(5.0))
        self.assertIsNotNone(self.rest, 'set-up: the robot did not come to rest')

    def start(self, args):
        child = Child(args)
        self.addCleanup(child.stop)
        return child

    def simulator_up(self, since):
        """True if /odom came after sim time `since` and /tb3_sim answers a ping."""
        return self.odom.latest() > since and rosnode.rosnode_ping(SIM_NODE, max_count=1)

    def run_script_and_kill(self, signum):
        """rosrun the script; `signum` to it KILL_AFTER s (sim) after it starts driving.

        Returns (sim time of the signal, the child)."""
        truth = self.truth
        child = self.start(['rosrun', 'tb3_sim_nav', SCRIPT])
        moving = wait_for(lambda: speed(truth.latest()) > 0.01 or not child.running(), wall_budget(10.0))
        self.assertTrue(moving and child.running(), 'set-up: %s did not start driving; %s'
                        % (SCRIPT, child.describe()))
        started = truth.latest().t
        self.assertTrue(truth.wait_until(started + KILL_AFTER, wall_budget(KILL_AFTER)),
                        'ground truth stopped while the script drove')
        self.assertTrue(child.running(), 'set-up: %s ended before it was killed; %s' % (SCRIPT, child.describe()))
        before = truth.latest()
        child.signal_group(signum)
        killed = rospy.get_time()
        self.assertGreater(speed(before), 0.9 * SCRIPT_SPEED, 'set-up: the robot was not driving its first leg '
                           'when the script was killed')
        return killed, child

    def stopped_at(self, since):
        """Sim time from which every sample is below STOPPED_SPEED, or None."""
        samples = self.truth.samples(start=since)
        for index, sample in enumerate(samples):
            if all(speed(s) < STOPPED_SPEED for s in samples[index:]):
                return sample.t
        return None


class Faults(FaultsBase):

    def test_wrong_type_on_cmd_vel_refused_simulator_up_twist_still_drives(self):
        truth = self.truth
        wrong = self.start(['rostopic', 'pub', '-r', '10', '/cmd_vel', 'std_msgs/String', 'data: hi'])
        t0 = truth.now()
        self.assertTrue(truth.wait_until(t0 + WRONG_TYPE_SECONDS, wall_budget(WRONG_TYPE_SECONDS)),
                        'ground truth stopped while a String was published on /cmd_vel')
        self.assertTrue(wrong.running(), 'set-up: rostopic pub of std_msgs/String on /cmd_vel ended; %s'
                        % wrong.describe())
        during = truth.samples(start=t0)
        moved = max(math.hypot(s.x - self.rest.x, s.y - self.rest.y) for s in during)
        self.assertLess(moved, 0.002, 'the robot moved %.4f m under String messages' % moved)
        self.assertTrue(self.simulator_up(t0 + WRONG_TYPE_SECONDS - 0.5), 'the simulator is down')
        # A correct Twist, while the String publisher is still at it.
        self.cmd_vel.publish(twist(0.1))
        sent = rospy.get_time()
        driving = wait_for(lambda: speed(truth.latest()) > 0.09, wall_budget(3.0))
        report('wrong_type', rostopic_running=wrong.running(), moved_under_string_m=moved,
               speed_after_twist=speed(truth.latest()), sim_seconds_to_drive=truth.now() - sent)
        self.assertTrue(driving, 'a Twist after the String messages did not drive the robot: %.3f m/s'
                        % speed(truth.latest()))
        self.assertTrue(wrong.running(), 'rostopic pub std_msgs/String died: %s' % wrong.describe())

    def test_two_publishers_fighting_speeds_within_limits_x1_05_simulator_up(self):
        truth = self.truth
        t0 = truth.now()
        fighters = [self.start(['rostopic', 'pub', '-r', '20', '/cmd_vel', 'geometry_msgs/Twist',
                                '{linear: {x: %s}}' % v]) for v in ('0.2', '-0.2')]
        self.assertTrue(wait_for(lambda: speed(truth.latest()) > 0.02, wall_budget(5.0)),
                        'set-up: the publishers never moved the robot')
        fight_start = truth.now()
        self.assertTrue(truth.wait_until(fight_start + FIGHT_SECONDS, wall_budget(FIGHT_SECONDS)),
                        'ground truth stopped during the fight')
        for fighter in fighters:
            self.assertTrue(fighter.running(), 'set-up: %s' % fighter.describe())
        samples = truth.samples(start=t0)
        motion = finite_difference_speeds(samples)
        report('fight', samples=len(samples), max_twist_v=max(speed(s) for s in samples),
               max_twist_w=max(abs(s.wz) for s in samples), max_pose_v=max(v for _, v, _ in motion),
               max_pose_w=max(abs(w) for _, _, w in motion),
               net_x=samples[-1].x - samples[0].x, max_abs_z=max(abs(s.z) for s in samples),
               max_tilt_deg=math.degrees(max(max(abs(s.roll), abs(s.pitch)) for s in samples)))
        self.assertLessEqual(max(speed(s) for s in samples), MAX_V * SLACK)
        self.assertLessEqual(max(abs(s.wz) for s in samples), MAX_W * SLACK)
        self.assertLessEqual(max(v for _, v, _ in motion), MAX_V * SLACK)
        self.assertLessEqual(max(abs(w) for _, _, w in motion), MAX_W * SLACK)
        self.assertLess(max(abs(s.z) for s in samples), 0.02, 'the robot left the ground')
        self.assertLess(math.degrees(max(max(abs(s.roll), abs(s.pitch)) for s in samples)), 5.0,
                        'the robot tipped')
        self.assertTrue(self.simulator_up(fight_start + FIGHT_SECONDS - 0.5), 'the simulator is down')

    def test_sigint_to_script_its_shutdown_hook_stops_robot_within_2s(self):
        killed, child = self.run_script_and_kill(signal.SIGINT)
        truth = self.truth
        self.assertTrue(truth.wait_until(killed + SIGINT_STOP_WITHIN + 1.0, wall_budget(SIGINT_STOP_WITHIN + 1.0)),
                        'ground truth stopped after the SIGINT')
        exit_code = child.wait(15.0)
        window = truth.samples(start=killed + SIGINT_STOP_WITHIN, end=killed + SIGINT_STOP_WITHIN + 1.0)
        stopped = self.stopped_at(killed)
        report('sigint', killed_at=killed, stopped_after_s=(stopped - killed) if stopped is not None else None,
               max_speed_in_window=max(speed(s) for s in window), exit_code=exit_code)
        self.assertGreater(len(window), 20)
        self.assertLess(max(speed(s) for s in window), STOPPED_SPEED,
                        'the robot still drives %.3f m/s %.0f s (sim) after Ctrl+C to %s; its output:\n%s'
                        % (max(speed(s) for s in window), SIGINT_STOP_WITHIN, SCRIPT, child.output()))
        self.assertIsNotNone(exit_code, '%s did not exit within 15 s of SIGINT' % SCRIPT)

    def test_sigkill_to_script_gazebo_profile_last_command_holds(self):
        killed, child = self.run_script_and_kill(signal.SIGKILL)
        truth = self.truth
        self.assertTrue(truth.wait_until(killed + 3.0, wall_budget(3.0)), 'ground truth stopped after the SIGKILL')
        window = truth.samples(start=killed + 1.0, end=killed + 3.0)
        report('sigkill_gazebo', min_speed=min(speed(s) for s in window), max_speed=max(speed(s) for s in window),
               exit_code=child.wait(5.0))
        self.assertGreater(len(window), 40)
        self.assertGreater(min(speed(s) for s in window), 0.9 * SCRIPT_SPEED,
                           'the robot did not keep its last command after SIGKILL')


if __name__ == '__main__':
    init_test_node('test_faults')
    rostest.rosrun('tb3_sim_nav', 'faults', Faults)
