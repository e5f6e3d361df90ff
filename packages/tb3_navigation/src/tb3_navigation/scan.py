"""Laser scans as the cores use them: beams checked one by one, end points in a frame. No ROS here.

A beam counts as a hit only if its range is finite and within [range_min,
range_max); NaN, inf and out-of-range readings are skipped beam by beam, as
gmapping and amcl skip them. A beam at range_max or beyond (or +inf, REP 117's
"nothing within range") still tells that the space along it up to
`free_range` is empty; `clear` gives those beams for the free-space updates.
"""
import math

import numpy as np


class Scan(object):
    """One scan's beams: `angles` (rad, in the sensor's frame), `ranges` (m), and which are hits."""

    def __init__(self, angle_min, angle_increment, ranges, range_min, range_max):
        ranges = np.asarray(ranges, dtype=float)
        self.angle_min, self.angle_increment = float(angle_min), float(angle_increment)
        self.angles = angle_min + angle_increment * np.arange(ranges.size)
        self.ranges = ranges
        self.range_min, self.range_max = float(range_min), float(range_max)
        with np.errstate(invalid='ignore'):
            self.hits = np.isfinite(ranges) & (ranges >= range_min) & (ranges < range_max)
            # Nothing within range along these: free up to the usable range.
            self.misses = ~self.hits & ((ranges >= range_max) | (np.isposinf(ranges)))

    @classmethod
    def from_message(cls, message):
        """From a sensor_msgs/LaserScan (or anything with its fields)."""
        return cls(message.angle_min, message.angle_increment, message.ranges, message.range_min,
                   message.range_max)

    def __len__(self):
        return self.ranges.size

    def within(self, max_range):
        """This scan without its hits longer than `max_range`, and without the beams that saw
        nothing within the sensor's range when `max_range` is shorter than that range: what
        gmapping's maxRange drops whole (a shorter maxUrange still clears along them)."""
        if not max_range < self.range_max:
            return self
        ranges = np.where(self.hits & (self.ranges <= max_range), self.ranges, np.nan)
        return Scan(self.angle_min, self.angle_increment, ranges, self.range_min, self.range_max)

    def subsample(self, max_beams):
        """Indices of at most `max_beams` beams spread evenly over the scan (amcl's laser_max_beams)."""
        count = len(self)
        if max_beams <= 0 or max_beams >= count:
            return np.arange(count)
        step = count / float(max_beams)
        return np.unique((np.arange(max_beams) * step).astype(np.intp))

    def hit_points(self, sensor_pose, max_range=math.inf, beams=None):
        """End points (n, 2), in the frame of `sensor_pose` (x, y, yaw), of the hits
        (of `beams` if given) closer than `max_range`."""
        keep = self.hits & (np.nan_to_num(self.ranges, nan=math.inf) < max_range)
        if beams is not None:
            chosen = np.zeros(len(self), dtype=bool)
            chosen[beams] = True
            keep &= chosen
        return endpoints(sensor_pose, self.angles[keep], self.ranges[keep])

    def rays(self, sensor_pose, max_range, free_range=None):
        """(ends (n, 2), hit (n,)) of the beams that tell something within `max_range`,
        in the frame of `sensor_pose`: a hit closer than max_range ends at its
        obstacle (hit True); any other hit or miss ends, empty, at
        `free_range` (default max_range; hit False)."""
        free_range = max_range if free_range is None else free_range
        ranges = np.nan_to_num(self.ranges, nan=math.inf, posinf=math.inf)
        hit = self.hits & (ranges < max_range)
        empty = (self.hits & ~hit) | self.misses
        use = hit | empty
        lengths = np.where(hit, ranges, min(free_range, max_range))[use]
        return endpoints(sensor_pose, self.angles[use], lengths), hit[use]


def endpoints(sensor_pose, angles, ranges):
    """Points (n, 2) at `ranges` along `angles` from `sensor_pose` (x, y, yaw)."""
    x, y, yaw = sensor_pose
    heading = yaw + np.asarray(angles, dtype=float)
    ranges = np.asarray(ranges, dtype=float)
    return np.stack((x + ranges * np.cos(heading), y + ranges * np.sin(heading)), axis=-1)
