"""The simulator node: parameters in, a world of robots stepped in sim time, topics and services out.

One physics step gives one timestamp to everything it publishes; each step's
data goes out before its /clock tick. The node holds one Config, the
simulation's (`sim.config`): dynamic_reconfigure replaces it there, and
every part reads it there.
"""
import dataclasses
import os
import sys
import time

import rospkg
import rospy
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from tb3_common.ros import lifecycle

from .. import params
from ..frames import planar
from ..pacing import Pacer
from ..robot_model import ModelError, load_model, model_urdf
from ..throttle import Throttle
from ..world_file import RobotSpec, WorldError, load_world
from . import messages, rospy_internals
from .descriptions import Descriptions
from .fleet import Fleet
from .gazebo import GazeboInterface
from .lockstep import LOCKSTEP_POLL, LOCKSTEP_POLL_SHARE, Lockstep
from .loop import Markers, Requests
from .master_watch import MasterWatch
from .odom_parents import WorldLinks
from .publishers import Publishers
from .reconfigure import Reconfigure

WARN_PERIOD = 5.0    # s between repeats of the same warning
IDLE_POLL = 0.01     # wall s between checks while paused or holding
#: rospy asks the master for this parameter at every log message while it is unset (its cache keeps no
#: missing parameter: rospy/impl/rosout.py, get_param_cached). A node that logs between a tick and its
#: reaction then waits on the master, which lockstep does not see, and its reaction lands steps late
#: (doc/design.md). Set to its default, every node caches it at its first message.
ROSOUT_TOPICS = '/rosout_disable_topics_generation'
RESTORED_PARAMETERS = ('/use_sim_time', '/robot_description', ROSOUT_TOPICS)  # set again on a new master


class SimulatorNode(object):
    """Steps the simulation in sim time and publishes what Gazebo's TurtleBot3s do."""

    def __init__(self, simulation, parameters, life):
        """`parameters`: a dict of the parameters it sets, for the master watch; `life`: the
        node's lifecycle.Life; the step loop runs until it says stop."""
        self.sim = simulation
        config = simulation.config
        self.life = life
        self.pacer = Pacer(config.real_time_factor, paused=config.paused, sleep=life.sleep)
        self.requests = Requests(life)
        self._throttle = Throttle(WARN_PERIOD)
        self._hold_until = 0.0
        self.publishers = Publishers(self._throttle)
        # Latched: a node that starts gets the time at once, even while paused,
        # not after a data message stamped later (hztest then measures nothing).
        self.clock_pub = self.publishers.advertise('clock', Clock, latch=True, on_subscribe=self._hold_clock)
        self.tf_pub = self.publishers.advertise('tf', TFMessage)
        self._tf = TFMessage()
        self.lockstep = None
        if config.lockstep:
            # Paced, a step has wall time to spare: look less often, for less CPU.
            factor = config.real_time_factor
            poll = max(LOCKSTEP_POLL, LOCKSTEP_POLL_SHARE / config.physics_rate / factor) if factor else LOCKSTEP_POLL
            self.lockstep = Lockstep(config.lockstep_timeout, poll, self._throttle, WARN_PERIOD,
                                     self.publishers.prompt)
        world_links = WorldLinks(config.world_frame, ()) if config.world_frame else None
        descriptions = Descriptions(parameters, self.publishers, config.robot_state_publisher)
        self.fleet = Fleet(simulation, self.publishers, self._throttle, descriptions, self.lockstep, world_links)
        self.markers = Markers(simulation, self.publishers, config.world_frame or config.odom_frame)
        self.gazebo = GazeboInterface(simulation, self.publishers, self.requests, self.fleet, self.markers,
                                      self.pacer, self.warn_throttled)
        if self.lockstep:  # ROBOTIS' moving obstacles (turtlebot3_dqn) move models through this topic
            self.lockstep.follow(self.gazebo.set_model_state)
        self.reconfigure = Reconfigure(simulation, self.requests)
        self._own_clock = rospy_internals.stop_following_clock()
        for name, handler in (('pause_physics', self._on_pause), ('unpause_physics', self._on_unpause),
                              ('reset_world', self._on_reset_world),
                              ('reset_simulation', self._on_reset_simulation)):
            rospy.Service('gazebo/' + name, Empty, handler)

    def warn_throttled(self, kind, text):
        if self._throttle.allow(kind):
            rospy.logwarn('%s (at most one such warning per %g s)', text, WARN_PERIOD)

    # --- inputs -------------------------------------------------------------
    def _hold_clock(self):
        """A node has subscribed to /clock: it is starting up. Hold time still
        while it connects its other topics, so that its first commands are not
        lost to connection set-up, which takes wall time, not sim time."""
        self._hold_until = time.monotonic() + self.sim.config.startup_hold

    def _on_pause(self, _request):
        self.pacer.pause()
        return EmptyResponse()

    def _on_unpause(self, _request):
        self.pacer.resume()
        return EmptyResponse()

    def _reset_world(self):
        self.sim.reset_world()
        self.markers.changed()

    def _on_reset_world(self, request):
        self.requests.run(self._reset_world, message=request)
        rospy.loginfo('reset_world: every robot and object back at its spawn pose, odometry zeroed')
        return EmptyResponse()

    def _reset_simulation(self):
        self.sim.reset_simulation()
        self.fleet.restart_schedules()
        self.pacer.restart()
        self.markers.changed()

    def _on_reset_simulation(self, request):
        self.requests.run(self._reset_simulation, message=request)
        rospy.loginfo('reset_simulation: every robot and object back at its spawn pose, time back to zero')
        return EmptyResponse()

    # --- the step loop ------------------------------------------------------
    def run(self):
        """Steps until the node is asked to end (lifecycle: a signal only sets a flag), so that
        nothing closes a connection while the step loop writes to it."""
        while not self.life.stopping:
            self.requests.serve()
            if self.pacer.paused or time.monotonic() < self._hold_until:
                self.pacer.restart()
                self.publishers.flush()
                time.sleep(IDLE_POLL)
                continue
            self.pacer.wait_until((self.sim.now_ns + self.sim.step_ns) * 1e-9)
            # Each step waits for the nodes' reaction to the last tick, and serves
            # what they asked of Gazebo's services meanwhile. Paced, they have had
            # the sleep to react: one look mostly finds them done.
            if self.lockstep:
                self.lockstep.wait(self.requests, clock_ns=self.sim.now_ns)
            self.step()

    def step(self):
        self.publishers.written.clear()
        self.fleet.apply_commands(self.sim.now_ns)
        self.sim.step()
        now_ns = self.sim.now_ns
        # One stamp for the whole step, new each step: rospy sends the latched
        # /clock to a new subscriber from another thread, so it must not change.
        stamp = messages.stamp_of(now_ns)
        published = self.publish_data(now_ns, stamp)
        self.gazebo.publish()
        self.publishers.flush()
        # The step's data goes out before /clock says its time has come, so a
        # node woken by the tick reads this step's tf and odom, not the step
        # before's (lockstep sees that it has): the same at any factor.
        if published and self.lockstep:
            self.lockstep.wait_for_readers(self.publishers.written)
        self.clock_pub.publish(Clock(clock=stamp))

    def publish_data(self, now_ns, stamp):
        """Publishes what is due at `now_ns`; False if nothing was."""
        due, transforms = self.fleet.publish(now_ns, stamp, paced=self.pacer.factor > 0.0)
        if transforms:
            if self._own_clock:  # the stamps of our log messages need be no finer
                rospy_internals.set_time(stamp)
            # One tf message a step for every robot's odom -> base and the world's links.
            self._tf.transforms = transforms
            self.tf_pub.publish(self._tf)
            if self.markers.moving():
                self.markers.changed(stamp)  # what moves is drawn where it is now
        return bool(due)


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
            robots.append((spec.name, model, planar(*spec.position, yaw=spec.yaw)))
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
                          'says otherwise; export TURTLEBOT3_MODEL=burger, waffle or waffle_pi to choose)',
                          config.model)
        return config, build(config, world.obstacles, robots)
    except (params.ParameterError, ModelError, WorldError, ValueError) as error:
        rospy.logfatal('tb3_sim cannot start: %s', error)
        rospy.signal_shutdown('bad start-up configuration')
        sys.exit(2)


def main():
    life = lifecycle.init_node('tb3_sim', watch_clock=False)  # it publishes /clock
    config, simulation = _start_up()
    if config.real_time_factor == 0.0:
        # As fast as possible, but only on CPU that no other node wants, so
        # that rviz and the shell stay responsive (lockstep waits for the
        # nodes that drive the robot whatever their priority).
        os.nice(10)
    if config.lockstep and not rospy.has_param(ROSOUT_TOPICS):
        rospy.set_param(ROSOUT_TOPICS, False)
    restored = dict((name, rospy.get_param(name)) for name in RESTORED_PARAMETERS if rospy.has_param(name))
    try:
        node = SimulatorNode(simulation, restored, life)
        MasterWatch(restored).start()
        node.run()
    finally:
        life.finish()  # the step loop has stopped: now rospy may close every connection
        simulation.close()
