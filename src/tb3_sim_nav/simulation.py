"""One simulated TurtleBot3: world, drive, sensors and odometry, without ROS.

The ROS edge feeds it commands, steps it, and publishes what it reads off;
everything that decides what the robot does lives here, testable with pytest.
"""
import math

import numpy as np

from .diff_drive import EncoderOdometry, wheel_speeds
from .sensors import Imu, Lidar
from .world import SimWorld


class Simulation(object):
    """Physics steps of `1 / physics_rate` s; time is an integer count of steps."""

    def __init__(self, config, geometry, obstacles=(), world_class=SimWorld):
        self.config = config
        self.geometry = geometry
        self.step_ns = int(round(1e9 / config['physics_rate']))
        self.spawn_pose = (config['x_pos'], config['y_pos'], config['z_pos'], config['yaw'])
        self.world = world_class(config['urdf_file'], self.spawn_pose,
                                 time_step=self.step_ns * 1e-9, wheel_torque=config['wheel_torque'],
                                 gui=config['gui'], obstacles=obstacles,
                                 ground_friction=config['ground_friction'],
                                 caster_friction=config['caster_friction'])
        rng = np.random.default_rng(None if config['seed'] < 0 else config['seed'])
        self.lidar = Lidar(self.world, 'base_scan', config['scan_samples'], config['scan_range_min'],
                           config['scan_range_max'], config['scan_noise'], rng) if config['scan'] else None
        self.imu = Imu(self.world, config['imu_gyro_noise'], config['imu_accel_noise'],
                       rng) if config['imu'] else None
        self._rng = rng
        # The firmware's idea of the wheels, which the real ones may not match.
        self.encoder_odometry = EncoderOdometry(
            geometry.wheel_radius * (1.0 + config['odom_wheel_radius_error']),
            geometry.wheel_separation * (1.0 + config['odom_wheel_separation_error']))
        self.steps = 0
        self._reset_drive()

    # --- time ---------------------------------------------------------------
    @property
    def now_ns(self):
        return self.steps * self.step_ns

    # --- commands -----------------------------------------------------------
    def _reset_drive(self):
        self._target = (0.0, 0.0)        # wheel speeds asked for (rad/s)
        self._wheels = (0.0, 0.0)        # wheel speeds the motors are set to
        self._last_command_ns = None
        self.world.set_wheel_speeds(0.0, 0.0)
        x, y, _z, yaw = self.spawn_pose
        self.encoder_odometry.reset(x, y, yaw)

    def command(self, v, w):
        """A sanitised body command (m/s, rad/s), taking effect at the next step.

        The motors reach their speed only to within their errors: timing
        alone cannot know that, encoders can.
        """
        left, right = wheel_speeds(v, w, *self.geometry)
        self._target = (left * (1.0 + self.config['left_motor_error']),
                        right * (1.0 + self.config['right_motor_error']))
        self._last_command_ns = self.now_ns

    def _motor_speeds(self):
        """The wheel speeds for the next step: timeout and acceleration limit applied."""
        target = self._target
        timeout = self.config['cmd_vel_timeout']
        if (timeout > 0.0 and self._last_command_ns is not None
                and self.now_ns - self._last_command_ns > timeout * 1e9):
            target = (0.0, 0.0)
        limit = self.config['wheel_acceleration'] / self.geometry.wheel_radius * self.step_ns * 1e-9
        if limit > 0.0:
            target = tuple(current + max(-limit, min(limit, wanted - current))
                           for current, wanted in zip(self._wheels, target))
        return target

    # --- stepping -----------------------------------------------------------
    def step(self):
        speeds = self._motor_speeds()
        if speeds != self._wheels:
            self.world.set_wheel_speeds(*speeds)
            self._wheels = speeds
        self.world.step()
        self.steps += 1
        if self.config['odom_source'] == 'encoders':
            self._read_encoders()

    def reset_world(self):
        """Robot back to its spawn pose and at rest, odometry zeroed; time runs on."""
        self.world.reset_robot(self.spawn_pose)
        self._reset_drive()
        if self.imu:
            self.imu.reset()

    def reset_simulation(self):
        """reset_world, and time back to zero."""
        self.reset_world()
        self.steps = 0

    # --- readings -----------------------------------------------------------
    def true_pose(self):
        """Position (x, y, z) and orientation (x, y, z, w) of base_footprint."""
        return self.world.base_pose()

    def _read_encoders(self):
        """Dead reckoning, every step as the firmware integrates every cycle."""
        angles, _ = self.world.wheel_states()
        noise = self.config['encoder_noise']
        if noise > 0.0:
            angles = np.asarray(angles) + self._rng.normal(0.0, noise, 2)
        self.encoder_odometry.update(*angles)

    def odometry_pose(self):
        """The pose odom reports: the true one (Gazebo) or the encoders' dead reckoning."""
        if self.config['odom_source'] == 'world':
            return self.true_pose()
        odometry = self.encoder_odometry
        return ((odometry.x, odometry.y, 0.0),
                (0.0, 0.0, math.sin(odometry.yaw / 2.0), math.cos(odometry.yaw / 2.0)))

    def true_twist(self):
        """Body-frame linear and angular velocity of base_footprint."""
        return self.world.base_twist()

    def odometry(self, truth):
        """odom's (pose, twist), given the true ones: the truth itself (Gazebo)
        or the encoders' dead reckoning, without reading the world twice."""
        if self.config['odom_source'] == 'world':
            return truth
        return self.odometry_pose(), self.odometry_twist()

    def odometry_twist(self):
        """Body-frame linear and angular velocity that odom reports."""
        if self.config['odom_source'] == 'world':
            return self.world.base_twist()
        _, speeds = self.world.wheel_states()
        radius = self.encoder_odometry.wheel_radius
        separation = self.encoder_odometry.wheel_separation
        return ((radius * (speeds[0] + speeds[1]) / 2.0, 0.0, 0.0),
                (0.0, 0.0, radius * (speeds[1] - speeds[0]) / separation))

    def wheel_states(self):
        return self.world.wheel_states()

    def scan(self):
        return self.lidar.scan()

    def imu_reading(self):
        return self.imu.read(self.now_ns * 1e-9)

    def close(self):
        self.world.close()
