"""Angle helpers that the *ROS by Example* navigation scripts import.

Same names and behaviour as rbx1_nav's module, built on PyKDL as it is.
"""
from math import pi

import PyKDL


def quat_to_angle(quat):
    """Yaw (rad) of a geometry_msgs/Quaternion (or anything with x, y, z, w)."""
    rotation = PyKDL.Rotation.Quaternion(quat.x, quat.y, quat.z, quat.w)
    _roll, _pitch, yaw = rotation.GetRPY()
    return yaw


def normalize_angle(angle):
    """`angle` (rad) brought into [-pi, pi] by whole turns."""
    while angle > pi:
        angle -= 2.0 * pi
    while angle < -pi:
        angle += 2.0 * pi
    return angle
