"""rotate_recovery: a full turn in place, to let the sensors clear the costmap around. No ROS here.

Turn left until half a turn is done, then on until back at the start yaw
(within yaw_goal_tolerance); each cycle at the speed that could still stop
in the turn left (sqrt(2 acc_lim_theta left)), between
min_in_place_vel_theta and max_vel_theta. Before each command the
footprint is checked on the local costmap at every sim_granularity of the
turn left; anything in the way ends the behaviour at once, as it does in
rotate_recovery. An addition: the turn also ends after `timeout` s, so that
a robot that cannot turn does not wait forever (rotate_recovery would).
"""
import math
from dataclasses import dataclass

import numpy as np

from tb3_common.params import Checked, parameter, positive
from tb3_common.pose2d import normalize_angle


@dataclass(frozen=True)
class RotateRecoveryConfig(Checked):
    """rotate_recovery's parameters: sim_granularity under its own name (~rotate_recovery/), the rest
    under ~TrajectoryPlannerROS/, which TurtleBot3's move_base.launch does not load, so its defaults hold."""
    sim_granularity: float = parameter(0.017, 'rad between footprint checks along the turn left', positive, 'rad')
    acc_lim_theta: float = parameter(3.2, 'rad/s^2: the turn slows to stop in time', positive, 'rad/s^2')
    max_vel_theta: float = parameter(1.0, 'rad/s: the fastest turn', positive, 'rad/s')
    min_in_place_vel_theta: float = parameter(0.4, 'rad/s: the slowest turn', positive, 'rad/s')
    yaw_goal_tolerance: float = parameter(0.10, 'rad: the turn is over this near the start yaw', positive, 'rad')


class RotateRecovery(object):
    """One turn, started at time `now` (s) with the robot at `yaw`."""

    def __init__(self, config, now, yaw, timeout=30.0):
        self.config, self.start, self.since, self.timeout = config, yaw, now, timeout
        self.half = False

    def command(self, now, pose, footprint_cost=None):
        """(v, w) for this cycle with the robot at `pose` (x, y, yaw, the costmap's frame),
        or None when the turn is over. `footprint_cost(poses)` < 0 where the footprint
        may not be (tb3_navigation.costmap.Costmap.footprint_cost); None: not checked."""
        config = self.config
        if self.half and abs(normalize_angle(pose[2] - self.start)) <= config.yaw_goal_tolerance:
            return None
        if now > self.since + self.timeout:
            return None
        if not self.half:
            to_half = abs(normalize_angle(pose[2] - (self.start + math.pi)))
            left = math.pi + to_half
            self.half = to_half < config.yaw_goal_tolerance
        else:
            left = abs(normalize_angle(pose[2] - self.start))
        if footprint_cost is not None:
            angles = pose[2] + np.arange(0.0, left, config.sim_granularity)
            poses = np.stack((np.full_like(angles, pose[0]), np.full_like(angles, pose[1]), angles), axis=-1)
            if len(poses) and np.any(footprint_cost(poses) < 0):
                return None
        speed = min(max(math.sqrt(2.0 * config.acc_lim_theta * left), config.min_in_place_vel_theta),
                    config.max_vel_theta)
        return (0.0, float(speed))
