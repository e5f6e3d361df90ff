#!/usr/bin/env python3
"""Driving into a wall: the robot stops against it, neither through nor over it.

In the walled arena (tb3_world.launch, spawn (-2, -0.5), yaw 0) the robot turns
on the spot to face -x (closed loop on ground truth), then is commanded 0.2 m/s
straight ahead at 20 Hz for 8 s of sim time: 1.6 m, while the west wall's
inner face is 0.46 m ahead and its outer face 0.56 m. The west wall is the box
centred at (-2.55, 0) turned by 3 pi / 2, 0.1 m thick and 2.987 m long: it
fills x in [-2.6, -2.5] for |y| < 1.49, and the robot drives along y = -0.5.

The robot's leading edge facing -x is its base plate's front face (and the
lidar's), 0.038 m ahead of base_footprint (URDF: box 0.140 m centred at
x -0.032; lidar radius 0.055 at x -0.017); the wheels reach 0.033 m. So
base_footprint's x must stay >= -2.5 + 0.038 (less 5 mm of contact
penetration), the robot must come to a stop there (< 1 cm/s) while the command
still says go, and stay on the ground (z within 2 cm of 0, tilt under 5 deg).
"""
import math
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist

from tb3_test_utils import (
    GroundTruth3D,
    Repeater,
    finite_difference_speeds,
    init_test_node,
    report,
    speed,
    turn_to,
    wait_for_simulator,
    wall_budget,
    wrap,
)

WALL_FACE_X = -2.5            # inner face of the west wall (m)
WALL_Y_EXTENT = 1.49          # the west wall spans |y| below this (m)
FRONT_EXTENT = 0.038          # base_footprint to the robot's front face (m)
HALF_WIDTH = 0.07             # half the base plate's width (m), for a heading error
PENETRATION = 0.005           # contact slop allowed (m)
SPEED = 0.2                   # m/s, commanded
PUSH_SECONDS = 8.0            # sim s of commanding SPEED
STILL_WINDOW = 2.0            # sim s at the end of the push that must be still
STOPPED_SPEED = 0.01          # m/s
MAX_HEIGHT = 0.02             # m
MAX_TILT_DEG = 5.0


class WallCollision(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.truth = GroundTruth3D()
        cls.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=10)
        cls.setup_error = None
        try:
            cls._run()
        except AssertionError as error:
            cls.setup_error = str(error)
        finally:
            cls.cmd_vel.publish(Twist())

    @classmethod
    def _run(cls):
        truth = cls.truth
        wait_for_simulator(truth, cls.cmd_vel)
        if not turn_to(truth, cls.cmd_vel, math.pi, wall_budget(15.0)):
            raise AssertionError('could not turn to face -x: yaw %.1f deg' % math.degrees(truth.latest().yaw))
        cls.facing = truth.wait_at_rest(timeout=wall_budget(3.0))
        if cls.facing is None:
            raise AssertionError('the robot did not come to rest after turning')
        # The leading edge, for this heading: the front corners of the base plate.
        heading_error = wrap(cls.facing.yaw - math.pi)
        cls.front_extent = FRONT_EXTENT * math.cos(heading_error) + HALF_WIDTH * abs(math.sin(heading_error))
        forward = Twist()
        forward.linear.x = SPEED
        repeater = Repeater(cls.cmd_vel, forward, rate=20.0)
        try:
            cls.push_start = truth.now()
            cls.push_end = cls.push_start + PUSH_SECONDS
            if not truth.wait_until(cls.push_end, wall_budget(PUSH_SECONDS)):
                raise AssertionError('ground truth stopped during the push')
            cls.commands_sent = repeater.count
        finally:
            repeater.stop()
        cls.path = truth.samples(start=cls.push_start, end=cls.push_end)
        cls.end_window = [s for s in cls.path if s.t >= cls.push_end - STILL_WINDOW]
        cls.min_x = min(s.x for s in cls.path)
        report('wall_push', heading_error_deg=math.degrees(heading_error), front_extent_m=cls.front_extent,
               start_x=cls.path[0].x, min_x=cls.min_x, end_x=cls.path[-1].x, end_y=cls.path[-1].y,
               limit_x=WALL_FACE_X + cls.front_extent - PENETRATION,
               end_window_max_speed=max(speed(s) for s in cls.end_window),
               max_z=max(s.z for s in cls.path), min_z=min(s.z for s in cls.path),
               max_tilt_deg=math.degrees(max(max(abs(s.roll), abs(s.pitch)) for s in cls.path)),
               commands_sent=cls.commands_sent)

    def setUp(self):
        if self.setup_error:
            self.fail('the wall push failed: ' + self.setup_error)

    def test_hits_the_west_wall_along_its_length(self):
        # Set-up facts the other tests rely on: it drove at the wall, within its span.
        self.assertLess(abs(self.path[0].y), WALL_Y_EXTENT - 0.2)
        self.assertTrue(all(abs(s.y) < WALL_Y_EXTENT - 0.2 for s in self.path),
                        'the robot left the west wall\'s span')
        moving = [s for s in self.path if speed(s) > 0.9 * SPEED]
        self.assertTrue(moving, 'the robot never reached 0.9 x %.2f m/s towards the wall' % SPEED)

    def test_base_footprint_never_below_wall_face_plus_front_extent(self):
        limit = WALL_FACE_X + self.front_extent - PENETRATION
        deepest = min(self.path, key=lambda s: s.x)
        self.assertGreaterEqual(deepest.x, limit,
                                'base_footprint reached x = %.4f at t = %.2f: the front is %.4f m into '
                                'the wall (limit x = %.4f)' % (deepest.x, deepest.t,
                                                               WALL_FACE_X + self.front_extent - deepest.x, limit))

    def _end_window(self):
        window = self.end_window
        self.assertGreater(len(window), 30)
        return window

    def test_pose_stands_still_against_the_wall_while_commanded_forward(self):
        window = self._end_window()
        moved = math.hypot(window[-1].x - window[0].x, window[-1].y - window[0].y)
        motion = max(v for _, v, _ in finite_difference_speeds(window))
        report('wall_end_window_poses', moved_m=moved, max_speed_from_poses=motion,
               x_range_m=max(s.x for s in window) - min(s.x for s in window),
               y_range_m=max(s.y for s in window) - min(s.y for s in window),
               yaw_range_deg=math.degrees(max(wrap(s.yaw - window[0].yaw) for s in window)
                                          - min(wrap(s.yaw - window[0].yaw) for s in window)))
        self.assertLess(motion, STOPPED_SPEED, 'moved at %.3f m/s (from poses 0.1 s apart) in the last '
                        '%.0f s of the push' % (motion, STILL_WINDOW))
        self.assertLess(moved, STOPPED_SPEED * STILL_WINDOW)
        # It stopped at the wall, not somewhere before it.
        self.assertLess(window[-1].x, WALL_FACE_X + self.front_extent + 0.02,
                        'stopped at x = %.3f, short of the wall' % window[-1].x)

    def test_ground_truth_twist_below_1cm_s_against_the_wall_while_commanded_forward(self):
        window = self._end_window()
        speeds = [speed(s) for s in window]
        fastest = max(window, key=speed)
        over = sum(1 for v in speeds if v >= STOPPED_SPEED)
        report('wall_end_window_twist', samples=len(speeds), max_speed=max(speeds),
               mean_speed=sum(speeds) / len(speeds), samples_over_1cm_s=over,
               max_abs_wz=max(abs(s.wz) for s in window),
               fastest='t=%.3f vx=%.4f vy=%.4f wz=%.4f' % (fastest.t, fastest.vx, fastest.vy, fastest.wz))
        self.assertLess(speed(fastest), STOPPED_SPEED,
                        'base_pose_ground_truth twist says %.3f m/s (vx %.3f, vy %.3f) at t = %.2f, in the '
                        'last %.0f s of the push, while the pose stands still; %d of %d samples >= %.2f m/s'
                        % (speed(fastest), fastest.vx, fastest.vy, fastest.t, STILL_WINDOW, over,
                           len(speeds), STOPPED_SPEED))

    def test_stays_on_the_ground_no_climbing(self):
        highest = max(self.path, key=lambda s: abs(s.z))
        self.assertLess(abs(highest.z), MAX_HEIGHT, 'z = %.4f m at t = %.2f' % (highest.z, highest.t))
        tilted = max(self.path, key=lambda s: max(abs(s.roll), abs(s.pitch)))
        tilt = math.degrees(max(abs(tilted.roll), abs(tilted.pitch)))
        self.assertLess(tilt, MAX_TILT_DEG, 'tilted %.1f deg at t = %.2f' % (tilt, tilted.t))


if __name__ == '__main__':
    init_test_node('test_wall_collision')
    rostest.rosrun('tb3_sim_nav', 'wall_collision', WallCollision)
