"""The mapping chapter, run as a learner runs it, measured: for `make demo DEMO_ARGS=--slam`, the bench and the tests.

map_world() does the e-manual's steps against a master of the caller's
(processes.start_master): `roslaunch tb3_sim_bringup tb3_world.launch`,
`roslaunch tb3_sim_bringup tb3_slam.launch open_rviz:=false`, a drive
(tb3_harness.route_driver steering on the truth, where the learner would use
the teleop), `rosrun map_server map_saver -f DIR/map`, both launches
stopped with Ctrl+C. It then measures the saved map against the world file
(tb3_harness.map_quality) and the end poses in map and odom against the
truth. No rospy in this process.
"""
import dataclasses
import json
import math
import os
import time

from .map_quality import measure
from .measure import CpuMeter, node_pid
from .processes import Process, RunError, master_pid, say, tail, wait_until
from .waypoints import WORLD_LOOP_START

READY_TIMEOUT = 60.0     # wall s for the launches to start
ROUTE_TIMEOUT = 900.0    # wall s for the drive (at factor 1: 90 s of sim time, plus start-up)
SAVE_TIMEOUT = 60.0      # wall s for map_saver


@dataclasses.dataclass
class MappingRun(object):
    """What one mapping run gave: paths (lists of [t, x, y, yaw]) of the truth, odometry and
    the map's pose; end errors (m, deg); the map's files and their measures; costs."""
    factor: float
    truth: list
    odom: list
    map: list
    sim_seconds: float
    wall_seconds: float
    cpu: dict                 # {process: share of a core} while the robot drove: tb3_slam, tb3_sim ...
    map_yaml: str
    quality: object           # map_quality.MapQuality
    map_error: tuple          # (m, deg) of the pose in map against the truth, at the end
    odom_error: tuple         # (m, deg) of odometry against the truth, at the end
    grid: object = None
    values: object = None

    @property
    def slam_cpu(self):
        """The share of a core the SLAM node used while the robot drove."""
        return self.cpu['tb3_slam']


def _error(estimate, truth):
    yaw = (estimate[3] - truth[3] + math.pi) % (2 * math.pi) - math.pi
    return math.hypot(estimate[1] - truth[1], estimate[2] - truth[2]), math.degrees(yaw)


def map_world(log_dir, output, factor=0.0, profile='realistic', seed=7, world='turtlebot3_world',
              launch='tb3_world.launch', route='world_loop', start=WORLD_LOOP_START):
    """One mapping run (see the module's doc); its MappingRun. RunError if a step fails."""
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
        process = Process(name, argv, log_dir, die_with_parent=True)
        started.append(process)
        return process
    try:
        sim = spawn('sim', ['roslaunch', 'tb3_sim_bringup', launch, 'profile:=%s' % profile,
                            'real_time_factor:=%g' % factor])
        slam = spawn('slam', ['roslaunch', 'tb3_sim_bringup', 'tb3_slam.launch', 'open_rviz:=false'])
        wait_until(lambda: 'tb3_slam parameters' in slam.output(None), READY_TIMEOUT, 'SLAM node',
                   watch=(sim, slam))
        nodes = ('/tb3_slam', '/tb3_sim', '/robot_state_publisher')
        pids = {}

        def found():
            pids.update((name, node_pid(name)) for name in nodes if pids.get(name) is None)
            return None not in pids.values()
        wait_until(found, READY_TIMEOUT, ', '.join(nodes), poll=0.1, watch=(sim, slam))
        path_file = os.path.join(log_dir, 'route_%g.json' % factor)
        say('mapping at factor %g: driving the %s route' % (factor, route))
        wall_start = time.monotonic()
        meter = CpuMeter([(name[1:], pids[name]) for name in nodes] + [('master', master_pid(master_uri))])
        driver = spawn('driver', ['python3', '-m', 'tb3_harness.route_driver', route, '--out', path_file])
        wait_until(lambda: not driver.running(), ROUTE_TIMEOUT, 'end of the route', watch=(sim, slam))
        wall = time.monotonic() - wall_start
        cpu = meter.shares()
        if driver.popen.returncode != 0:
            raise RunError('the route driver ended with code %s: %s' % (driver.popen.returncode, tail(driver.log)))
        with open(path_file) as stream:
            paths = json.load(stream)
        map_name = os.path.join(output, 'map')
        saver = spawn('map_saver', ['rosrun', 'map_server', 'map_saver', '-f', map_name])
        if saver.wait(SAVE_TIMEOUT) != 0:
            raise RunError('map_saver did not save the map (exit %s): %s' % (saver.popen.returncode, tail(saver.log)))
        say('mapping at factor %g: the route took %.1f s of sim time, %.1f s wall; map saved to %s.yaml'
            % (factor, paths['sim_seconds'], wall, map_name))
    finally:
        for process in reversed(started):
            process.stop()
    saved = load_map(map_name + '.yaml')
    worlds = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds')
    obstacles = load_world(world, worlds).obstacles
    quality = measure(saved.grid, saved.values, obstacles, start[:2])
    if not paths['map']:
        raise RunError('no pose in the map frame was ever recorded: %s' % tail(slam.log))
    return MappingRun(factor, paths['truth'], paths['odom'], paths['map'], paths['sim_seconds'], wall, cpu,
                      map_name + '.yaml', quality, _error(paths['map'][-1], paths['truth'][-1]),
                      _error(paths['odom'][-1], paths['truth'][-1]), saved.grid, saved.values)


def table(run):
    """The run's figures as lines of text, for the demo's summary and the bench."""
    quality = run.quality
    rows = [('route', '%.1f m in %.1f s of sim time, %.1f s wall (real_time_factor %g)'
             % (path_length(run.truth), run.sim_seconds, run.wall_seconds, run.factor)),
            ('pose in map at the end, off the truth', '%.3f m, %.2f deg' % run.map_error),
            ('odometry at the end, off the truth', '%.3f m, %.2f deg' % run.odom_error),
            ('occupied cells within 0.10 m of a real surface', '%.1f %% (goal >= 95 %%)'
             % (100 * quality.occupied_near_surface)),
            ('visible surface with an occupied cell within 0.10 m', '%.1f %% (goal >= 80 %%)'
             % (100 * quality.surface_covered)),
            ('wall thickness', '%g cells (goal: 1 or 2)' % quality.wall_thickness),
            ('doubled walls', '%.1f %% of the occupied cells' % (100 * quality.doubled_wall_share)),
            ('SLAM CPU while driving', '%.0f %% of a core' % (100 * run.slam_cpu))]
    width = max(len(name) for name, _ in rows)
    return ['turtlebot3_world mapped by tb3_slam.launch (profile realistic), saved by map_saver'] + [
        '  %-*s  %s' % (width, name, value) for name, value in rows]


def draw(run, filename):
    """The saved map under the world's outline, with the true, odometry and map paths."""
    import rospkg

    from tb3_sim_nav.world_file import load_world

    from .map_quality import render_png
    worlds = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds')
    render_png(filename, run.grid, run.values, load_world('turtlebot3_world', worlds).obstacles,
               paths={'truth': [p[1:3] for p in run.truth], 'odometry': [p[1:3] for p in run.odom],
                      'pose in map': [p[1:3] for p in run.map]},
               title='turtlebot3_world mapped (profile realistic): pose in map %.3f m off the truth, '
                     'odometry %.3f m' % (run.map_error[0], run.odom_error[0]))


def path_length(path):
    return sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(path, path[1:]))
