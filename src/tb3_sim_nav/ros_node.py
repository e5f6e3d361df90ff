"""The ROS edge: parameters in, topics and services around a SimWorld.

The only module of the package that imports rospy. One physics step gives
one timestamp to everything it publishes.
"""
import sys
import time

import rospy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from . import params
from .diff_drive import Limits, sanitize_twist, wheel_speeds
from .pacing import Pacer, Schedule
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, ModelError, read_drive_geometry

WARN_PERIOD = 5.0  # s between repeats of the same warning
PAUSED_POLL = 0.01  # wall s between checks while paused
# Diagonal covariances of odom, as Gazebo's diff-drive plugin fills them:
# x, y and yaw are known well; z, roll and pitch are not estimated at all.
COVARIANCE_DIAGONAL = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def _diagonal(values):
    matrix = [0.0] * 36
    for index, value in enumerate(values):
        matrix[index * 7] = value
    return matrix


class SimulatorNode(object):
    """Steps the world in sim time and publishes what Gazebo's TurtleBot3 does."""

    def __init__(self, config, geometry):
        from .world import SimWorld  # imports pybullet: after the parameters are known good
        self.config = config
        self.geometry = geometry
        self.limits = Limits(config['max_linear_speed'], config['max_angular_speed'])
        self.step_ns = int(round(1e9 / config['physics_rate']))
        self.world = SimWorld(config['urdf_file'],
                              (config['x_pos'], config['y_pos'], config['z_pos'], config['yaw']),
                              time_step=self.step_ns * 1e-9, wheel_torque=config['wheel_torque'],
                              gui=config['gui'])
        self.pacer = Pacer(config['real_time_factor'], paused=config['paused'])
        self.steps = 0
        self._command = (0.0, 0.0)
        self._applied = None
        self._odom_due = Schedule(round(1e9 / config['odom_rate']))
        self._joints_due = Schedule(round(1e9 / config['joint_states_rate']))
        self._clock = Clock()
        self._make_messages()
        self.clock_pub = rospy.Publisher('clock', Clock, queue_size=10)
        self.odom_pub = rospy.Publisher('odom', Odometry, queue_size=10)
        self.truth_pub = rospy.Publisher('base_pose_ground_truth', Odometry, queue_size=10)
        self.joints_pub = rospy.Publisher('joint_states', JointState, queue_size=10)
        self.tf_pub = rospy.Publisher('tf', TFMessage, queue_size=100)
        rospy.Subscriber('cmd_vel', Twist, self._on_cmd_vel, queue_size=10)
        rospy.Service('gazebo/pause_physics', Empty, self._on_pause)
        rospy.Service('gazebo/unpause_physics', Empty, self._on_unpause)

    def _make_messages(self):
        """Messages reused every publication: only stamps and values change."""
        frame, child = self.config['odom_frame'], self.config['base_frame']
        self._odom = Odometry()
        self._odom.header.frame_id = frame
        self._odom.child_frame_id = child
        self._odom.pose.covariance = _diagonal(COVARIANCE_DIAGONAL)
        self._odom.twist.covariance = _diagonal(COVARIANCE_DIAGONAL)
        self._truth = Odometry()
        self._truth.header.frame_id = frame
        self._truth.child_frame_id = child
        self._transform = TransformStamped()
        self._transform.header.frame_id = frame
        self._transform.child_frame_id = child
        self._tf = TFMessage(transforms=[self._transform])
        self._joints = JointState(name=[LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT])

    # --- inputs -----------------------------------------------------------
    def _on_cmd_vel(self, twist):
        v, w, complaints = sanitize_twist((twist.linear.x, twist.linear.y, twist.linear.z),
                                          (twist.angular.x, twist.angular.y, twist.angular.z),
                                          self.limits)
        if complaints:
            rospy.logwarn_throttle(WARN_PERIOD, 'cmd_vel: ' + '; '.join(complaints))
        self._command = (v, w)  # one atomic assignment; the step loop picks it up

    def _on_pause(self, _request):
        self.pacer.pause()
        return EmptyResponse()

    def _on_unpause(self, _request):
        self.pacer.resume()
        return EmptyResponse()

    # --- the step loop ------------------------------------------------------
    def run(self):
        while not rospy.is_shutdown():
            if self.pacer.paused:
                time.sleep(PAUSED_POLL)
                continue
            self.pacer.wait_until((self.steps + 1) * self.step_ns * 1e-9)
            self.step()

    def step(self):
        command = self._command
        if command is not self._applied:
            self.world.set_wheel_speeds(*wheel_speeds(command[0], command[1], *self.geometry))
            self._applied = command
        self.world.step()
        self.steps += 1
        now_ns = self.steps * self.step_ns
        stamp = rospy.Time(now_ns // 1000000000, now_ns % 1000000000)
        self._clock.clock = stamp
        self.clock_pub.publish(self._clock)
        if self._odom_due.due(now_ns):
            self.publish_odometry(stamp)
        if self._joints_due.due(now_ns):
            self.publish_joint_states(stamp)

    def publish_odometry(self, stamp):
        position, orientation = self.world.base_pose()
        linear, angular = self.world.base_twist()
        for message in (self._odom, self._truth):
            message.header.stamp = stamp
            pose = message.pose.pose
            pose.position.x, pose.position.y, pose.position.z = position
            (pose.orientation.x, pose.orientation.y,
             pose.orientation.z, pose.orientation.w) = orientation
            twist = message.twist.twist
            twist.linear.x, twist.linear.y, twist.linear.z = linear
            twist.angular.x, twist.angular.y, twist.angular.z = angular
        transform = self._transform.transform
        self._transform.header.stamp = stamp
        transform.translation.x, transform.translation.y, transform.translation.z = position
        transform.rotation = self._odom.pose.pose.orientation
        self.odom_pub.publish(self._odom)
        self.tf_pub.publish(self._tf)
        self.truth_pub.publish(self._truth)

    def publish_joint_states(self, stamp):
        positions, velocities = self.world.wheel_states()
        self._joints.header.stamp = stamp
        self._joints.position = positions
        self._joints.velocity = velocities
        self.joints_pub.publish(self._joints)

    def close(self):
        self.world.close()


def main():
    rospy.init_node('tb3_sim')
    try:
        config = params.resolve(lambda name, default: rospy.get_param('~' + name, default))
        geometry = read_drive_geometry(config['urdf_file'])
    except (params.ParameterError, ModelError) as error:
        rospy.logfatal('tb3_sim cannot start: %s', error)
        sys.exit(2)
    rospy.loginfo('tb3_sim parameters: %s', ', '.join('%s=%r' % item for item in config.items()))
    rospy.loginfo('tb3_sim drive geometry from %s: wheel radius %.4f m, separation %.4f m',
                  config['urdf_file'], geometry.wheel_radius, geometry.wheel_separation)
    node = SimulatorNode(config, geometry)
    try:
        node.run()
    finally:
        node.close()
