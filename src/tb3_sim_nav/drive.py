"""A differential drive's motor controller: body commands in, wheel speeds out.

What a TurtleBot3's firmware and motors make of a command: each wheel's
speed ramps at most `wheel_acceleration` per second, a motor may turn a
fraction faster or slower than asked, and with a command timeout the robot
stops when commands cease. Time is integer nanoseconds of simulated time.
"""
from .diff_drive import wheel_speeds


class Drive(object):

    def __init__(self, geometry, wheel_acceleration=1.0, cmd_vel_timeout=0.0, motor_errors=(0.0, 0.0)):
        self.geometry = geometry
        self.configure(wheel_acceleration, cmd_vel_timeout, motor_errors)
        self.reset()

    def configure(self, wheel_acceleration, cmd_vel_timeout, motor_errors):
        """The knobs, at start-up or while running (the next step uses them)."""
        self.cmd_vel_timeout_ns = cmd_vel_timeout * 1e9
        self.motor_errors = tuple(motor_errors)
        # rad/s per second of a wheel whose rim may gain `wheel_acceleration` m/s per second
        self.wheel_acceleration = wheel_acceleration / self.geometry.wheel_radius

    def reset(self):
        self._target = (0.0, 0.0)     # wheel speeds asked for (rad/s), before the motors' errors
        self.speeds = (0.0, 0.0)      # wheel speeds the motors are set to
        self._last_command_ns = None

    def command(self, v, w, now_ns):
        """A sanitised body command (m/s, rad/s), taking effect at the next step.

        The motors reach their speed only to within their errors: timing
        alone cannot know that, encoders can.
        """
        self._target = wheel_speeds(v, w, *self.geometry)
        self._last_command_ns = now_ns

    def step(self, now_ns, step_s):
        """The wheel speeds for the step from `now_ns`: timeout and acceleration limit applied."""
        target = tuple(speed * (1.0 + error) for speed, error in zip(self._target, self.motor_errors))
        if (self.cmd_vel_timeout_ns > 0.0 and self._last_command_ns is not None
                and now_ns - self._last_command_ns > self.cmd_vel_timeout_ns):
            target = (0.0, 0.0)
        limit = self.wheel_acceleration * step_s
        if limit > 0.0:
            target = tuple(current + max(-limit, min(limit, wanted - current))
                           for current, wanted in zip(self.speeds, target))
        self.speeds = target
        return target
