"""The local controller: dwa_local_planner as TurtleBot3's move_base runs it. No ROS here.

Each cycle (controller_frequency, 10 Hz) the controller samples velocities
(v, w) in the dynamic window: what the accelerations allow within one period
(acc_lim_x 2.5 m/s^2 and acc_lim_theta 3.2 rad/s^2 over 0.1 s: +-0.25 m/s,
+-0.32 rad/s around the robot's velocity), vx_samples x vth_samples of them
(20 x 40) with 0 added where the window spans it. A sample must move at
least min_vel_trans or turn at least min_vel_theta and not exceed
max_vel_trans, and must not flip the direction the robot has just been
moving or turning in (the oscillation flags, reset after
oscillation_reset_dist or oscillation_reset_angle). Each is scored by DWA's
critics (tb3_navigation.trajectory_scoring); the cheapest wins (the first
sampled among equals); none: the robot is told to stop and the call fails.

Where DWA's choice would back away from a plan that lies ahead, or DWA finds
nothing (ours, see _face_the_plan), the robot stops and turns in place to face
the plan instead.

Within xy_goal_tolerance of the goal (latched if latch_xy_goal_tolerance)
the stop-and-rotate controller takes over: slow down with the accelerations
until stopped (trans_stopped_vel, theta_stopped_vel 0.1), then turn in place
towards the goal's yaw (between min_vel_theta and max_vel_theta, slow enough
to stop in time) until within yaw_goal_tolerance, each command checked
against the costmap first. One deviation: DWA raises an in-place turn to
min_vel_theta after its acceleration check (0 -> 1.37 rad/s at once on the
Burger); here the acceleration window comes last, so every command is
reachable from the current velocity in one period.

stop_time_buffer is read and ignored, as dwa_local_planner ignores it.
Poses, plans and the costmap are in one frame (the local costmap's, odom);
velocities in the robot's. Every command is finite and within the limits.
The parameters (DwaConfig, dwa_config) are tb3_navigation.dwa_config's.
"""
import math
from dataclasses import dataclass, replace

import numpy as np

from tb3_common.pose2d import normalize_angle
from tb3_navigation.dwa_config import DwaConfig
from tb3_navigation.trajectory_scoring import GOAL_ZONE, TrajectoryScorer, velocity_samples

EPSILON = 1e-4  # m/s, rad/s: SimpleTrajectoryGenerator's slack on the velocity limits
#: Where the controller aims, as a share of xy_goal_tolerance and yaw_goal_tolerance. DWA stops the
#: moment it is within them; at 10 Hz, 0.11 m/s and 1.37 rad/s (the least speeds it drives at) that
#: left the Burger 0.038-0.045 m and up to 0.169 rad off with a perfect pose, so a localization
#: error of 1-2 cm put the true pose outside. Here the approach ends within ARRIVAL of the distance
#: tolerance, or within PASSED of it once the robot drives away from the goal again (it went by:
#: turning back would only oscillate), and the goal counts as reached only once the turn in place
#: has brought the heading within ARRIVAL of the yaw tolerance. Within the tolerance itself it also
#: ends after STALLED periods (5 s, twice a half turn in place) without coming 1 mm nearer, where DWA
#: would have stopped at once: near a wall the sampled trajectories left only a step forward and one
#: back, and the Burger stood 4.8 cm from the goal until move_base's oscillation_timeout. (After 1 s
#: it ended approaches still turning towards the goal, 5 cm off.)
ARRIVAL = 0.3
PASSED = 0.5
STALLED = 50
#: Within xy_goal_tolerance, before the approach is over, DWA's samples (each moving at least
#: min_vel_trans or turning at least min_vel_theta) left the Burger circling 2-4 cm from the goal,
#: v 0.04 m/s and w 1.4 rad/s, for 3-5 s a goal, and 10 s and more (move_base's oscillation_timeout)
#: near walls (nav_sim's closed loop and the system tests). There the controller turns in place to
#: face the goal's position (or to back onto it) to within FACING rad, then drives straight at it.
FACING = 0.1


@dataclass(frozen=True)
class Command:
    """A velocity command (v m/s, w rad/s), whether the controller found one (ok), the
    trajectory it follows (n, 3) (the local plan), when not ok, why, and the part of the
    global plan it followed (DWAPlannerROS's global_plan)."""
    v: float
    w: float
    ok: bool
    trajectory: np.ndarray = None
    reason: str = ''
    followed: np.ndarray = None


class DwaController(object):
    """DWA over `costmap` (a tb3_navigation.costmap.Costmap, the local one, updated by its owner)."""

    def __init__(self, costmap, config=DwaConfig()):
        self.costmap = costmap
        self.scorer = TrajectoryScorer(costmap, config)
        self.configure(config)
        self._rotating = False  # turning to the goal's yaw (LatchedStopRotateController's rotating_to_goal_)
        self.reset()

    def configure(self, config):
        """New parameters (dynamic_reconfigure's): the next compute() samples and scores with them."""
        self.config = self.scorer.config = config

    def reset(self):
        """A new global plan: forget the goal latch and the oscillation flags (DWAPlannerROS::setPlan).
        A turn to the goal's yaw goes on (resetLatching keeps rotating_to_goal_): move_base plans anew
        at 5 Hz, and forgetting it braked every other period, turning at a quarter of the speed."""
        self._latched = False
        self._flags = {}
        self._stationary = None

    def _same_goal(self, goal):
        # In the local frame the goal moves with every correction of the localization (map -> odom):
        # a goal that moved less than the tolerance is the same goal.
        last = getattr(self, '_arrival_goal', None)
        return last is not None and math.hypot(goal[0] - last[0], goal[1] - last[1]) <= self.config.xy_goal_tolerance

    def _arrive(self, pose, goal):
        """Whether the approach is over (once over, it stays so for this goal, across new plans): within
        ARRIVAL of xy_goal_tolerance, within PASSED of it and past the closest point of the way in, or
        within it and STALLED periods (calls) without coming nearer."""
        if not self._same_goal(goal):
            self._arrival_goal, self._arrived, self._closest = (goal[0], goal[1]), False, math.inf
            self._rotating, self._stalled = False, 0
        distance = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
        tolerance = self.config.xy_goal_tolerance
        self._stalled = 0 if distance < self._closest - 1e-3 else self._stalled + 1
        if distance <= ARRIVAL * tolerance or (distance <= PASSED * tolerance and distance > self._closest + 1e-3) \
                or (distance <= tolerance and self._stalled >= STALLED):
            self._arrived = True
        self._closest = min(self._closest, distance)
        return self._arrived

    # --- the goal ---------------------------------------------------------------------------

    def is_position_reached(self, pose, plan):
        """Within xy_goal_tolerance, the approach over (see _arrive); or latched."""
        config = self.config
        goal = plan[-1]
        distance = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
        arrived = self._same_goal(goal) and self._arrived
        if (config.latch_xy_goal_tolerance and self._latched) or \
                (distance <= config.xy_goal_tolerance and (arrived or distance <= ARRIVAL * config.xy_goal_tolerance)):
            self._latched = True
            return True
        return False

    def is_goal_reached(self, pose, velocity, plan):
        """At the goal's position and yaw, and stopped (LatchedStopRotateController::isGoalReached)."""
        config = self.config
        plan = np.asarray(plan, dtype=float)
        if not len(plan) or not self.is_position_reached(pose, plan):
            return False
        return (abs(normalize_angle(plan[-1][2] - pose[2])) <= ARRIVAL * config.yaw_goal_tolerance and
                abs(velocity[0]) <= config.trans_stopped_vel and abs(velocity[1]) <= config.theta_stopped_vel)

    # --- the command ------------------------------------------------------------------------

    def compute(self, pose, velocity, plan):
        """The Command for the robot at `pose` (x, y, yaw) moving at `velocity` (v, w) to
        follow `plan` [(x, y, yaw), ...] to its last pose."""
        pose = np.asarray(pose, dtype=float)
        velocity = np.asarray(velocity, dtype=float)
        plan = np.asarray(plan, dtype=float).reshape(-1, 3)
        if not (np.all(np.isfinite(pose)) and np.all(np.isfinite(velocity)) and np.all(np.isfinite(plan))):
            return Command(0.0, 0.0, False, reason='a non-finite pose, velocity or plan')
        local = self._local_plan(pose, plan)
        if not len(local):
            return Command(0.0, 0.0, False, reason='no point of the plan within the local costmap')
        self._arrive(pose, plan[-1])
        maps = self.scorer.maps(pose, local)
        if self.is_position_reached(pose, plan):
            command = self._stop_and_rotate(pose, velocity, maps, plan[-1][2])
        else:
            self._rotating = False
            command = None
            if math.hypot(plan[-1][0] - pose[0], plan[-1][1] - pose[1]) <= self.config.xy_goal_tolerance:
                command = self._last_centimetres(pose, velocity, maps, plan[-1])
            if command is None:
                command = self._dwa(pose, velocity, maps, plan[-1])
                if not command.ok or command.v < 0:
                    command = self._face_the_plan(pose, velocity, maps, local) or command
        return replace(self._safe(command), followed=local)

    def _local_plan(self, pose, plan):
        """transformGlobalPlan: from the first pose within half the costmap's size of the
        robot, up to the first beyond it."""
        grid = self.costmap.grid
        threshold = max(grid.width, grid.height) * grid.resolution / 2.0
        near = np.hypot(plan[:, 0] - pose[0], plan[:, 1] - pose[1]) <= threshold
        if not near.any():
            return plan[:0]
        first = int(np.argmax(near))
        beyond = np.flatnonzero(~near[first:])
        return plan[first:first + (beyond[0] if len(beyond) else len(plan))]

    def _safe(self, command):
        config = self.config
        v, w = command.v, command.w
        if not (math.isfinite(v) and math.isfinite(w)):
            return Command(0.0, 0.0, False, reason='a non-finite command')
        v = min(max(v, config.min_vel_x), config.max_vel_x, config.max_vel_trans)
        v = max(v, -config.max_vel_trans)
        w = min(max(w, -config.max_vel_theta), config.max_vel_theta)
        return replace(command, v=float(v), w=float(w))

    def _braking(self, velocity):
        """(v, w) slowing down as hard as the accelerations allow (a stop at once would ask for more)."""
        config, period = self.config, self.config.sim_period
        return (math.copysign(max(0.0, abs(velocity[0]) - config.acc_lim_x * period), velocity[0]),
                math.copysign(max(0.0, abs(velocity[1]) - config.acc_lim_theta * period), velocity[1]))

    def _turning(self, difference, velocity):
        """The turn rate in place towards a heading `difference` rad away: between min_vel_theta and
        max_vel_theta, slow enough to stop in time, within acc_lim_theta of the current turn."""
        config, period = self.config, self.config.sim_period
        speed = min(config.max_vel_theta, max(config.min_vel_theta, abs(difference)))
        speed = min(speed, math.sqrt(2.0 * config.acc_lim_theta * abs(difference)))
        speed = min(config.max_vel_theta, max(config.min_vel_theta, speed))
        # The last step turns just what is left: a full period at min_vel_theta would turn
        # 0.137 rad, most of the yaw tolerance, past the heading.
        speed = min(speed, abs(difference) / period)
        reach = config.acc_lim_theta * period
        return min(max(math.copysign(speed, difference), velocity[1] - reach), velocity[1] + reach)

    def _turn_in_place(self, error, velocity):
        """(v, w) towards a heading `error` rad away: braking until stopped (trans_stopped_vel), then
        turning in place."""
        if abs(velocity[0]) <= self.config.trans_stopped_vel:
            return 0.0, self._turning(error, velocity)
        return self._braking(velocity)

    def _checked(self, pose, maps, v, w):
        """The Command (v, w) with its trajectory, or None if its footprint would meet an obstacle
        (`maps`: the scorer's maps for this pose and local plan)."""
        costs, trajectories = self.scorer.score(pose, np.array([[v, w]]), maps, check_all=True)
        return None if costs[0] < 0 else Command(v, w, True, trajectories[0])

    def _stop_and_rotate(self, pose, velocity, maps, goal_yaw):
        config = self.config
        difference = normalize_angle(goal_yaw - pose[2])
        if abs(difference) <= ARRIVAL * config.yaw_goal_tolerance:
            self._rotating = False
            return Command(0.0, self._braking(velocity)[1], True, pose[None, :])
        stopped = abs(velocity[0]) <= config.trans_stopped_vel and abs(velocity[1]) <= config.theta_stopped_vel
        if not self._rotating and not stopped:
            (v, w), what = self._braking(velocity), 'stopping'
        else:
            self._rotating = True
            v, w, what = 0.0, self._turning(difference, velocity), 'rotating'
        return self._checked(pose, maps, v, w) or Command(0.0, 0.0, False, reason='%s would collide' % what)

    def _last_centimetres(self, pose, velocity, maps, goal):
        """Within xy_goal_tolerance, the approach not over: stop, turn in place to face the goal's
        position (backwards, if it lies behind and min_vel_x allows), then drive straight at it, the
        last step just what is left. None (DWA then) if that would meet an obstacle."""
        config, period = self.config, self.config.sim_period
        distance = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
        bearing = normalize_angle(math.atan2(goal[1] - pose[1], goal[0] - pose[0]) - pose[2])
        backwards = abs(bearing) > math.pi / 2 and config.min_vel_x < 0.0
        error = normalize_angle(bearing - math.pi) if backwards else bearing
        if abs(error) > FACING:
            v, w = self._turn_in_place(error, velocity)
        else:
            reach = config.acc_lim_x * period
            speed = min(config.min_vel_trans, distance * math.cos(error) / period)
            v = min(max(-speed if backwards else speed, velocity[0] - reach), velocity[0] + reach)
            w = self._braking(velocity)[1]
        return self._checked(pose, maps, v, w)

    def _face_the_plan(self, pose, velocity, maps, local):
        """Instead of DWA's backing, or where DWA finds nothing: stop, then turn in place to face the first
        point of the local plan forward_point_distance or more away; None (DWA's command then) if there is
        none, the robot faces it within FACING, or the turn would meet an obstacle. Where every forward arc
        of DWA's window comes nearer than obstacle_clearance or meets an obstacle (a door frame, a corner
        turned early), DWA backs away; with no turn in place within its window from rest (min_vel_theta
        1.37 rad/s, acc_lim_theta 3.2 over 0.1 s) it drove forward again, one period each way (the
        oscillation flags go with every new plan, five times a second), until move_base's recoveries gave
        up. tools/bench_house_tour.py, five tours of 12 goals: 58 -> 60 reached, standing still 280 -> 137 s.
        Where DWA found nothing at all, the robot once stood for the rest of an exploration: turned at a goal
        into a corner of turtlebot3_house, facing the wall, every arc met the wall or a post behind it."""
        config = self.config
        ahead = np.flatnonzero(np.hypot(local[:, 0] - pose[0], local[:, 1] - pose[1]) >= config.forward_point_distance)
        if not len(ahead):
            return None
        target = local[ahead[0]]
        error = normalize_angle(math.atan2(target[1] - pose[1], target[0] - pose[0]) - pose[2])
        if abs(error) <= FACING:
            return None
        return self._checked(pose, maps, *self._turn_in_place(error, velocity))

    def _dwa(self, pose, velocity, maps, goal):
        config = self.config
        period = config.sim_period
        low_v = max(config.min_vel_x, velocity[0] - config.acc_lim_x * period)
        high_v = min(config.max_vel_x, velocity[0] + config.acc_lim_x * period)
        low_w = max(-config.max_vel_theta, velocity[1] - config.acc_lim_theta * period)
        high_w = min(config.max_vel_theta, velocity[1] + config.acc_lim_theta * period)
        vs = velocity_samples(min(low_v, high_v), high_v, config.vx_samples)
        ws = velocity_samples(min(low_w, high_w), high_w, config.vth_samples)
        samples = np.stack(np.meshgrid(vs, ws, indexing='ij'), axis=-1).reshape(-1, 2)
        moving = (np.abs(samples[:, 0]) + EPSILON >= config.min_vel_trans) | \
                 (np.abs(samples[:, 1]) + EPSILON >= config.min_vel_theta)
        samples = samples[moving & (np.abs(samples[:, 0]) - EPSILON <= config.max_vel_trans)]
        samples = samples[self._allowed(samples[:, 0], samples[:, 1])] if self._flags else samples
        if not len(samples):
            return Command(0.0, 0.0, False, reason='no velocity in the dynamic window')
        far = math.hypot(goal[0] - pose[0], goal[1] - pose[1]) > GOAL_ZONE
        costs, trajectories = self.scorer.score(pose, samples, maps, clearance=far)
        valid = np.flatnonzero(costs >= 0)
        if not len(valid):
            return Command(0.0, 0.0, False, reason='every trajectory collides or leaves the plan')
        best = valid[np.argmin(costs[valid])]
        v, w = samples[best]
        self._update_flags(pose, v, w)
        return Command(float(v), float(w), True, trajectories[best])

    # --- oscillation flags (base_local_planner's OscillationCostFunction) ------------------

    def _allowed(self, v, w):
        """Where the velocities (arrays) `v`, `w` are not ruled out by the flags set."""
        flags = self._flags
        return ~((bool(flags.get('forward_only')) & (v < 0)) | (bool(flags.get('backward_only')) & (v > 0)) |
                 (bool(flags.get('left_only')) & (w < 0)) | (bool(flags.get('right_only')) & (w > 0)))

    def _update_flags(self, pose, v, w):
        flags, config = self._flags, self.config
        set_now = False
        for value, up, down, up_only, down_only, applies in (
                (v, 'forward', 'backward', 'forward_only', 'backward_only', True),
                (w, 'left', 'right', 'left_only', 'right_only', abs(v) <= config.min_vel_trans)):
            if not applies:
                continue
            if value < 0:
                if flags.get(up):
                    flags[down_only] = set_now = True
                flags[up], flags[down] = False, True
            elif value > 0:
                if flags.get(down):
                    flags[up_only] = set_now = True
                flags[down], flags[up] = False, True
        if set_now:
            self._stationary = np.array(pose, dtype=float)
        if any(flags.get(name) for name in ('forward_only', 'backward_only', 'left_only', 'right_only')):
            moved = np.hypot(*(pose[:2] - self._stationary[:2])) if self._stationary is not None else math.inf
            turned = abs(normalize_angle(pose[2] - self._stationary[2])) if self._stationary is not None else 0.0
            if moved > config.oscillation_reset_dist or turned > config.oscillation_reset_angle:
                flags.clear()

