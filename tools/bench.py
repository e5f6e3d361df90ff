"""`make bench`: speed, CPU, memory and start-up of the simulator, as a table.

Run inside `source setup.bash`. A benchmark, not a test: it measures and
prints medians over several runs, with the machine and the date, and marks
each figure against its target. It starts one master on a free loopback port
and stops everything it starts by process group (the demo's machinery).

    python3 tools/bench.py [--runs N] [--parts rtf,cpu,floor,camera,scripts]
"""
import argparse
import datetime
import math
import os
import statistics
import sys
import time

from tb3_harness import leftovers, mapping, navigating, report, tutorial
from tb3_harness.measure import cpu_seconds, machine, memory_mib, sim_pid, sim_uri
from tb3_harness.processes import Process, RunError, say, start_master, wait_until
from tb3_harness.screen import start_xvfb
from tb3_harness.tcpros_reader import TcprosReader

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

LAUNCH = ['roslaunch', '--wait', 'tb3_sim_bringup']
EMPTY_WORLD, WALLED_WORLD = 'tb3_empty_world.launch', 'tb3_world.launch'  # the tutorial's two
MULTI_HOUSE = 'multi_tb3.launch'  # as it starts: three robots in turtlebot3_house, far apart
# The same three in turtlebot3_world, within each other's lidar range, as test/multi_tb3.test has them.
MULTI_WORLD = ' '.join(['multi_tb3.launch', 'world:=turtlebot3_world'] + [
    '%s_tb3_%s:=%g' % (robot, key, value) for robot, pose in
    (('first', (-2.0, -0.5, 0.0)), ('second', (-2.0, 0.5, 0.0)), ('third', (-1.5, 1.6, -0.8)))
    for key, value in zip(('x_pos', 'y_pos', 'yaw'), pose)])
GLOBAL_TOPICS = ['clock', 'tf']
ROBOT_TOPICS = ['odom', 'joint_states', 'base_pose_ground_truth', 'scan', 'imu']
TOPICS = GLOBAL_TOPICS + ROBOT_TOPICS
THREE = ['tb3_0', 'tb3_1', 'tb3_2']
#: Seven more robots for ten in turtlebot3_world, between the pillars.
SEVEN = [('tb3_%d' % (3 + index), position) for index, position in enumerate(
    [(0.55, 0.55), (-0.55, 0.55), (0.55, -0.55), (-0.55, -0.55), (1.65, 0.55), (1.65, -0.55), (0.55, 1.65)])]
#: Twenty-seven more for thirty in turtlebot3_house: free spots of its floor, found by
#: house_spots() (far from multi_tb3.launch's three and from each other).
HOUSE_ROBOTS = 27
# (label, launch file and arguments, its robots' names, sensors switched off, read by a
# rospy node, target). Each topic of each robot is read by a TcprosReader
# (nearly free), or by one rospy node, which handles each message in python.
# In the empty world no lidar beam can hit anything, and none is cast;
# turtlebot3_world casts them.
RTF_ROWS = [('1 robot, empty world, every topic read', EMPTY_WORLD, [''], {}, False, None),
            ('  the same without scan', EMPTY_WORLD, [''], {'scan': False}, False, None),
            ('  the same without imu', EMPTY_WORLD, [''], {'imu': False}, False, None),
            ('  the same without scan and imu', EMPTY_WORLD, [''], {'scan': False, 'imu': False}, False, None),
            ('  the same, every topic read by a rospy node', EMPTY_WORLD, [''], {}, True, None),
            ('1 robot, turtlebot3_world, every topic read', WALLED_WORLD, [''], {}, False, 30.0),
            ('3 robots, turtlebot3_world, every topic read', MULTI_WORLD, THREE, {}, False, 10.0),
            ('3 robots, turtlebot3_house (multi_tb3.launch), every topic read', MULTI_HOUSE, THREE, {}, False,
             None),
            ('10 robots, turtlebot3_world, every topic read', MULTI_WORLD, THREE + [name for name, _ in SEVEN], {},
             False, None),
            ('30 robots, turtlebot3_house, every topic read', MULTI_HOUSE,
             THREE + ['tb3_%d' % (3 + index) for index in range(HOUSE_ROBOTS)], {}, False, None)]
CPU_SCRIPT = 'odom_out_and_back.py'  # the tutorial script that reads tf
FRAME_SIZES = [(320, 240), (640, 360), (640, 480), (1280, 720), (1920, 1080)]
# (label, model, camera size and rate or None for the defaults, camera topics
# read; None: rviz shows camera.rviz on a screen of its own)
ALL_OF_THE_R200 = ['rgb/image_raw', 'depth/image_raw', 'depth/points']
CAMERA_ROWS = [('waffle_pi, defaults', 'waffle_pi', None, None, ['rgb/image_raw']),
               ('waffle_pi, 640 x 480 at 30 Hz (Gazebo\'s)', 'waffle_pi', (640, 480), 30.0, ['rgb/image_raw']),
               ('waffle_pi, defaults, rviz showing camera.rviz', 'waffle_pi', None, None, None),
               ('waffle_pi, 640 x 480 at 30 Hz, rviz showing camera.rviz', 'waffle_pi', (640, 480), 30.0, None),
               ('waffle, defaults, colour, depth and cloud', 'waffle', None, None, ALL_OF_THE_R200),
               ('waffle, 640 x 360 at 30 Hz, colour, depth and cloud', 'waffle', (640, 360), 30.0, ALL_OF_THE_R200),
               ('waffle, 1920 x 1080 at 30 Hz (Gazebo\'s), all three', 'waffle', (1920, 1080), 30.0, ALL_OF_THE_R200)]
PHYSICS_RATE = 100.0  # the simulator's default steps per sim second
RVIZ_SETTLE = 15.0    # wall s for rviz to start and show the camera before measuring
TARGETS = {'cpu': 5.0, 'startup': 3.0, 'speedup': 10.0}


class Listener(object):
    """Subscribes to `topics` of the simulator (by default every one, so every
    sensor is computed) without deserialising, and notes the newest /clock and
    the first tf."""

    def __init__(self, topics=TOPICS):
        import rospy
        from rosgraph_msgs.msg import Clock
        from tf2_msgs.msg import TFMessage
        self.clock = None
        self.first_tf_wall = None
        self.subscribers = [rospy.Subscriber(topic, rospy.AnyMsg, lambda _message: None, queue_size=1)
                            for topic in topics if topic not in ('clock', 'tf')]
        if 'clock' in topics:
            self.subscribers.append(rospy.Subscriber('clock', Clock, self._on_clock, queue_size=1))
        self.subscribers.append(rospy.Subscriber('tf', TFMessage, self._on_tf, queue_size=10))

    def _on_clock(self, message):
        self.clock = message.clock.to_sec()

    def _on_tf(self, message):
        if self.first_tf_wall is None and any(t.child_frame_id == 'base_footprint' for t in message.transforms):
            self.first_tf_wall = time.monotonic()

    def close(self):
        for subscriber in self.subscribers:
            subscriber.unregister()
        self.subscribers = []


def house_spots(count, clearance=0.5, spacing=1.0):
    """`count` (x, y) spots of turtlebot3_house's floor, on a grid, at least
    `clearance` m from any wall and `spacing` m from multi_tb3.launch's three."""
    import numpy as np
    from tb3_sim_nav.world_file import load_world
    from tb3_sim_nav.world_map import in_plane, signed_distance
    walls = in_plane(load_world('turtlebot3_house', os.path.join(ROOT, 'worlds')).obstacles, 0.1)
    taken = [(-7.0, -1.0), (7.0, -1.0), (0.5, 3.0)]  # multi_tb3.launch's defaults (first, second, third)
    xs, ys = np.meshgrid(np.arange(-7.5, 7.6, spacing), np.arange(-4.5, 4.6, spacing))
    grid = np.column_stack((xs.ravel(), ys.ravel()))
    free = grid[signed_distance(walls, grid) > clearance]
    free = [tuple(spot) for spot in free if min(math.dist(spot, other) for other in taken) >= spacing]
    if len(free) < count:
        raise RunError('turtlebot3_house has %d free spots, not %d' % (len(free), count))
    return [free[index * len(free) // count] for index in range(count)]


def start_sim(name, log_dir, factor, launch=EMPTY_WORLD, sensors=None, robots=('',)):
    """One of the tutorial's launches at `factor`; `sensors` maps 'scan' and
    'imu' to False to switch them off (private parameters of /tb3_sim); more
    than three `robots`: the seven of SEVEN join MULTI_WORLD's three, or the
    house's spots join MULTI_HOUSE's three."""
    import rosgraph
    master = rosgraph.Master('/tb3_bench')
    for key in ('scan', 'imu'):
        master.setParam('/tb3_sim/' + key, (sensors or {}).get(key, True))
    argv = LAUNCH + launch.split() + ['real_time_factor:=%g' % factor]
    if len(robots) > len(THREE):
        house = launch == MULTI_HOUSE
        extra = (zip(robots[len(THREE):], house_spots(len(robots) - len(THREE))) if house else SEVEN)
        world = os.path.join(log_dir, 'many_robots.yaml')
        source = os.path.join(ROOT, 'worlds', 'turtlebot3_house.yaml' if house else 'turtlebot3_world.yaml')
        with open(source) as walls, open(world, 'w') as many:
            many.write(walls.read() + 'robots:\n' + ''.join(
                '  - {name: %s, model: burger, position: [%g, %g]}\n' % ((name,) + tuple(position))
                for name, position in extra))
        argv.append('world:=' + world)  # roslaunch: the last world:= wins
    return Process(name, argv, log_dir)


def measure_rtf(log_dir, launch, robots, sensors, seconds, rospy_reader=False):
    """At factor 0: sim seconds per wall second, the node's CPU per step (us) and
    its peak RSS. Every topic of every robot is read by a TcprosReader, or with
    `rospy_reader` by a rospy node."""
    listener = Listener() if rospy_reader else None
    sim = start_sim('rtf', log_dir, 0.0, launch, sensors, robots)
    readers = []
    try:
        if listener is None:
            topics = ['/' + topic for topic in GLOBAL_TOPICS] + [
                '/' + robot + ('/' if robot else '') + topic for robot in robots for topic in ROBOT_TOPICS
                if sensors.get(topic, True)]
            readers = [TcprosReader(sim_uri, topic) for topic in topics]
            clock = readers[0]
        else:
            clock = listener
        wait_until(lambda: clock.clock is not None and clock.clock > 1.0, 120, '/clock')
        time.sleep(1.0)
        pid = sim_pid()
        sim_start, wall_start, cpu_start = clock.clock, time.monotonic(), cpu_seconds(pid)
        time.sleep(seconds)
        sim_end, wall_end, cpu_end = clock.clock, time.monotonic(), cpu_seconds(pid)
        steps = (sim_end - sim_start) * PHYSICS_RATE
        return (sim_end - sim_start) / (wall_end - wall_start), 1e6 * (cpu_end - cpu_start) / steps, memory_mib(pid)
    finally:
        for reader in readers:
            reader.close()
        if listener is not None:
            listener.close()
        sim.stop()


def measure_frames(runs):
    """Median wall and CPU ms to render one frame (colour and depth) of the
    Waffle's camera in turtlebot3_world, by size, with pybullet's EGL plugin
    on Mesa's llvmpipe (the simulator's choice) and, in a world without it,
    with its TinyRenderer (once loaded, the plugin renders every image)."""
    from tb3_sim_nav.camera import Camera
    from tb3_sim_nav.frames import planar
    from tb3_sim_nav.params import resolve
    from tb3_sim_nav.robot_model import load_model
    from tb3_sim_nav.simulation import Simulation
    from tb3_sim_nav.world_file import load_world
    model = load_model(os.path.join(ROOT, 'urdf', 'turtlebot3_waffle.urdf'))
    obstacles = load_world('turtlebot3_world', os.path.join(ROOT, 'worlds')).obstacles
    costs, egl = {}, None
    for name, cameras in (('egl', True), ('tiny', False)):
        simulation = Simulation(resolve(lambda key, default: default), obstacles, cameras=cameras)
        try:
            if cameras:
                import pybullet
                egl = simulation.world.renderer != pybullet.ER_TINY_RENDERER
            body = simulation.add_robot('', model, planar(-2.0, -0.5)).body
            for width, height in FRAME_SIZES:
                camera = Camera(body, model.cameras[0], width, height, model.cameras[0].horizontal_fov, 30.0)
                camera.render()  # the first frame sets the renderer up
                walls, cpus = [], []
                for _ in range(runs * 3):
                    wall, cpu = time.perf_counter(), time.process_time()
                    camera.render()
                    walls.append(1000.0 * (time.perf_counter() - wall))
                    cpus.append(1000.0 * (time.process_time() - cpu))
                costs[(name, width, height)] = (median(walls), median(cpus))
                say('frame %d x %d, %s: %.1f ms wall, %.1f ms CPU' % ((width, height, name) + costs[(name, width, height)]))
        finally:
            simulation.close()
    return costs, egl


def measure_camera(log_dir, model, size, rate, topics, seconds):
    """At factor 1 in turtlebot3_world, with the camera's `topics` read (None:
    rviz shows camera.rviz on an Xvfb screen): sim seconds per wall second, the
    simulator's CPU (% of a core) and the colour images a sim second (a camera
    drops frames rather than hold the world back: ros/sensor_io.py)."""
    import rosgraph
    master = rosgraph.Master('/tb3_bench')
    for key, value in zip(('camera_width', 'camera_height', 'camera_rate'), (size or (None, None)) + (rate,)):
        if value is None:
            if master.hasParam('/tb3_sim/' + key):
                master.deleteParam('/tb3_sim/' + key)
        else:
            master.setParam('/tb3_sim/' + key, value)
    for key in ('scan', 'imu'):
        master.setParam('/tb3_sim/' + key, True)
    sim = Process('camera_' + model, LAUNCH + [WALLED_WORLD, 'model:=' + model], log_dir)
    readers, viewers = [], []
    try:
        frames = []  # one None a colour image (counted, not kept; beside rviz, by one more reader)
        readers = [TcprosReader(sim_uri, '/camera/rgb/image_raw', keep=lambda body: frames.append(None))] + [
            TcprosReader(sim_uri, topic) for topic in ['/clock'] + ['/camera/' + topic for topic in topics or []
                                                                     if topic != 'rgb/image_raw']]
        clock = readers[1]
        wait_until(lambda: clock.clock is not None and clock.clock > 2.0, 120, '/clock')
        if topics is None:
            xvfb, display = start_xvfb()
            viewers = [xvfb, Process('rviz', ['rosrun', 'rviz', 'rviz', '-d', os.path.join(ROOT, 'rviz', 'camera.rviz')],
                                     log_dir, env=dict(os.environ, DISPLAY=display))]
            time.sleep(RVIZ_SETTLE)
        pid = sim_pid()
        sim_start, wall_start, cpu_start, frames_start = clock.clock, time.monotonic(), cpu_seconds(pid), len(frames)
        time.sleep(seconds)
        sim_end, wall_end, cpu_end, frames_end = clock.clock, time.monotonic(), cpu_seconds(pid), len(frames)
        return ((sim_end - sim_start) / (wall_end - wall_start), 100.0 * (cpu_end - cpu_start) / (wall_end - wall_start),
                (frames_end - frames_start) / (sim_end - sim_start))
    finally:
        for process in reversed(viewers):
            process.stop()
        for reader in readers:
            reader.close()
        sim.stop()
        for key in ('camera_width', 'camera_height', 'camera_rate'):
            if master.hasParam('/tb3_sim/' + key):
                master.deleteParam('/tb3_sim/' + key)


def measure_cpu_and_startup(log_dir, seconds):
    """CPU of the node at factor 1 while driving a circle, its peak RSS, and
    the wall time from `roslaunch` to the first odom -> base_footprint."""
    import rospy
    from geometry_msgs.msg import Twist
    listener = Listener()
    launched = time.monotonic()
    sim = start_sim('cpu', log_dir, 1.0)
    publisher = rospy.Publisher('cmd_vel', Twist, queue_size=1)
    try:
        wait_until(lambda: listener.first_tf_wall is not None, 60, 'odom -> base_footprint')
        startup = listener.first_tf_wall - launched
        pid = sim_pid()
        command = Twist()
        command.linear.x, command.angular.z = 0.1, -0.5
        time.sleep(1.0)
        cpu_start, wall_start = cpu_seconds(pid), time.monotonic()
        while time.monotonic() - wall_start < seconds:
            publisher.publish(command)
            time.sleep(0.1)
        cpu = 100.0 * (cpu_seconds(pid) - cpu_start) / (time.monotonic() - wall_start)
        return cpu, memory_mib(pid), startup
    finally:
        publisher.unregister()
        listener.close()
        sim.stop()


def measure_cpu_of_script(log_dir, script):
    """CPU of the node at factor 1 while a tutorial script drives it, as in the
    tutorial: its only other subscribers are robot_state_publisher and, for
    tf, this bench (which waits for the first one)."""
    listener = Listener(topics=('tf',))
    sim = start_sim('cpu_' + script[:-3], log_dir, 1.0)
    try:
        wait_until(lambda: listener.first_tf_wall is not None, 60, 'odom -> base_footprint')
        listener.close()
        pid = sim_pid()
        cpu_start, wall_start = cpu_seconds(pid), time.monotonic()
        driver = Process('cpu_' + script[:-3] + '.script', ['rosrun', 'tb3_sim_nav', script], log_dir)
        try:
            wait_until(lambda: not driver.running(), 300, 'end of %s' % script)
        finally:
            driver.stop()
        if driver.popen.returncode != 0:
            raise RunError('%s exited with code %s; see %s' % (script, driver.popen.returncode, driver.log))
        return 100.0 * (cpu_seconds(pid) - cpu_start) / (time.monotonic() - wall_start)
    finally:
        listener.close()
        sim.stop()


def measure_floor(log_dir, seconds, physics):
    """CPU of tools/clock_floor.py, which only sleeps to each tick and
    publishes /clock (with `physics`, steps pybullet too): for scale."""
    listener = Listener(topics=('clock',))
    argv = [sys.executable, os.path.join(ROOT, 'tools', 'clock_floor.py')] + (['--physics'] if physics else [])
    floor = Process('floor' + ('_physics' if physics else ''), argv, log_dir)
    try:
        wait_until(lambda: listener.clock is not None, 60, '/clock from clock_floor.py')
        time.sleep(1.0)
        cpu_start, wall_start = cpu_seconds(floor.popen.pid), time.monotonic()
        time.sleep(seconds)
        return 100.0 * (cpu_seconds(floor.popen.pid) - cpu_start) / (time.monotonic() - wall_start)
    finally:
        listener.close()
        floor.stop()


def run_scripts(log_dir, factor):
    """Each tutorial script on a fresh simulator at `factor`: wall time and end pose."""
    options = argparse.Namespace(real_time_factor=factor, profile=None)
    results = {}
    for script, expected in tutorial.SCRIPTS:
        result, error = tutorial.run_script(script, expected, options, log_dir)
        if error:
            raise RunError('%s at factor %g: %s' % (script, factor, error))
        results[script] = (result.wall_time, report.summarize(result).end)
    return results


def median(values):
    return statistics.median(values) if values else float('nan')


def verdict(ok):
    return 'met' if ok else 'MISSED'


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
            'navigation (tb3_navigation.launch: amcl and move_base), four goals in turtlebot3_world:',
            '%-58s %11.1f%%' % ('  CPU of amcl and move_base at factor 1 while driving', 100 * nav_1.stack_cpu),
            '%-58s %12.1f' % ('  real-time factor reached with them, as fast as possible',
                              nav_0.sim_seconds / nav_0.wall_seconds),
            '%-58s %12s' % ('  goals reached, factor 1 / 0', ' / '.join(reached)),
            '%-58s %10.1f cm' % ('  worst true distance from a goal reached', 100 * worst)]


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
                             'default all')
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
        frames, egl, cameras = {}, None, {}
        if 'camera' in parts:
            frames, egl = measure_frames(args.runs)
            for label, model, size, rate, topics in CAMERA_ROWS:
                cameras[label] = [measure_camera(log_dir, model, size, rate, topics, args.cpu_seconds)
                                  for _ in range(args.runs)]
                say('camera %s: real-time factor %s, CPU %s, frames a sim second %s' % (
                    label, [round(r, 2) for r, _, _ in cameras[label]], [round(c, 1) for _, c, _ in cameras[label]],
                    [round(f, 1) for _, _, f in cameras[label]]))
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
                                                       median(cpu), TARGETS['cpu'], verdict(median(cpu) < TARGETS['cpu'])),
                      '%-58s %11.1f%%  < %g %%: %s' % ('  the same, %s driving, no sensor read' % CPU_SCRIPT[:-3],
                                                       median(cpu_script), TARGETS['cpu'],
                                                       verdict(median(cpu_script) < TARGETS['cpu'])),
                      '%-58s %10.2f s  < %g s: %s' % ('start-up: roslaunch to first odom->base_footprint',
                                                      median(startup), TARGETS['startup'],
                                                      verdict(median(startup) < TARGETS['startup']))]
        if floor:
            lines += ['%-58s %11.1f%%' % ('  floor: a python loop paced to 100 Hz publishing /clock', median(floor[False])),
                      '%-58s %11.1f%%' % ('  floor: the same, a pybullet step each tick', median(floor[True]))]
        if frames:
            lines.append('one frame of the Waffle\'s camera (colour and depth), wall / CPU ms, %s; TinyRenderer:'
                         % ('EGL on llvmpipe' if egl else 'EGL not loaded: TinyRenderer'))
            for width, height in FRAME_SIZES:
                lines.append('%-58s %6.1f / %5.1f ms;  %6.1f / %5.1f ms' % (
                    ('  %d x %d' % (width, height),) + frames[('egl', width, height)] + frames[('tiny', width, height)]))
        if cameras:
            lines.append('factor 1 in turtlebot3_world, the camera read: real-time factor, CPU of the simulator, '
                         'colour images a sim second:')
            for label, _, _, _, _ in CAMERA_ROWS:
                factor = median([r for r, _, _ in cameras[label]])
                lines.append('%-58s %7.2f  %5.1f%%  %5.1f Hz  %s' % (
                    '  ' + label, factor, median([c for _, c, _ in cameras[label]]),
                    median([f for _, _, f in cameras[label]]), 'real time: %s' % verdict(factor >= 0.95)))
        if rss:
            lines.append('%-58s %8.0f MiB' % ('peak RSS of the simulator node (max over runs)', max(rss)))
        for script, _ in (tutorial.SCRIPTS if scripts else []):
            (wall_1, end_1), (wall_0, end_0) = scripts[1.0][script], scripts[0.0][script]
            ratio = wall_1 / wall_0
            apart = math.hypot(end_0[1] - end_1[1], end_0[2] - end_1[2])
            turn = abs(math.degrees(report.normalize(end_0[3] - end_1[3])))
            lines += ['%-58s %7.1f s / %.1f s = %.1fx  >= %gx: %s'
                      % (script + ' wall time, factor 1 / factor 0', wall_1, wall_0, ratio,
                         TARGETS['speedup'], verdict(ratio >= TARGETS['speedup'])),
                      '%-58s %6.3f m %5.2f deg  (ends %+.3f %+.3f %+.1f deg / %+.3f %+.3f %+.1f deg)'
                      % ('  end pose, factor 0 against factor 1', apart, turn,
                         end_1[1], end_1[2], math.degrees(end_1[3]), end_0[1], end_0[2], math.degrees(end_0[3]))]
        if mapped:
            lines += nav_rows(mapped, navigated)
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
