#!/usr/bin/env python
""" calibrate_linear.py - drive a test distance by odometry, to check odometry with a tape measure.

    In the style of the tutorial's scripts, with the interface of ROS by
    Example's calibrate_linear.py. The robot drives ~test_distance straight
    ahead, watching tf (odom -> base) until odometry says it is there, stops,
    and logs how far odometry thinks it went. Measure how far it really went:
    the base controller's new odom_linear_scale_correction is its present one
    times (real distance / odometry's distance). Here the base controller is
    the simulator:

        rosrun dynamic_reconfigure dynparam set /tb3_sim odom_linear_scale_correction 0.98

    The script then waits; each time start_test is set true again it drives
    the distance again from where the robot stands:

        rosrun dynamic_reconfigure dynparam set /calibrate_linear start_test true

    Private parameters, also served through dynamic_reconfigure:
      ~test_distance                 distance to drive (m), default 1.0
      ~speed                         forward speed (m/s), default 0.15
      ~tolerance                     stop within this of the distance (m), default 0.01
      ~odom_linear_scale_correction  multiplies what odometry says, default 1.0
      ~start_test                    drive at once, default true
      ~odom_frame, ~base_frame       default /odom and /base_footprint
"""

from math import copysign, sqrt

import rospy
import tf
from dynamic_reconfigure.server import Server
from geometry_msgs.msg import Twist

from tb3_sim_nav.cfg import CalibrateLinearConfig


class CalibrateLinear():
    def __init__(self):
        # Give the node a name
        rospy.init_node('calibrate_linear', anonymous=False)

        # Set rospy to execute a shutdown function when exiting
        rospy.on_shutdown(self.shutdown)

        # The frames, and the rate at which we watch odometry
        self.odom_frame = rospy.get_param('~odom_frame', '/odom')
        self.base_frame = rospy.get_param('~base_frame', '/base_footprint')
        r = rospy.Rate(30)

        # Publisher to control the robot's speed
        self.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=5)

        # Our own dynamic_reconfigure server. It reads our private parameters (their
        # defaults are in cfg/CalibrateLinear.cfg) and hands them to reconfigure() at
        # once, and again whenever dynparam changes one.
        self.server = Server(CalibrateLinearConfig, self.reconfigure)

        # The tf listener gives the position of the base in the odom frame
        self.tf_listener = tf.TransformListener()
        self.tf_listener.waitForTransform(self.odom_frame, self.base_frame, rospy.Time(), rospy.Duration(60.0))

        x_start, y_start = self.get_position()
        while not rospy.is_shutdown():
            # Stand still unless a test is on
            move_cmd = Twist()
            x, y = self.get_position()
            if self.start_test:
                # How far odometry says we have come, corrected by our factor
                distance = self.correction * sqrt((x - x_start) ** 2 + (y - y_start) ** 2)
                error = distance - self.test_distance
                if abs(error) < self.tolerance:
                    # There: stop and say so
                    self.start_test = False
                    self.server.update_configuration({'start_test': False})
                    rospy.loginfo("Odometry says %.3f m. Measure the real distance: the base's "
                                  "odom_linear_scale_correction times (real / %.3f) is the new one.",
                                  distance, distance)
                else:
                    # Forward if short of it, back if past it
                    move_cmd.linear.x = copysign(self.speed, -error)
            else:
                # The next test starts from where we stand
                x_start, y_start = x, y
            self.cmd_vel.publish(move_cmd)
            r.sleep()

    def reconfigure(self, config, level):
        # New values from dynamic_reconfigure (also once at start: our parameters)
        self.test_distance = config['test_distance']
        self.speed = config['speed']
        self.tolerance = config['tolerance']
        self.correction = config['odom_linear_scale_correction']
        self.start_test = config['start_test']
        return config

    def get_position(self):
        # The current position of the base in the odom frame
        (trans, rot) = self.tf_listener.lookupTransform(self.odom_frame, self.base_frame, rospy.Time(0))
        return trans[0], trans[1]

    def shutdown(self):
        # Always stop the robot when shutting down the node.
        rospy.loginfo("Stopping the robot...")
        self.cmd_vel.publish(Twist())
        rospy.sleep(1)

if __name__ == '__main__':
    try:
        CalibrateLinear()
    except rospy.ROSInterruptException:
        rospy.loginfo("Linear calibration terminated.")
