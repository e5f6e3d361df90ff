#!/usr/bin/env python3
"""/gazebo/pause_physics and /gazebo/unpause_physics, as Gazebo offers them.

With the robot driving: pause stops /clock (over a wall-time wait) and the
robot (no ground-truth pose changes, and after unpausing it resumes where it
was, not 2 s further on); a node started while paused has the paused time at
once (/clock is latched), not zero; unpause makes /clock advance again, at the
real-time factor (no rush to catch up), and the robot drives on with its last
command.
"""
import math
import subprocess
import sys
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty

from tb3_test_utils import GroundTruth, init_test_node, real_time_factor, report, speed, wait_for, wall_budget

PAUSED_WALL_SECONDS = 2.0
DRIVE = (0.1, 0.3)
# A node of its own (rospy inits once per process): its sim time, once it has one.
LATE_NODE = ('import time, rospy\n'
             'rospy.init_node("started_while_paused", anonymous=True)\n'
             'deadline = time.monotonic() + 10.0\n'
             'while rospy.get_time() == 0.0 and time.monotonic() < deadline:\n'
             '    time.sleep(0.01)\n'
             'print(repr(rospy.get_time()))\n')


class ClockWatch(object):
    def __init__(self):
        self.lock = threading.Lock()
        self.values = []   # (wall time, sim time)
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=None)

    def _on_clock(self, message):
        with self.lock:
            self.values.append((time.monotonic(), message.clock.to_sec()))

    def latest(self):
        with self.lock:
            return self.values[-1][1] if self.values else -math.inf

    def count(self):
        with self.lock:
            return len(self.values)


class PauseUnpause(unittest.TestCase):

    def setUp(self):
        self.clock = ClockWatch()
        self.truth = GroundTruth()
        self.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=10)
        self.addCleanup(self.cmd_vel.publish, Twist())
        self.assertTrue(self.truth.wait_first(60.0), 'no base_pose_ground_truth within 60 s')
        for service in ('/gazebo/pause_physics', '/gazebo/unpause_physics'):
            rospy.wait_for_service(service, 30.0)
        self.pause = rospy.ServiceProxy('/gazebo/pause_physics', Empty)
        self.unpause = rospy.ServiceProxy('/gazebo/unpause_physics', Empty)
        self.addCleanup(self.unpause)  # never leave the world paused
        self.assertTrue(wait_for(lambda: self.cmd_vel.get_num_connections() > 0, 30.0),
                        'the simulator never subscribed to /cmd_vel')

    def test_pause_stops_clock_and_robot_unpause_resumes_both(self):
        truth, clock = self.truth, self.clock
        drive = Twist()
        drive.linear.x, drive.angular.z = DRIVE
        self.cmd_vel.publish(drive)
        self.assertTrue(wait_for(lambda: speed(truth.latest()) > 0.9 * DRIVE[0], wall_budget(3.0)),
                        'set-up: the robot did not start driving')

        # --- pause -------------------------------------------------------------
        self.pause()
        # A step in flight when the call returned may still publish: let it land.
        time.sleep(0.2)
        paused_clock, paused_count = clock.latest(), clock.count()
        paused_pose = truth.latest()
        paused_wall = time.monotonic()
        late = subprocess.run([sys.executable, '-c', LATE_NODE], stdout=subprocess.PIPE,
                              universal_newlines=True, timeout=60)
        # The point: wall time passes, sim time must not.
        time.sleep(max(0.0, paused_wall + PAUSED_WALL_SECONDS - time.monotonic()))
        clock_during, count_during = clock.latest(), clock.count()
        pose_during = truth.latest()
        report('paused', clock_before=paused_clock, clock_after=clock_during,
               clock_messages_while_paused=count_during - paused_count,
               wall_seconds=PAUSED_WALL_SECONDS)
        self.assertEqual(clock_during, paused_clock,
                         '/clock advanced %.3f s while paused' % (clock_during - paused_clock))
        self.assertEqual(count_during, paused_count, '/clock kept publishing while paused')
        report('started_while_paused', exit_code=late.returncode, its_time=late.stdout.strip())
        self.assertEqual(late.returncode, 0, 'the node started while paused failed')
        self.assertAlmostEqual(float(late.stdout), paused_clock, places=6,
                               msg='a node started while paused has time %s, not the paused %.3f'
                               % (late.stdout.strip(), paused_clock))
        self.assertEqual((pose_during.x, pose_during.y, pose_during.yaw),
                         (paused_pose.x, paused_pose.y, paused_pose.yaw),
                         'the ground-truth pose changed while paused')

        # --- unpause -----------------------------------------------------------
        wall_unpaused = time.monotonic()
        self.unpause()
        self.assertTrue(wait_for(lambda: clock.latest() > paused_clock, 10.0),
                        '/clock did not advance within 10 s of unpausing')
        self.assertTrue(truth.wait_until(paused_pose.t + 0.01, 10.0), 'no ground truth after unpausing')
        resumed = truth.samples(start=paused_pose.t + 1e-6)[0]
        jump = math.hypot(resumed.x - paused_pose.x, resumed.y - paused_pose.y)
        # Over 2 wall s after unpausing, sim time advances at the real-time factor.
        time.sleep(max(0.0, wall_unpaused + 2.0 - time.monotonic()))
        with clock.lock:
            after = [(w, s) for w, s in clock.values if w >= wall_unpaused]
        advanced = after[-1][1] - paused_clock
        wall = after[-1][0] - wall_unpaused
        self.assertTrue(truth.wait_sim(1.0), 'ground truth stopped after unpausing')
        moving = truth.latest()
        report('unpaused', first_step_jump_m=jump, sim_advanced_s=advanced, wall_s=wall,
               speed_after=speed(moving), real_time_factor=real_time_factor())
        # At 0.1 m/s one odom period (1/30 s) is 3.3 mm; 2 s of driving would be 0.2 m.
        self.assertLess(jump, 0.01, 'the robot moved %.3f m while paused' % jump)
        self.assertGreater(advanced, 0.5 * min(wall, 1.0), '/clock advanced only %.3f s in %.1f wall s '
                           'after unpausing' % (advanced, wall))
        factor = real_time_factor()
        if factor > 0.0:
            self.assertLess(advanced, 1.5 * factor * wall,
                            '/clock advanced %.2f s in %.2f wall s after unpausing: it raced to '
                            'catch up the paused time' % (advanced, wall))
        self.assertGreater(speed(moving), 0.9 * DRIVE[0], 'the robot did not drive on after unpausing')


if __name__ == '__main__':
    init_test_node('test_pause_unpause')
    rostest.rosrun('tb3_sim_nav', 'pause_unpause', PauseUnpause)
