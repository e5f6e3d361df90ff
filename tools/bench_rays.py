"""The lidars' cost with many Burgers in one world, core only, no ROS: bench_sim.py's ten in turtlebot3_world or
thirty in turtlebot3_house.

Times Lidar.read_all of all their lidars (CPU, time.process_time) and keeps
their noiseless ranges. With --before, a second source tree (its src folder,
e.g. `git archive merge22 src tb3_navigation/src | tar -x -C /tmp/base`) is
measured too, round by round in turn with this one, each round in a fresh
process; it prints both, their ratio, and how far the ranges agree. The
machine is shared: compare trees in one run, not runs.

    python3 tools/bench_rays.py [--house] [--before /tmp/base/src] [--rounds 5] [--casts 40]
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

from bench_sim import SEVEN, house_spots

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: (x, y, yaw) of multi_tb3.launch's three as bench_sim.py's MULTI_WORLD places them, and as the launch does.
WORLD_THREE = [(-2.0, -0.5, 0.0), (-2.0, 0.5, 0.0), (-1.5, 1.6, -0.8)]
HOUSE_THREE = [(-7.0, -1.0, 1.57), (7.0, -1.0, 1.57), (0.5, 3.0, 0.0)]


def robots(house):
    """(world, [(x, y, yaw) of each robot]) of bench_sim.py's ten in turtlebot3_world or thirty in turtlebot3_house."""
    if house:
        return 'turtlebot3_house', HOUSE_THREE + [(x, y, 0.0) for x, y in house_spots(27)]
    return 'turtlebot3_world', WORLD_THREE + [(x, y, 0.0) for _, (x, y) in SEVEN]


def measure(casts, world_name, poses):
    """(CPU us of each read_all of the robots' lidars, their ranges) in this process's tree."""
    from tb3_sim_nav.frames import planar
    from tb3_sim_nav.params import resolve
    from tb3_sim_nav.robot_model import load_model
    from tb3_sim_nav.sensors import Lidar
    from tb3_sim_nav.simulation import build
    from tb3_sim_nav.world_file import load_world
    burger = load_model(os.path.join(ROOT, 'urdf', 'turtlebot3_burger.urdf'))
    parameters = dict(model=os.path.join(ROOT, 'urdf', 'turtlebot3_burger.urdf'), scan_noise=0.0, seed=1)
    config = resolve(lambda name, default: parameters.get(name, default))
    world = load_world(world_name, os.path.join(ROOT, 'worlds'))
    simulation = build(config, world.obstacles, [('tb3_%d' % index, burger, planar(x, y, 0.0, yaw))
                                                 for index, (x, y, yaw) in enumerate(poses)])
    for _ in range(50):  # 0.5 s: the robots settle on their wheels
        simulation.step()
    lidars = [robot.lidar for robot in simulation.robots.values()]
    ranges = Lidar.read_all(lidars)
    times = []
    for _ in range(casts):
        start = time.process_time()
        Lidar.read_all(lidars)
        times.append((time.process_time() - start) * 1e6)
    simulation.close()
    return times, [[value if math.isfinite(value) else str(value) for value in scan] for scan in ranges]


def map_world(rounds, repeats=15):
    """Table rows (label, value) of test_map's load time and its lidar cost against turtlebot3_world's."""
    import numpy as np

    import tb3_sim_nav.world_rays
    from tb3_sim_nav.world import World
    from tb3_sim_nav.world_file import load_world
    test_map, worlds = os.path.join(ROOT, 'maps', 'rbx1', 'test_map.yaml'), os.path.join(ROOT, 'worlds')
    loads = []
    for _ in range(rounds):
        start = time.process_time()  # CPU of this process, pybullet's included
        loaded = load_world(test_map, worlds)
        parsed = time.process_time()
        World(0.01, loaded.obstacles).close()
        loads.append((parsed - start, time.process_time() - parsed))
    angles = np.arange(360) * 2 * math.pi / 360
    directions = np.stack((np.cos(angles), np.sin(angles), np.zeros(360)), -1)

    def scan_cost(world, spots):
        """Mean CPU s of a 3.5 m scan at the Burger's lidar height from each (x, y) of `spots`."""
        total = 0.0
        for x, y in spots:
            origin = np.array([x, y, 0.182])
            world.rays.cast([origin], [directions], 3.5, [None])
            start = time.process_time()
            for _ in range(repeats):
                world.rays.cast([origin], [directions], 3.5, [None])
            total += time.process_time() - start
        return total / repeats / len(spots)

    # Three free spots of each: the book's living and dining rooms; the launch's spawn, among the pillars, a corner.
    map_spots, world_spots = [(0.0, 0.0), (0.72, 2.23), (-0.86, 0.0)], [(-2.0, -0.5), (0.5, 0.5), (1.6, 1.6)]
    mapped = World(0.01, loaded.obstacles)
    reference = World(0.01, load_world('turtlebot3_world', worlds).obstacles)
    every_beam, costs = tb3_sim_nav.world_rays.MAX_STILL_SHAPES, []
    try:
        for _ in range(rounds):  # interleaved
            tb3_sim_nav.world_rays.MAX_STILL_SHAPES = every_beam
            mapped_cost = scan_cost(mapped, map_spots)
            tb3_sim_nav.world_rays.MAX_STILL_SHAPES = -1
            costs.append((mapped_cost, scan_cost(reference, world_spots)))
    finally:
        tb3_sim_nav.world_rays.MAX_STILL_SHAPES = every_beam
        mapped.close()
        reference.close()
    occupied = int((loaded.map.values == 100).sum())
    # The fastest of the rounds: what each costs when no other process takes the CPU (2 shared cores).
    best_map, best_world = min(a for a, _ in costs), min(b for _, b in costs)
    return [('test_map: occupied cells -> boxes', '%d -> %d' % (occupied, len(loaded.obstacles))),
            ('test_map load: YAML and boxes, s (median)', '%.3f' % statistics.median(a for a, _ in loads)),
            ('test_map load: pybullet bodies, s (median)', '%.3f' % statistics.median(b for _, b in loads)),
            ('360-beam scan in test_map, ms (best)', '%.2f' % (1e3 * best_map)),
            ('same, turtlebot3_world every beam in pybullet, ms (best)', '%.2f' % (1e3 * best_world)),
            ('ratio test_map / turtlebot3_world', '%.2f' % (best_map / best_world))]


def run(src, casts, world, poses):
    """measure() in a fresh process whose tb3_sim_nav is `src`'s."""
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [src, os.path.join(os.path.dirname(src), 'tb3_navigation', 'src'), os.environ.get('PYTHONPATH', '')]))
    output = subprocess.run([sys.executable, __file__, '--child', json.dumps([casts, world, poses])],
                            env=environment, check=True, stdout=subprocess.PIPE).stdout
    return json.loads(output.splitlines()[-1])  # pybullet prints its build time first


def agreement(before, after):
    """(rays whose hit or miss differs, |differences| of the ranges both hit, rays)."""
    differ, gaps, rays = 0, [], 0
    for old, new in zip(before, after):
        for a, b in zip(old, new):
            rays += 1
            if isinstance(a, str) or isinstance(b, str):
                differ += a != b
            else:
                gaps.append(abs(a - b))
    return differ, gaps, rays


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--house', action='store_true', help="bench_sim.py's thirty robots in turtlebot3_house")
    parser.add_argument('--before', help='the src folder of the tree to compare with')
    parser.add_argument('--rounds', type=int, default=5)
    parser.add_argument('--casts', type=int, default=40, help='read_all calls a round')
    parser.add_argument('--map-world', action='store_true', help="test_map as a world: load time and lidar cost")
    parser.add_argument('--child', help=argparse.SUPPRESS)
    arguments = parser.parse_args()
    if arguments.map_world:
        from tb3_harness.measure import machine
        print('map world, machine: %s; %d rounds, CPU time of this process' % (machine(), arguments.rounds))
        for label, value in map_world(arguments.rounds):
            print('%-58s %12s' % (label, value))
        return
    if arguments.child:
        print(json.dumps(measure(*json.loads(arguments.child))))
        return
    world, poses = robots(arguments.house)
    trees = [('this', os.path.join(ROOT, 'src'))] + ([('before', arguments.before)] if arguments.before else [])
    times, ranges = dict((name, []) for name, _ in trees), {}
    for round_ in range(arguments.rounds):
        for name, src in (trees if round_ % 2 == 0 else trees[::-1]):
            spent, ranges[name] = run(os.path.abspath(src), arguments.casts, world, poses)
            times[name].append(statistics.median(spent) / len(poses))
    for name, _ in trees:
        print('%-6s  %7.0f us a scan (CPU; median of %d read_alls of %d lidars in %s, rounds %s)'
              % (name, statistics.median(times[name]), arguments.casts, len(poses), world,
                 ' '.join('%.0f' % value for value in times[name])))
    if arguments.before:
        print('this / before: %.2f' % (statistics.median(times['this']) / statistics.median(times['before'])))
        differ, gaps, rays = agreement(ranges['before'], ranges['this'])
        print('ranges: %d of %d rays differ in hit or miss; of the %d hits of both, %d differ by more than '
              '0.01 mm, %d by more than 7 mm; at most %.2g m' % (differ, rays, len(gaps), sum(g > 1e-5 for g in gaps),
                                                                sum(g > 0.007 for g in gaps), max(gaps + [0.0])))


if __name__ == '__main__':
    main()
