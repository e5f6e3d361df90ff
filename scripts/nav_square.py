#!/usr/bin/env python
""" nav_square.py - drive a square with odometry feedback through tf.

    In the style of the tutorial's odom_out_and_back.py: each side is driven
    until tf says the robot has covered it, each corner turned until tf says
    it has turned 90 degrees.

    Private parameters:
      ~side               length of a side (m), default 1.0
      ~linear_speed       forward speed (m/s), default 0.15
      ~angular_speed      turning speed (rad/s), default 0.5
      ~angular_tolerance  stop turning this short of 90 degrees (degrees), default 1.0
      ~rate               control loop rate (Hz), default 20
"""

from math import pi, radians, sqrt

import rospy
import tf
from geometry_msgs.msg import Point, Quaternion, Twist

from transform_utils import normalize_angle, quat_to_angle


class NavSquare():
    def __init__(self):
        # Give the node a name
        rospy.init_node('nav_square', anonymous=False)

        # Set rospy to execute a shutdown function when exiting
        rospy.on_shutdown(self.shutdown)

        # The square's size, the speeds and the turning tolerance
        side = rospy.get_param('~side', 1.0)
        linear_speed = rospy.get_param('~linear_speed', 0.15)
        angular_speed = rospy.get_param('~angular_speed', 0.5)
        angular_tolerance = radians(rospy.get_param('~angular_tolerance', 1.0))
        r = rospy.Rate(rospy.get_param('~rate', 20))

        # Publisher to control the robot's speed
        self.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=5)

        # The tf listener gives the pose of the base in the odom frame
        self.tf_listener = tf.TransformListener()
        self.odom_frame = '/odom'
        self.base_frame = self.find_base_frame()

        # Four sides, each followed by a left turn of 90 degrees
        for corner in range(4):
            # Drive forward until tf says the side is done
            (position, rotation) = self.get_odom()
            x_start, y_start = position.x, position.y
            distance = 0
            move_cmd = Twist()
            move_cmd.linear.x = linear_speed
            while distance < side and not rospy.is_shutdown():
                self.cmd_vel.publish(move_cmd)
                r.sleep()
                (position, rotation) = self.get_odom()
                distance = sqrt((position.x - x_start) ** 2 + (position.y - y_start) ** 2)

            # Stop before turning
            self.cmd_vel.publish(Twist())
            rospy.sleep(1)

            # Turn left until tf says we have turned 90 degrees
            move_cmd = Twist()
            move_cmd.angular.z = angular_speed
            last_angle = rotation
            turn_angle = 0
            while abs(turn_angle) + angular_tolerance < pi / 2 and not rospy.is_shutdown():
                self.cmd_vel.publish(move_cmd)
                r.sleep()
                (position, rotation) = self.get_odom()
                turn_angle += normalize_angle(rotation - last_angle)
                last_angle = rotation

            # Stop before the next side
            self.cmd_vel.publish(Twist())
            rospy.sleep(1)

        # Stop the robot for good
        self.cmd_vel.publish(Twist())

    def find_base_frame(self):
        # Robots name their base /base_footprint or /base_link: take whichever tf knows
        for frame in ('/base_footprint', '/base_link'):
            try:
                self.tf_listener.waitForTransform(self.odom_frame, frame, rospy.Time(), rospy.Duration(5.0))
                return frame
            except (tf.Exception, tf.ConnectivityException, tf.LookupException):
                pass
        rospy.logerr("Cannot find transform between /odom and /base_link or /base_footprint")
        rospy.signal_shutdown("tf Exception")
        raise SystemExit(1)

    def get_odom(self):
        # The current pose of the base in the odom frame: (Point, yaw)
        (trans, rot) = self.tf_listener.lookupTransform(self.odom_frame, self.base_frame, rospy.Time(0))
        return (Point(*trans), quat_to_angle(Quaternion(*rot)))

    def shutdown(self):
        # Always stop the robot when shutting down the node.
        rospy.loginfo("Stopping the robot...")
        self.cmd_vel.publish(Twist())
        rospy.sleep(1)

if __name__ == '__main__':
    try:
        NavSquare()
    except rospy.ROSInterruptException:
        rospy.loginfo("Navigation square node terminated.")
