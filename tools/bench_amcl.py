"""The localization core's accuracy, its CPU per filter update and its particle counts, as tables.

Run inside `source setup.bash`. A benchmark, not a test: it records the loop
around turtlebot3_world's pillars and a drive through test_navigation's four
goals (profile realistic, as test_localization does; ~15 s each) and feeds
them to tb3_navigation.localization.Amcl on the shipped map with TurtleBot3's
parameters: the error of what a ROS user sees (tf map -> base_footprint, at
every scan after the first quarter of the drive, and at the scans within
5 cm of a goal) against the truth, the estimate as published and the cloud's
mean (refine_estimate false); then CPU per update, timed with
time.process_time (numpy here runs on one thread). No ROS master.

    python3 tools/bench_amcl.py [--seeds N]
"""
import argparse
import datetime
import os
import platform
import time

import numpy as np

from tb3_common.map_files import load_map
from tb3_harness import ROOT
from tb3_harness.drives import (
    TIGHT,
    WORLD_GOALS,
    WORLD_GOALS_ROUTE,
    WORLD_LOOP,
    WORLD_LOOP_START,
    record_drive,
    run,
    scan,
    travelled,
    world_grid,
)
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import RVIZ_COVARIANCE, Amcl

AT_GOAL = 0.05  # m: a scan taken this near a goal counts as one at the goal


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


def accuracy(drives, seeds):
    """Rows of tf's error (cm: median, p95, worst) on each drive, as published and as the cloud's mean."""
    shipped = load_map(os.path.join(ROOT, 'maps', 'turtlebot3_world.yaml'))
    print('error of tf map -> base_footprint against the truth, cm (median / p95 / worst), %d seeds' % seeds)
    print('%-52s %-20s %-20s' % ('drive', 'published', "the cloud's mean"))
    for name, drive, goals in drives:
        distance = travelled(drive)
        late = distance > distance[-1] / 4.0
        near = np.zeros(len(drive.times), dtype=bool)
        for goal in goals:
            near |= np.hypot(*(drive.truth[:, :2] - goal[:2]).T) < AT_GOAL
        cells = {}
        for refine in (True, False):
            errors = []
            for seed in range(seeds):
                amcl = Amcl(AmclConfig(refine_estimate=refine), shipped.grid, shipped.values, seed=seed)
                amcl.initialise(drive.truth[0], TIGHT)
                errors.append(run(amcl, drive)[0])
            errors = np.array(errors)
            cells[refine] = [100 * np.percentile(errors[:, late], [50, 95, 100]),
                             100 * np.percentile(errors[:, near], [50, 95, 100]) if near.any() else None]
        for row, label in enumerate(('after its first quarter', 'at the goals (%d scans)' % near.sum())):
            if cells[True][row] is not None:
                print('%-52s %-20s %-20s' % ('%s, %s' % (name, label), '%.1f / %.1f / %.1f' % tuple(cells[True][row]),
                                             '%.1f / %.1f / %.1f' % tuple(cells[False][row])))
    print()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seeds', type=int, default=3, help='filter runs per row (default 3)')
    seeds = parser.parse_args().seeds
    print('# tb3_navigation.localization, %s, %s, %d CPUs, python %s, numpy %s'
          % (datetime.date.today(), platform.processor() or platform.machine(), os.cpu_count(),
             platform.python_version(), np.__version__))
    drive = record_drive('turtlebot3_world', WORLD_LOOP_START, WORLD_LOOP)
    goals = record_drive('turtlebot3_world', WORLD_LOOP_START, WORLD_GOALS_ROUTE)
    accuracy([('the loop (13.6 m)', drive, []), ("test_navigation's goals", goals, WORLD_GOALS)], seeds)
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
