"""Differential-drive maths: command limits, wheel speeds, encoder odometry.

Plain floats in, plain floats out; SI units (m, rad, s) throughout.
"""
import math
from collections import namedtuple

from tb3_common.pose2d import normalize_angle

Limits = namedtuple('Limits', 'max_linear max_angular')

#: TurtleBot3 Burger, from ROBOTIS' specification and firmware.
BURGER_LIMITS = Limits(max_linear=0.22, max_angular=2.84)


def _clamp(value, limit):
    return max(-limit, min(limit, value))


def sanitize_twist(linear, angular, limits):
    """The command a differential drive can follow, and why it differs.

    `linear` and `angular` are the Twist's (x, y, z) triples. Returns
    (v, w, complaints): v and w finite and within `limits`, complaints a
    list of sentences for the user (empty when the command was fine).
    A message with any non-finite field is treated as corrupt: stop.
    """
    values = tuple(linear) + tuple(angular)
    if not all(math.isfinite(value) for value in values):
        return 0.0, 0.0, ['non-finite value in %s: stopping the robot' % (values,)]
    complaints = []
    v, w = float(linear[0]), float(angular[2])
    if any(linear[1:]) or any(angular[:2]):
        complaints.append('linear.y/z and angular.x/y are ignored: a differential drive '
                          'follows only linear.x and angular.z')
    clamped_v, clamped_w = _clamp(v, limits.max_linear), _clamp(w, limits.max_angular)
    if clamped_v != v:
        complaints.append('linear.x %g m/s clamped to %g' % (v, clamped_v))
    if clamped_w != w:
        complaints.append('angular.z %g rad/s clamped to %g' % (w, clamped_w))
    # "+ 0.0" turns -0.0 into 0.0, so a stop never reads as negative.
    return clamped_v + 0.0, clamped_w + 0.0, complaints


def wheel_speeds(v, w, wheel_radius, wheel_separation):
    """Left and right wheel angular speeds (rad/s) for body speeds v (m/s), w (rad/s)."""
    half_track = wheel_separation / 2.0
    return (v - w * half_track) / wheel_radius, (v + w * half_track) / wheel_radius


def body_twist(left, right, wheel_radius, wheel_separation):
    """Body speeds (v, w) for left and right wheel angular speeds (rad/s)."""
    return (wheel_radius * (left + right) / 2.0,
            wheel_radius * (right - left) / wheel_separation)


class EncoderOdometry(object):
    """Dead reckoning from wheel angles, as the TurtleBot3 firmware does it.

    Each update takes the total wheel angles (rad) and integrates the step
    with the heading at its midpoint (second-order Runge-Kutta). A base
    controller's calibration multiplies each step's distance by
    `linear_scale` and its turn by `angular_scale`.
    """

    def __init__(self, wheel_radius, wheel_separation, x=0.0, y=0.0, yaw=0.0, linear_scale=1.0,
                 angular_scale=1.0):
        self.wheel_radius = wheel_radius
        self.wheel_separation = wheel_separation
        self.linear_scale, self.angular_scale = linear_scale, angular_scale
        self.reset(x, y, yaw)

    def reset(self, x=0.0, y=0.0, yaw=0.0):
        self.x, self.y, self.yaw = x, y, yaw
        self._last_angles = None

    def update(self, left_angle, right_angle):
        if self._last_angles is not None:
            left_delta = left_angle - self._last_angles[0]
            right_delta = right_angle - self._last_angles[1]
            distance, turn = body_twist(left_delta, right_delta,
                                        self.wheel_radius, self.wheel_separation)
            distance, turn = distance * self.linear_scale, turn * self.angular_scale
            heading = self.yaw + turn / 2.0
            self.x += distance * math.cos(heading)
            self.y += distance * math.sin(heading)
            self.yaw = normalize_angle(self.yaw + turn)
        self._last_angles = (left_angle, right_angle)
        return self.x, self.y, self.yaw

    def twist(self, left_speed, right_speed):
        """Body speeds (v, w) these encoders read from wheel speeds (rad/s), scaled as the steps are."""
        v, w = body_twist(left_speed, right_speed, self.wheel_radius, self.wheel_separation)
        return v * self.linear_scale, w * self.angular_scale
