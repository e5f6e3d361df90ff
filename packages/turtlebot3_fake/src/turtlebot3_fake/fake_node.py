"""The turtlebot3_fake_node node: ROBOTIS' fake TurtleBot3 (turtlebot3_fake.fake) over ROS.

    export TURTLEBOT3_MODEL=burger
    roslaunch turtlebot3_fake turtlebot3_fake.launch

In: `cmd_vel` (geometry_msgs/Twist). Out, 30 times a second of ROS time (as
ROBOTIS' ros::Rate): `odom` (nav_msgs/Odometry, ROBOTIS' covariances),
`joint_states` (both wheels) and tf odom -> base_footprint, all with one
stamp. No scan, no physics: the robot goes through walls. The parameters
(turtlebot3_fake.fake.FakeConfig) are read in the node's namespace, as
ROBOTIS' are, or privately.
"""
import dataclasses
import os

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from tb3_common.ros import lifecycle, params
from tb3_common.ros.poses import fill_pose

from .fake import COVARIANCE, LEFT, RIGHT, WHEEL_SEPARATION, FakeConfig, FakeRobot

NODE = 'turtlebot3_fake_node'
LOOP_RATE = 30.0   # Hz, ROBOTIS' ros::Rate
WARN_EVERY = 10.0  # s between repeats of one warning


def config_overrides():
    """ROBOTIS' node reads its parameters in its namespace: those set there (unless also set
    privately); tb3_model from $TURTLEBOT3_MODEL where neither sets it."""
    overrides = dict((field.name, rospy.get_param(field.name)) for field in dataclasses.fields(FakeConfig)
                     if rospy.has_param(field.name) and not rospy.has_param('~' + field.name))
    if 'tb3_model' not in overrides and not rospy.has_param('~tb3_model') and os.environ.get('TURTLEBOT3_MODEL'):
        overrides['tb3_model'] = os.environ['TURTLEBOT3_MODEL']
    return overrides


class FakeNode(object):

    def __init__(self, life):
        self.config = params.read_or_exit(NODE, FakeConfig, overrides=config_overrides())
        self.robot = FakeRobot(WHEEL_SEPARATION[self.config.tb3_model])
        self.odom = Odometry()
        self.odom.header.frame_id, self.odom.child_frame_id = self.config.odom_frame, self.config.base_frame
        self.odom.pose.covariance = self.odom.twist.covariance = COVARIANCE
        self.joints = JointState()
        self.joints.header.frame_id = self.config.joint_states_frame
        self.joints.name = [self.config.wheel_left_joint_name, self.config.wheel_right_joint_name]
        self.joints.effort = [0.0, 0.0]
        self.transform = TransformStamped()
        self.transform.header.frame_id, self.transform.child_frame_id = self.config.odom_frame, self.config.base_frame
        self.odom_pub = rospy.Publisher('odom', Odometry, queue_size=100)
        self.joints_pub = rospy.Publisher('joint_states', JointState, queue_size=100)
        self.broadcaster = tf2_ros.TransformBroadcaster()
        rospy.Subscriber('cmd_vel', Twist, life.callback(self._on_cmd_vel), queue_size=100)
        self.robot.update(rospy.get_time())

    def _on_cmd_vel(self, message):
        if not self.robot.command(message.linear.x, message.angular.z, rospy.get_time()):
            rospy.logwarn_throttle(WARN_EVERY, '%s: a cmd_vel with NaN or inf (linear.x %r, angular.z %r): '
                                   'stopping' % (NODE, message.linear.x, message.angular.z))

    def publish(self, stamp):
        """One update at `stamp`: odom, joint_states and tf."""
        self.robot.update(stamp.to_sec())
        fill_pose(self.odom.pose.pose, self.robot.pose)
        self.odom.twist.twist.linear.x, self.odom.twist.twist.angular.z = self.robot.velocity
        self.odom.header.stamp = stamp
        self.odom_pub.publish(self.odom)

        self.joints.position = list(self.robot.wheel_position)
        self.joints.velocity = [self.robot.wheel_velocity[LEFT], self.robot.wheel_velocity[RIGHT]]
        self.joints.header.stamp = stamp
        self.joints_pub.publish(self.joints)

        self.transform.header.stamp = stamp
        fill_pose(self.transform.transform, self.robot.pose)
        self.broadcaster.sendTransform(self.transform)

    def run(self, life):
        period = 1.0 / LOOP_RATE
        while not life.stopping:
            started = rospy.get_time()
            self.publish(rospy.Time.now())
            # The rest of the period, of ROS time: sim time under /clock, else wall time.
            rest = max(0.0, period - (rospy.get_time() - started))
            if rospy.rostime.is_wallclock():
                life.sleep(rest)
            else:
                life.sleep_sim(rest)
        life.finish()


def main():
    life = lifecycle.init_node(NODE)
    FakeNode(life).run(life)
