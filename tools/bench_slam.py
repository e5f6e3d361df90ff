"""CPU per scan and accuracy of the SLAM core (tb3_navigation.slam) on recorded drives, as a table.

Run inside `source setup.bash`. A benchmark, not a test: it records the unit
tests' drives of the simulated Burger (realistic profile), feeds them to
Slam, and prints per drive the CPU time of Slam.update per scan
(time.process_time: median, 95th percentile, mean, max), the pose's error
against the truth (at the end and the worst along the drive), the
odometry's, and the map's measures (tb3_harness.map_quality).

    python3 tools/bench_slam.py [--drives loop,tour,house]
"""
import argparse
import datetime
import os
import platform
import sys
import time

import numpy as np

from tb3_common.pose2d import normalize_angle
from tb3_harness import ROOT
from tb3_harness.drives import (
    HOUSE_OUTSIDE,
    HOUSE_TOUR,
    HOUSE_TOUR_START,
    WORLD_LOOP,
    WORLD_LOOP_START,
    path_length,
    record_drive,
)
from tb3_harness.map_quality import QualityConfig
from tb3_harness.map_quality import measure as map_quality
from tb3_navigation.scan import Scan
from tb3_navigation.slam import Slam
from tb3_sim_nav.world_file import load_world

#: The whole of turtlebot3_house's rooms from tb3_house.launch's spawn pose and back: 75 m.
HOUSE_ROUND = [(-1.0, 1.2), (-1.0, 4.0), (-4.0, 4.0), (-4.4, 3.3), (-6.3, 3.3), (-6.3, 1.6), (-6.3, 0.3),
               (-6.5, -2.8), (-6.3, 0.3), (-6.3, 1.6), (-6.3, 3.3), (-4.4, 3.3), (-3.0, 1.0), (-1.0, 0.4),
               (1.2, 0.4), (3.0, 0.4), (3.0, 1.2), (3.0, 4.6), (1.0, 4.6), (1.0, 1.6), (1.0, 4.6), (3.0, 4.6),
               (6.5, 4.0), (6.8, 1.0), (6.2, 0.5), (6.2, -1.0), (5.6, -1.5), (5.6, -4.5), (6.8, -4.5), (6.8, -1.0),
               (6.2, -0.6), (6.2, 0.5), (3.0, 0.4), (-1.0, 0.4), (-3.0, 1.0)]

DRIVES = {
    'loop': ('turtlebot3_world', WORLD_LOOP_START, WORLD_LOOP),
    'tour': ('turtlebot3_house', HOUSE_TOUR_START, HOUSE_TOUR),
    'house': ('turtlebot3_house', HOUSE_TOUR_START, HOUSE_ROUND),
    'outside': ('turtlebot3_house', HOUSE_TOUR_START, HOUSE_OUTSIDE),
}


def errors(poses, truth):
    return np.hypot(*(poses[:, :2] - truth[:, :2]).T), np.degrees(np.abs(normalize_angle(poses[:, 2] - truth[:, 2])))


def measure(name):
    world, start, waypoints = DRIVES[name]
    drive = record_drive(world, start, waypoints)
    slam, poses, cpu = Slam(), [], []
    for stamp, odom, ranges in zip(drive.times, drive.odom, drive.ranges):
        scan = Scan(drive.angle_min, drive.angle_increment, ranges, drive.range_min, drive.range_max)
        begin = time.process_time()
        poses.append(slam.update(stamp, odom, scan, drive.scan_pose))
        cpu.append(time.process_time() - begin)
    poses, cpu = np.array(poses), np.array(cpu) * 1000.0
    distance, turn = errors(poses, drive.truth)
    odom_distance, odom_turn = errors(drive.odom, drive.truth)
    obstacles = load_world(world, os.path.join(ROOT, 'worlds')).obstacles
    quality = map_quality(slam.grid, slam.map_values(), obstacles, start[:2])
    near05 = map_quality(slam.grid, slam.map_values(), obstacles, start[:2], QualityConfig(tolerance=0.05))
    return dict(drive=name, scans=len(cpu), metres=path_length(drive.truth),
                cpu_median=np.median(cpu), cpu_p95=np.percentile(cpu, 95), cpu_mean=cpu.mean(), cpu_max=cpu.max(),
                end_cm=100 * distance[-1], end_deg=turn[-1], worst_cm=100 * distance.max(), worst_deg=turn.max(),
                odom_end_cm=100 * odom_distance[-1], odom_end_deg=odom_turn[-1],
                near05=100 * near05.occupied_near_surface, near=100 * quality.occupied_near_surface,
                covered=100 * quality.surface_covered,
                thickness=quality.wall_thickness, thicker=100 * quality.thick_wall_share,
                doubled=100 * quality.doubled_wall_share)


#: (key, width, format) of each column.
COLUMNS = [('drive', 6, '%s'), ('scans', 6, '%d'), ('metres', 7, '%.1f'), ('cpu_median', 11, '%.1f'),
           ('cpu_p95', 8, '%.1f'), ('cpu_mean', 9, '%.1f'), ('cpu_max', 8, '%.1f'), ('end_cm', 7, '%.1f'),
           ('end_deg', 8, '%.2f'), ('worst_cm', 9, '%.1f'), ('worst_deg', 10, '%.2f'), ('odom_end_cm', 12, '%.1f'),
           ('odom_end_deg', 13, '%.2f'), ('near05', 7, '%.1f'), ('near', 6, '%.1f'), ('covered', 8, '%.1f'),
           ('thickness', 10, '%.1f'), ('thicker', 8, '%.1f'), ('doubled', 8, '%.1f')]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--drives', default='loop,tour', help='of: %s' % ', '.join(DRIVES))
    args = parser.parse_args()
    print('# SLAM core, %s, %s, %s, %d CPUs, load %.2f' % (
        datetime.date.today(), platform.node(), platform.processor() or platform.machine(), os.cpu_count(),
        os.getloadavg()[0]))
    print('# cpu: ms of process time per Slam.update; cm/deg: pose against the truth; map (tb3_harness.map_quality, '
          '%): occupied cells within 0.05 and 0.10 m of a surface, surface covered (of the whole world), wall '
          'thickness (median cells), walls thicker than 2 cells, doubled')
    print(' '.join(key.rjust(width) for key, width, _ in COLUMNS))
    for name in args.drives.split(','):
        row = measure(name.strip())
        print(' '.join((fmt % row[key]).rjust(width) for key, width, fmt in COLUMNS))
        sys.stdout.flush()


if __name__ == '__main__':
    main()
