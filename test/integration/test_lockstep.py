#!/usr/bin/env python3
"""Lockstep: the simulator holds each step until the nodes publishing cmd_vel
have reacted to it, so as fast as possible a rospy.Rate loop sees sim time
as at real time.

This node is such a node. Each of its Rate(50) ticks must come exactly 20 ms
of sim time after the one before (without lockstep, at factor 0, the
simulator outruns a python node by many steps, and rospy.Rate drops the
ticks it is late for), and a command sent at a tick must be the one in force
for the next 20 ms: the robot, told 0.1 m/s for 250 ticks from rest, covers
what the same commands give at real time.
"""
import math
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist

from tb3_test_utils import GroundTruth, init_test_node, real_time_factor, report, wait_for_simulator

TICKS = 250
RATE = 50.0
SPEED = 0.1  # m/s


class Lockstep(unittest.TestCase):

    def test_every_tick_20ms_apart_and_the_robot_where_its_commands_say(self):
        truth = GroundTruth()
        cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=5)
        wait_for_simulator(truth, cmd_vel)
        start_pose = truth.latest()
        rate = rospy.Rate(RATE)
        rate.sleep()  # anchors the rate on a tick of its own
        forward = Twist()
        forward.linear.x = SPEED
        ticks, wall_start = [], time.monotonic()
        for _ in range(TICKS):
            cmd_vel.publish(forward)
            rate.sleep()
            ticks.append(rospy.get_rostime().to_nsec())
        cmd_vel.publish(Twist())
        wall = time.monotonic() - wall_start
        gaps = [(later - earlier) / 1e6 for earlier, later in zip(ticks, ticks[1:])]
        off = [gap for gap in gaps if gap != 1000.0 / RATE]
        report('lockstep', factor=real_time_factor(), ticks=TICKS, wall_s=wall,
               sim_s=(ticks[-1] - ticks[0]) / 1e9, distinct_gaps_ms=sorted(set(gaps)))
        self.assertEqual(off, [], '%d of %d ticks not 20 ms after the one before: %s'
                         % (len(off), len(gaps), off[:10]))
        # The robot accelerates at 1 m/s^2 (0.1 s to reach 0.1 m/s) and keeps
        # 0.1 m/s until the stop: 250 ticks of 20 ms give 0.5 m, less 5 mm
        # lost accelerating, give or take what settles in the first steps.
        rest = truth.wait_at_rest(timeout=60.0)
        self.assertIsNotNone(rest, 'the robot did not stop after the last tick')
        travelled = math.hypot(rest.x - start_pose.x, rest.y - start_pose.y)
        report('lockstep_distance', travelled_m=travelled, expected_m=SPEED * TICKS / RATE)
        self.assertAlmostEqual(travelled, SPEED * TICKS / RATE, delta=0.01)


if __name__ == '__main__':
    init_test_node('test_lockstep')
    rostest.rosrun('tb3_sim_nav', 'test_lockstep', Lockstep)
