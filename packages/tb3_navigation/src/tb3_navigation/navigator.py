"""move_base's state machine, as a pure class fed the time. No ROS here.

move_base runs one goal at a time through three states:

- PLANNING: the global planner is asked for a plan (at most planner_frequency
  times a second); the robot is held still. No plan for planner_patience s
  (or past max_planning_retries, if >= 0) -> CLEARING.
- CONTROLLING: the goal reached (the controller says so: position, yaw,
  stopped) -> SUCCEEDED. Otherwise the controller's command is sent and the
  plan renewed every 1 / planner_frequency s (a failed renewal keeps the old
  plan). No command found: back to PLANNING with the robot stopped, or, when
  none was found for controller_patience s, CLEARING. Not moving
  oscillation_distance in oscillation_timeout s (if > 0) -> CLEARING.
- CLEARING: the next recovery behaviour, then PLANNING again; move_base's
  default list (TurtleBot3 sets none): conservative_reset (forget the
  obstacles seen outside a conservative_reset_dist square around the
  robot), rotate_recovery (turn in place a full turn), aggressive_reset (the
  same outside a square of 4 x move_base's circumscribed_radius, 0.46 m by
  default), rotate_recovery. When they are used up: ABORTED, with
  move_base's message for what started the recovery.

A new goal replaces the current one (which is PREEMPTED) and restarts in
PLANNING; a cancel PREEMPTS it. A goal whose position is not finite, whose
quaternion is not finite, far from unit length or tilted, or whose frame
cannot be brought into the global frame is ABORTED at once. After any end,
the next step commands a stop (move_base's publishZeroVelocity), then None
while idle: the node sends nothing then and leaves the robot to others.

The rotation (tb3_navigation.recovery) takes several steps here: move_base
runs it to its end inside one cycle; here goals and cancels still come
through while it turns.
"""
import math
from dataclasses import dataclass

import numpy as np

from tb3_common.params import Checked, frame_id, non_negative, number, parameter, positive
from tb3_common.pose2d import IDENTITY, compose, yaw_of_quaternion
from tb3_navigation.recovery import RotateRecovery, RotateRecoveryConfig

PENDING, PREEMPTED, SUCCEEDED, ABORTED = 0, 2, 3, 4  # actionlib_msgs/GoalStatus
PLANNING, CONTROLLING, CLEARING = 'PLANNING', 'CONTROLLING', 'CLEARING'
PLANNING_R, CONTROLLING_R, OSCILLATION_R = 'planning', 'controlling', 'oscillation'
ABORT_TEXT = {  # move_base's words
    PLANNING_R: 'Failed to find a valid plan. Even after executing recovery behaviors.',
    CONTROLLING_R: 'Failed to find a valid control. Even after executing recovery behaviors.',
    OSCILLATION_R: 'Robot is oscillating. Even after executing recovery behaviors.'}
#: What started the recoveries, as the node logs it beside each behaviour.
TRIGGER_TEXT = {PLANNING_R: 'no valid plan within planner_patience',
                CONTROLLING_R: 'no valid command within controller_patience',
                OSCILLATION_R: 'not moving oscillation_distance within oscillation_timeout'}
STOP = (0.0, 0.0)
DEFAULT_RECOVERIES = ('conservative_reset', 'rotate_recovery', 'aggressive_reset', 'rotate_recovery')
RECOVERIES = ('conservative_reset', 'aggressive_reset', 'rotate_recovery')


def _behaviours(value):
    unknown = [name for name in value if name not in RECOVERIES]
    return 'unknown behaviour %r (%s)' % (unknown[0], ', '.join(RECOVERIES)) if unknown else None


@dataclass(frozen=True)
class NavigatorConfig(Checked):
    """move_base's parameters: TurtleBot3's move_base_params.yaml, move_base's defaults for the rest.
    recovery_behaviors names the behaviours in order (move_base's list gives {name, type}
    each: the node passes the names of the clear_costmap_recovery and rotate_recovery ones)."""
    global_frame: str = parameter('map', 'the global costmap\'s frame: goals are planned in it', frame_id)
    controller_frequency: float = parameter(10.0, 'Hz: control cycles (sim time)', positive, 'Hz')
    planner_frequency: float = parameter(5.0, 'Hz: the global plan is made anew this often while driving; 0: only '
                                              'once per goal', non_negative, 'Hz')
    planner_patience: float = parameter(5.0, 's without a plan before the recoveries', non_negative, 's')
    controller_patience: float = parameter(15.0, 's without a valid command before the recoveries', non_negative, 's')
    max_planning_retries: int = parameter(-1, 'failed plans before the recoveries; -1: planner_patience alone '
                                              'decides', number(-1))
    oscillation_timeout: float = parameter(10.0, 's without moving oscillation_distance before the recoveries; 0: '
                                                 'never', non_negative, 's')
    oscillation_distance: float = parameter(0.2, 'm: moving this far resets the oscillation timer', non_negative, 'm')
    conservative_reset_dist: float = parameter(3.0, 'm: the first recovery forgets obstacles outside this square',
                                               non_negative, 'm')
    circumscribed_radius: float = parameter(0.46, "m: the aggressive reset's square is 4 times this (move_base "
                                                  'reads it as ~local_costmap/circumscribed_radius)', non_negative, 'm')
    recovery_behavior_enabled: bool = parameter(True, 'false: no recoveries, ABORTED at once')
    clearing_rotation_allowed: bool = parameter(True, 'false: the recoveries do not turn in place')
    recovery_behaviors: tuple = parameter(DEFAULT_RECOVERIES, "move_base's default four, in its order", _behaviours)
    quaternion_norm_tolerance: float = parameter(1e-3, "a goal's quaternion further than this from length 1 is "
                                                       'ABORTED', non_negative)
    rotation_timeout: float = parameter(30.0, 's: a recovery turn gives up after this (ours: a robot that cannot '
                                              'turn)', non_negative, 's')


@dataclass(frozen=True)
class Outcome:
    """How a goal ended: status (SUCCEEDED, PREEMPTED, ABORTED), move_base's text, the goal (x, y, yaw)."""
    status: int
    text: str
    goal: tuple = None


@dataclass(frozen=True)
class Step:
    """What one cycle wants: cmd (v, w) to send, or None (send nothing); the state; the
    goal's Outcome if it ended; the global plan if a new one was made; the local plan;
    the recovery behaviour started, if any; the part of the global plan the controller
    followed (in the local frame)."""
    cmd: tuple
    state: str
    outcome: Outcome = None
    plan: list = None
    local_plan: np.ndarray = None
    recovery: str = None
    followed: np.ndarray = None


def goal_error(position, orientation, tolerance=1e-3):
    """Why a goal cannot be taken (text), or None: a non-finite position; move_base's
    isQuaternionValid (finite, not near zero length, z axis vertical); and, as the
    issue asks, a length more than `tolerance` from 1."""
    if not all(math.isfinite(value) for value in position):
        return 'Aborting on goal because it was sent with a non-finite position %r' % (tuple(position),)
    x, y, z, w = orientation
    if not all(math.isfinite(value) for value in orientation):
        return 'Aborting on goal because it was sent with an invalid quaternion (nans or infs)'
    length = math.sqrt(x * x + y * y + z * z + w * w)
    if length * length < 1e-6:
        return 'Aborting on goal because it was sent with an invalid quaternion (length close to zero)'
    if abs(length - 1.0) > tolerance:
        return 'Aborting on goal because it was sent with a quaternion that is not normalised (length %.6g)' % length
    x, y, z, w = x / length, y / length, z / length, w / length
    if abs((1.0 - 2.0 * (x * x + y * y)) - 1.0) > 1e-3:  # the rotated z axis's z component
        return 'Aborting on goal because it was sent with an invalid quaternion (z axis not vertical)'
    return None


class Navigator(object):
    """move_base for one robot: `planner` has make_plan(costmap, start, goal, tolerance=None);
    `controller` has reset(), is_goal_reached(pose, velocity, plan) and compute(pose,
    velocity, plan) -> a Command (v, w, ok, trajectory), in the local costmap's frame;
    the costmaps (or None) have clear_obstacles(centre, size), reset(), and the local
    one footprint_cost(poses); `rotation` configures rotate_recovery."""

    def __init__(self, config, planner, controller, global_costmap=None, local_costmap=None,
                 rotation=RotateRecoveryConfig()):
        self.config, self.planner, self.controller, self.rotation = config, planner, controller, rotation
        self.global_costmap, self.local_costmap = global_costmap, local_costmap
        self.goal = None
        self.plan = None
        self.state = PLANNING
        self._stop_once = False

    @property
    def active(self):
        return self.goal is not None

    # --- goals ------------------------------------------------------------------------------

    def set_goal(self, now, position, orientation, frame=None, frame_to_global=None):
        """Takes a goal: `position` (x, y, z) and `orientation` (x, y, z, w) in `frame` (the
        global frame if None). `frame_to_global(frame)` gives the pose (x, y, yaw) of another
        frame in the global one, or None if it cannot. Returns the Outcomes this causes: the
        previous goal PREEMPTED (if one was active), this one ABORTED (if it is refused)."""
        outcomes = []
        if self.active:
            outcomes.append(self._end(PREEMPTED, 'Preempted by a new goal.'))
        error = goal_error(position, orientation, self.config.quaternion_norm_tolerance)
        frame = (self.config.global_frame if frame is None else frame).lstrip('/')
        pose = None
        if error is None:
            length = math.sqrt(sum(value * value for value in orientation))
            pose = (float(position[0]), float(position[1]), yaw_of_quaternion(*(v / length for v in orientation)))
        if error is None and frame != self.config.global_frame:
            offset = frame_to_global(frame) if frame_to_global is not None and frame else None
            if offset is None or not np.all(np.isfinite(offset)):
                error = ("Aborting on goal because its frame '%s' cannot be transformed into '%s'"
                         % (frame, self.config.global_frame))
            else:
                pose = tuple(float(value) for value in compose(offset, pose))
        if error is not None:
            self._stop_once = True
            return outcomes + [Outcome(ABORTED, error, pose)]
        self.goal, self.plan, self.state = pose, None, PLANNING
        self._recovery_index, self._trigger, self._behaviour = 0, PLANNING_R, None
        self._last_valid_plan = self._last_valid_control = self._last_oscillation_reset = now
        self._oscillation_pose = None
        self._next_plan = now
        self._retries = 0
        self._stop_once = False
        return outcomes

    def cancel(self):
        """The goal PREEMPTED (an Outcome), or None if there was none; the next step stops the robot."""
        return self._end(PREEMPTED, 'Goal canceled.') if self.active else None

    def _end(self, status, text):
        outcome = Outcome(status, text, self.goal)
        self.goal, self.plan, self.state, self._behaviour = None, None, PLANNING, None
        self._stop_once = True
        return outcome

    # --- services ---------------------------------------------------------------------------

    def make_plan(self, start, goal, tolerance=0.0, add_unreachable_goal=True):
        """The make_plan service: a plan from `start` to `goal` (x, y, yaw) on the global
        costmap, else one to the reachable point nearest the goal within `tolerance`
        with the goal appended if `add_unreachable_goal` (move_base's
        make_plan_add_unreachable_goal); [] if none; None while a goal is active (move_base
        refuses then)."""
        if self.active:
            return None
        plan = self.planner.make_plan(self.global_costmap, start, goal)
        if not plan and tolerance > 0:
            plan = self.planner.make_plan(self.global_costmap, start, goal, tolerance)
            plan = plan + [tuple(float(v) for v in goal)] if plan and add_unreachable_goal else plan
        return plan or []

    def clear_costmaps(self):
        """The clear_costmaps service: both costmaps' obstacles forgotten."""
        for costmap in (self.global_costmap, self.local_costmap):
            if costmap is not None:
                costmap.reset()

    # --- the cycle --------------------------------------------------------------------------

    def step(self, now, pose, velocity, global_to_local=IDENTITY):
        """One control cycle at time `now` (s) with the robot at `pose` (x, y, yaw, global
        frame) moving at `velocity` (v, w); `global_to_local` is the pose of the global
        frame in the local costmap's (map in odom). Returns a Step."""
        if not self.active:
            cmd, self._stop_once = (STOP if self._stop_once else None), False
            return Step(cmd, self.state)
        if not (np.all(np.isfinite(pose)) and np.all(np.isfinite(velocity))
                and np.all(np.isfinite(global_to_local))):
            return Step(STOP, self.state)  # nothing to steer by: hold still, time goes on
        config = self.config
        last = self._oscillation_pose
        if last is None or math.hypot(pose[0] - last[0], pose[1] - last[1]) >= config.oscillation_distance:
            self._last_oscillation_reset, self._oscillation_pose = now, tuple(pose)
            if self._trigger == OSCILLATION_R:
                self._recovery_index = 0
        new_plan = None
        if self.state == PLANNING or (self.state == CONTROLLING and config.planner_frequency > 0
                                      and now >= self._next_plan):
            new_plan = self._plan(now, pose)
        if self.state == PLANNING:
            return Step(STOP, PLANNING, plan=new_plan)
        if self.state == CLEARING:
            return self._clear(now, pose, global_to_local, new_plan)
        return self._control(now, pose, velocity, global_to_local, new_plan)

    def _plan(self, now, pose):
        config = self.config
        if config.planner_frequency > 0:
            self._next_plan = now + 1.0 / config.planner_frequency
        plan = self.planner.make_plan(self.global_costmap, tuple(pose), self.goal)
        if plan:
            self.plan = plan
            self._last_valid_plan, self._retries = now, 0
            self.controller.reset()
            if self._trigger == PLANNING_R:
                self._recovery_index = 0
            if self.state == PLANNING:
                self.state = CONTROLLING
            if config.planner_frequency <= 0:
                self._next_plan = math.inf
            return plan
        if self.state == PLANNING:
            self._retries += 1
            if now > self._last_valid_plan + config.planner_patience or \
                    0 <= config.max_planning_retries < self._retries:
                self.state, self._trigger = CLEARING, PLANNING_R
        return None

    def _control(self, now, pose, velocity, global_to_local, new_plan):
        config = self.config
        local_pose = compose(global_to_local, pose)
        local_plan = compose(global_to_local, np.asarray(self.plan, dtype=float))
        if self.controller.is_goal_reached(local_pose, velocity, local_plan):
            return Step(STOP, CONTROLLING, self._end(SUCCEEDED, 'Goal reached.'), new_plan)
        if config.oscillation_timeout > 0 and now > self._last_oscillation_reset + config.oscillation_timeout:
            self.state, self._trigger = CLEARING, OSCILLATION_R
            return Step(STOP, CLEARING, plan=new_plan)
        command = self.controller.compute(local_pose, velocity, local_plan)
        if command.ok and math.isfinite(command.v) and math.isfinite(command.w):
            self._last_valid_control = now
            if self._trigger == CONTROLLING_R:
                self._recovery_index = 0
            return Step((float(command.v), float(command.w)), CONTROLLING, plan=new_plan,
                        local_plan=command.trajectory, followed=getattr(command, 'followed', None))
        if now > self._last_valid_control + config.controller_patience:
            self.state, self._trigger = CLEARING, CONTROLLING_R
        else:
            self.state, self._last_valid_plan, self._retries = PLANNING, now, 0
            self._next_plan = now
        return Step(STOP, self.state, plan=new_plan)

    # --- recovery ---------------------------------------------------------------------------

    def _behaviours(self):
        config = self.config
        if not config.recovery_behavior_enabled:
            return ()
        return tuple(name for name in config.recovery_behaviors
                     if config.clearing_rotation_allowed or name != 'rotate_recovery')

    @property
    def recovery_reason(self):
        """Why the recoveries run (TRIGGER_TEXT)."""
        return TRIGGER_TEXT[self._trigger]

    def _clear(self, now, pose, global_to_local, new_plan):
        started, local = None, compose(global_to_local, pose)  # the rotation is watched in the local frame
        if self._behaviour is None:
            behaviours = self._behaviours()
            if self._recovery_index >= len(behaviours):
                return Step(STOP, CLEARING, self._end(ABORTED, ABORT_TEXT[self._trigger]), new_plan)
            started = behaviours[self._recovery_index]
            self._recovery_index += 1
            if started == 'rotate_recovery':
                self._behaviour = RotateRecovery(self.rotation, now, local[2], self.config.rotation_timeout)
            else:
                size = (self.config.conservative_reset_dist if started == 'conservative_reset'
                        else 4.0 * self.config.circumscribed_radius)
                for costmap, centre in ((self.global_costmap, pose), (self.local_costmap, local)):
                    if costmap is not None:
                        costmap.clear_obstacles(centre[:2], size)
                self._back_to_planning(now)
                return Step(STOP, CLEARING, plan=new_plan, recovery=started)
        footprint_cost = None if self.local_costmap is None else self.local_costmap.footprint_cost
        cmd = self._behaviour.command(now, local, footprint_cost)
        if cmd is None:
            self._behaviour = None
            self._back_to_planning(now)
            cmd = STOP
        return Step(cmd, CLEARING, plan=new_plan, recovery=started)

    def _back_to_planning(self, now):
        self._last_oscillation_reset = self._last_valid_plan = self._next_plan = now
        self._retries, self.state = 0, PLANNING
