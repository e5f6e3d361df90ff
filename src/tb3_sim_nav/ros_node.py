"""The ROS edge: parameters in, topics and services around a Simulation.

The only module of the package that imports rospy. One physics step gives
one timestamp to everything it publishes.
"""
import math
import os
import sys
import threading
import time
import warnings
import xmlrpc.client

import rosgraph
import rospkg
import rospy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState, LaserScan
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from . import params
from .diff_drive import Limits, sanitize_twist
from .pacing import Pacer, Schedule
from .quiescence import InputWaits, ProcessGone, ProcessWatch
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, ModelError, read_drive_geometry
from .throttle import Throttle
from .world_file import WorldError, load_world

WARN_PERIOD = 5.0    # s between repeats of the same warning
IDLE_POLL = 0.01     # wall s between checks while paused or holding
LOCKSTEP_POLL = 0.0001  # wall s between looks at a node the step waits for, at least ...
LOCKSTEP_POLL_SHARE = 0.05  # ... and this share of a step's wall time when paced
PID_RETRY = 1.0      # wall s between asks of a local node that did not tell its PID
# Diagonal covariances of odom, as Gazebo's diff-drive plugin fills them:
# x, y and yaw are known well; z, roll and pitch are not estimated at all.
ODOM_COVARIANCE = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def _diagonal(values):
    matrix = [0.0] * (len(values) ** 2)
    for index, value in enumerate(values):
        matrix[index * (len(values) + 1)] = value
    return matrix


def _set_xyz(vector, values):
    vector.x, vector.y, vector.z = values


def _set_quaternion(quaternion, values):
    quaternion.x, quaternion.y, quaternion.z, quaternion.w = values


def synchronous_publisher(topic, message_class, **options):
    """A synchronous publisher: publish() writes to every subscriber's socket at once.

    rospy's queued publishers hand each message to a writer thread per
    subscriber; faster than real time the step loop starves those threads of
    the GIL, and /clock then reaches subscribers in bursts, so their
    rospy.Rate loops see time jump and drop ticks. Written in the step loop,
    every tick leaves in order, at once. No Nagle delay for small messages.
    """
    with warnings.catch_warnings():  # rospy warns whenever queue_size is None
        warnings.simplefilter('ignore', SyntaxWarning)
        return rospy.Publisher(topic, message_class, queue_size=None, tcp_nodelay=True, **options)


def stop_following_clock():
    """Under sim time rospy subscribes every node to /clock, this one too:
    here that would send every tick through a socket back to where it came
    from. Drop that subscription (True); the step loop sets rospy's time."""
    from rospy.impl import simtime
    if rospy.rostime.is_wallclock() or simtime._clock_sub is None:
        return False
    simtime._clock_sub.unregister()
    return True


class _OnSubscribe(rospy.SubscribeListener):
    def __init__(self, callback):
        super(_OnSubscribe, self).__init__()
        self._callback = callback

    def peer_subscribe(self, topic_name, topic_publish, peer_publish):
        self._callback()


class SimulatorNode(object):
    """Steps the simulation in sim time and publishes what Gazebo's TurtleBot3 does."""

    def __init__(self, config, simulation):
        self.config = config
        self.sim = simulation
        self.limits = Limits(config['max_linear_speed'], config['max_angular_speed'])
        self.pacer = Pacer(config['real_time_factor'], paused=config['paused'])
        self._lock = threading.Lock()  # steps versus reset services
        self._warnings = Throttle(WARN_PERIOD)
        self._command = (0.0, 0.0, 0)  # v, w, count of commands received
        self._applied_count = 0
        self._hold_until = 0.0
        self._make_schedules()
        self._make_messages()
        # Latched: a node that starts gets the time at once, even while paused,
        # not after a data message stamped later (hztest then measures nothing).
        self.clock_pub = synchronous_publisher('clock', Clock, latch=True,
                                               subscriber_listener=_OnSubscribe(self._hold_clock))
        self.odom_pub = synchronous_publisher('odom', Odometry)
        self.truth_pub = synchronous_publisher('base_pose_ground_truth', Odometry)
        self.joints_pub = synchronous_publisher('joint_states', JointState)
        self.tf_pub = synchronous_publisher('tf', TFMessage)
        self.scan_pub = synchronous_publisher('scan', LaserScan) if simulation.lidar else None
        self.imu_pub = synchronous_publisher('imu', Imu) if simulation.imu else None
        self.lockstep = None  # set below; the cmd_vel callback may run before
        cmd_vel = rospy.Subscriber('cmd_vel', Twist, self._on_cmd_vel, queue_size=10, tcp_nodelay=True)
        self._own_clock = stop_following_clock()
        # Paced, a step has wall time to spare: look less often, for less CPU.
        factor = config['real_time_factor']
        poll = max(LOCKSTEP_POLL, LOCKSTEP_POLL_SHARE / config['physics_rate'] / factor) if factor else LOCKSTEP_POLL
        self.lockstep = Lockstep(cmd_vel, config['lockstep_timeout'], poll, self._warnings) if config['lockstep'] else None
        for name, handler in (('pause_physics', self._on_pause), ('unpause_physics', self._on_unpause),
                              ('reset_world', self._on_reset_world),
                              ('reset_simulation', self._on_reset_simulation)):
            rospy.Service('gazebo/' + name, Empty, handler)

    def _make_schedules(self):
        self._due = dict((name, Schedule(round(1e9 / self.config[name + '_rate'])))
                         for name in ('odom', 'joint_states', 'scan', 'imu'))

    def _make_messages(self):
        """Messages reused every publication: only stamps and values change."""
        frame, child = self.config['odom_frame'], self.config['base_frame']
        self._odom = Odometry()
        self._odom.header.frame_id = frame
        self._odom.child_frame_id = child
        self._odom.pose.covariance = _diagonal(ODOM_COVARIANCE)
        self._odom.twist.covariance = _diagonal(ODOM_COVARIANCE)
        self._truth = Odometry()
        self._truth.header.frame_id = frame
        self._truth.child_frame_id = child
        self._transform = TransformStamped()
        self._transform.header.frame_id = frame
        self._transform.child_frame_id = child
        self._tf = TFMessage(transforms=[self._transform])
        self._joints = JointState(name=[LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT])
        lidar = self.sim.lidar
        if lidar:
            self._scan = LaserScan(angle_min=0.0, angle_increment=lidar.angle_increment,
                                   angle_max=lidar.angle_increment * (self.config['scan_samples'] - 1),
                                   scan_time=1.0 / self.config['scan_rate'],
                                   range_min=lidar.range_min, range_max=lidar.range_max)
            self._scan.header.frame_id = 'base_scan'
        if self.sim.imu:
            self._imu = Imu()
            self._imu.header.frame_id = 'imu_link'
            gyro, accel = self.config['imu_gyro_noise'], self.config['imu_accel_noise']
            # A zero covariance would claim a perfect sensor: keep a floor.
            self._imu.orientation_covariance = _diagonal([1e-6] * 3)
            self._imu.angular_velocity_covariance = _diagonal([max(gyro ** 2, 1e-8)] * 3)
            self._imu.linear_acceleration_covariance = _diagonal([max(accel ** 2, 1e-6)] * 3)

    # --- inputs -------------------------------------------------------------
    def _on_cmd_vel(self, twist):
        v, w, complaints = sanitize_twist((twist.linear.x, twist.linear.y, twist.linear.z),
                                          (twist.angular.x, twist.angular.y, twist.angular.z),
                                          self.limits)
        for complaint in complaints:
            # Throttled per kind (its first word), so that a flood of one kind
            # of bad command cannot hide another.
            if self._warnings.allow(complaint.split()[0]):
                rospy.logwarn('cmd_vel: %s (at most one such warning per %g s)', complaint, WARN_PERIOD)
        self._command = (v, w, self._command[2] + 1)  # one assignment; the step loop picks it up
        if self.lockstep:
            self.lockstep.receive_threads.add(threading.get_native_id())

    def _hold_clock(self):
        """A node has subscribed to /clock: it is starting up. Hold time still
        while it connects its other topics, so that its first commands are not
        lost to connection set-up, which takes wall time, not sim time."""
        self._hold_until = time.monotonic() + self.config['startup_hold']

    def _on_pause(self, _request):
        self.pacer.pause()
        return EmptyResponse()

    def _on_unpause(self, _request):
        self.pacer.resume()
        return EmptyResponse()

    def _on_reset_world(self, _request):
        with self._lock:
            self.sim.reset_world()
        rospy.loginfo('reset_world: robot back at its spawn pose, odometry zeroed')
        return EmptyResponse()

    def _on_reset_simulation(self, _request):
        with self._lock:
            self.sim.reset_simulation()
            self.pacer.restart()
        rospy.loginfo('reset_simulation: robot back at its spawn pose, time back to zero')
        return EmptyResponse()

    # --- the step loop ------------------------------------------------------
    def run(self):
        step_s = self.sim.step_ns * 1e-9
        while not rospy.is_shutdown():
            if self.pacer.paused or time.monotonic() < self._hold_until:
                self.pacer.restart()
                time.sleep(IDLE_POLL)
                continue
            self.pacer.wait_until((self.sim.steps + 1) * step_s)
            # Each step waits for the nodes' reaction to the last tick. Paced,
            # they have had the sleep to react: one look mostly finds them done.
            if self.lockstep:
                self.lockstep.wait()
            with self._lock:
                self.step()

    def step(self):
        v, w, count = self._command
        if count != self._applied_count:
            self.sim.command(v, w)
            self._applied_count = count
        self.sim.step()
        now_ns = self.sim.now_ns
        # One stamp for the whole step, new each step: rospy sends the latched
        # /clock to a new subscriber from another thread, so it must not change.
        stamp = rospy.Time(*divmod(now_ns, 1000000000))
        published = self.publish_data(now_ns, stamp)
        # The step's data goes out before /clock says its time has come, so a
        # node woken by the tick reads this step's tf and odom, not the step
        # before's (lockstep sees that it has): the same at any factor.
        if published and self.lockstep:
            self.lockstep.wait()
        self.clock_pub.publish(Clock(clock=stamp))

    def publish_data(self, now_ns, stamp):
        """Publishes what is due at `now_ns`; False if nothing was."""
        due = self._due
        published = False
        if due['odom'].due(now_ns):
            if self._own_clock:  # the stamps of our log messages need be no finer
                rospy.rostime._set_rostime(stamp)
            self.publish_odometry(stamp)
            published = True
        if due['joint_states'].due(now_ns):
            self.publish_joint_states(stamp)
            published = True
        # The sensors cost most of a step: nobody listening, nothing computed.
        if self.scan_pub and due['scan'].due(now_ns) and self.scan_pub.get_num_connections():
            self.publish_scan(stamp)
            published = True
        if self.imu_pub and due['imu'].due(now_ns) and self.imu_pub.get_num_connections():
            self.publish_imu(stamp)
            published = True
        return published

    def publish_odometry(self, stamp):
        truth = (self.sim.true_pose(), self.sim.true_twist())
        odom_pose, odom_twist = self.sim.odometry(truth)
        for message, (position, orientation), (linear, angular) in (
                (self._odom, odom_pose, odom_twist), (self._truth,) + truth):
            message.header.stamp = stamp
            _set_xyz(message.pose.pose.position, position)
            _set_quaternion(message.pose.pose.orientation, orientation)
            _set_xyz(message.twist.twist.linear, linear)
            _set_xyz(message.twist.twist.angular, angular)
        self._transform.header.stamp = stamp
        _set_xyz(self._transform.transform.translation, odom_pose[0])
        _set_quaternion(self._transform.transform.rotation, odom_pose[1])
        self.odom_pub.publish(self._odom)
        self.tf_pub.publish(self._tf)
        self.truth_pub.publish(self._truth)

    def publish_joint_states(self, stamp):
        positions, velocities = self.sim.wheel_states()
        self._joints.header.stamp = stamp
        self._joints.position = positions
        self._joints.velocity = velocities
        self.joints_pub.publish(self._joints)

    def publish_scan(self, stamp):
        self._scan.header.stamp = stamp
        self._scan.ranges = self.sim.scan().tolist()
        self.scan_pub.publish(self._scan)

    def publish_imu(self, stamp):
        reading = self.sim.imu_reading()
        self._imu.header.stamp = stamp
        _set_quaternion(self._imu.orientation, reading.orientation)
        _set_xyz(self._imu.angular_velocity, reading.angular_velocity)
        _set_xyz(self._imu.linear_acceleration, reading.linear_acceleration)
        self.imu_pub.publish(self._imu)


class _TimeoutTransport(xmlrpc.client.Transport):
    def make_connection(self, host):
        connection = super(_TimeoutTransport, self).make_connection(host)
        connection.timeout = 1.0  # s: a node that hangs must not hang the simulator
        return connection


def _local_pid(connection):
    """PID of the node at the other end of a subscriber connection, asked over
    its XML-RPC API (as rosnode does); None if it runs on another machine.
    Raises LookupError when a node on this machine does not tell."""
    try:
        sock = connection.socket
        if sock.getpeername()[0] != sock.getsockname()[0]:
            return None
    except (AttributeError, OSError):  # closed meanwhile: nothing to wait for
        return None
    try:
        proxy = xmlrpc.client.ServerProxy(connection.endpoint_id, transport=_TimeoutTransport())
        code, message, pid = proxy.getPid(rospy.get_name())
    except Exception as error:  # refused, timed out, not a ROS node
        raise LookupError(str(error) or type(error).__name__)
    if code != 1:
        raise LookupError(message)
    return pid


class Lockstep(object):
    """Holds each step until the local nodes that publish cmd_vel have reacted to it.

    Otherwise a node's reaction to a tick costs it wall time in which the
    simulator runs on: its commands land late in sim time, and a rospy.Rate
    loop that falls two periods behind drops ticks, so a script's path would
    depend on the factor and the machine's load (even at real time, a python
    script's first ticks, slowed by its connections, can be dropped). A node
    that has not reacted within `timeout` (it computes, or never sleeps) is not
    waited for until it is seen waiting again: the simulator never stalls on it.
    """

    def __init__(self, cmd_vel, timeout, poll, warnings):
        self._cmd_vel = cmd_vel
        self._timeout = timeout
        self._poll = poll
        self._warnings = warnings
        self._connections = None  # the list of cmd_vel connections last followed
        self._connecting = False  # some of them still shaking hands
        self._ask_again_at = math.inf  # when to ask a local node that did not tell its PID
        self._watches = {}   # publisher node name -> ProcessWatch of its process
        self._behind = set()  # node names not waited for until seen waiting
        self.receive_threads = InputWaits()  # the threads that ran our cmd_vel callback

    def _follow_publishers(self):
        """Watch the processes of cmd_vel's publishers, anew whenever they change."""
        impl = self._cmd_vel.impl
        # rospy replaces the list whenever a connection comes or goes, and
        # lists a connection before a thread of its own has connected it:
        # look again each step until every listed one has its handshake done.
        if impl is None or (impl.connections is self._connections and not self._connecting
                            and time.monotonic() < self._ask_again_at):
            return
        connections = self._connections = impl.connections
        connected = [connection for connection in connections if connection.header is not None]
        self._connecting = len(connected) < len(connections)
        names = set(connection.callerid_pub for connection in connected)
        for name in set(self._watches) - names:
            self._watches.pop(name).close()
            self._behind.discard(name)
        self.receive_threads.clear()  # ended connections' threads; live ones come back
        unknown = []
        for connection in connected:
            name = connection.callerid_pub
            if name in self._watches:
                continue
            try:
                pid = _local_pid(connection)
                if pid is not None:
                    self._watches[name] = ProcessWatch(pid)
            except ProcessGone:
                pass
            except LookupError as error:
                unknown.append('%s (%s)' % (name, error))
        # Not waited for until it tells: ask again a second later.
        self._ask_again_at = time.monotonic() + PID_RETRY if unknown else math.inf
        if unknown and self._warnings.allow('lockstep pid'):
            rospy.loginfo('lockstep: no PID from %s: not waiting for it; asking again every %g s (wall)',
                          ', '.join(unknown), PID_RETRY)

    def _reacted(self, name):
        try:
            return self._watches[name].waiting()
        except ProcessGone:  # it ended: nothing more will come from it
            return True

    def wait(self):
        self._follow_publishers()
        # A node left behind and now seen waiting has reacted: no second look.
        recovered = set(name for name in self._behind if self._reacted(name))
        self._behind -= recovered
        pending = [name for name in self._watches if name not in self._behind and name not in recovered]
        deadline = time.monotonic() + self._timeout
        while True:
            pending = [name for name in pending if not self._reacted(name)]
            if not pending:
                break
            if time.monotonic() > deadline:
                self._behind.update(pending)
                # Information, not a fault: at real time nothing waits for
                # a busy node either (Gazebo never does).
                if self._warnings.allow('lockstep'):
                    rospy.loginfo('lockstep: %s did not wait for /clock within %g s (wall); stepping on '
                                  'without it until it does (at most one such message per %g s)',
                                  ', '.join(pending), self._timeout, WARN_PERIOD)
                return
            time.sleep(self._poll)
        # The commands they sent are read: let our callback have handled them.
        while not self.receive_threads.all_waiting():
            if time.monotonic() > deadline:
                return
            time.sleep(self._poll)


class MasterWatch(threading.Thread):
    """Registers this node again with a master that was restarted.

    Peer-to-peer connections survive a master's restart, but a new master
    knows no node: without this, nodes started afterwards would never find
    the simulator. Parameters the tutorial's nodes need (/use_sim_time,
    /robot_description) are set again too.
    """
    PERIOD = 1.0  # wall s between looks at the master
    RESTORED_PARAMETERS = ('/use_sim_time', '/robot_description')

    def __init__(self):
        super(MasterWatch, self).__init__(name='master_watch', daemon=True)
        self.master = rosgraph.Master(rospy.get_name())
        self.parameters = dict((name, rospy.get_param(name)) for name in self.RESTORED_PARAMETERS
                               if rospy.has_param(name))
        self.master_pid = self.master.getPid()

    def run(self):
        reachable = True
        while not rospy.is_shutdown():
            time.sleep(self.PERIOD)
            try:
                pid = self.master.getPid()
            except Exception:  # refused, reset, timed out: all mean "not there now"
                if reachable:
                    rospy.logwarn('the ROS master at %s is gone: simulating on; nodes already connected '
                                  'keep their topics; waiting for a master to come back',
                                  self.master.master_uri)
                reachable = False
                continue
            if pid != self.master_pid:
                self._register_again()
                self.master_pid = pid
                rospy.logwarn('a new ROS master is up at %s: registered /tb3_sim\'s topics and services '
                              'with it again', self.master.master_uri)
            reachable = True

    def _register_again(self):
        from rospy.impl import registration
        topics, services = registration.get_topic_manager(), registration.get_service_manager()
        uri = rospy.core.get_node_uri()
        for name, value in self.parameters.items():
            self.master.setParam(name, value)
        managers = [listener for listener in registration.get_registration_listeners().listeners
                    if isinstance(listener, registration.RegManager)]
        for topic, message_type in topics.get_publications():
            self.master.registerPublisher(topic, message_type, uri)
        for topic, message_type in topics.get_subscriptions():
            publishers = self.master.registerSubscriber(topic, message_type, uri)
            for manager in managers:
                manager.publisher_update(topic, publishers)
        for service, service_uri in services.get_services():
            self.master.registerService(service, service_uri, uri)


def _start_up():
    """Parameters, URDF and world checked, or a fatal message and exit status 2."""
    try:
        from .simulation import Simulation
    except ImportError as error:
        rospy.logfatal('tb3_sim cannot start: %s. %s has no pybullet: run `make setup` and '
                       '`source setup.bash`, or see the README on other workspaces', error, sys.executable)
        sys.exit(2)
    try:
        config = params.resolve(lambda name, default: rospy.get_param('~' + name, default))
        geometry = read_drive_geometry(config['urdf_file'])
        worlds = os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds')
        obstacles = load_world(config['world'], worlds)
        rospy.loginfo('tb3_sim parameters: %s', ', '.join('%s=%r' % item for item in config.items()))
        rospy.loginfo('tb3_sim: wheel radius %.4f m and separation %.4f m from %s; world %r with %d obstacles',
                      geometry.wheel_radius, geometry.wheel_separation, config['urdf_file'],
                      config['world'], len(obstacles))
        return config, Simulation(config, geometry, obstacles)
    except (params.ParameterError, ModelError, WorldError, ValueError) as error:
        rospy.logfatal('tb3_sim cannot start: %s', error)
        rospy.signal_shutdown('bad start-up configuration')
        sys.exit(2)


def main():
    rospy.init_node('tb3_sim')
    config, simulation = _start_up()
    if config['real_time_factor'] == 0.0:
        # As fast as possible, but only on CPU that no other node wants, so
        # that rviz and the shell stay responsive (lockstep waits for the
        # nodes that drive the robot whatever their priority).
        os.nice(10)
    try:
        node = SimulatorNode(config, simulation)
        MasterWatch().start()
        node.run()
    finally:
        simulation.close()
