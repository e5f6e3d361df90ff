"""Simulated LDS-01 lidar and IMU of one robot, read off its RobotBody. No ROS here.

Both return plain numbers (SI units, the sensor's own frame); the ROS edge
turns them into LaserScan and Imu messages.
"""
import math
from collections import namedtuple

import numpy as np
import pybullet


ImuReading = namedtuple('ImuReading', 'orientation angular_velocity linear_acceleration')


class Lidar(object):
    """A planar scanner: `samples` beams over a full turn from angle 0, counter-clockwise.

    Ranges are hit distances plus Gaussian noise; a beam that hits nothing
    within `range_max` reads +inf and one that hits closer than `range_min`
    reads -inf (REP 117). The beams see the ground, the obstacles and the
    other robots, never the robot itself.
    """

    def __init__(self, body, link, samples=360, range_min=0.12, range_max=3.5,
                 noise_stddev=0.01, rng=None):
        self.body = body
        self.link = link
        self.range_min, self.range_max = range_min, range_max
        self.noise_stddev = noise_stddev
        self.rng = rng if rng is not None else np.random.default_rng()
        self.samples = samples
        self.angle_increment = 2.0 * math.pi / samples
        angles = np.arange(samples) * self.angle_increment
        self._beams = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(samples)])

    def scan(self):
        """Ranges (m) of one full turn, as a numpy array."""
        origin, orientation = self.body.link_pose(self.link)
        rotation = np.reshape(pybullet.getMatrixFromQuaternion(orientation), (3, 3))
        ends = origin + self._beams.dot(rotation.T) * self.range_max
        ranges = self.body.world.cast_rays(origin, ends, ignore=self.body) * self.range_max
        hit_something = np.isfinite(ranges)
        if self.noise_stddev > 0.0:
            ranges = ranges + self.rng.normal(0.0, self.noise_stddev, len(ranges))
        ranges[hit_something & (ranges < self.range_min)] = -math.inf
        ranges[hit_something & (ranges > self.range_max)] = math.inf
        return ranges


class Imu(object):
    """Orientation, body rates and specific force (acceleration minus gravity)
    of the robot's base, in the base's axes (imu_link is aligned with them).

    Acceleration is the change of velocity between two readings, so the
    first reading after construction or reset assumes the robot was at rest.
    """

    def __init__(self, body, gyro_noise=0.0, accel_noise=0.0, rng=None):
        self.body = body
        self.gyro_noise, self.accel_noise = gyro_noise, accel_noise
        self.rng = rng if rng is not None else np.random.default_rng()
        self.reset()

    def reset(self):
        self._last = None  # (time s, world linear velocity)

    def read(self, now):
        """The reading at simulated time `now` (s)."""
        _, orientation = self.body.base_pose()
        linear, angular = self.body.base_velocity()
        linear = np.asarray(linear)
        if self._last is None or now <= self._last[0]:
            acceleration = np.zeros(3)
        else:
            acceleration = (linear - self._last[1]) / (now - self._last[0])
        self._last = (now, linear)
        base_from_world = np.reshape(pybullet.getMatrixFromQuaternion(orientation), (3, 3)).T
        specific_force = base_from_world.dot(acceleration - np.asarray(self.body.world.gravity))
        rates = base_from_world.dot(angular)
        if self.gyro_noise > 0.0:
            rates = rates + self.rng.normal(0.0, self.gyro_noise, 3)
        if self.accel_noise > 0.0:
            specific_force = specific_force + self.rng.normal(0.0, self.accel_noise, 3)
        return ImuReading(orientation, rates, specific_force)
