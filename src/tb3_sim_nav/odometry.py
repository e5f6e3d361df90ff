"""Where a robot's odom comes from: the world (Gazebo) or its wheel encoders (firmware).

Both answer `read(truth)` with (pose, twist) given the true ones, so the
truth is read off the world once per publication; `update()` runs after
every physics step and `reset(x, y, yaw)` after a reset.
"""
import math

import numpy as np

from .diff_drive import EncoderOdometry


class WorldOdometry(object):
    """Gazebo's TurtleBot3 odometry: the true pose and twist, no drift."""

    def update(self):
        pass

    def reset(self, x, y, yaw):
        pass

    def read(self, truth):
        return truth


class WheelOdometry(object):
    """The firmware's dead reckoning from the wheel angles, integrated every
    step. It believes in wheels that may differ from the real ones by the
    calibration errors, and reads the encoders with Gaussian noise."""

    def __init__(self, body, geometry, radius_error=0.0, separation_error=0.0, noise=0.0, rng=None):
        self.body = body
        self.noise = noise
        self.rng = rng if rng is not None else np.random.default_rng()
        self.encoders = EncoderOdometry(geometry.wheel_radius * (1.0 + radius_error),
                                        geometry.wheel_separation * (1.0 + separation_error))

    def update(self):
        angles, _ = self.body.wheel_states()
        if self.noise > 0.0:
            angles = np.asarray(angles) + self.rng.normal(0.0, self.noise, 2)
        self.encoders.update(*angles)

    def reset(self, x, y, yaw):
        self.encoders.reset(x, y, yaw)

    def read(self, truth=None):
        encoders = self.encoders
        _, speeds = self.body.wheel_states()
        radius, separation = encoders.wheel_radius, encoders.wheel_separation
        pose = ((encoders.x, encoders.y, 0.0),
                (0.0, 0.0, math.sin(encoders.yaw / 2.0), math.cos(encoders.yaw / 2.0)))
        twist = ((radius * (speeds[0] + speeds[1]) / 2.0, 0.0, 0.0),
                 (0.0, 0.0, radius * (speeds[1] - speeds[0]) / separation))
        return pose, twist
