"""Plane poses (x, y, yaw) to geometry_msgs and back: the one converter of every node of ours.

`plane_pose(message)` reads a pose from any message that carries one:
geometry_msgs Pose, PoseStamped, PoseWithCovariance(Stamped), Transform,
TransformStamped, nav_msgs Odometry (its pose). `pose_message`,
`pose_stamped` and `transform_stamped` go the other way. Yaw <-> quaternion
is tb3_common.pose2d's. Messages only: no rospy here.
"""
from geometry_msgs.msg import Pose, PoseStamped, TransformStamped

from ..pose2d import quaternion_of_yaw, yaw_of_quaternion


def _innermost(message):
    """The Pose or Transform inside `message`: .pose (twice for a PoseWithCovarianceStamped or an
    Odometry), .transform."""
    inner = message
    for _ in range(3):
        if hasattr(inner, 'position') or hasattr(inner, 'translation'):
            return inner
        inner = getattr(inner, 'pose', None) or getattr(inner, 'transform', None)
    raise TypeError('no pose in a %s' % type(message).__name__)


def plane_pose(message):
    """(x, y, yaw) of the pose in `message` (its height, roll and pitch dropped)."""
    inner = _innermost(message)
    position = inner.position if hasattr(inner, 'position') else inner.translation
    q = inner.orientation if hasattr(inner, 'orientation') else inner.rotation
    return position.x, position.y, yaw_of_quaternion(q.x, q.y, q.z, q.w)


def fill_pose(target, pose):
    """Write the plane pose (x, y, yaw) into a Pose or Transform `target`; returns it."""
    position = target.position if hasattr(target, 'position') else target.translation
    q = target.orientation if hasattr(target, 'orientation') else target.rotation
    position.x, position.y, position.z = float(pose[0]), float(pose[1]), 0.0
    q.x, q.y, q.z, q.w = quaternion_of_yaw(float(pose[2]))
    return target


def pose_message(pose):
    """A geometry_msgs/Pose at (x, y, yaw)."""
    return fill_pose(Pose(), pose)


def pose_stamped(pose, frame_id, stamp):
    """A geometry_msgs/PoseStamped at (x, y, yaw) in `frame_id`."""
    message = PoseStamped()
    message.header.frame_id, message.header.stamp = frame_id, stamp
    fill_pose(message.pose, pose)
    return message


def transform_stamped(parent, child, pose, stamp):
    """The geometry_msgs/TransformStamped parent -> child that puts `child` at (x, y, yaw) in `parent`."""
    message = TransformStamped()
    message.header.frame_id, message.header.stamp, message.child_frame_id = parent, stamp, child
    fill_pose(message.transform, pose)
    return message
