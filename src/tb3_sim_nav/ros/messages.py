"""ROS messages filled from the simulation's readings; no master needed.

Each message is made once per robot and reused: a publication changes only
its stamp and values.
"""
import numpy as np
import rospy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, LaserScan, PointCloud2, PointField
from visualization_msgs.msg import Marker, MarkerArray

from ..robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT

# Diagonal covariances of odom, as Gazebo's diff-drive plugin fills them:
# x, y and yaw are known well; z, roll and pitch are not estimated at all.
ODOM_COVARIANCE = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def stamp_of(now_ns):
    """The ROS time of sim time `now_ns` (ns), exactly."""
    return rospy.Time(*divmod(now_ns, 1000000000))


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
    message.orientation_covariance = diagonal([1e-6] * 3)
    imu_noise(message, gyro_noise, accel_noise)
    return message


def imu_noise(message, gyro_noise, accel_noise):
    """The covariances of an IMU whose noise has these standard deviations; a zero
    covariance would claim a perfect sensor: keep a floor."""
    message.angular_velocity_covariance = diagonal([max(gyro_noise ** 2, 1e-8)] * 3)
    message.linear_acceleration_covariance = diagonal([max(accel_noise ** 2, 1e-6)] * 3)


def fill_imu(message, stamp, reading):
    message.header.stamp = stamp
    _set_quaternion(message.orientation, reading.orientation)
    _set_xyz(message.angular_velocity, reading.angular_velocity)
    _set_xyz(message.linear_acceleration, reading.linear_acceleration)


#: Bytes per pixel of the image encodings the cameras publish.
ENCODINGS = {'rgb8': 3, '32FC1': 4}
#: A point of the depth cloud: x, y, z (m, optical frame) and its colour packed in a float32, as PCL's rgb.
POINT = np.dtype([('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('rgb', '<f4')])


def image(frame, width, height, encoding):
    message = Image(height=height, width=width, encoding=encoding, is_bigendian=0,
                    step=width * ENCODINGS[encoding])
    message.header.frame_id = frame
    return message


def fill_image(message, stamp, pixels):
    """`pixels`: H x W x 3 uint8 (rgb8) or H x W float32 (32FC1, metres)."""
    message.header.stamp = stamp
    message.data = pixels.astype(pixels.dtype.newbyteorder('<'), copy=False).tobytes()


def camera_info(frame, camera):
    """The CameraInfo of a camera.Camera: K from its size and field of view, no distortion."""
    fx, _, cx, _, fy, cy, _, _, _ = camera.intrinsics()
    message = CameraInfo(width=camera.width, height=camera.height, distortion_model='plumb_bob',
                         D=[0.0] * 5, K=list(camera.intrinsics()), R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                         P=[fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0])
    message.header.frame_id = frame
    return message


def points(frame, width, height):
    """An organised PointCloud2 of x, y, z and rgb, H x W points, NaN where there is no depth."""
    fields = [PointField(name=name, offset=POINT.fields[name][1], datatype=PointField.FLOAT32, count=1)
              for name in POINT.names]
    message = PointCloud2(height=height, width=width, fields=fields, is_bigendian=False,
                          point_step=POINT.itemsize, row_step=POINT.itemsize * width, is_dense=False)
    message.header.frame_id = frame
    return message


def fill_points(message, stamp, xyz, rgb):
    """`xyz`: H x W x 3 float32, `rgb`: H x W x 3 uint8."""
    cloud = np.empty(xyz.shape[:2], dtype=POINT)
    cloud['x'], cloud['y'], cloud['z'] = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    packed = (rgb[..., 0].astype(np.uint32) << 16) | (rgb[..., 1].astype(np.uint32) << 8) | rgb[..., 2]
    cloud['rgb'] = packed.view(np.float32)
    message.header.stamp = stamp
    message.data = cloud.tobytes()


MARKER_TYPES = {'box': Marker.CUBE, 'cylinder': Marker.CYLINDER, 'sphere': Marker.SPHERE}


def world_markers(frame, shapes, stamp):
    """A MarkerArray of (model name, model_files.Shape) pairs, in `frame`: the
    last ones cleared first, then one marker per shape (namespace: its model),
    locked to `frame` so rviz moves them with it."""
    array = MarkerArray(markers=[Marker(action=Marker.DELETEALL)])
    array.markers[0].header.frame_id = frame
    for index, (name, shape) in enumerate(shapes):
        marker = Marker(ns=name, id=index, type=MARKER_TYPES[shape.kind], action=Marker.ADD, frame_locked=True)
        marker.header.frame_id, marker.header.stamp = frame, stamp
        (position, orientation) = shape.pose
        marker.pose.position.x, marker.pose.position.y, marker.pose.position.z = position
        (marker.pose.orientation.x, marker.pose.orientation.y, marker.pose.orientation.z,
         marker.pose.orientation.w) = orientation
        if shape.kind == 'box':
            marker.scale.x, marker.scale.y, marker.scale.z = shape.size
        elif shape.kind == 'cylinder':
            marker.scale.x = marker.scale.y = 2.0 * shape.size[0]
            marker.scale.z = shape.size[1]
        else:
            marker.scale.x = marker.scale.y = marker.scale.z = 2.0 * shape.size[0]
        marker.color.r, marker.color.g, marker.color.b, marker.color.a = shape.color
        array.markers.append(marker)
    return array
