"""ROS messages filled from the simulation's readings; no master needed.

Each message is made once per robot and reused: a publication changes only
its stamp and values.
"""
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState, LaserScan

from ..robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT

# Diagonal covariances of odom, as Gazebo's diff-drive plugin fills them:
# x, y and yaw are known well; z, roll and pitch are not estimated at all.
ODOM_COVARIANCE = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def diagonal(values):
    matrix = [0.0] * (len(values) ** 2)
    for index, value in enumerate(values):
        matrix[index * (len(values) + 1)] = value
    return matrix


def _set_xyz(vector, values):
    vector.x, vector.y, vector.z = values


def _set_quaternion(quaternion, values):
    quaternion.x, quaternion.y, quaternion.z, quaternion.w = values


def odometry(frame, child, covariance=True):
    message = Odometry()
    message.header.frame_id = frame
    message.child_frame_id = child
    if covariance:
        message.pose.covariance = diagonal(ODOM_COVARIANCE)
        message.twist.covariance = diagonal(ODOM_COVARIANCE)
    return message


def fill_odometry(message, stamp, pose, twist):
    """`pose` is ((x, y, z), (x, y, z, w)), `twist` ((linear), (angular)) in the child frame."""
    message.header.stamp = stamp
    _set_xyz(message.pose.pose.position, pose[0])
    _set_quaternion(message.pose.pose.orientation, pose[1])
    _set_xyz(message.twist.twist.linear, twist[0])
    _set_xyz(message.twist.twist.angular, twist[1])


def transform(frame, child):
    message = TransformStamped()
    message.header.frame_id = frame
    message.child_frame_id = child
    return message


def fill_transform(message, stamp, pose):
    message.header.stamp = stamp
    _set_xyz(message.transform.translation, pose[0])
    _set_quaternion(message.transform.rotation, pose[1])


def joint_states():
    return JointState(name=[LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT])


def fill_joint_states(message, stamp, positions, velocities):
    message.header.stamp = stamp
    message.position = positions
    message.velocity = velocities


def scan(frame, lidar, rate):
    """A LaserScan for a sensors.Lidar: a full turn from angle 0, counter-clockwise."""
    message = LaserScan(angle_min=0.0, angle_increment=lidar.angle_increment,
                        angle_max=lidar.angle_increment * (lidar.samples - 1), scan_time=1.0 / rate,
                        range_min=lidar.range_min, range_max=lidar.range_max)
    message.header.frame_id = frame
    return message


def fill_scan(message, stamp, ranges):
    message.header.stamp = stamp
    message.ranges = ranges.tolist()


def imu(frame, gyro_noise, accel_noise):
    message = Imu()
    message.header.frame_id = frame
    # A zero covariance would claim a perfect sensor: keep a floor.
    message.orientation_covariance = diagonal([1e-6] * 3)
    message.angular_velocity_covariance = diagonal([max(gyro_noise ** 2, 1e-8)] * 3)
    message.linear_acceleration_covariance = diagonal([max(accel_noise ** 2, 1e-6)] * 3)
    return message


def fill_imu(message, stamp, reading):
    message.header.stamp = stamp
    _set_quaternion(message.orientation, reading.orientation)
    _set_xyz(message.angular_velocity, reading.angular_velocity)
    _set_xyz(message.linear_acceleration, reading.linear_acceleration)
