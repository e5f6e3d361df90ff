"""The simulator's figures for `make bench` (tools/bench.py): its fastest
real-time factor with one to thirty robots, its CPU and start-up at factor 1,
the floor of a bare /clock loop, the tutorial's scripts at factors 1 and 0.

Each starts the tutorial's launch files on the bench's master and stops
everything it started (the harness's Process).
"""
import argparse
import math
import os
import statistics
import sys
import time

from tb3_harness import report, tutorial
from tb3_harness.measure import cpu_seconds, memory_mib, sim_pid, sim_uri
from tb3_harness.processes import Process, RunError, wait_until
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
PHYSICS_RATE = 100.0  # the simulator's default steps per sim second


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
