#!/usr/bin/env python3
"""The world drawn in rviz stays under the lidar's dots, also when odometry drifts.

tb3_world.launch with profile:=realistic: odom is integrated from the
encoders and drifts from the truth. The simulator draws the world file's
obstacles in the frame `world` (on /world_markers) and publishes tf world ->
odom as where odometry puts the world; rviz, fixed in odom, then draws the
obstacles where the robot's own view (its lidar, carried by odom) sees them.

The robot drives circles until its odometry is off the truth (at least
MIN_DRIFT), stops, and one scan's points are carried through tf from
base_scan to world, at the scan's stamp: each within MAX_OFF of the surface
of an obstacle of the world file (read independently here), for at least
MIN_SHARE of the finite beams. Without the world -> odom correction they
would be off by the drift.

Then /gazebo/set_model_state teleports the robot back to its spawn pose:
the encoders saw no wheel turn, so odom stays where it was (within
STILL) while the truth jumps; tf world -> odom takes the jump, so tf's
world -> base_footprint is the truth again.
"""
import math
import unittest

import numpy as np
import rospkg
import rospy
import rostest
import tf2_ros
import yaml
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import SetModelState
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from visualization_msgs.msg import MarkerArray

from tb3_test_utils import GroundTruth, Repeater, init_test_node, report, wait_for_simulator, yaw_of

MIN_DRIFT = 0.01   # m, odometry off the truth before the check means anything
MAX_OFF = 0.03     # m, a lidar point from an obstacle's surface (noise is 1 cm)
MIN_SHARE = 0.95
DRIVE_SECONDS = 20.0
TIMEOUT = 30.0
SPAWN = (-2.0, -0.5)  # tb3_world.launch's
STILL = 0.005      # m, odom's move across the teleport (the robot settles where it lands)


def surface_distance(point, obstacle):
    """Distance in the plane from `point` (x, y) to the surface of a world-file obstacle."""
    (kind, fields), = obstacle.items()
    x, y = fields['position'][:2]
    if kind == 'cylinder':
        return abs(math.hypot(point[0] - x, point[1] - y) - fields['radius'])
    yaw = fields.get('yaw', 0.0)
    dx, dy = point[0] - x, point[1] - y
    local = (math.cos(yaw) * dx + math.sin(yaw) * dy, -math.sin(yaw) * dx + math.cos(yaw) * dy)
    half = (fields['size'][0] / 2, fields['size'][1] / 2)
    outside = [max(abs(c) - h, 0.0) for c, h in zip(local, half)]
    if any(outside):
        return math.hypot(*outside)
    return min(h - abs(c) for c, h in zip(local, half))  # inside: to the nearest face


def matrix(transform):
    q, t = transform.rotation, transform.translation
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), t.x],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), t.y],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), t.z],
                     [0, 0, 0, 1]])


class WorldInRviz(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        with open(rospkg.RosPack().get_path('tb3_sim_nav') + '/worlds/turtlebot3_world.yaml') as world:
            cls.obstacles = yaml.safe_load(world)['obstacles']
        cls.truth = GroundTruth()
        cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=1)
        cls.buffer = tf2_ros.Buffer(rospy.Duration(60.0))
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        wait_for_simulator(cls.truth, cmd_vel)
        circle = Twist()
        circle.linear.x, circle.angular.z = 0.15, 0.6
        repeater = Repeater(cmd_vel, circle)
        try:
            cls.truth.wait_sim(DRIVE_SECONDS)
        finally:
            repeater.stop()
            cmd_vel.publish(Twist())
        cls.truth.wait_at_rest(timeout=TIMEOUT)
        odom = rospy.wait_for_message('/odom', Odometry, TIMEOUT)
        truth = cls.truth.latest()
        cls.drift = math.hypot(odom.pose.pose.position.x - truth.x, odom.pose.pose.position.y - truth.y)
        cls.drift_deg = math.degrees(abs(math.remainder(yaw_of(odom.pose.pose.orientation) - truth.yaw, 2 * math.pi)))
        cls.scan = rospy.wait_for_message('/scan', LaserScan, TIMEOUT)
        cls.markers = rospy.wait_for_message('/world_markers', MarkerArray, TIMEOUT)
        cls.to_world = matrix(cls.buffer.lookup_transform('world', cls.scan.header.frame_id, cls.scan.header.stamp,
                                                          rospy.Duration(TIMEOUT)).transform)
        cls.to_odom = matrix(cls.buffer.lookup_transform('odom', cls.scan.header.frame_id, cls.scan.header.stamp,
                                                         rospy.Duration(TIMEOUT)).transform)

    def points(self, transform):
        scan = self.scan
        angles = scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))
        ranges = np.array(scan.ranges)
        finite = np.isfinite(ranges)
        local = np.stack([ranges * np.cos(angles), ranges * np.sin(angles), np.zeros_like(ranges),
                          np.ones_like(ranges)])[:, finite]
        return transform.dot(local)[:2].T

    def share_on_surfaces(self, points):
        offs = [min(surface_distance(point, obstacle) for obstacle in self.obstacles) for point in points]
        return sum(off <= MAX_OFF for off in offs) / float(len(offs)), max(offs)

    def test_the_odometry_has_drifted(self):
        report('odometry_drift', metres=self.drift, degrees=self.drift_deg)
        self.assertGreater(self.drift, MIN_DRIFT, 'odometry did not drift: the check below would mean nothing')

    def test_lidar_points_in_the_world_frame_lie_on_the_world_files_obstacles(self):
        points = self.points(self.to_world)
        share, worst = self.share_on_surfaces(points)
        # As rviz would draw them without world -> odom: the odom frame taken for the world.
        share_odom, _ = self.share_on_surfaces(self.points(self.to_odom))
        report('lidar_on_obstacles', beams=len(points), share=share, worst_m=worst, share_if_odom_were_world=share_odom)
        self.assertGreaterEqual(share, MIN_SHARE)
        self.assertLess(share_odom, share, 'without world -> odom the points should fall off the obstacles')

    def test_the_markers_are_drawn_in_the_world_frame(self):
        drawn = [marker for marker in self.markers.markers if marker.ns]
        self.assertEqual(len(drawn), len(self.obstacles))
        self.assertTrue(all(marker.header.frame_id == 'world' and marker.frame_locked for marker in drawn))

    def test_teleported_odom_stays_while_the_truth_and_world_to_odom_jump(self):
        odom_before = rospy.wait_for_message('/odom', Odometry, TIMEOUT).pose.pose.position
        state = ModelState(model_name='turtlebot3_burger')
        state.pose.position.x, state.pose.position.y = SPAWN
        state.pose.orientation.w = 1.0
        rospy.wait_for_service('/gazebo/set_model_state', TIMEOUT)
        answer = rospy.ServiceProxy('/gazebo/set_model_state', SetModelState)(state)
        self.assertTrue(answer.success, answer.status_message)
        self.truth.wait_sim(0.5)
        truth = self.truth.latest()
        odom = rospy.wait_for_message('/odom', Odometry, TIMEOUT)
        odom_moved = math.hypot(odom.pose.pose.position.x - odom_before.x, odom.pose.pose.position.y - odom_before.y)
        seen = self.buffer.lookup_transform('world', 'base_footprint', odom.header.stamp,
                                            rospy.Duration(TIMEOUT)).transform.translation
        report('teleport_realistic', truth=(truth.x, truth.y), odom_moved_m=odom_moved, tf_world_base=(seen.x, seen.y))
        self.assertAlmostEqual(truth.x, SPAWN[0], delta=0.01)
        self.assertAlmostEqual(truth.y, SPAWN[1], delta=0.01)
        self.assertLess(odom_moved, STILL)
        self.assertLess(math.hypot(seen.x - truth.x, seen.y - truth.y), 0.01)


if __name__ == '__main__':
    init_test_node('test_world_in_rviz')
    rostest.rosrun('tb3_sim_nav', 'world_in_rviz', WorldInRviz)
