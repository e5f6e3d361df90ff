#!/usr/bin/env python
""" calibrate_angular.py - turn a test angle by odometry, to check odometry against the truth.

    In the style of the tutorial's scripts, with the interface of ROS by
    Example's calibrate_angular.py. The robot turns in place, watching tf
    (odom -> base) until odometry says it has turned ~test_angle, stops, and
    logs the angle odometry saw. Mark where it really points: the base
    controller's new odom_angular_scale_correction is its present one times
    (real angle / odometry's angle). Here the base controller is the
    simulator:

        rosrun dynamic_reconfigure dynparam set /tb3_sim odom_angular_scale_correction 1.02

    The script then waits; each time start_test is set true again it turns
    the angle again, the other way round:

        rosrun dynamic_reconfigure dynparam set /calibrate_angular start_test true

    Private parameters, also served through dynamic_reconfigure:
      ~test_angle                     angle to turn (degrees), default 360
      ~speed                          turning speed (rad/s), default 0.5
      ~tolerance                      stop within this of the angle (degrees), default 1.0
      ~odom_angular_scale_correction  multiplies what odometry says, default 1.0
      ~start_test                     turn at once, default true
      ~odom_frame, ~base_frame        default /odom and /base_footprint
"""

from math import degrees, radians

import rospy
import tf
from dynamic_reconfigure.server import Server
from geometry_msgs.msg import Quaternion, Twist

from tb3_sim_nav.cfg import CalibrateAngularConfig
from transform_utils import normalize_angle, quat_to_angle


class CalibrateAngular():
    def __init__(self):
        # Give the node a name
        rospy.init_node('calibrate_angular', anonymous=False)

        # Set rospy to execute a shutdown function when exiting
        rospy.on_shutdown(self.shutdown)

        # The frames, and the rate at which we watch odometry
        self.odom_frame = rospy.get_param('~odom_frame', '/odom')
        self.base_frame = rospy.get_param('~base_frame', '/base_footprint')
        r = rospy.Rate(30)

        # Publisher to control the robot's speed
        self.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=5)

        # Our own dynamic_reconfigure server. It reads our private parameters (their
        # defaults are in cfg/CalibrateAngular.cfg) and hands them to reconfigure() at
        # once, and again whenever dynparam changes one.
        self.server = Server(CalibrateAngularConfig, self.reconfigure)

        # The tf listener gives the heading of the base in the odom frame
        self.tf_listener = tf.TransformListener()
        self.tf_listener.waitForTransform(self.odom_frame, self.base_frame, rospy.Time(), rospy.Duration(60.0))

        direction = 1
        while not rospy.is_shutdown():
            if self.start_test:
                # Turn until odometry says we have turned the test angle
                move_cmd = Twist()
                move_cmd.angular.z = direction * self.speed
                last_angle = self.get_odom_angle()
                turn_angle = 0
                while abs(turn_angle) + self.tolerance < self.test_angle and self.start_test:
                    if rospy.is_shutdown():
                        return
                    self.cmd_vel.publish(move_cmd)
                    r.sleep()
                    angle = self.get_odom_angle()
                    turn_angle += self.correction * normalize_angle(angle - last_angle)
                    last_angle = angle

                # Stop and say how far odometry saw us turn
                self.cmd_vel.publish(Twist())
                self.start_test = False
                self.server.update_configuration({'start_test': False})
                rospy.loginfo("Odometry says %.1f degrees. Mark the real angle: the base's "
                              "odom_angular_scale_correction times (real / %.1f) is the new one.",
                              degrees(abs(turn_angle)), degrees(abs(turn_angle)))

                # The next test turns the other way
                direction = -direction
            r.sleep()

    def reconfigure(self, config, level):
        # New values from dynamic_reconfigure (also once at start: our parameters)
        self.test_angle = radians(config['test_angle'])
        self.speed = config['speed']
        self.tolerance = radians(config['tolerance'])
        self.correction = config['odom_angular_scale_correction']
        self.start_test = config['start_test']
        return config

    def get_odom_angle(self):
        # The current heading of the base in the odom frame
        (trans, rot) = self.tf_listener.lookupTransform(self.odom_frame, self.base_frame, rospy.Time(0))
        return quat_to_angle(Quaternion(*rot))

    def shutdown(self):
        # Always stop the robot when shutting down the node.
        rospy.loginfo("Stopping the robot...")
        self.cmd_vel.publish(Twist())
        rospy.sleep(1)

if __name__ == '__main__':
    try:
        CalibrateAngular()
    except rospy.ROSInterruptException:
        rospy.loginfo("Angular calibration terminated.")
