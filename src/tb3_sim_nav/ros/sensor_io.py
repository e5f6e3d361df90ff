"""Each sensor's ROS side: one IO class per kind of sensor, owning its publishers and its schedule.

An IO is `due(now_ns, paced)` when its schedule says so and someone reads one of
its topics (the sensors cost most of a step: nobody listening, nothing computed);
the node then reads every due sensor at once (sensors.read_all) and hands
each IO its reading to `publish(stamp, reading)`. An IO whose topics do not
all need the reading (a camera_info alone) says so in needs_reading().
IO_CLASSES maps each core sensor kind to its IO class.

A robot with a name lives in its namespace and prefixes its frames, as
ROBOTIS' multi-robot set-up does (tb3_0/odom, tb3_0/odom -> tb3_0/base_footprint);
the tutorial's robot has no name.
"""
import time

from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, LaserScan, PointCloud2

from .. import sensors
from ..camera import Camera
from ..frames import compose, inverse
from ..pacing import Schedule, WallShare
from . import messages

#: The most of the wall time a camera's frames may take while paced (CameraIO).
CAMERA_WALL_SHARE = 0.5


class SensorIO(object):
    """What every IO shares: the sensor, its schedule, its publishers."""

    def __init__(self, sensor, prefix):
        self.sensor = sensor
        self.prefix = prefix
        self.schedule = Schedule(round(1e9 / sensor.rate))
        self.publishers = []
        self.lockstep_readers = ()  # publishers whose local readers that publish tf lockstep waits for
        self.transforms = ()        # what it adds to the step's one tf message, once published
        self.odom_frame = None      # an odometry's frame, which the world links to (odom_parents.py)

    def advertise(self, publishers, topic, message_class):
        publisher = publishers.advertise(self.prefix + topic, message_class)
        self.publishers.append(publisher)
        return publisher

    def wanted(self):
        return any(publisher.get_num_connections() for publisher in self.publishers)

    def due(self, now_ns, paced=False):
        """`paced`: the simulation keeps to a real-time factor (not as fast as possible)."""
        return self.schedule.due(now_ns) and self.wanted()

    def restart(self):
        """Due at the next step, as at start (sim time went back to zero)."""
        self.schedule.restart()

    def needs_reading(self):
        return True

    def publish(self, stamp, reading):
        raise NotImplementedError

    def close(self):
        for publisher in self.publishers:
            publisher.unregister()


class OdomIO(SensorIO):
    """odom and base_pose_ground_truth, and for the step's tf message odom -> base
    (the same stamp as odom) and world -> odom (where odometry puts the world, so
    that what is drawn in the world frame appears under the lidar's dots in any
    profile). Always due on schedule: tf needs it whoever reads odom."""

    def __init__(self, sensor, prefix, publishers, config):
        super(OdomIO, self).__init__(sensor, prefix)
        self.odom_frame = odom_frame = prefix + config.odom_frame
        base_frame = prefix + config.base_frame
        self.odom = messages.odometry(odom_frame, base_frame)
        self.truth = messages.odometry(odom_frame, base_frame, covariance=False)
        self.transform = messages.transform(odom_frame, base_frame)
        self.world_transform = messages.transform(config.world_frame, odom_frame) if config.world_frame else None
        self.odom_pub = self.advertise(publishers, 'odom', Odometry)
        self.truth_pub = self.advertise(publishers, 'base_pose_ground_truth', Odometry)
        self.transforms = (self.transform,)

    def wanted(self):
        return True

    def publish(self, stamp, reading):
        truth, (pose, twist) = reading
        messages.fill_transform(self.transform, stamp, pose)
        if self.world_transform is not None:
            messages.fill_transform(self.world_transform, stamp, compose(truth[0], inverse(pose)))
        if self.odom_pub.get_num_connections():
            messages.fill_odometry(self.odom, stamp, pose, twist)
            self.odom_pub.publish(self.odom)
        if self.truth_pub.get_num_connections():
            messages.fill_odometry(self.truth, stamp, *truth)
            self.truth_pub.publish(self.truth)


class JointStatesIO(SensorIO):
    """joint_states, and for a robot with a name (unless ~robot_state_publisher is
    false) what robot_state_publisher would make of them: the wheels' links in
    the step's tf message, stamped as joint_states (robot_state.py)."""

    def __init__(self, sensor, prefix, publishers, config):
        super(JointStatesIO, self).__init__(sensor, prefix)
        self.message = messages.joint_states()
        self.publisher = self.advertise(publishers, 'joint_states', JointState)
        if prefix and config.robot_state_publisher:
            self.transforms = tuple(messages.transform(prefix + joint.parent, prefix + joint.child)
                                    for joint in sensor.joints)

    def wanted(self):
        return bool(self.transforms) or super(JointStatesIO, self).wanted()

    def publish(self, stamp, reading):
        messages.fill_joint_states(self.message, stamp, *reading)
        self.publisher.publish(self.message)
        for transform, joint, position in zip(self.transforms, self.sensor.joints, reading.positions):
            messages.fill_transform(transform, stamp, joint.pose(position))


class ScanIO(SensorIO):

    def __init__(self, sensor, prefix, publishers, config):
        super(ScanIO, self).__init__(sensor, prefix)
        self.message = messages.scan(prefix + sensor.link, sensor, sensor.rate)
        self.publisher = self.advertise(publishers, 'scan', LaserScan)
        self.lockstep_readers = (self.publisher,)  # a SLAM or a localizer reads the scan and publishes tf

    def publish(self, stamp, reading):
        messages.fill_scan(self.message, stamp, reading)
        self.publisher.publish(self.message)


class ImuIO(SensorIO):
    """The IMU; its covariances follow the sensor's noise, which dynamic_reconfigure may change."""

    def __init__(self, sensor, prefix, publishers, config):
        super(ImuIO, self).__init__(sensor, prefix)
        self._noise = (sensor.gyro_noise, sensor.accel_noise)
        self.message = messages.imu(prefix + sensor.link, *self._noise)
        self.publisher = self.advertise(publishers, 'imu', Imu)

    def publish(self, stamp, reading):
        noise = (self.sensor.gyro_noise, self.sensor.accel_noise)
        if noise != self._noise:
            messages.imu_noise(self.message, *noise)
            self._noise = noise
        messages.fill_imu(self.message, stamp, reading)
        self.publisher.publish(self.message)


class CameraIO(SensorIO):
    """One camera's topics, as Gazebo's camera plugins name them: the colour
    image and its camera_info; a depth camera's depth image, its camera_info
    and its cloud too. Rendered only while someone subscribes to an image.

    Paced, a camera's frames (render and publish) take at most
    CAMERA_WALL_SHARE of the wall time, and a frame due before then is
    dropped, as Gazebo's rendering, which runs beside its physics, delivers
    fewer frames when short of time and never slows the world down. A frame
    costs 40 ms of CPU on Mesa's llvmpipe at best; on this 2-core VM, shared
    and loaded, 85 ms and 0.5 s of wall time: rendering every frame held the
    world at 0.1 of real time (rviz_camera.test's robot did not get round its
    circle). On a quiet machine a 640 x 480 frame takes 32 ms of wall time:
    the default 15 Hz (67 ms apart) all render. As fast as possible (factor
    0), every frame is rendered."""

    def __init__(self, sensor, prefix, publishers, config):
        super(CameraIO, self).__init__(sensor, prefix)
        self._share = WallShare(CAMERA_WALL_SHARE)
        spec = sensor.spec
        frame = prefix + spec.frame
        self.image = messages.image(frame, sensor.width, sensor.height, 'rgb8')
        self.info = messages.camera_info(frame, sensor)
        self.image_pub = self.advertise(publishers, spec.image_topic, Image)
        self.info_pubs = [self.advertise(publishers, spec.info_topic, CameraInfo)]
        self.depth_pub = self.points_pub = None
        if spec.depth:
            self.depth = messages.image(frame, sensor.width, sensor.height, '32FC1')
            self.points = messages.points(frame, sensor.width, sensor.height)
            self.depth_pub = self.advertise(publishers, spec.depth_topic, Image)
            self.points_pub = self.advertise(publishers, spec.points_topic, PointCloud2)
            self.info_pubs.append(self.advertise(publishers, spec.depth_info_topic, CameraInfo))

    def needs_reading(self):
        return any(publisher is not None and publisher.get_num_connections()
                   for publisher in (self.image_pub, self.depth_pub, self.points_pub))

    def due(self, now_ns, paced=False):
        return super(CameraIO, self).due(now_ns) and not (paced and not self._share.allows() and
                                                          self.needs_reading())

    def publish(self, stamp, reading):
        started = time.monotonic()
        if reading is not None:
            rgb, depth = reading
            if self.image_pub.get_num_connections():
                messages.fill_image(self.image, stamp, rgb)
                self.image_pub.publish(self.image)
            if self.depth_pub is not None and self.depth_pub.get_num_connections():
                messages.fill_image(self.depth, stamp, depth)
                self.depth_pub.publish(self.depth)
            if self.points_pub is not None and self.points_pub.get_num_connections():
                messages.fill_points(self.points, stamp, self.sensor.points(depth), rgb)
                self.points_pub.publish(self.points)
        self.info.header.stamp = stamp
        for publisher in self.info_pubs:
            if publisher.get_num_connections():
                publisher.publish(self.info)
        if reading is not None:
            self._share.spent(self.sensor.render_seconds + time.monotonic() - started)


#: The IO class of each kind of sensor.
IO_CLASSES = {sensors.Odometry: OdomIO, sensors.WheelEncoders: JointStatesIO, sensors.Lidar: ScanIO,
              sensors.Imu: ImuIO, Camera: CameraIO}
