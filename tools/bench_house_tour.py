"""Tours of turtlebot3_house through move_base's cores, as a table. No ROS, no simulator.

Run inside `source setup.bash`. A benchmark, not a test: the navigation stack
with TurtleBot3's values (tb3_harness.nav_sim's closed loop: the tests'
unicycle, lidar and map) is sent to random goals in the house, each tour
from where the last goal ended, with the planner's obstacle_clearance of
ours and without it (navfn's plans), on the same goals. Per tour: goals
reached, sim time, time standing still (within 0.2 m for 10 s or more), the
recoveries run and the footprint's least clearance, with the machine and the date.

    python3 tools/bench_house_tour.py [--seeds 1,2,3] [--goals 12]
"""
import argparse
import datetime
import math
import sys
import time

import numpy as np

from tb3_common.pose2d import quaternion_of_yaw
from tb3_harness.exploring import stood_still
from tb3_harness.measure import machine
from tb3_harness.nav_sim import PERIOD, Lidar, Unicycle, run_stack, stack, world_cut
from tb3_navigation.navigator import SUCCEEDED
from tb3_navigation.planner import PlannerConfig
from tb3_sim_nav import world_map

START = (-3.0, 1.0, 0.0)  # turtlebot3_house.launch's spawn
GOAL_TIMEOUT = 150.0  # sim s a goal may take
STILL_RADIUS, STILL_SECONDS = 0.2, 10.0


def goals(obstacles, costmap, seed, count, clearance=0.2):
    """`count` goals (x, y, yaw) at least `clearance` m from the house's obstacles, on its known floor."""
    rng = np.random.default_rng(seed)
    found = []
    while len(found) < count:
        point = rng.uniform((-7.0, -5.0), (7.0, 5.0))
        cell = costmap.grid.to_cells(point)
        if world_map.signed_distance(obstacles, point[None, :])[0] > clearance and costmap.grid.inside(cell) \
                and costmap.costs[cell[1], cell[0]] < 200:
            found.append((float(point[0]), float(point[1]), float(rng.uniform(-math.pi, math.pi))))
    return found


def standing_still(poses):
    """Seconds of the stretches in which the robot stayed within STILL_RADIUS for STILL_SECONDS or more
    (exploring.stood_still of the poses, one a period)."""
    path = [(index * PERIOD, pose[0], pose[1]) for index, pose in enumerate(poses)]
    return sum(seconds for _, seconds, _ in stood_still(path, STILL_RADIUS, STILL_SECONDS))


def tour(obstacles, seed, count, planner_config):
    """A row: reached, sent, sim s, still s, recoveries, least clearance (m), wall s."""
    navigator, global_costmap, local_costmap = stack(obstacles, START, planner_config)
    robot, lidar = Unicycle(START), Lidar(obstacles)
    reached = recoveries = 0
    sim = still = 0.0
    least = math.inf
    wall = time.perf_counter()
    for goal in goals(obstacles, global_costmap, seed, count):
        navigator.set_goal(0.0, goal[:2] + (0.0,), quaternion_of_yaw(goal[2]))
        poses = [robot.pose.copy()]
        outcome, steps, clearance = run_stack(navigator, global_costmap, local_costmap, robot, lidar, GOAL_TIMEOUT,
                                              poses=poses)
        reached += outcome is not None and outcome.status == SUCCEEDED
        recoveries += sum(1 for step in steps if step.recovery)
        sim += len(steps) * PERIOD
        still += standing_still(poses)
        least = min(least, clearance['all'])
    return reached, count, sim, still, recoveries, least, time.perf_counter() - wall


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seeds', default='1,2,3', help='one tour of random goals per seed')
    parser.add_argument('--goals', type=int, default=12, help='goals per tour')
    args = parser.parse_args(argv)
    obstacles = world_cut('turtlebot3_house')
    print('# turtlebot3_house tours, %d goals each: %s, %s' % (args.goals, machine(), datetime.date.today()))
    print('| plans | seed | reached | sim s | standing still s | recoveries | least clearance m | wall s |')
    print('|---|---|---|---|---|---|---|---|')
    totals = {}
    configs = (("navfn's", PlannerConfig(obstacle_clearance=0.0)), ('obstacle_clearance 0.12', PlannerConfig()))
    for label, config in configs:
        for seed in (int(value) for value in args.seeds.split(',')):
            row = tour(obstacles, seed, args.goals, config)
            totals.setdefault(label, []).append(row)
            print('| %s | %d | %d/%d | %.0f | %.0f | %d | %.3f | %.0f |' % ((label, seed) + row), flush=True)
    for label, rows in totals.items():
        reached, sent, sim, still, recoveries = (sum(row[i] for row in rows) for i in range(5))
        print('| %s | all | %d/%d | %.0f | %.0f (%.0f %%) | %d | %.3f | %.0f |' % (
            label, reached, sent, sim, still, 100.0 * still / sim, recoveries, min(row[5] for row in rows),
            sum(row[6] for row in rows)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
