"""Poses as (position (x, y, z), orientation (x, y, z, w)): compose, invert, express in another frame. No ROS here.

This is the simulator core's one pose convention: bodies, robots, spawns and
readings all speak it. A pose given as x, y, z and a heading (launch
arguments, world files) becomes one through `planar`. Yaw <-> quaternion is
written once for the whole project, in tb3_common.pose2d.
"""
import math

import numpy as np

from tb3_common.pose2d import quaternion_of_yaw, yaw_of_quaternion

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def planar(x, y, z=0.0, yaw=0.0):
    """The pose at (x, y, z) heading `yaw` (rad, about z)."""
    return (float(x), float(y), float(z)), quaternion_of_yaw(yaw)


def yaw_of(orientation):
    """The heading (rad, about z) of an orientation (x, y, z, w)."""
    return yaw_of_quaternion(*orientation)


def matrix(q):
    """The 3 x 3 rotation matrix of a unit quaternion (x, y, z, w): its columns are the frame's axes."""
    x, y, z, w = q
    return np.array([[1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
                     [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
                     [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)]])


def quaternion_multiply(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def conjugate(q):
    return (-q[0], -q[1], -q[2], q[3])


def normalized(q):
    """`q` of length 1, or ValueError if it has none to speak of."""
    norm = math.sqrt(sum(value * value for value in q))
    if not norm > 1e-9 or not math.isfinite(norm):
        raise ValueError('orientation %s is not a rotation (its length is %g)' % (tuple(q), norm))
    return tuple(value / norm for value in q)


def rotate(q, vector):
    """`vector` (x, y, z) rotated by the unit quaternion `q`."""
    x, y, z, _ = quaternion_multiply(quaternion_multiply(q, tuple(vector) + (0.0,)), conjugate(q))
    return (x, y, z)


def compose(a, b):
    """The pose `b`, given in the frame of pose `a`, in the frame `a` is given in."""
    (position, orientation), (offset, turn) = a, b
    moved = rotate(orientation, offset)
    return (tuple(p + m for p, m in zip(position, moved)), quaternion_multiply(orientation, turn))


def inverse(pose):
    position, orientation = pose
    back = conjugate(orientation)
    return (tuple(-value for value in rotate(back, position)), back)


def relative(reference, pose):
    """`pose` (in the world) expressed in the frame of `reference` (in the world)."""
    return compose(inverse(reference), pose)


def from_rpy(roll, pitch, yaw):
    """The quaternion of fixed-axis roll, pitch, yaw (as URDF and SDF write them)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)
