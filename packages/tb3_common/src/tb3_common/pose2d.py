"""Poses in the plane, (x, y, yaw) tuples or arrays (..., 3): compose, invert, relate. No ROS here."""
import math

import numpy as np

IDENTITY = (0.0, 0.0, 0.0)


def normalize_angle(angle):
    """`angle` (a number or an array) in [-pi, pi)."""
    wrapped = (np.asarray(angle, dtype=float) + math.pi) % (2.0 * math.pi) - math.pi
    return float(wrapped) if wrapped.ndim == 0 else wrapped


def compose(a, b):
    """Pose `b`, given in the frame of pose `a`, in the frame `a` is given in (arrays broadcast)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    cos, sin = np.cos(a[..., 2]), np.sin(a[..., 2])
    return np.stack((a[..., 0] + cos * b[..., 0] - sin * b[..., 1],
                     a[..., 1] + sin * b[..., 0] + cos * b[..., 1],
                     normalize_angle(a[..., 2] + b[..., 2])), axis=-1)


def inverse(pose):
    pose = np.asarray(pose, dtype=float)
    cos, sin = np.cos(pose[..., 2]), np.sin(pose[..., 2])
    return np.stack((-cos * pose[..., 0] - sin * pose[..., 1],
                     sin * pose[..., 0] - cos * pose[..., 1],
                     normalize_angle(-pose[..., 2])), axis=-1)


def relative(reference, pose):
    """`pose` expressed in the frame of `reference` (both in one frame)."""
    return compose(inverse(reference), pose)


def transform_points(pose, points):
    """Points (n, 2) given in the frame of `pose`, in the frame `pose` is given in."""
    x, y, yaw = pose
    cos, sin = math.cos(yaw), math.sin(yaw)
    points = np.asarray(points, dtype=float)
    return np.stack((x + cos * points[:, 0] - sin * points[:, 1], y + sin * points[:, 0] + cos * points[:, 1]),
                    axis=-1)


def yaw_of_quaternion(x, y, z, w):
    """The heading of a rotation given as a quaternion (x, y, z, w): its yaw as ZYX Euler angles, tf's
    getEulerYPR's. The quaternion need not be normalised (a map_saver reads one from a YAML by hand)."""
    return math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)


def quaternion_of_yaw(yaw):
    """(x, y, z, w) of a turn by `yaw` about z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)
