"""tb3_navigation.loop_closure's search for a loop, in a corridor where a slide scores as well as the truth."""
import math

import numpy as np

from tb3_common.grid import Grid
from tb3_common.pose2d import IDENTITY
from tb3_navigation.loop_closure import LoopCloser, Node
from tb3_navigation.scan import Scan
from tb3_navigation.slam_config import SlamConfig

HALF_WIDTH = 0.5  # m: the corridor's walls at y = +-0.5, endless along x


def corridor_scan(pose, beams=360, range_max=3.5):
    """A scan from `pose` (x, y, yaw) between the corridor's walls (inf where no wall is in range)."""
    angles = -math.pi + np.arange(beams) * (2 * math.pi / beams)
    sin = np.sin(pose[2] + angles)
    with np.errstate(divide='ignore'):
        ranges = np.where(sin > 0, (HALF_WIDTH - pose[1]) / sin, (-HALF_WIDTH - pose[1]) / sin)
    ranges = np.where((np.abs(sin) > 1e-9) & (ranges <= range_max), ranges, np.inf)
    return Scan(-math.pi, 2 * math.pi / beams, ranges, 0.12, range_max)


def corridor_there_and_back():
    """A LoopCloser that went 5 m out along the corridor and back to the start (search off)."""
    config = SlamConfig()
    loops = LoopCloser(config, Grid(config.delta, 400, 400, (-10.0, -10.0, 0.0)))
    no_walls = np.zeros((400, 400), dtype=bool)
    path = [(x, 0.0, 0.0) for x in np.arange(0.0, 5.0, 0.2)] + [(x, 0.0, math.pi) for x in np.arange(5.0, -0.01, -0.2)]
    for pose in path:
        scan = corridor_scan(pose)
        loops.add(pose, scan.hit_points(IDENTITY), Node(scan, IDENTITY, 3.5, pose), lambda: no_walls, search=False)
    return loops, path, no_walls


def test_a_scan_of_too_few_points_closes_no_loop():
    """Back at the start, a scan with no points (0 >= 0.6 * 0) once passed as agreeing with its pose and tied
    it to the old scans as it stood, 11.6 cm off on a recorded exploration. Now a closing match must also
    score minimumScore, as the SLAM's own: its points, each on a wall, score a little less than one each."""
    loops, path, no_walls = corridor_there_and_back()
    points = corridor_scan(path[-1]).hit_points(IDENTITY)

    def spread(n):
        return points[::len(points) // n][:n]
    few = int(loops.config.minimumScore)
    assert loops._match_old(len(path) - 1, points[:0], lambda: no_walls) is None
    assert loops._match_old(len(path) - 1, spread(few), lambda: no_walls) is None
    assert loops._match_old(len(path) - 1, spread(few + few // 2), lambda: no_walls) is not None


def test_a_pose_whose_heading_drifted_is_turned_back_where_it_is_not_slid_along_the_corridor():
    """Out along the corridor and back to the start; the pose of the last scan 3 degrees off in heading.
    The coarse search finds places along the corridor about as good as any (here one 0.4 m on). That
    match scores clearly better than the turned pose as it is, but no better than the pose refined where
    it lies: the closure takes the latter (the position kept, the heading turned back)."""
    loops, path, no_walls = corridor_there_and_back()
    truth = path[-1]
    drifted = (truth[0], truth[1], truth[2] + math.radians(3.0))
    loops.graph.poses[-1] = drifted
    points = corridor_scan(truth).hit_points(IDENTITY)
    old, matched = loops._match_old(len(path) - 1, points, lambda: no_walls)
    assert old < len(path) - 10
    assert abs(matched[0] - truth[0]) < 0.03 and abs(matched[1] - truth[1]) < 0.03
    assert abs(math.remainder(matched[2] - truth[2], 2 * math.pi)) < math.radians(0.5)
