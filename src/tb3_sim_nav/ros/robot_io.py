"""One robot's ROS interface: cmd_vel in; odom, tf, ground truth, joint states, scan, IMU out.

A robot with a name lives in its namespace and prefixes its frames, as
ROBOTIS' multi-robot set-up does (tb3_0/cmd_vel, tb3_0/odom ->
tb3_0/base_footprint); the tutorial's robot has no name: cmd_vel, odom ->
base_footprint.
"""
import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, LaserScan, PointCloud2

from ..diff_drive import sanitize_twist
from ..frames import compose, inverse
from ..pacing import Schedule
from ..robot import LIDAR_LINK
from . import messages

IMU_LINK = 'imu_link'


class RobotIO(object):

    def __init__(self, robot, config, publishers, throttle, on_command=None):
        """`on_command()` is called from the thread that received a command."""
        self.robot = robot
        self.prefix = prefix = robot.name + '/' if robot.name else ''
        self._throttle = throttle
        self._on_command = on_command
        self._command = (0.0, 0.0, 0)  # v, w, count of commands received
        self._applied = 0
        self.odom_frame = odom_frame = prefix + config.odom_frame
        base_frame = prefix + config.base_frame
        self.odom = messages.odometry(odom_frame, base_frame)
        self.truth = messages.odometry(odom_frame, base_frame, covariance=False)
        self.transform = messages.transform(odom_frame, base_frame)
        # world -> odom: where odometry puts the world, so that what is drawn in
        # the world frame appears under the lidar's dots in any profile.
        self.world_transform = messages.transform(config.world_frame, odom_frame) if config.world_frame else None
        self.joints = messages.joint_states()
        self.odom_pub = publishers.advertise(prefix + 'odom', Odometry)
        self.truth_pub = publishers.advertise(prefix + 'base_pose_ground_truth', Odometry)
        self.joints_pub = publishers.advertise(prefix + 'joint_states', JointState)
        self.scan_pub = self.imu_pub = None
        if robot.lidar:
            self.scan = messages.scan(prefix + LIDAR_LINK, robot.lidar, config.scan_rate)
            self.scan_pub = publishers.advertise(prefix + 'scan', LaserScan)
        if robot.imu:
            self.imu = messages.imu(prefix + IMU_LINK, config.imu_gyro_noise, config.imu_accel_noise)
            self.imu_pub = publishers.advertise(prefix + 'imu', Imu)
        self.cameras = [CameraIO(camera, prefix, publishers) for camera in robot.cameras]
        self.cmd_vel = rospy.Subscriber(prefix + 'cmd_vel', Twist, self._on_cmd_vel, queue_size=10,
                                        tcp_nodelay=True)

    def _on_cmd_vel(self, twist):
        v, w, complaints = sanitize_twist((twist.linear.x, twist.linear.y, twist.linear.z),
                                          (twist.angular.x, twist.angular.y, twist.angular.z),
                                          self.robot.limits)
        for complaint in complaints:
            # Throttled per robot and kind (its first word), so that a flood of
            # one kind of bad command cannot hide another.
            if self._throttle.allow((self.prefix, complaint.split()[0])):
                rospy.logwarn('%scmd_vel: %s (at most one such warning per %g s)', self.prefix, complaint,
                              self._throttle.period)
        self._command = (v, w, self._command[2] + 1)  # one assignment; the step loop picks it up
        if self._on_command:
            self._on_command()

    def apply_command(self, now_ns):
        """Hand the robot the newest command, if one came since the last step."""
        v, w, count = self._command
        if count != self._applied:
            self.robot.command(v, w, now_ns)
            self._applied = count

    def publish_odometry(self, stamp):
        """odom and ground truth published, read off the world once; the
        odom -> base transform filled for the node's tf message."""
        truth = self.robot.truth()
        pose, twist = self.robot.odometry(truth)
        messages.fill_odometry(self.odom, stamp, pose, twist)
        messages.fill_odometry(self.truth, stamp, *truth)
        messages.fill_transform(self.transform, stamp, pose)
        if self.world_transform is not None:
            messages.fill_transform(self.world_transform, stamp, compose(truth[0], inverse(pose)))
        self.odom_pub.publish(self.odom)
        self.truth_pub.publish(self.truth)

    def publish_joint_states(self, stamp):
        messages.fill_joint_states(self.joints, stamp, *self.robot.wheel_states())
        self.joints_pub.publish(self.joints)

    def publish_scan(self, stamp):
        """The sensors cost most of a step: nobody listening, nothing computed (False)."""
        if not (self.scan_pub and self.scan_pub.get_num_connections()):
            return False
        messages.fill_scan(self.scan, stamp, self.robot.scan())
        self.scan_pub.publish(self.scan)
        return True

    def publish_imu(self, stamp, now_s):
        if not (self.imu_pub and self.imu_pub.get_num_connections()):
            return False
        messages.fill_imu(self.imu, stamp, self.robot.imu_reading(now_s))
        self.imu_pub.publish(self.imu)
        return True

    def publish_cameras(self, now_ns, stamp):
        published = False
        for camera in self.cameras:
            published = camera.publish(now_ns, stamp) or published
        return published

    def close(self):
        for topic in (self.odom_pub, self.truth_pub, self.joints_pub, self.scan_pub, self.imu_pub, self.cmd_vel):
            if topic is not None:
                topic.unregister()
        for camera in self.cameras:
            camera.close()


def _subscribed(publisher):
    return publisher is not None and publisher.get_num_connections() > 0


class CameraIO(object):
    """One camera's topics, as Gazebo's camera plugins name them: the colour
    image and its camera_info; a depth camera's depth image, its camera_info
    and its cloud too. Rendered only while someone subscribes to an image."""

    def __init__(self, camera, prefix, publishers):
        spec = camera.spec
        frame = prefix + spec.frame
        self.camera = camera
        self._due = Schedule(round(1e9 / camera.rate))
        self.image = messages.image(frame, camera.width, camera.height, 'rgb8')
        self.info = messages.camera_info(frame, camera)
        self.image_pub = publishers.advertise(prefix + spec.image_topic, Image)
        self.info_pubs = [publishers.advertise(prefix + spec.info_topic, CameraInfo)]
        self.depth_pub = self.points_pub = None
        if spec.depth:
            self.depth = messages.image(frame, camera.width, camera.height, '32FC1')
            self.points = messages.points(frame, camera.width, camera.height)
            self.depth_pub = publishers.advertise(prefix + spec.depth_topic, Image)
            self.points_pub = publishers.advertise(prefix + spec.points_topic, PointCloud2)
            self.info_pubs.append(publishers.advertise(prefix + spec.depth_info_topic, CameraInfo))

    def publish(self, now_ns, stamp):
        """Publishes what is due and wanted at `now_ns`; False if nothing was."""
        if not self._due.due(now_ns):
            return False
        wanted = [publisher for publisher in [self.image_pub, self.depth_pub, self.points_pub] + self.info_pubs
                  if _subscribed(publisher)]
        if not wanted:
            return False
        if set(wanted) & {self.image_pub, self.depth_pub, self.points_pub}:
            rgb, depth = self.camera.render()
            if self.image_pub in wanted:
                messages.fill_image(self.image, stamp, rgb)
                self.image_pub.publish(self.image)
            if self.depth_pub in wanted:
                messages.fill_image(self.depth, stamp, depth)
                self.depth_pub.publish(self.depth)
            if self.points_pub in wanted:
                messages.fill_points(self.points, stamp, self.camera.points(depth), rgb)
                self.points_pub.publish(self.points)
        self.info.header.stamp = stamp
        for publisher in self.info_pubs:
            if publisher in wanted:
                publisher.publish(self.info)
        return True

    def close(self):
        for publisher in [self.image_pub, self.depth_pub, self.points_pub] + self.info_pubs:
            if publisher is not None:
                publisher.unregister()
