"""The simulator node: parameters in, a world of robots stepped in sim time, topics and services out.

One physics step gives one timestamp to everything it publishes; each step's
data goes out before its /clock tick.
"""
import dataclasses
import math
import os
import queue
import sys
import threading
import time

import rospkg
import rospy
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, EmptyResponse
from tb3_navigation.ros import lifecycle
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from .. import params
from ..pacing import Pacer, Schedule
from ..robot_model import ModelError, load_model, model_urdf
from ..throttle import Throttle
from ..simulation import ModelStateError
from ..world_file import ROBOT_NAME, RobotSpec, WorldError, load_world
from . import messages, rospy_internals
from .descriptions import Descriptions
from .gazebo import GazeboInterface
from .lockstep import LOCKSTEP_POLL, LOCKSTEP_POLL_SHARE, Lockstep
from .master_watch import MasterWatch
from .odom_parents import WorldLinks
from .publishers import Publishers
from .reconfigure import Reconfigure
from .robot_io import RobotIO

WARN_PERIOD = 5.0    # s between repeats of the same warning
IDLE_POLL = 0.01     # wall s between checks while paused or holding
REQUEST_TIMEOUT = 10.0  # wall s a service waits for the step loop to take its request
RESTORED_PARAMETERS = ('/use_sim_time', '/robot_description')  # set again on a new master


class SimulatorNode(object):
    """Steps the simulation in sim time and publishes what Gazebo's TurtleBot3s do."""

    def __init__(self, config, simulation, descriptions, life):
        """`life`: the node's lifecycle.Life; the step loop runs until it says stop."""
        self.config = config
        self.sim = simulation
        self.descriptions = descriptions
        self.life = life
        self.pacer = Pacer(config.real_time_factor, paused=config.paused, sleep=life.sleep)
        self._requests = queue.Queue()  # work of other threads, for the step loop
        self._throttle = Throttle(WARN_PERIOD)
        self._hold_until = 0.0
        self._due = dict((name, Schedule(round(1e9 / rate))) for name, rate in (
            ('odom', config.odom_rate), ('joint_states', config.joint_states_rate),
            ('scan', config.scan_rate), ('imu', config.imu_rate)))
        self.publishers = Publishers(self._throttle)
        # Latched: a node that starts gets the time at once, even while paused,
        # not after a data message stamped later (hztest then measures nothing).
        self.clock_pub = self.publishers.advertise('clock', Clock, latch=True, on_subscribe=self._hold_clock)
        self.tf_pub = self.publishers.advertise('tf', TFMessage)
        self._tf = TFMessage()
        self.world_links = WorldLinks(config.world_frame, ()) if config.world_frame else None
        self.lockstep = None
        if config.lockstep:
            # Paced, a step has wall time to spare: look less often, for less CPU.
            factor = config.real_time_factor
            poll = max(LOCKSTEP_POLL, LOCKSTEP_POLL_SHARE / config.physics_rate / factor) if factor else LOCKSTEP_POLL
            self.lockstep = Lockstep(config.lockstep_timeout, poll, self._throttle, WARN_PERIOD)
        self.robots = {}  # name -> RobotIO
        for robot in simulation.robots.values():
            self._add_io(robot)
        self.markers_pub = self.publishers.advertise('world_markers', MarkerArray, latch=True)
        self.world_changed()
        self.gazebo = GazeboInterface(self)
        self.reconfigure = Reconfigure(self)
        self._own_clock = rospy_internals.stop_following_clock()
        for name, handler in (('pause_physics', self._on_pause), ('unpause_physics', self._on_unpause),
                              ('reset_world', self._on_reset_world),
                              ('reset_simulation', self._on_reset_simulation)):
            rospy.Service('gazebo/' + name, Empty, handler)

    def _add_io(self, robot):
        io = self.robots[robot.name] = RobotIO(robot, self.config, self.publishers, self._throttle,
                                                self._command_received if self.lockstep else None)
        if self.world_links:
            self.world_links.parents.add(io.odom_frame)
        if self.lockstep:
            self.lockstep.follow(io.cmd_vel)
            if io.scan_pub:
                self.lockstep.follow_readers(io.scan_pub)
        self.descriptions.start(robot)

    def spawn_robot(self, name, model, pose, model_name):
        """A robot spawned while running (in the step loop): it gets what a launched one has."""
        if not ROBOT_NAME.match(name):
            raise ModelStateError('robot_namespace %r must be a ROS name: a letter, then letters, digits or _' % name)
        (x, y, z), orientation = pose
        yaw = math.atan2(2.0 * (orientation[3] * orientation[2] + orientation[0] * orientation[1]),
                         1.0 - 2.0 * (orientation[1] ** 2 + orientation[2] ** 2))
        try:
            robot = self.sim.add_robot(name, model, (x, y, z, yaw), model_name)
        except ValueError as error:
            raise ModelStateError(str(error))
        self._add_io(robot)
        rospy.loginfo('spawned robot %s (model %s) at (%.2f, %.2f) yaw %.2f', name, model_name, x, y, yaw)

    def forget_robot(self, robot):
        """A deleted robot's interface closed (in the step loop)."""
        io = self.robots.pop(robot.name)
        if self.lockstep:
            self.lockstep.forget(io.cmd_vel)
            if io.scan_pub:
                self.lockstep.forget_readers(io.scan_pub)
        io.close()
        self.descriptions.stop(robot.name)

    def world_changed(self, stamp=None):
        """The world's obstacles and objects drawn anew on world_markers (latched)."""
        frame = self.config.world_frame or self.config.odom_frame
        self.markers_pub.publish(messages.world_markers(frame, self.sim.world.visual_shapes(),
                                                        stamp or rospy.Time(*divmod(self.sim.now_ns, 1000000000))))

    def run_in_loop(self, work, timeout=REQUEST_TIMEOUT):
        """work()'s result, run by the step loop between steps; its exception raised here."""
        done, result = threading.Event(), {}
        self._requests.put((work, done, result))
        deadline = time.monotonic() + timeout
        while not done.wait(IDLE_POLL * 10):
            if self.life.stopping:
                raise ModelStateError('the simulator is shutting down')
            if time.monotonic() > deadline:
                raise ModelStateError('the simulator did not get to the request within %g s (wall)' % timeout)
        if 'error' in result:
            raise result['error']
        return result.get('value')

    def _serve_requests(self):
        while True:
            try:
                work, done, result = self._requests.get_nowait()
            except queue.Empty:
                return
            try:
                result['value'] = work()
            except Exception as error:  # handed back to the thread that asked
                result['error'] = error
            done.set()

    def warn_throttled(self, kind, text):
        if self._throttle.allow(kind):
            rospy.logwarn('%s (at most one such warning per %g s)', text, WARN_PERIOD)

    def fastest_output(self):
        """(parameter name, rate) of the fastest output: physics may not step slower."""
        rates = [('odom_rate', self.config.odom_rate), ('joint_states_rate', self.config.joint_states_rate),
                 ('scan_rate', self.config.scan_rate), ('imu_rate', self.config.imu_rate)] + [
            ('camera_rate', camera.rate) for robot in self.sim.robots.values() for camera in robot.cameras]
        return max(rates, key=lambda item: item[1])

    def set_real_time_factor(self, factor):
        self.pacer.set_factor(factor)

    # --- inputs -------------------------------------------------------------
    def _command_received(self):
        self.lockstep.receive_threads.add(threading.get_native_id())

    def _hold_clock(self):
        """A node has subscribed to /clock: it is starting up. Hold time still
        while it connects its other topics, so that its first commands are not
        lost to connection set-up, which takes wall time, not sim time."""
        self._hold_until = time.monotonic() + self.config.startup_hold

    def _on_pause(self, _request):
        self.pacer.pause()
        return EmptyResponse()

    def _on_unpause(self, _request):
        self.pacer.resume()
        return EmptyResponse()

    def _reset_world(self):
        self.sim.reset_world()
        self.world_changed()

    def _on_reset_world(self, _request):
        self.run_in_loop(self._reset_world)
        rospy.loginfo('reset_world: every robot and object back at its spawn pose, odometry zeroed')
        return EmptyResponse()

    def _reset_simulation(self):
        self.sim.reset_simulation()
        self.pacer.restart()
        self.world_changed()

    def _on_reset_simulation(self, _request):
        self.run_in_loop(self._reset_simulation)
        rospy.loginfo('reset_simulation: every robot and object back at its spawn pose, time back to zero')
        return EmptyResponse()

    # --- the step loop ------------------------------------------------------
    def run(self):
        """Steps until the node is asked to end (lifecycle: a signal only sets a flag), so that
        nothing closes a connection while the step loop writes to it."""
        while not self.life.stopping:
            self._serve_requests()
            if self.pacer.paused or time.monotonic() < self._hold_until:
                self.pacer.restart()
                self.publishers.flush()
                time.sleep(IDLE_POLL)
                continue
            self.pacer.wait_until((self.sim.now_ns + self.sim.step_ns) * 1e-9)
            # Each step waits for the nodes' reaction to the last tick. Paced,
            # they have had the sleep to react: one look mostly finds them done.
            if self.lockstep:
                self.lockstep.wait()
            self.step()

    def step(self):
        now_ns = self.sim.now_ns
        for io in self.robots.values():
            io.apply_command(now_ns)
        self.sim.step()
        now_ns = self.sim.now_ns
        # One stamp for the whole step, new each step: rospy sends the latched
        # /clock to a new subscriber from another thread, so it must not change.
        stamp = rospy.Time(*divmod(now_ns, 1000000000))
        published = self.publish_data(now_ns, stamp)
        self.gazebo.publish()
        self.publishers.flush()
        # The step's data goes out before /clock says its time has come, so a
        # node woken by the tick reads this step's tf and odom, not the step
        # before's (lockstep sees that it has): the same at any factor.
        if published and self.lockstep:
            self.lockstep.wait()
        self.clock_pub.publish(Clock(clock=stamp))

    def publish_data(self, now_ns, stamp):
        """Publishes what is due at `now_ns`; False if nothing was."""
        due = self._due
        robots = self.robots.values()
        published = False
        if due['odom'].due(now_ns):
            if self._own_clock:  # the stamps of our log messages need be no finer
                rospy_internals.set_time(stamp)
            for io in robots:
                io.publish_odometry(stamp)
            # One tf message for every robot's odom -> base and the world's links.
            self._tf.transforms = [io.transform for io in robots] + (
                self.world_links.links(robots, stamp) if self.world_links else [])
            self.tf_pub.publish(self._tf)
            if any(not body.static for body in self.sim.world.objects.values()):
                self.world_changed(stamp)  # what moves is drawn where it is now
            published = True
        if due['joint_states'].due(now_ns):
            for io in robots:
                io.publish_joint_states(stamp)
            published = True
        if due['scan'].due(now_ns):
            for io in robots:
                published = io.publish_scan(stamp) or published
        if due['imu'].due(now_ns):
            now_s = now_ns * 1e-9
            for io in robots:
                published = io.publish_imu(stamp, now_s) or published
        for io in robots:
            published = io.publish_cameras(now_ns, stamp) or published
        return published


def robot_specs(config, world):
    """The robots to spawn: those of ~robots, or else the one of ~model
    without a name (the tutorial's), and then the world file's."""
    own = list(config.robots) or [RobotSpec('', config.model, (config.x_pos, config.y_pos, config.z_pos),
                                            config.yaw)]
    return own + list(world.robots)


def _start_up():
    """Parameters, models and world checked, the robots placed, or a fatal
    message and exit status 2."""
    try:
        from ..simulation import build
    except ImportError as error:
        rospy.logfatal('tb3_sim cannot start: %s. %s has no pybullet: run `make setup` and '
                       '`source setup.bash`, or see the README on other workspaces', error, sys.executable)
        sys.exit(2)
    try:
        config = params.resolve(lambda name, default: rospy.get_param('~' + name, default))
        package = rospkg.RosPack().get_path('tb3_sim_nav')
        world = load_world(config.world, os.path.join(package, 'worlds'), config.map_wall_height)
        rospy.loginfo('tb3_sim parameters: %s', ', '.join('%s=%r' % (field.name, getattr(config, field.name))
                                                          for field in dataclasses.fields(config)))
        robots = []
        for spec in robot_specs(config, world):
            model = load_model(model_urdf(spec.model, os.path.join(package, 'urdf')))
            robots.append((spec.name, model, spec.position + (spec.yaw,)))
            rospy.loginfo('tb3_sim: robot %s from %s: wheel radius %.4f m, separation %.4f m, limits %g m/s '
                          'and %g rad/s, at (%.2f, %.2f, %.2f) yaw %.2f', spec.name or '(no namespace)',
                          model.urdf_file, model.geometry.wheel_radius, model.geometry.wheel_separation,
                          config.max_linear_speed or model.limits.max_linear,
                          config.max_angular_speed or model.limits.max_angular, *(spec.position + (spec.yaw,)))
        if world.map is None:
            rospy.loginfo('tb3_sim: world %r with %d obstacles', config.world, len(world.obstacles))
        else:
            grid = world.map.grid
            rospy.loginfo('tb3_sim: world %r is a map (%d x %d at %g m): its occupied cells are %d walls '
                          '~map_wall_height = %g m tall', config.world, grid.width, grid.height, grid.resolution,
                          len(world.obstacles), config.map_wall_height)
        if 'TURTLEBOT3_MODEL' not in os.environ:
            rospy.loginfo('tb3_sim: TURTLEBOT3_MODEL is not set: the launch gave model %s (burger unless model:= '
                          'says otherwise; export TURTLEBOT3_MODEL=burger, waffle or waffle_pi to choose)', config.model)
        return config, build(config, world.obstacles, robots)
    except (params.ParameterError, ModelError, WorldError, ValueError) as error:
        rospy.logfatal('tb3_sim cannot start: %s', error)
        rospy.signal_shutdown('bad start-up configuration')
        sys.exit(2)


def main():
    life = lifecycle.init_node('tb3_sim')
    config, simulation = _start_up()
    if config.real_time_factor == 0.0:
        # As fast as possible, but only on CPU that no other node wants, so
        # that rviz and the shell stay responsive (lockstep waits for the
        # nodes that drive the robot whatever their priority).
        os.nice(10)
    restored = dict((name, rospy.get_param(name)) for name in RESTORED_PARAMETERS if rospy.has_param(name))
    descriptions = Descriptions(restored, config.robot_state_publisher)
    try:
        node = SimulatorNode(config, simulation, descriptions, life)
        MasterWatch(restored).start()
        node.run()
    finally:
        life.finish()  # the step loop has stopped: now rospy may close every connection
        descriptions.stop_all()
        simulation.close()
