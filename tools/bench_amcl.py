"""CPU of the localization core per filter update, and its particle counts, as a table.

Run inside `source setup.bash`. A benchmark, not a test: it records the loop
around turtlebot3_world's pillars (profile realistic, as test_localization
does; ~5 s) and feeds it to tb3_navigation.localization.Amcl, timing each
update with time.process_time (CPU of this process: numpy here runs on one
thread). No ROS master.

    python3 tools/bench_amcl.py [--seeds N]
"""
import argparse
import datetime
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'test', 'unit'))

from drives import WORLD_LOOP, WORLD_LOOP_START, record_drive  # noqa: E402
from test_localization import RVIZ_COVARIANCE, TIGHT, scan, world_grid  # noqa: E402
from tb3_navigation.amcl_config import AmclConfig  # noqa: E402
from tb3_navigation.localization import Amcl  # noqa: E402


def feed(amcl, drive):
    """(CPU s of each update that updated, CPU s of its likelihood part, particle counts after each)."""
    model_time = []
    weights = amcl.model.weights

    def timed(*args, **kwargs):
        start = time.process_time()
        result = weights(*args, **kwargs)
        model_time.append(time.process_time() - start)
        return result
    amcl.model.weights = timed
    totals, parts, counts = [], [], []
    for index in range(len(drive.times)):
        reading = scan(drive, index)
        before = len(model_time)
        start = time.process_time()
        if amcl.update(drive.odom[index], reading, drive.scan_pose):
            totals.append(time.process_time() - start)
            parts.append(sum(model_time[before:]))
            counts.append(len(amcl.particles))
    return np.array(totals), np.array(parts), np.array(counts)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seeds', type=int, default=3, help='filter runs per row (default 3)')
    seeds = parser.parse_args().seeds
    print('# tb3_navigation.localization, %s, %s, %d CPUs, python %s, numpy %s'
          % (datetime.date.today(), platform.processor() or platform.machine(), os.cpu_count(),
             platform.python_version(), np.__version__))
    drive = record_drive('turtlebot3_world', WORLD_LOOP_START, WORLD_LOOP)
    world = world_grid('turtlebot3_world')
    print('loop: %d scans at 5 Hz, 13.6 m; 180 of 360 beams, those under 3.5 m (~163) weighed' % len(drive.times))
    print('ms of CPU per filter update; lik. = its likelihood part\n')
    print('%-34s %8s %8s %10s %10s %s' % ('case', 'updates', 'ms med', 'ms p95', 'lik. med', 'particles min/med/max'))
    cases = [('fixed 500 particles, tracking', dict(min_particles=500, max_particles=500), TIGHT, 0.0),
             ('fixed 3000 particles, tracking', dict(min_particles=3000, max_particles=3000), TIGHT, 0.0),
             ("TurtleBot3's (KLD), tracking", {}, TIGHT, 0.0),
             ("TurtleBot3's, 0.5 m 30 deg off", {}, RVIZ_COVARIANCE, 0.5)]
    for name, changes, covariance, offset in cases:
        totals, parts, counts = [], [], []
        for seed in range(seeds):
            amcl = Amcl(AmclConfig(**changes), *world, seed=seed)
            amcl.initialise(drive.truth[0] + (offset, 0.0, 0.52 if offset else 0.0), covariance)
            total, part, count = feed(amcl, drive)
            totals.append(total)
            parts.append(part)
            counts.append(count)
        total, part, count = np.concatenate(totals), np.concatenate(parts), np.concatenate(counts)
        print('%-34s %8d %8.1f %10.1f %10.1f %d/%d/%d' % (name, len(total), 1e3 * np.median(total),
                                                         1e3 * np.percentile(total, 95), 1e3 * np.median(part),
                                                         count.min(), np.median(count), count.max()))
        if offset:
            print('  particles, first 12 updates of seed 0: %s' % ' '.join(str(value) for value in counts[0][:12]))


if __name__ == '__main__':
    main()
