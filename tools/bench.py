"""`make bench`: speed, CPU, memory and start-up of the simulator, as a table.

Run inside `source setup.bash`. A benchmark, not a test: it measures and
prints medians over several runs, with the machine and the date, and marks
each figure against its target. It starts one master on a free loopback port
and stops everything it starts by process group (the demo's machinery). The
simulator's figures are measured in bench_sim.py, the cameras' in
bench_camera.py, the maps' and navigation's by the harness (mapping.py,
navigating.py).

    python3 tools/bench.py [--runs N] [--parts rtf,cpu,floor,camera,scripts,nav,explore]
"""
import argparse
import datetime
import math
import os
import sys

import bench_camera
from bench_sim import (
    CPU_SCRIPT,
    ROOT,
    RTF_ROWS,
    measure_cpu_and_startup,
    measure_cpu_of_script,
    measure_floor,
    measure_rtf,
    median,
    run_scripts,
    verdict,
)

from tb3_common.pose2d import normalize_angle
from tb3_harness import exploring, leftovers, mapping, navigating, tutorial
from tb3_harness.measure import machine
from tb3_harness.processes import RunError, say, start_master

TARGETS = {'cpu': 5.0, 'startup': 3.0, 'speedup': 10.0}


def cpu_rows(runs):
    """A row for each process of the runs at factors 1 and 0 (the same processes): its share of a core."""
    return ['%-58s %5.1f / %.1f %%' % ('    %s' % name, 100 * runs[1.0].cpu[name], 100 * runs[0.0].cpu[name])
            for name in runs[1.0].cpu]


def strict(run):
    """The MapQuality of an exploration's map with issue 31's tolerance, 0.05 m (the harness's is 0.10)."""
    from tb3_harness.map_quality import QualityConfig
    return run.measured(QualityConfig(tolerance=0.05))


def explore_rows(explored, navigated):
    """The house explored as fast as possible with and without explore_bounds, then its four rooms
    navigated on the first map (what `make demo DEMO_ARGS=--explore` does)."""
    lines = ['turtlebot3_house explored (tb3_slam.launch explore:=true, profile realistic), factor 0, one run each:']
    for label, run in explored.items():
        quality, still = run.quality, run.still_spells()
        lines += ['  %s:' % label,
                  '%-58s %12s' % ('    goals sent, blacklisted', '%d, %d' % (run.goals, run.blacklisted)),
                  '%-58s %5.0f s / %.0f s' % ('    sim / wall time (the launches included)', run.sim_seconds,
                                              run.wall_seconds),
                  '%-58s %12.1f' % ('    real-time factor', run.sim_seconds / run.wall_seconds),
                  '%-58s %12s' % ('    stood still (0.2 m for 20 s or more): times, sim s',
                                  '%d, %.0f s' % (len(still), sum(seconds for _, seconds, _ in still))),
                  '%-58s %5.1f / %.1f %%' % ('    occupied cells within 0.05 / 0.10 m of a surface',
                                             100 * strict(run).occupied_near_surface,
                                             100 * quality.occupied_near_surface),
                  '%-58s %11.1f%%' % ('    surfaces covered', 100 * quality.surface_covered),
                  '%-58s %11.1f%%' % ('    walls drawn twice (surface points)', 100 * quality.doubled_wall_share),
                  '    CPU of each process while exploring:']
        lines += ['%-58s %11.1f%%' % ('      %s' % name, 100 * share) for name, share in run.cpu.items()]
    first = next(iter(explored.values()))
    reached = sum(o.state == 'SUCCEEDED' for o in navigated.outcomes)
    lines += ['  its four rooms navigated on the first map (amcl, move_base):',
              '%-58s %12s' % ('    goals reached, worst true distance', '%d/%d, %.1f cm' % (
                  reached, len(navigated.outcomes), 100 * max(o.xy_error for o in navigated.outcomes))),
              '%-58s %5.0f s / %.0f s' % ('    sim / wall time of the goals', navigated.sim_seconds,
                                          navigated.wall_seconds),
              '%-58s %10.0f s  <= 120 s: %s' % ('  exploring (launches included) and the goals, wall time',
                                                first.wall_seconds + navigated.wall_seconds,
                                                verdict(first.wall_seconds + navigated.wall_seconds <= 120))]
    return lines


def nav_rows(mapped, navigated):
    """The mapping and navigation chapters' rows: one run each at factor 1 and as fast as possible."""
    slam_1, slam_0, nav_1, nav_0 = mapped[1.0], mapped[0.0], navigated[1.0], navigated[0.0]
    reached = ['%d/%d' % (sum(o.state == 'SUCCEEDED' for o in run.outcomes), len(run.outcomes))
               for run in (nav_1, nav_0)]
    worst = max(o.xy_error for o in nav_1.outcomes + nav_0.outcomes)
    return ['SLAM (tb3_slam.launch) round turtlebot3_world\'s pillars, profile realistic, one run each:',
            '%-58s %11.1f%%' % ('  CPU of the SLAM node at factor 1 while driving', 100 * slam_1.slam_cpu),
            '%-58s %12.1f' % ('  real-time factor reached with it, as fast as possible',
                              slam_0.sim_seconds / slam_0.wall_seconds),
            '%-58s %7.1f / %.1f cm' % ('  pose in map at the end, factor 1 / 0 (odometry: %.1f cm)'
                                       % (100 * slam_1.odom_error[0]), 100 * slam_1.map_error[0],
                                       100 * slam_0.map_error[0]),
            '%-58s %5.1f / %.1f %%' % ('  occupied cells on a surface of the world, factor 1 / 0',
                                      100 * slam_1.quality.occupied_near_surface,
                                      100 * slam_0.quality.occupied_near_surface),
            '  CPU of each process while driving, factor 1 / 0:'] + cpu_rows(mapped) + [
            'navigation (tb3_navigation.launch: amcl and move_base), four goals in turtlebot3_world:',
            '%-58s %11.1f%%' % ('  CPU of amcl and move_base at factor 1 while driving', 100 * nav_1.stack_cpu),
            '%-58s %12.1f' % ('  real-time factor reached with them, as fast as possible',
                              nav_0.sim_seconds / nav_0.wall_seconds),
            '%-58s %12s' % ('  goals reached, factor 1 / 0', ' / '.join(reached)),
            '%-58s %10.1f cm' % ('  worst true distance from a goal reached', 100 * worst),
            '  CPU of each process on the way to the goals, factor 1 / 0:'] + cpu_rows(navigated)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--runs', type=int, default=3, help='runs per figure (median reported)')
    parser.add_argument('--seconds', type=float, default=10.0, help='wall s per real-time-factor run')
    parser.add_argument('--cpu-seconds', type=float, default=30.0, help='wall s of the CPU measurement')
    parser.add_argument('--parts', default='rtf,cpu,floor,camera,scripts,nav',
                        help='comma-separated: rtf (max real-time factor), cpu (CPU, memory, start-up), '
                             'floor (CPU of a bare /clock loop, for scale), camera (frame costs, real time '
                             'with a camera read), scripts (the tutorial scripts at factor 1 and 0), nav (the '
                             'SLAM and the navigation stack at factor 1 and as fast as possible, once each); '
                             'default all; explore (turtlebot3_house explored with and without explore_bounds, '
                             'its rooms navigated: about 20 minutes) only when named')
    parser.add_argument('--output', default=os.path.join(ROOT, 'bench_output'))
    args = parser.parse_args(argv)
    log_dir = os.path.join(args.output, 'logs')
    os.makedirs(log_dir, exist_ok=True)
    master = None
    lines = []
    try:
        master = start_master(log_dir)
        import rospy
        rospy.init_node('tb3_bench', anonymous=True, argv=[sys.argv[0]], disable_signals=True)
        parts = args.parts.split(',')
        rtf, step_cost, rss = {}, {}, []
        for label, launch, robots, sensors, rospy_reader, _ in (RTF_ROWS if 'rtf' in parts else []):
            rtf[label], step_cost[label] = [], []
            for run in range(args.runs):
                value, cost, peak = measure_rtf(log_dir, launch, robots, sensors, args.seconds, rospy_reader)
                say('%s, run %d: real-time factor %.1f, %.0f us of CPU a step' % (label, run + 1, value, cost))
                rtf[label].append(value)
                step_cost[label].append(cost)
                rss.append(peak)
        cpu, cpu_script, startup = [], [], []
        for run in range(args.runs if 'cpu' in parts else 0):
            used, peak, started = measure_cpu_and_startup(log_dir, args.cpu_seconds)
            say('factor 1 while driving, run %d: %.1f %% of a core, start-up %.2f s' % (run + 1, used, started))
            cpu.append(used)
            rss.append(peak)
            startup.append(started)
            cpu_script.append(measure_cpu_of_script(log_dir, CPU_SCRIPT))
            say('factor 1 while %s drives, run %d: %.1f %% of a core' % (CPU_SCRIPT, run + 1, cpu_script[-1]))
        floor = dict((physics, []) for physics in ((False, True) if 'floor' in parts else ()))
        for run in range(args.runs if floor else 0):
            for physics in floor:
                floor[physics].append(measure_floor(log_dir, args.cpu_seconds, physics))
                say('floor%s, run %d: %.1f %% of a core' % (' with physics' if physics else '', run + 1,
                                                            floor[physics][-1]))
        camera = bench_camera.measure(log_dir, args.runs, args.cpu_seconds) if 'camera' in parts else None
        scripts = {}
        if 'scripts' in parts:
            for factor in (1.0, 0.0):
                scripts[factor] = run_scripts(log_dir, factor)
        mapped, navigated = {}, {}
        for factor in ((1.0, 0.0) if 'nav' in parts else ()):
            folder = os.path.join(args.output, 'map_at_factor_%g' % factor)
            os.makedirs(folder, exist_ok=True)
            mapped[factor] = mapping.map_world(log_dir, folder, factor=factor)
            say('SLAM at factor %g: %.1f s of sim time in %.1f s wall, the SLAM %.0f %% of a core' % (
                factor, mapped[factor].sim_seconds, mapped[factor].wall_seconds, 100 * mapped[factor].slam_cpu))
            navigated[factor] = navigating.navigate_world(log_dir, factor=factor)
            say('navigation at factor %g: %.1f s of sim time in %.1f s wall, amcl and move_base %.0f %% of a core'
                % (factor, navigated[factor].sim_seconds, navigated[factor].wall_seconds,
                   100 * navigated[factor].stack_cpu))

        explored, house = {}, None
        if 'explore' in parts:
            launch, start, bounded = exploring.WORLDS['turtlebot3_house']
            for label, slam_args in (('with explore_bounds (the demo)', bounded), ('without explore_bounds', ())):
                folder = os.path.join(args.output, 'house_%s' % ('bounded' if slam_args else 'unbounded'))
                os.makedirs(folder, exist_ok=True)
                explored[label] = exploring.explore_world(
                    log_dir, folder, 'turtlebot3_house', launch, start, factor=0.0, timeout=3600.0,
                    slam_command=exploring.SLAM_COMMAND + list(slam_args))
                say('turtlebot3_house %s: %s' % (label, explored[label].summary()))
                if house is None:
                    house = navigating.navigate_world(log_dir, factor=0.0, world='turtlebot3_house',
                                                      launch=launch, map_file=explored[label].map_yaml,
                                                      goals=navigating.HOUSE_GOALS, spawn=navigating.HOUSE_SPAWN)

        lines += ['tb3_sim_nav benchmark, %s' % datetime.date.today().isoformat(),
                  'machine: %s' % machine(),
                  'medians of %d runs; real-time factor = sim seconds per wall second' % args.runs, '',
                  '%-58s %12s  %s' % ('figure', 'value', 'target')]
        if rtf:
            lines.append('max real-time factor (factor 0), and CPU of the simulator per step:')
            for label, _, _, _, _, target in RTF_ROWS:
                value = median(rtf[label])
                lines.append('%-58s %12.1f  %6.0f us/step%s' % (
                    '  ' + label, value, median(step_cost[label]),
                    '  >= %g: %s' % (target, verdict(value >= target)) if target else ''))
        if cpu:
            lines += ['%-58s %11.1f%%  < %g %%: %s' % ('CPU of the simulator at factor 1, driving, all topics read',
                                                       median(cpu), TARGETS['cpu'],
                                                       verdict(median(cpu) < TARGETS['cpu'])),
                      '%-58s %11.1f%%  < %g %%: %s' % ('  the same, %s driving, no sensor read' % CPU_SCRIPT[:-3],
                                                       median(cpu_script), TARGETS['cpu'],
                                                       verdict(median(cpu_script) < TARGETS['cpu'])),
                      '%-58s %10.2f s  < %g s: %s' % ('start-up: roslaunch to first odom->base_footprint',
                                                      median(startup), TARGETS['startup'],
                                                      verdict(median(startup) < TARGETS['startup']))]
        if floor:
            lines += ['%-58s %11.1f%%' % ('  floor: a python loop paced to 100 Hz publishing /clock',
                                          median(floor[False])),
                      '%-58s %11.1f%%' % ('  floor: the same, a pybullet step each tick', median(floor[True]))]
        if camera:
            lines += bench_camera.table(*camera)
        if rss:
            lines.append('%-58s %8.0f MiB' % ('peak RSS of the simulator node (max over runs)', max(rss)))
        for script, _ in (tutorial.SCRIPTS if scripts else []):
            (wall_1, end_1), (wall_0, end_0) = scripts[1.0][script], scripts[0.0][script]
            ratio = wall_1 / wall_0
            apart = math.hypot(end_0[1] - end_1[1], end_0[2] - end_1[2])
            turn = abs(math.degrees(normalize_angle(end_0[3] - end_1[3])))
            lines += ['%-58s %7.1f s / %.1f s = %.1fx  >= %gx: %s'
                      % (script + ' wall time, factor 1 / factor 0', wall_1, wall_0, ratio,
                         TARGETS['speedup'], verdict(ratio >= TARGETS['speedup'])),
                      '%-58s %6.3f m %5.2f deg  (ends %+.3f %+.3f %+.1f deg / %+.3f %+.3f %+.1f deg)'
                      % ('  end pose, factor 0 against factor 1', apart, turn,
                         end_1[1], end_1[2], math.degrees(end_1[3]), end_0[1], end_0[2], math.degrees(end_0[3]))]
        if mapped:
            lines += nav_rows(mapped, navigated)
        if explored:
            lines += explore_rows(explored, house)
    except RunError as error:
        print('bench FAILED: %s' % error, file=sys.stderr)
        return 1
    finally:
        if master is not None:
            import rospy
            rospy.signal_shutdown('bench done')
            master.stop()
    text = '\n'.join(lines)
    print('\n' + text)
    with open(os.path.join(args.output, 'bench.txt'), 'w') as table:
        table.write(text + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(leftovers.run('make bench', main))
