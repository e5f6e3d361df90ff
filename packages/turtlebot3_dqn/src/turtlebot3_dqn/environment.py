"""ROBOTIS' machine-learning stage as a plain Python environment: reset() and step(), no ROS code to write.

    from turtlebot3_dqn.environment import Env
    env = Env(stage=1)                 # a stage world must be running (roslaunch turtlebot3_gazebo ...)
    state, info = env.reset()
    state, reward, terminated, truncated, info = env.step(2)

Gymnasium's signature (a gymnasium.Env, with its spaces, when gymnasium is
importable; the same shape without it). It is environment_stage_N.py's Env
over ROS: it publishes `cmd_vel`, reads `odom` and `scan`, resets through
`gazebo/reset_simulation` and puts the goal box in place through
`gazebo/delete_model` and `gazebo/spawn_sdf_model`; the maths is core.py's.

Departures, each for the same episodes at any real-time factor (the
simulator's lockstep waits for this process between two steps, but not for
the master or for a connection being made): one persistent subscriber of
`scan` (ROBOTIS' wait_for_message subscribes anew every step) and
persistent service connections; the pose is the last odometry stamped
before the scan (odom and scan of one step come on two connections, in
either order); no wall-time sleeps (respawnGoal's time.sleep(0.5)); the goal
box is deleted and spawned without waiting for gazebo/model_states.

While step() and reset() wait for the next scan, the process tells the
simulator's lockstep that only data wakes it (tb3_common.wake), so the
simulator does not wait for its reaction to the /clock ticks in between.
An Env that starts its own node (rospy not yet initialised) says so for the
whole process: code of yours that acts on sim time in another thread
meanwhile should start its node first (rospy.init_node), and the simulator
then waits for the process at every tick.
"""
import collections
import os
import threading

import numpy as np
import rospkg
import rospy
from gazebo_msgs.srv import DeleteModel, SpawnModel
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty

from tb3_common.ros import lifecycle
from tb3_common.ros.poses import plane_pose, pose_message

from . import core

try:  # Gymnasium's base class and spaces, when it is installed (Debian has none: pip install gymnasium)
    import gymnasium
    from gymnasium import spaces
    _Base = gymnasium.Env
except ImportError:
    gymnasium = spaces = None
    _Base = object

GOAL_MODEL = 'goal'     # respawnGoal's model name
CONNECT_TIMEOUT = 30.0  # wall s to wait for the simulator's topics and services at start
ODOM_HISTORY = 64       # odometry messages kept to find the one before a scan (30 Hz: 2 s)
STOP_POLL = 0.05        # wall s between two looks at the end flag while waiting


class SimulatorMissing(RuntimeError):
    """No simulator answers: the message says what to start."""


def goal_box_sdf():
    """The goal box's SDF (turtlebot3_simulations' turtlebot3_square/goal_box, shipped here)."""
    path = os.path.join(rospkg.RosPack().get_path('turtlebot3_dqn'), 'models', 'goal_box', 'model.sdf')
    with open(path) as stream:
        return stream.read()


class Env(_Base):
    """One stage (1-4) of ROBOTIS' chapter. reset(seed, options) -> (state, info); step(action) ->
    (state, reward, terminated, truncated, info): terminated on a collision, truncated after
    `episode_step` steps; a goal reached gives its reward, moves the goal and the episode goes on,
    as ROBOTIS' does. info: {'goal': reached this step, 'collision', 'goals' this episode, 'steps',
    'sim_time' (s, the scan's stamp)}. reset's options may hold {'goal': (x, y)}: the goal box there
    (ROBOTIS' keeps the goal where it was)."""

    metadata = {'render_modes': []}

    def __init__(self, stage=1, seed=None, episode_step=500, scan_timeout=5.0, life=None, namespace=''):
        """`seed`: of the goals' positions; `life`: the node's tb3_common lifecycle (a node of its own,
        named turtlebot3_dqn_env, is started when rospy has none); `namespace`: a robot's ('tb3_0')."""
        if stage not in core.STAGES:
            raise ValueError('stage must be one of %s, not %r' % (sorted(core.STAGES), stage))
        self.stage = core.STAGES[stage]
        self.episode_step, self.scan_timeout = episode_step, scan_timeout
        if life is None:
            life = lifecycle.init_node('turtlebot3_dqn_env') if not rospy.core.is_initialized() else lifecycle.Life()
        self.life = life
        self.goals = core.Goals(stage, seed)
        self.goal = None  # where the goal box stands now
        self._goal_sdf = goal_box_sdf()
        self._condition = threading.Condition()
        self._scans, self._scan = 0, None
        self._odometry = collections.deque(maxlen=ODOM_HISTORY)
        topic = (lambda name: namespace.strip('/') + '/' + name) if namespace else (lambda name: name)
        self._cmd_vel = rospy.Publisher(topic('cmd_vel'), Twist, queue_size=5)
        odom = rospy.Subscriber(topic('odom'), Odometry, self._on_odom, queue_size=ODOM_HISTORY)
        self.life.stores([odom.resolved_name])  # _next_scan takes the odometry of its scan's time
        rospy.Subscriber(topic('scan'), LaserScan, self._on_scan, queue_size=1)
        self._services = {}
        for name, kind in (('gazebo/reset_simulation', Empty), ('gazebo/spawn_sdf_model', SpawnModel),
                           ('gazebo/delete_model', DeleteModel)):
            try:
                rospy.wait_for_service(name, CONNECT_TIMEOUT)
            except rospy.ROSException:
                raise SimulatorMissing('no %s within %.0f s: start a stage world first (roslaunch turtlebot3_gazebo '
                                       'turtlebot3_stage_%d.launch)' % (name, CONNECT_TIMEOUT, stage))
            self._services[name] = rospy.ServiceProxy(name, kind, persistent=True)
        self._wait(lambda: self._cmd_vel.get_num_connections() > 0, CONNECT_TIMEOUT, 'a reader of cmd_vel')
        # Each persistent service connection is made at its first call, asking the master where the
        # service is: the simulator's lockstep does not wait for the master, so a first call in an episode
        # landed some steps later at one factor than at another (a goal's respawn: a score 0.2 apart). Every
        # connection made here, before the first episode: a goal box spawned (or refused: an earlier run
        # left one), deleted and spawned at respawnGoal's first goal, and the simulation starts afresh.
        self._call('gazebo/spawn_sdf_model', GOAL_MODEL, self._goal_sdf, '', pose_message(self.goals.goal + (0.0,)),
                   'world')
        self.goal = self.goals.goal
        self._place_goal(self.goals.goal)
        self._call('gazebo/reset_simulation')
        self.steps = self.goals_reached = 0
        self.start_distance = 1.0
        size = self.stage.state_size
        if spaces is not None:
            self.action_space = spaces.Discrete(core.ACTION_SIZE)
            self.observation_space = spaces.Box(-np.inf, np.inf, (size,), np.float32)

    @property
    def state_size(self):
        return self.stage.state_size

    # --- what comes in (rospy's threads) ---------------------------------------------------------
    def _on_odom(self, message):
        with self._condition:
            self._odometry.append((message.header.stamp.to_nsec(), plane_pose(message)))
            self._condition.notify_all()

    def _on_scan(self, message):
        with self._condition:
            self._scan, self._scans = message, self._scans + 1
            self._condition.notify_all()

    def _wait(self, predicate, timeout, what):
        waited = 0.0  # wall s: sim time may stand still
        while not predicate():
            if self.life.stopping:
                raise KeyboardInterrupt('asked to end')
            if waited >= timeout:
                raise SimulatorMissing('no %s within %.0f s: is a stage world running?' % (what, timeout))
            self.life.sleep(0.01)
            waited += 0.01

    def _next_scan(self, after):
        """The first scan after the `after`th, with the robot's pose then: ROBOTIS' wait_for_message
        ('scan', timeout=5) in a loop, which warns here each time it waits `scan_timeout` in vain.
        Only data wakes this process meanwhile, and odometry alone does not: the simulator need not
        wait for its reaction to /clock, nor to a step that sent only odometry. So the odometry of the
        scan's time, sent in the same step on another connection, may come after the scan: it is
        waited for (then any data wakes this process), and the last odometry before the scan is in."""
        while True:
            with self.life.waiting_for_data(except_stored=True):
                self._await(lambda: self._scans > after, 'scan')
            with self._condition:
                scan, after = self._scan, self._scans
            stamp = scan.header.stamp.to_nsec()
            with self.life.waiting_for_data():
                self._await(lambda: self._odometry and self._odometry[-1][0] >= stamp, 'odometry')
            with self._condition:
                before = [pose for at, pose in self._odometry if at < stamp]
            if before:
                return scan, before[-1]
            # no odometry before it (the first scan after a reset): the next scan

    def _await(self, predicate, what):
        """Until `predicate()` holds (it reads what rospy's threads write, under the condition)."""
        waited = 0.0
        while True:
            with self._condition:
                # In slices: a signal only sets the flag, and Ctrl+C ends the simulator too, whose data
                # would have woken this wait.
                if self._condition.wait_for(lambda: predicate() or self.life.stopping, STOP_POLL):
                    if self.life.stopping:
                        raise KeyboardInterrupt('asked to end')
                    return
            if self.life.stopping:
                raise KeyboardInterrupt('asked to end')
            waited += STOP_POLL
            if waited >= self.scan_timeout:
                waited = 0.0
                rospy.logwarn('turtlebot3_dqn: no %s for %.0f s: is the simulation paused?', what, self.scan_timeout)

    def _observe(self, scan, pose):
        ranges = core.ranges_of(scan.ranges, scan.range_min)
        if len(ranges) != core.BEAMS:
            raise ValueError('the scan has %d beams; the chapter\'s agent takes %d: start the stage world with '
                             'scan_samples:=%d (its default)' % (len(ranges), core.BEAMS, core.BEAMS))
        return core.observe(self.stage, ranges, pose, self.goal)

    # --- the goal box ----------------------------------------------------------------------------
    def _call(self, name, *args):
        try:
            return self._services[name](*args)
        except (rospy.ServiceException, rospy.ROSException) as error:
            if self.life.stopping:
                raise KeyboardInterrupt('asked to end')
            raise SimulatorMissing('%s failed: %s' % (name, error))

    def _place_goal(self, goal):
        """The goal box to `goal`: the old one deleted, a new one spawned (respawnGoal's way)."""
        if self.goal is not None:
            self._call('gazebo/delete_model', GOAL_MODEL)
        answer = self._call('gazebo/spawn_sdf_model', GOAL_MODEL, self._goal_sdf, '', pose_message(goal + (0.0,)),
                            'world')
        if not answer.success:
            raise SimulatorMissing('gazebo/spawn_sdf_model: %s' % answer.status_message)
        self.goal = tuple(goal)
        rospy.loginfo('Goal position : %.1f, %.1f', goal[0], goal[1])

    # --- Gymnasium's interface ---------------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """reset_simulation, the first scan after it; the goal box where it was (at first ROBOTIS' (0.6, 0)),
        or at options['goal']. (state, info)."""
        if seed is not None:
            self.goals = core.Goals(self.stage.number, seed)
        if _Base is not object:
            super(Env, self).reset(seed=seed)
        self._cmd_vel.publish(Twist())
        self._call('gazebo/reset_simulation')
        goal = (options or {}).get('goal')
        if goal is not None:
            self._place_goal(tuple(goal))
        # What came before the reset is in (lockstep waited for this process before serving it), and time
        # went back to zero: the next scan and the odometry from here on are the new episode's.
        with self._condition:
            seen = self._scans
            self._odometry.clear()
        scan, pose = self._next_scan(seen)
        self.steps = self.goals_reached = 0
        self.start_distance = core.distance_to(pose, self.goal)
        state, _, _ = self._observe(scan, pose)
        return np.asarray(state, np.float32), {'sim_time': scan.header.stamp.to_sec(), 'goal_at': self.goal}

    def step(self, action):
        """The action's twist, then the next scan: (state, reward, terminated, truncated, info)."""
        with self._condition:
            seen = self._scans
        linear, angular = core.twist(int(action))
        command = Twist()
        command.linear.x, command.angular.z = linear, angular
        self._cmd_vel.publish(command)
        scan, pose = self._next_scan(seen)
        self.steps += 1
        state, collided, at_goal = self._observe(scan, pose)
        reward = core.reward(self.stage, state, int(action), self.start_distance, collided, at_goal)
        if collided:
            rospy.loginfo('Collision!!')
            self._cmd_vel.publish(Twist())
        if at_goal:
            rospy.loginfo('Goal!!')
            self.goals_reached += 1
            self._cmd_vel.publish(Twist())
            self._place_goal(self.goals.next())
            self.start_distance = core.distance_to(pose, self.goal)
        truncated = not collided and self.steps > self.episode_step
        if truncated:
            rospy.loginfo('Time out!!')
        info = {'goal': at_goal, 'collision': collided, 'goals': self.goals_reached, 'steps': self.steps,
                'sim_time': scan.header.stamp.to_sec(), 'goal_at': self.goal}
        return np.asarray(state, np.float32), reward, collided, truncated, info

    def close(self):
        """Stops the robot (the node, if this class started it, ends with the process)."""
        if not rospy.core.is_shutdown():
            self._cmd_vel.publish(Twist())
