"""What the SLAM's unit tests share (no ROS): recorded drives fed to a Slam, and the measures of its
poses and map against the truth and the world file. The drive they share, turtlebot3_world's loop of
13.6 m around the pillars (its odometry ends 18 cm and 2.8 degrees off), is localization_drives' `loop`.
"""
import numpy as np

from tb3_common.pose2d import normalize_angle
from tb3_harness import ROOT as REPO
from tb3_harness.map_quality import measure
from tb3_navigation.scan import Scan
from tb3_navigation.slam import Slam
from tb3_sim_nav.world_file import load_world


def scans_of(drive, ranges=None):
    ranges = drive.ranges if ranges is None else ranges
    return [Scan(drive.angle_min, drive.angle_increment, r, drive.range_min, drive.range_max) for r in ranges]


def run(drive, indices=None, odom=None, ranges=None, slam=None):
    """Feed `drive`'s scans (those of `indices`, in that order, stamped 0.2 s apart) to a Slam;
    returns it, the poses it gave and whether each scan was taken for a jump."""
    slam = slam or Slam()
    indices = range(len(drive.times)) if indices is None else indices
    odom = drive.odom if odom is None else odom
    scans = scans_of(drive, ranges)
    poses, jumps = [], []
    for step, index in enumerate(indices):
        poses.append(slam.update(0.2 * step, odom[index], scans[index], drive.scan_pose))
        jumps.append(slam.jumped)
    return slam, np.array(poses), np.array(jumps)


def errors(poses, truth):
    """Distance (n,) and heading error (n,) of poses (n, 3) from the truth (n, 3)."""
    return np.hypot(*(poses[:, :2] - truth[:, :2]).T), np.abs(normalize_angle(poses[:, 2] - truth[:, 2]))


def obstacles(world):
    return load_world(world, str(REPO / 'worlds')).obstacles


def quality(slam, world, start):
    """tb3_harness.map_quality's measures of the SLAM's map in `world`'s obstacles, from `start` (x, y)."""
    return measure(slam.grid, slam.map_values(), world, start[:2])
