"""Measures of a map (OccupancyGrid values) against the world it was made in, for the tests of the mapping cores.

The truth is the world file's cut at the lidar's height (tb3_sim_nav.world_map):
- precision: the share of occupied cells whose centre lies within a tolerance
  of an obstacle's outline (a doubled or smeared wall lowers it);
- the visible outline: the outline points that the drive's beams reached, at
  the true poses, from the side they face (outline's outward normals), within
  the usable range: the part of the world a map can be asked to show;
- coverage: the share of those points with an occupied cell within a tolerance;
- thickness: at each visible outline point, how many occupied cells the wall's
  normal crosses within a band around the outline.
"""
import math

import numpy as np
from scipy.spatial import cKDTree

from tb3_sim_nav import world_map

OCCUPIED = 100


def occupied_centres(values, grid):
    """The centres (n, 2) of the occupied cells of `values` (rows from the lowest y) on `grid`."""
    rows, cols = np.nonzero(values == OCCUPIED)
    return grid.centres(np.stack((cols, rows), axis=-1))


def precision(values, grid, obstacles, tolerance=0.10):
    """Share of the occupied cells within `tolerance` m of an obstacle's outline (inside or out)."""
    centres = occupied_centres(values, grid)
    return float(np.mean(np.abs(world_map.signed_distance(obstacles, centres)) <= tolerance))


def true_hits(drive, max_range):
    """Where the drive's beams shorter than `max_range` ended (n, 2), put at the true poses, and
    the beams' directions (n, 2)."""
    ends, directions = [], []
    x, y, yaw = drive.scan_pose
    for pose, ranges in zip(drive.truth, drive.ranges):
        angles = drive.angle_min + drive.angle_increment * np.arange(len(ranges))
        use = np.isfinite(ranges) & (ranges >= drive.range_min) & (ranges < max_range)
        cos, sin = math.cos(pose[2]), math.sin(pose[2])
        sensor = (pose[0] + cos * x - sin * y, pose[1] + sin * x + cos * y)
        heading = pose[2] + yaw + angles[use]
        direction = np.stack((np.cos(heading), np.sin(heading)), axis=-1)
        ends.append(sensor + ranges[use, None] * direction)
        directions.append(direction)
    return np.concatenate(ends), np.concatenate(directions)


def visible_outline(obstacles, drive, max_range, spacing=0.02, near=0.03):
    """The outline points (n, 2) and normals (n, 2) that a beam of the drive hit (an end point within
    `near` m, coming from the side the point faces) closer than `max_range`."""
    points, normals = world_map.outline(obstacles, spacing)
    ends, directions = true_hits(drive, max_range)
    distance, nearest = cKDTree(points).query(ends, distance_upper_bound=near)
    found = np.isfinite(distance)
    facing = np.einsum('ij,ij->i', directions[found], normals[nearest[found]]) < 0
    seen = np.zeros(len(points), dtype=bool)
    seen[nearest[found][facing]] = True
    return points[seen], normals[seen]


def coverage(values, grid, points, tolerance=0.10):
    """Share of `points` (n, 2) with an occupied cell's centre within `tolerance` m."""
    centres = occupied_centres(values, grid)
    if not len(centres) or not len(points):
        return 0.0
    distance, _ = cKDTree(centres).query(points, distance_upper_bound=tolerance)
    return float(np.mean(np.isfinite(distance)))


def thickness(values, grid, points, normals, band=0.10, step=0.005):
    """At each outline point (n, 2), how many occupied cells its outward normal (n, 2)
    crosses from `band` m inside the obstacle to `band` m out (n,)."""
    offsets = np.arange(-band, band + step / 2, step)
    probes = points[:, None, :] + offsets[None, :, None] * normals[:, None, :]
    cells = grid.to_cells(probes)
    inside = grid.inside(cells)
    rows, cols = np.clip(cells[..., 1], 0, grid.height - 1), np.clip(cells[..., 0], 0, grid.width - 1)
    occupied = inside & (values[rows, cols] == OCCUPIED)
    flat = np.where(occupied, rows * grid.width + cols, -1)
    # Distinct occupied cells per probe line: sort each line, count changes.
    flat.sort(axis=1)
    distinct = (np.diff(flat, axis=1) != 0) & (flat[:, 1:] >= 0)
    return distinct.sum(axis=1) + (flat[:, 0] >= 0)


def ghosts(values, grid, obstacles, points, normals, near=0.10, far=0.30, step=0.01):
    """How many of the outline points (n, 2) have an occupied cell in front of them, between
    `near` and `far` m along their outward normals (n, 2), where the world is free (farther
    than `near` from every outline): a wall drawn a second time, off the first."""
    offsets = np.arange(near, far + step / 2, step)
    probes = (points[:, None, :] + offsets[None, :, None] * normals[:, None, :]).reshape(-1, 2)
    free = world_map.signed_distance(obstacles, probes) > near
    cells = grid.to_cells(probes)
    inside = grid.inside(cells)
    rows, cols = np.clip(cells[:, 1], 0, grid.height - 1), np.clip(cells[:, 0], 0, grid.width - 1)
    ghost = (free & inside & (values[rows, cols] == OCCUPIED)).reshape(len(points), -1)
    return int(np.count_nonzero(ghost.any(axis=1)))
