"""The fake_localization node: ros-planning/navigation's (noetic) interface over fake_localization.localizer.

    rosrun fake_localization fake_localization
    <node pkg="fake_localization" type="fake_localization" name="fake_localization"/>

In: `base_pose_ground_truth` (nav_msgs/Odometry: only its pose is used; the
simulator publishes it, as Stage does) and `initialpose` (rviz's 2D Pose
Estimate). Out: latched `amcl_pose` (PoseWithCovarianceStamped, covariance
zero) and `particlecloud` (PoseArray of that one pose), both stamped as the
truth, and tf global_frame_id -> odom_frame_id, post-dated by
transform_tolerance, that puts base_frame_id on the estimate (odom -> base
is looked up at the truth's stamp, as the original's message filter waits
for it). Our simulator stops publishing world -> odom once another node
publishes a parent of odom (tb3_sim_nav.ros.odom_parents), so the two do
not fight over it.

As this project's other nodes, in a namespace (ROS_NAMESPACE=tb3_0) the
frames not set as parameters get the namespace as a prefix (tb3_0/odom,
tb3_0/base_link, tb3_0/map), as ROBOTIS' multi-robot frames are named.
Each truth is handled in its callback, start to end.
"""
import threading

import rospy
from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
from nav_msgs.msg import Odometry

from fake_localization.localizer import FakeLocalizationConfig, FakeLocalizer
from tb3_common.ros import lifecycle, params
from tb3_common.ros.frames import Frames, namespaced
from tb3_common.ros.poses import fill_pose, plane_pose

NODE = 'fake_localization'
FRAMES = ('odom_frame_id', 'base_frame_id', 'global_frame_id')
TF_WAIT = 0.2  # wall s a truth waits for odom -> base at its stamp (it comes with the truth, from the simulator)


class FakeLocalizationNode(object):

    def __init__(self, life):
        namespace = rospy.get_namespace()
        defaults = FakeLocalizationConfig()
        frames = dict((name, namespaced(getattr(defaults, name), namespace)) for name in FRAMES
                      if not rospy.has_param('~' + name))
        self.config = params.read_or_exit(NODE, FakeLocalizationConfig, overrides=frames)
        self.localizer = FakeLocalizer(self.config)
        self._lock = threading.Lock()  # the localizer, between the truth's and initialpose's threads
        self.frames = Frames(NODE)
        self.pose_pub = rospy.Publisher('amcl_pose', PoseWithCovarianceStamped, queue_size=1, latch=True)
        self.cloud_pub = rospy.Publisher('particlecloud', PoseArray, queue_size=1, latch=True)
        rospy.Subscriber('base_pose_ground_truth', Odometry, life.callback(self._on_truth), queue_size=100)
        rospy.Subscriber('initialpose', PoseWithCovarianceStamped, life.callback(self._on_initial_pose),
                         queue_size=1)

    def _on_truth(self, message):
        stamp = message.header.stamp
        config = self.config
        base_in_odom = self.frames.pose(config.odom_frame_id, config.base_frame_id, stamp, timeout=TF_WAIT)
        if base_in_odom is None:
            return
        try:
            with self._lock:
                estimate, odom_in_global = self.localizer.update(plane_pose(message), base_in_odom)
        except ValueError as error:
            self.frames.warn('truth', 'ignoring a ground truth: %s', error)
            return
        self.frames.send(config.global_frame_id, config.odom_frame_id, odom_in_global,
                         stamp + rospy.Duration(config.transform_tolerance))
        pose = PoseWithCovarianceStamped()
        pose.header.stamp, pose.header.frame_id = stamp, config.global_frame_id
        fill_pose(pose.pose.pose, estimate)
        self.pose_pub.publish(pose)
        cloud = PoseArray()
        cloud.header = pose.header
        cloud.poses = [pose.pose.pose]  # the particle cloud is the one pose
        self.cloud_pub.publish(cloud)

    def _on_initial_pose(self, message):
        frame = message.header.frame_id.lstrip('/')
        if frame != self.config.global_frame_id:
            rospy.logwarn('%s: frame id of "initialpose" (%s) is different from the global frame %s', NODE,
                          message.header.frame_id, self.config.global_frame_id)
        pose = plane_pose(message)
        try:
            with self._lock:
                self.localizer.set_pose(pose)
        except ValueError as error:
            rospy.logwarn('%s: ignoring an initial pose: %s', NODE, error)
            return
        rospy.loginfo('%s: initial pose (%.3f, %.3f, %.3f): the estimate moves there', NODE, *pose)


def main():
    life = lifecycle.init_node(NODE)
    FakeLocalizationNode(life)
    life.spin()

