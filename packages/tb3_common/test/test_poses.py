"""The one pose converter: every message that carries a pose, both ways, and yaw <-> quaternion."""
import math

import pytest
from geometry_msgs.msg import PoseArray, PoseStamped, PoseWithCovarianceStamped, TransformStamped
from nav_msgs.msg import Odometry
from tf.transformations import euler_from_quaternion, quaternion_from_euler

from tb3_common.pose2d import quaternion_of_yaw, yaw_of_quaternion
from tb3_common.ros.poses import fill_pose, plane_pose, pose_message, pose_stamped, transform_stamped

POSE = (1.5, -2.25, 2.9)


@pytest.mark.parametrize('message', [PoseStamped(), PoseWithCovarianceStamped(), Odometry(), TransformStamped()])
def test_every_message_that_carries_a_pose_reads_back_what_was_written(message):
    inner = message.transform if isinstance(message, TransformStamped) else message.pose
    fill_pose(inner.pose if hasattr(inner, 'pose') else inner, POSE)
    assert plane_pose(message) == pytest.approx(POSE, abs=1e-12)


def test_the_builders_put_the_pose_frame_and_stamp_where_ros_reads_them():
    assert plane_pose(pose_message(POSE)) == pytest.approx(POSE, abs=1e-12)
    stamped = pose_stamped(POSE, 'map', None)
    assert stamped.header.frame_id == 'map' and plane_pose(stamped) == pytest.approx(POSE, abs=1e-12)
    transform = transform_stamped('map', 'odom', POSE, None)
    assert (transform.header.frame_id, transform.child_frame_id) == ('map', 'odom')
    assert transform.transform.translation.z == 0.0 and plane_pose(transform) == pytest.approx(POSE, abs=1e-12)


def test_a_message_without_a_pose_is_refused():
    with pytest.raises(TypeError, match='no pose in a PoseArray'):
        plane_pose(PoseArray())


@pytest.mark.parametrize('roll, pitch, yaw', [(0.0, 0.0, 0.7), (0.0, 0.0, -3.1), (0.3, -0.2, 2.5), (0.0, 0.0, math.pi)])
def test_yaw_of_a_quaternion_is_tfs_even_tilted_or_not_normalised(roll, pitch, yaw):
    q = quaternion_from_euler(roll, pitch, yaw)
    assert yaw_of_quaternion(*q) == pytest.approx(euler_from_quaternion(q)[2], abs=1e-12)
    assert yaw_of_quaternion(*(3.0 * q)) == pytest.approx(euler_from_quaternion(q)[2], abs=1e-12)
    assert yaw_of_quaternion(*quaternion_of_yaw(yaw)) == pytest.approx(math.atan2(math.sin(yaw), math.cos(yaw)))
