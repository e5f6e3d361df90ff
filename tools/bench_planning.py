"""Speed of the planning cores (tb3_navigation), as a table. No ROS, no simulator.

Run inside `source setup.bash`. A benchmark, not a test: it measures medians
(wall and CPU time) over several runs on turtlebot3_house's cut laid on a
400 x 260 grid (20 x 13 m at 0.05 m, the issue's "house") and on
turtlebot3_world's, and prints them with the machine and the date.

    python3 tools/bench_planning.py [--runs N]
"""
import argparse
import datetime
import math
import statistics
import sys
import time

import numpy as np

from tb3_common.grid import Grid
from tb3_common.pose2d import compose
from tb3_harness.measure import machine
from tb3_harness.nav_sim import SCAN_POSE, Lidar, costmaps, world_cut  # the tests' world, lidar and map
from tb3_navigation.controller import DwaController
from tb3_navigation.costmap import Costmap, CostmapConfig
from tb3_navigation.dwa_config import dwa_config
from tb3_navigation.planner import GlobalPlanner, plan_length
from tb3_sim_nav import world_map


def timed(function, runs):
    """(median wall ms, median CPU ms) of `runs` calls."""
    walls, cpus = [], []
    for _ in range(runs):
        wall, cpu = time.perf_counter(), time.process_time()
        function()
        walls.append(1e3 * (time.perf_counter() - wall))
        cpus.append(1e3 * (time.process_time() - cpu))
    return statistics.median(walls), statistics.median(cpus)


def house():
    obstacles = world_cut('turtlebot3_house')
    xmin, ymin, xmax, ymax = world_map.bounds(obstacles)
    grid = Grid(0.05, 400, 260, ((xmin + xmax) / 2 - 10.0, (ymin + ymax) / 2 - 6.5, 0.0))
    inside = world_map.occupied(obstacles, grid.all_centres().reshape(-1, 2)).reshape(grid.shape)
    return obstacles, Costmap(grid, CostmapConfig(), static=np.where(inside, 100, 0).astype(np.int8))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--runs', type=int, default=11)
    runs = parser.parse_args().runs
    rows = []
    obstacles, costmap = house()
    start, goal = (-6.0, -1.0, 0.0), (6.5, 2.5, 0.0)
    planner = GlobalPlanner()
    plan = planner.make_plan(costmap, start, goal)

    rng = np.random.default_rng(0)

    def changed(cells=None):
        """A plan after `cells` random cells' costs changed by one, walls left as they are (None: every cell)."""
        chosen = np.zeros(costmap.costs.size, dtype=bool)
        chosen[slice(None) if cells is None else rng.choice(chosen.size, cells, replace=False)] = True
        costmap.costs = np.where(chosen.reshape(costmap.costs.shape) & (costmap.costs < 252), costmap.costs ^ 1,
                                 costmap.costs)
        planner.make_plan(costmap, start, goal)
    changed(300)  # the first mend builds the index of which edges each cell weighs in
    rows.append(('house plan across (%.1f m), costs unchanged' % plan_length(plan),
                 timed(lambda: planner.make_plan(costmap, start, goal), runs)))
    rows.append(('house plan across, 300 cells changed (graphs mended)', timed(lambda: changed(300), runs)))
    rows.append(('house plan across, costs changed (graphs built anew)',
                 timed(changed, runs)))
    rows.append(('house plan across, exhaustive (tolerance 0.05 m)',
                 timed(lambda: planner.make_plan(costmap, start, goal, tolerance=0.05), runs)))
    lidar = Lidar(obstacles)
    scans = iter([lidar.scan(start) for _ in range(2 * runs + 1)])  # each with its own noise, as the lidar's
    costmap.update(start, next(scans), compose(start, SCAN_POSE))
    rows.append(('house global costmap update with a new scan',
                 timed(lambda: costmap.update(start, next(scans), compose(start, SCAN_POSE)), runs)))
    rows.append(('house global costmap update without a scan',
                 timed(lambda: costmap.update(start), runs)))

    obstacles = world_cut()
    robot = (-1.65, -0.55, 0.0)
    global_costmap, local_costmap = costmaps(obstacles, robot)
    scan = Lidar(obstacles).scan(robot)
    rows.append(('world local costmap update (3 x 3 m) with a scan',
                 timed(lambda: local_costmap.update(robot, scan, compose(robot, SCAN_POSE)), runs)))
    world_plan = np.array(GlobalPlanner().make_plan(global_costmap, robot, (0.55, -0.55, 0.0)))
    controller = DwaController(local_costmap, dwa_config())
    local_costmap.update(robot, scan, compose(robot, SCAN_POSE))
    for label, velocity in (('from rest', (0.0, 0.0)), ('cruising', (0.2, 0.1))):
        rows.append(('DWA command %s (%d samples)' % (label, 20 * 40),
                     timed(lambda: controller.compute(robot, velocity, world_plan), runs)))

    print('tb3_navigation planning cores, %s, %s, median of %d runs'
          % (machine(), datetime.date.today().isoformat(), runs))
    print('| %-52s | %9s | %8s |' % ('what', 'wall ms', 'CPU ms'))
    print('|%s|%s|%s|' % ('-' * 54, '-' * 11, '-' * 10))
    for label, (wall, cpu) in rows:
        print('| %-52s | %9.1f | %8.1f |' % (label, wall, cpu))
    print('load average: %s' % ' '.join(open('/proc/loadavg').read().split()[:3]))
    return 0 if all(math.isfinite(wall) for _, (wall, _) in rows) else 1


if __name__ == '__main__':
    sys.exit(main())
