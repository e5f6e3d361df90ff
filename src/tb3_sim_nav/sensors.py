"""A robot's sensors: each one unit with one small protocol. No ROS here.

Every sensor has
    name            its kind, which is also its topic's stem: 'odom', 'joint_states', 'scan', 'imu', 'camera'
    rate            Hz of sim time it is read at (the ROS edge schedules it)
    rate_parameter  the ~parameter that sets `rate`, for messages about it
    configure(config)  the live knobs of a params.Config, at start-up or while running
    reset()         after the robot was put back (reset_world, reset_simulation)
    update()        after every physics step (most do nothing)
    read(now_ns)    its reading at sim time `now_ns`, in plain numbers (SI units, its own frame)
and the class a `build(body, model, config, rng)` that gives the robot's
sensors of that kind (none when the config switches it off). Kinds that
gain from being read together (the lidars: one ray cast for all) also have
`read_all(sensors, now_ns)`. The robot holds its sensors as one list
(robot.py's KINDS makes it); the ROS edge gives each an IO class
(ros/sensor_io.py). doc/design.md, "Adding a sensor", lists the files.
"""
import math
from collections import namedtuple

import numpy as np

from .frames import matrix
from .odometry import WheelOdometry, WorldOdometry
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT

ImuReading = namedtuple('ImuReading', 'orientation angular_velocity linear_acceleration')
#: The true pose and twist of base_footprint (pose in the world, twist in its own frame), and odom's.
OdometryReading = namedtuple('OdometryReading', 'truth odom')
#: Wheel angles (rad) and speeds (rad/s), left then right.
WheelReading = namedtuple('WheelReading', 'positions velocities')

LIDAR_LINK = 'base_scan'
IMU_LINK = 'imu_link'


class Sensor(object):
    """The protocol's defaults."""

    name = None
    rate_parameter = None

    def __init__(self, body, rate):
        self.body = body
        self.rate = rate

    def configure(self, config):
        pass

    def reset(self):
        pass

    def update(self):
        pass

    def read(self, now_ns):
        raise NotImplementedError

    @classmethod
    def read_all(cls, sensors, now_ns):
        return [sensor.read(now_ns) for sensor in sensors]


class Odometry(Sensor):
    """odom and the ground truth, from the robot's odometry source: the world
    (Gazebo) or its wheel encoders (the firmware), chosen by ~odom_source."""

    name, rate_parameter = 'odom', 'odom_rate'

    def __init__(self, body, rate, source):
        super(Odometry, self).__init__(body, rate)
        self.source = source

    @classmethod
    def build(cls, body, model, config, rng):
        source = WorldOdometry() if config.odom_source == 'world' else WheelOdometry(body, model.geometry, config, rng)
        return [cls(body, config.odom_rate, source)]

    def configure(self, config):
        self.source.configure(config)

    def reset(self):
        self.source.reset(self.body.base_pose())

    def update(self):
        self.source.update()

    def read(self, now_ns):
        truth = (self.body.base_pose(), self.body.base_twist())
        return OdometryReading(truth, self.source.read(truth))


class WheelEncoders(Sensor):
    """The wheels' joint states; `joints` are the wheels' URDF joints, left then right."""

    name, rate_parameter = 'joint_states', 'joint_states_rate'

    def __init__(self, body, rate, joints=()):
        super(WheelEncoders, self).__init__(body, rate)
        self.joints = tuple(joints)

    @classmethod
    def build(cls, body, model, config, rng):
        named = dict((joint.name, joint) for joint in model.joints)
        return [cls(body, config.joint_states_rate, [named[name] for name in (LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT)])]

    def read(self, now_ns):
        return WheelReading(*self.body.wheel_states())


class Lidar(Sensor):
    """A planar scanner (the LDS-01): `samples` beams over a full turn from angle 0, counter-clockwise.

    Ranges are hit distances plus Gaussian noise; a beam that hits nothing
    within `range_max` reads +inf and one that hits closer than `range_min`
    reads -inf (REP 117). The beams see the ground, the obstacles and the
    other robots, never the robot itself.
    """

    name, rate_parameter = 'scan', 'scan_rate'

    def __init__(self, body, link=LIDAR_LINK, samples=360, range_min=0.12, range_max=3.5, noise_stddev=0.01,
                 rng=None, rate=5.0):
        super(Lidar, self).__init__(body, rate)
        self.link = link
        self.range_min, self.range_max = range_min, range_max
        self.noise_stddev = noise_stddev
        self.rng = rng if rng is not None else np.random.default_rng()
        self.samples = samples
        self.angle_increment = 2.0 * math.pi / samples
        angles = np.arange(samples) * self.angle_increment
        self._beams = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(samples)])

    @classmethod
    def build(cls, body, model, config, rng):
        if not config.scan:
            return []
        return [cls(body, LIDAR_LINK, config.scan_samples, config.scan_range_min, config.scan_range_max,
                    config.scan_noise, rng, config.scan_rate)]

    def configure(self, config):
        self.noise_stddev = config.scan_noise

    def read(self, now_ns=None):
        """Ranges (m) of one full turn, as a numpy array."""
        return self.read_all([self], now_ns)[0]

    @classmethod
    def read_all(cls, lidars, now_ns=None):
        """The scans of several lidars of one world, their rays cast together."""
        if not lidars:
            return []
        poses = [lidar.body.link_pose(lidar.link) for lidar in lidars]
        directions = np.array([lidar._beams.dot(matrix(orientation).T) for lidar, (_, orientation) in
                               zip(lidars, poses)])
        reach = max(lidar.range_max for lidar in lidars)
        distances = lidars[0].body.world.rays.cast([position for position, _ in poses], directions, reach,
                                              [lidar.body for lidar in lidars])
        return [lidar._ranges(found) for lidar, found in zip(lidars, distances)]

    def _ranges(self, distances):
        hit = distances <= self.range_max
        ranges = np.where(hit, distances, math.inf)
        if self.noise_stddev > 0.0:
            ranges = ranges + self.rng.normal(0.0, self.noise_stddev, len(ranges))
        ranges[hit & (ranges < self.range_min)] = -math.inf
        ranges[hit & (ranges > self.range_max)] = math.inf
        return ranges


class Imu(Sensor):
    """Orientation, body rates and specific force (acceleration minus gravity)
    of the robot's base, in the base's axes (imu_link is aligned with them).

    Acceleration is the change of velocity between two readings, so the
    first reading after construction or reset assumes the robot was at rest.
    """

    name, rate_parameter = 'imu', 'imu_rate'
    link = IMU_LINK

    def __init__(self, body, gyro_noise=0.0, accel_noise=0.0, rng=None, rate=100.0):
        super(Imu, self).__init__(body, rate)
        self.gyro_noise, self.accel_noise = gyro_noise, accel_noise
        self.rng = rng if rng is not None else np.random.default_rng()
        self.reset()

    @classmethod
    def build(cls, body, model, config, rng):
        return [cls(body, config.imu_gyro_noise, config.imu_accel_noise, rng, config.imu_rate)] if config.imu else []

    def configure(self, config):
        self.gyro_noise, self.accel_noise = config.imu_gyro_noise, config.imu_accel_noise

    def reset(self):
        self._last = None  # (time s, world linear velocity)

    def read(self, now_ns):
        """The reading at simulated time `now_ns` (ns)."""
        now = now_ns * 1e-9
        _, orientation = self.body.base_pose()
        linear, angular = self.body.base_velocity()
        linear = np.asarray(linear)
        if self._last is None or now <= self._last[0]:
            acceleration = np.zeros(3)
        else:
            acceleration = (linear - self._last[1]) / (now - self._last[0])
        self._last = (now, linear)
        base_from_world = matrix(orientation).T
        specific_force = base_from_world.dot(acceleration - np.asarray(self.body.world.gravity))
        rates = base_from_world.dot(angular)
        if self.gyro_noise > 0.0:
            rates = rates + self.rng.normal(0.0, self.gyro_noise, 3)
        if self.accel_noise > 0.0:
            specific_force = specific_force + self.rng.normal(0.0, self.accel_noise, 3)
        return ImuReading(orientation, rates, specific_force)


def read_all(sensors, now_ns):
    """The readings of `sensors` (of one world) at `now_ns`, in their order; each
    kind reads its own together (read_all: one ray cast for every lidar)."""
    kinds = {}
    for sensor in sensors:
        kinds.setdefault(type(sensor), []).append(sensor)
    readings = {}
    for kind, group in kinds.items():
        readings.update(zip(map(id, group), kind.read_all(group, now_ns)))
    return [readings[id(sensor)] for sensor in sensors]
