"""A world file's obstacles as the lidar sees them: a cut at one height, in 2-D. No ROS, no pybullet.

What a planar lidar at `height` above the ground can see of a world is the
cut of its boxes and cylinders at that height: an obstacle whose height range
does not cover it (a table top, the bar above a door, a low step) is not
there for the lidar, nor for a map made from it. From that cut come the maps
shipped for ROBOTIS' worlds (occupied where a cell's centre lies inside an
obstacle) and the measures of a map against the truth (each point's distance
to the nearest surface; the outline of each obstacle).
"""
import math

import numpy as np

BURGER_SCAN_HEIGHT = 0.182  # m: base_scan above the ground on the Burger (and lower on the Waffles: 0.132)


def in_plane(obstacles, height=BURGER_SCAN_HEIGHT):
    """The obstacles whose height range covers `height`."""
    cut = []
    for obstacle in obstacles:
        tall = obstacle.size[2] if obstacle.kind == 'box' else obstacle.size[1]
        bottom = obstacle.position[2] - tall / 2.0
        if bottom <= height <= bottom + tall:
            cut.append(obstacle)
    return cut


def _local(obstacle, points):
    """Points (n, 2) in the obstacle's own frame (centre, turned by its yaw)."""
    cos, sin = math.cos(obstacle.yaw), math.sin(obstacle.yaw)
    dx, dy = points[:, 0] - obstacle.position[0], points[:, 1] - obstacle.position[1]
    return cos * dx + sin * dy, -sin * dx + cos * dy


def signed_distance(obstacles, points):
    """Distance (n,) from each point (n, 2) to the nearest obstacle's outline in
    the plane: negative inside an obstacle; +inf if there is none."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    nearest = np.full(len(points), np.inf)
    for obstacle in obstacles:
        x, y = _local(obstacle, points)
        if obstacle.kind == 'box':
            half_x, half_y = obstacle.size[0] / 2.0, obstacle.size[1] / 2.0
            out_x, out_y = np.abs(x) - half_x, np.abs(y) - half_y
            outside = np.hypot(np.maximum(out_x, 0.0), np.maximum(out_y, 0.0))
            distance = np.where((out_x <= 0) & (out_y <= 0), np.maximum(out_x, out_y), outside)
        else:
            distance = np.hypot(x, y) - obstacle.size[0]
        nearest = np.where(np.abs(distance) < np.abs(nearest), distance, nearest)
    return nearest


def occupied(obstacles, points):
    """True (n,) where a point (n, 2) lies inside an obstacle (or on its outline)."""
    return signed_distance(obstacles, points) <= 0.0


def outline(obstacles, spacing=0.02):
    """Points (n, 2) every `spacing` m along each obstacle's outline, and their outward normals (n, 2)."""
    points, normals = [], []
    for obstacle in obstacles:
        cos, sin = math.cos(obstacle.yaw), math.sin(obstacle.yaw)
        if obstacle.kind == 'box':
            half = (obstacle.size[0] / 2.0, obstacle.size[1] / 2.0)
            local, outward = [], []
            for axis in (0, 1):
                other = 1 - axis
                count = max(2, int(math.ceil(2 * half[other] / spacing)) + 1)
                along = np.linspace(-half[other], half[other], count)
                for side in (-1.0, 1.0):
                    face = np.zeros((count, 2))
                    face[:, axis], face[:, other] = side * half[axis], along
                    normal = np.zeros((count, 2))
                    normal[:, axis] = side
                    local.append(face)
                    outward.append(normal)
            local, outward = np.concatenate(local), np.concatenate(outward)
        else:
            count = max(8, int(math.ceil(2 * math.pi * obstacle.size[0] / spacing)))
            angles = np.arange(count) * 2 * math.pi / count
            outward = np.stack((np.cos(angles), np.sin(angles)), axis=-1)
            local = outward * obstacle.size[0]
        rotation = np.array([[cos, -sin], [sin, cos]])
        points.append(local.dot(rotation.T) + obstacle.position[:2])
        normals.append(outward.dot(rotation.T))
    if not points:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.concatenate(points), np.concatenate(normals)


def bounds(obstacles, margin=0.0):
    """(xmin, ymin, xmax, ymax) of the obstacles' outlines, widened by `margin`."""
    points, _ = outline(obstacles, spacing=0.05)
    if not len(points):
        return -margin, -margin, margin, margin
    low, high = points.min(axis=0) - margin, points.max(axis=0) + margin
    return low[0], low[1], high[0], high[1]
