"""A robot that maps a world by itself, run as a learner runs it, measured: for the tests, the demo and the bench.

explore_world() does it against a master of the caller's
(processes.start_master): `roslaunch tb3_sim_bringup tb3_world.launch` (or
another world's launch), `roslaunch tb3_sim_bringup tb3_slam.launch
explore:=true open_rviz:=false`, waits until the explore node says
"exploration done", then `rosrun map_server map_saver -f DIR/map`, and
stops both launches with Ctrl+C. A recorder (tb3_harness.pose_recorder)
keeps the true path meanwhile. It then measures the saved map against the
world file (tb3_harness.map_quality; the free floor within the world's own
box, not the yard round turtlebot3_house that the SLAM's map also holds) and the footprint's least distance to
the world along the true path (tb3_harness.navigating.clearance). No rospy
in this process.
"""
import dataclasses
import json
import math
import os
import re
import time

from .map_quality import QualityConfig, measure
from .measure import CpuMeter, node_pid
from .navigating import clearance
from .processes import Process, RunError, master_pid, say, tail, wait_until

READY_TIMEOUT = 60.0   # wall s for the launches to start
SAVE_TIMEOUT = 60.0    # wall s for map_saver
BURGER_FOOTPRINT = [(-0.105, -0.105), (-0.105, 0.105), (0.041, 0.105), (0.041, -0.105)]
DONE = re.compile(r'\[([0-9.]+) s\] exploration done: (.*?)\. Explored ([0-9.]+) m2 free and ([0-9.]+) m2 occupied, '
                  r'([0-9]+) % .*?; ([0-9]+) goals sent in ([0-9.]+) s, ([0-9]+) blacklisted')
GOAL = re.compile(r'explore: \[([0-9.]+) s\] goal ([0-9]+) \(')
GOAL_LINE = re.compile(r'explore: (\[[0-9.]+ s\] goal [0-9]+ .*)')
#: A robot that stays within STILL_REACH m of one spot for STILL_LEAST s of sim time or more stands still:
#: move_base's recoveries, goals given up after explore's progress_timeout (30 s).
STILL_REACH, STILL_LEAST = 0.2, 20.0


@dataclasses.dataclass
class ExplorationRun(object):
    """What one exploration gave: the done line's reason, goals sent and blacklisted, the sim
    time from the first goal to the end, the wall time from the launches' start; the true path
    ([t, x, y, yaw]), recorded until the launches stop; the saved map's files and measures; the
    footprint's least clearance (m); the sim time of the done line."""
    world: str
    factor: float
    done_text: str
    goals: int
    blacklisted: int
    sim_seconds: float
    wall_seconds: float
    truth: list
    map_yaml: str
    quality: object          # map_quality.MapQuality
    clearance: float
    cpu: dict                # {process: share of a core} from the explorer's start to its end
    grid: object = None
    values: object = None
    start: tuple = None      # the spawn (x, y)
    obstacles: list = None   # the world's (world_file.load_world)
    done_at: float = math.inf  # sim s of the explore node's "exploration done"

    def measured(self, config=QualityConfig()):
        """The map's MapQuality (map_quality.measure) under `config` (the harness's tolerance by default)."""
        from tb3_sim_nav import world_map
        return measure(self.grid, self.values, self.obstacles, self.start, config,
                       bounds=world_map.bounds(world_map.in_plane(self.obstacles)))

    def still_spells(self):
        """stood_still() of the true path until the exploration was done: the robot stands still on
        while the map is saved and the launches stop (36 and 64 s of sim time in two runs)."""
        return stood_still([pose for pose in self.truth if pose[0] <= self.done_at])

    def summary(self):
        still = self.still_spells()
        return ('%s explored in %.1f s of sim time (%.1f s wall at factor %g): %d goals, %d blacklisted; %s; '
                'stood still %d times, %.0f s in all; footprint at least %.3f m from the world; %s' % (
                    self.world, self.sim_seconds, self.wall_seconds, self.factor, self.goals, self.blacklisted,
                    self.done_text, len(still), sum(seconds for _, seconds, _ in still), self.clearance,
                    self.quality.summary()))


def stood_still(path, reach=STILL_REACH, least=STILL_LEAST):
    """Where a path [[t, x, y, ...], ...] (sim s, m) stayed within `reach` m of where it was at a time for
    `least` s or more: [(start, seconds, (x, y))], in order."""
    spells, first = [], 0
    while first < len(path):
        last = first
        while last + 1 < len(path) and math.hypot(path[last + 1][1] - path[first][1],
                                                  path[last + 1][2] - path[first][2]) < reach:
            last += 1
        seconds = path[last][0] - path[first][0]
        if seconds >= least:
            spells.append((path[first][0], seconds, (path[first][1], path[first][2])))
        first = last + 1
    return spells


def _read(path):
    try:
        with open(path, errors='replace') as stream:
            return stream.read()
    except OSError:
        return ''


def progress(log_text):
    """(goals sent, sim time of the last one, done match or None) from the explore node's log."""
    goals = GOAL.findall(log_text)
    return len(goals), float(goals[-1][0]) if goals else math.nan, DONE.search(log_text)


#: The SLAM with exploration, as the walkthrough has it but without rviz.
SLAM_COMMAND = ['roslaunch', 'tb3_sim_bringup', 'tb3_slam.launch', 'explore:=true', 'open_rviz:=false']


def explore_world(log_dir, output, world='turtlebot3_world', launch='tb3_world.launch', start=(-2.0, -0.5),
                  factor=0.0, profile='realistic', seed=7, timeout=900.0, launch_args=(), say_every=60.0,
                  slam_command=SLAM_COMMAND, when_saved=None):
    """One exploration (see the module's doc); its ExplorationRun. RunError if a step fails or the
    explore node is not done within `timeout` wall s. `start`: the spawn (x, y) of `launch`;
    `slam_command`: the argv that starts the SLAM and the explorer (a test types the README's
    through bash); `when_saved()` is called once the map is saved, before anything is stopped."""
    import rosgraph
    import rospkg

    from tb3_common.map_files import load_map
    from tb3_sim_nav.world_file import load_world
    master_uri = os.environ['ROS_MASTER_URI']
    if master_pid(master_uri) is None:
        raise RunError('no ROS master at %s' % master_uri)
    rosgraph.Master('/tb3_harness').setParam('/tb3_sim/seed', seed)
    started = []

    def spawn(name, argv):
        process = Process(name, argv, log_dir)
        started.append(process)
        return process
    path_file = os.path.join(log_dir, 'exploration_path.json')
    map_name = os.path.join(output, 'map')
    wall_start = time.monotonic()
    try:
        sim = spawn('sim', ['roslaunch', 'tb3_sim_bringup', launch, 'profile:=%s' % profile,
                            'real_time_factor:=%g' % factor] + list(launch_args))
        recorder = spawn('recorder', ['python3', '-m', 'tb3_harness.pose_recorder', '--out', path_file])
        slam = spawn('slam', list(slam_command))
        wait_until(lambda: 'connected to move_base' in _read(slam.log), READY_TIMEOUT, 'explore node',
                   watch=(sim, slam, recorder))
        say('exploring %s at factor %g' % (world, factor))
        told, shown = time.monotonic(), 0
        meter = CpuMeter([(name[1:], node_pid(name)) for name in ('/tb3_slam', '/move_base', '/explore', '/tb3_sim',
                                                                   '/robot_state_publisher')]
                         + [('master', master_pid(master_uri))])

        def done():
            nonlocal told, shown
            text = _read(slam.log)
            lines = GOAL_LINE.findall(text)
            for line in lines[shown:]:  # a line per goal: sim time, frontier, area mapped so far
                say('%s: %s' % (world, line))
            shown = len(lines)
            if time.monotonic() - told > say_every:
                told = time.monotonic()
                goals, last, _ = progress(text)
                say('exploring %s: %d goals so far, the last at %.1f s of sim time' % (world, goals, last))
            return DONE.search(text) is not None
        wait_until(done, timeout, 'end of the exploration ("exploration done" in %s)' % slam.log, poll=1.0,
                   watch=(sim, slam, recorder))
        wall = time.monotonic() - wall_start
        cpu = meter.shares()
        match = progress(_read(slam.log))[2]
        saver = spawn('map_saver', ['rosrun', 'map_server', 'map_saver', '-f', map_name])
        if saver.wait(SAVE_TIMEOUT) != 0:
            raise RunError('map_saver did not save the map (exit %s): %s' % (saver.popen.returncode, tail(saver.log)))
        say('%s explored: %s' % (world, match.group(0)))
        if when_saved is not None:
            when_saved()
    finally:
        for process in reversed(started):
            process.stop()
    with open(path_file) as stream:
        truth = json.load(stream)['truth']
    saved = load_map(map_name + '.yaml')
    worlds = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds')
    obstacles = load_world(world, worlds).obstacles
    run = ExplorationRun(world, factor, match.group(2), int(match.group(6)), int(match.group(8)),
                         float(match.group(7)), wall, truth, map_name + '.yaml', None,
                         clearance(truth, obstacles, BURGER_FOOTPRINT), cpu, saved.grid, saved.values,
                         tuple(start[:2]), obstacles, float(match.group(1)))
    run.quality = run.measured()
    return run


#: The worlds explored from their launch's spawn pose: launch, spawn (x, y), the SLAM's launch args.
#: turtlebot3_house is open to a yard on its south side: explore_bounds keeps the goals in the house's
#: box (the yard took 400 s more, and walls mapped from outside and inside came out doubled), drawn along
#: its outer walls' middle lines (x +-7.5, y +-5.275): a box round their outer faces (+-7.6, +-5.4) let
#: frontiers in the yard just beyond the open south side count as inside, and once a run drove round the
#: house's outside, its map 3 degrees off (2026-11-29).
HOUSE_BOUNDS = '[-7.5,-5.275,7.5,5.275]'
WORLDS = {'turtlebot3_world': ('tb3_world.launch', (-2.0, -0.5), ()),
          'turtlebot3_house': ('tb3_house.launch', (-3.0, 1.0), ('explore_bounds:=' + HOUSE_BOUNDS,))}


def table(run):
    """The exploration's figures, for the demo's table."""
    quality = run.quality
    return ['%s explored alone by tb3_slam.launch explore:=true (profile realistic), real_time_factor %g'
            % (run.world, run.factor),
            '  ended: %s' % run.done_text,
            '  %d goals sent, %d blacklisted, in %.1f s of sim time (%.1f s wall)'
            % (run.goals, run.blacklisted, run.sim_seconds, run.wall_seconds),
            '  reachable free floor mapped as free: %.1f %%' % (100 * quality.free_floor_mapped),
            '  occupied cells on a surface of the world: %.1f %%; surfaces covered: %.1f %%; walls %.1f cells thick'
            % (100 * quality.occupied_near_surface, 100 * quality.surface_covered, quality.wall_thickness),
            '  footprint never nearer than %.3f m to the world' % run.clearance,
            '  map saved: %s' % run.map_yaml]


def draw(run, filename, navigation_path=None):
    """The saved map under the world's outline, with the true path (and a navigation's after it)."""
    from .map_quality import render_png
    paths = {'exploration path': [p[1:3] for p in run.truth]}
    if navigation_path:
        paths['navigation path'] = [p[1:3] for p in navigation_path]
    render_png(filename, run.grid, run.values, run.obstacles, paths=paths,
               title='%s explored alone: %.0f %% of the reachable free floor mapped, %.0f s of sim time, %d goals'
                     % (run.world, 100 * run.quality.free_floor_mapped, run.sim_seconds, run.goals))


def main(argv=None):
    """python3 -m tb3_harness.exploring WORLD --out DIR: one exploration against a master of
    its own (profile realistic, as fast as possible), its figures, and DIR/exploration.png."""
    import argparse

    from .processes import start_master
    parser = argparse.ArgumentParser(description=main.__doc__.split('\n')[0])
    parser.add_argument('world', choices=sorted(WORLDS))
    parser.add_argument('--out', required=True, help='a folder for the logs, the map and the picture')
    parser.add_argument('--timeout', type=float, default=3600.0, help='wall s for the exploration')
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    os.environ.setdefault('TURTLEBOT3_MODEL', 'burger')
    launch, start, slam_args = WORLDS[args.world]
    master = start_master(args.out)
    try:
        run = explore_world(args.out, args.out, world=args.world, launch=launch, start=start, timeout=args.timeout,
                            slam_command=SLAM_COMMAND + list(slam_args))
    finally:
        master.stop()
    draw(run, os.path.join(args.out, 'exploration.png'))
    print(run.summary())
    return 0


if __name__ == '__main__':
    import sys
    sys.exit(main())
