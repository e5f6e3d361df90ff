"""Where a robot's odom comes from: the world (Gazebo) or its wheel encoders (firmware).

Both answer `read(truth)` with (pose, twist) given the true ones, so the
truth is read off the world once per publication; `update()` runs after
every physics step, `reset(pose)` after a reset (the spawn pose: odometry
starts there), and `configure(config)` when the knobs change. sensors.Odometry
is the sensor that holds one.
"""
import numpy as np

from .diff_drive import EncoderOdometry
from .frames import planar, yaw_of


class WorldOdometry(object):
    """Gazebo's TurtleBot3 odometry: the true pose and twist, no drift (and nothing to calibrate)."""

    def configure(self, config):
        pass

    def update(self):
        pass

    def reset(self, pose):
        pass

    def read(self, truth):
        return truth


class WheelOdometry(object):
    """The firmware's dead reckoning from the wheel angles, integrated every
    step. It believes in wheels that may differ from the real ones by the
    calibration errors, and reads the encoders with Gaussian noise."""

    def __init__(self, body, geometry, config, rng=None):
        self.body = body
        self.geometry = geometry
        self.rng = rng if rng is not None else np.random.default_rng()
        self.encoders = EncoderOdometry(geometry.wheel_radius, geometry.wheel_separation)
        self.configure(config)

    def configure(self, config):
        """The wheels it believes in, its noise and its calibration, from a params.Config."""
        self.noise = config.encoder_noise
        encoders = self.encoders
        encoders.wheel_radius = self.geometry.wheel_radius * (1.0 + config.odom_wheel_radius_error)
        encoders.wheel_separation = self.geometry.wheel_separation * (1.0 + config.odom_wheel_separation_error)
        encoders.linear_scale = config.odom_linear_scale_correction
        encoders.angular_scale = config.odom_angular_scale_correction

    def update(self):
        angles, _ = self.body.wheel_states()
        if self.noise > 0.0:
            angles = np.asarray(angles) + self.rng.normal(0.0, self.noise, 2)
        self.encoders.update(*angles)

    def reset(self, pose):
        (x, y, _), orientation = pose
        self.encoders.reset(x, y, yaw_of(orientation))

    def read(self, truth=None):
        encoders = self.encoders
        _, speeds = self.body.wheel_states()
        v, w = encoders.twist(*speeds)
        return planar(encoders.x, encoders.y, 0.0, encoders.yaw), ((v, 0.0, 0.0), (0.0, 0.0, w))
