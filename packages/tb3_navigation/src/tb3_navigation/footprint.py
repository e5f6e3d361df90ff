"""A robot's footprint, a polygon ((x, y), ...) in base_footprint, as costmap_2d makes and
measures it (footprint.cpp): its radii, points along its outline, and whether points lie
inside it. No ROS here.
"""
import math

import numpy as np


def circle_footprint(radius):
    """costmap_2d's makeFootprintFromRadius: the 16-corner polygon ((x, y), ...) it makes of
    `robot_radius` when no footprint is given."""
    angles = np.arange(16) * 2.0 * math.pi / 16
    return tuple((float(math.cos(angle) * radius), float(math.sin(angle) * radius)) for angle in angles)


def footprint_radii(footprint):
    """(inscribed, circumscribed) radius of a footprint about its origin: the nearest
    and the farthest of its edges and vertices (costmap_2d's calculateMinAndMaxDistances)."""
    points = np.asarray(footprint, dtype=float)
    starts, ends = points, np.roll(points, -1, axis=0)
    along = ends - starts
    share = np.clip(-np.sum(starts * along, axis=1) / np.maximum(np.sum(along * along, axis=1), 1e-300), 0.0, 1.0)
    edges = np.hypot(*(starts + share[:, None] * along).T)
    vertices = np.hypot(*points.T)
    return float(min(edges.min(), vertices.min())), float(max(edges.max(), vertices.max()))


def outline(footprint, spacing):
    """Points (n, 2) along a footprint's edges, at most `spacing` apart, vertices included."""
    points = np.asarray(footprint, dtype=float)
    pieces = []
    for start, end in zip(points, np.roll(points, -1, axis=0)):
        count = max(1, int(math.ceil(math.hypot(*(end - start)) / spacing)))
        pieces.append(start + (end - start) * (np.arange(count) / float(count))[:, None])
    return np.concatenate(pieces)


def inside_convex(polygon, points):
    """True where points (n, 2) lie inside a convex polygon (either winding)."""
    polygon = np.asarray(polygon, dtype=float)
    edges = np.roll(polygon, -1, axis=0) - polygon
    relative = points[:, None, :] - polygon[None, :, :]
    cross = edges[None, :, 0] * relative[..., 1] - edges[None, :, 1] * relative[..., 0]
    return np.all(cross >= 0, axis=1) | np.all(cross <= 0, axis=1)
