"""dwa_local_planner's parameters by its names (DwaConfig), each checked, with TurtleBot3's values. No ROS.

The local controller (tb3_navigation.controller) takes a DwaConfig; move_base
reads one from the parameter server under ~DWAPlannerROS/.
"""
from dataclasses import dataclass

from tb3_common.params import Checked, fail, non_negative, number, parameter, positive


def _no_sideways(value):
    return None if value == 0 else 'must be 0: a TurtleBot3 is a differential base (no sideways speed)'


@dataclass(frozen=True)
class DwaConfig(Checked):
    """dwa_local_planner's parameters: dwa_local_planner_params_burger.yaml (noetic), and
    dwa_local_planner's defaults for those it does not set. `live` ones are DWAPlanner.cfg's:
    dynamic_reconfigure changes them on a running node."""
    max_vel_x: float = parameter(0.22, 'm/s', non_negative, 'm/s', live=True)
    min_vel_x: float = parameter(-0.22, 'm/s: negative drives backwards (move_forward_only: 0)', None, 'm/s',
                                 live=True)
    max_vel_y: float = parameter(0.0, 'a differential base: 0', _no_sideways, 'm/s', live=True)
    min_vel_y: float = parameter(0.0, 'a differential base: 0', _no_sideways, 'm/s', live=True)
    max_vel_trans: float = parameter(0.22, 'm/s', positive, 'm/s', live=True)
    min_vel_trans: float = parameter(0.11, 'm/s: slower drives must turn at least min_vel_theta', non_negative, 'm/s',
                                     live=True)
    max_vel_theta: float = parameter(2.75, 'rad/s', positive, 'rad/s', live=True)
    min_vel_theta: float = parameter(1.37, 'rad/s: the slowest turn in place', non_negative, 'rad/s', live=True)
    acc_lim_x: float = parameter(2.5, 'm/s^2', non_negative, 'm/s^2', live=True)
    acc_lim_y: float = parameter(0.0, 'unused: a differential base has no y speed', non_negative, 'm/s^2', live=True)
    acc_lim_theta: float = parameter(3.2, 'rad/s^2', non_negative, 'rad/s^2', live=True)
    xy_goal_tolerance: float = parameter(0.05, 'm: the goal is reached this near (the controller aims at 0.3 of it)',
                                         non_negative, 'm', live=True)
    yaw_goal_tolerance: float = parameter(0.17, 'rad: and turned this near (aims at 0.3 of it)', non_negative, 'rad',
                                          live=True)
    latch_xy_goal_tolerance: bool = parameter(False, 'true: once near enough, only turn')
    sim_time: float = parameter(1.5, 's each sampled trajectory is simulated', positive, 's', live=True)
    sim_granularity: float = parameter(0.025, 'm between checks along a trajectory', positive, 'm', live=True)
    angular_sim_granularity: float = parameter(0.1, 'rad between checks along a turn', positive, 'rad', live=True)
    vx_samples: int = parameter(20, 'speeds sampled', number(1), live=True)
    vy_samples: int = parameter(0, 'unused: all y speeds are 0 on a differential base', non_negative, live=True)
    vth_samples: int = parameter(40, 'turn rates sampled', number(1), live=True)
    controller_frequency: float = parameter(10.0, 'Hz: the window of reachable speeds is one period of the '
                                                  'accelerations', positive, 'Hz')
    path_distance_bias: float = parameter(32.0, 'weight of staying on the global plan', non_negative, live=True)
    goal_distance_bias: float = parameter(20.0, 'weight of getting to the local goal', non_negative, live=True)
    occdist_scale: float = parameter(0.02, 'weight of keeping off obstacles', non_negative, live=True)
    obstacle_clearance: float = parameter(0.12, 'm (ours): trajectories keep this far from obstacles whenever one can',
                                          non_negative, 'm')
    forward_point_distance: float = parameter(0.325, 'm: the point ahead scored too', None, 'm', live=True)
    forward_point_scoring: bool = parameter(True, "ours: false scores a trajectory's end alone (turns in place by "
                                                  'the goal distance forward_point_distance ahead), as '
                                                  "base_local_planner's TrajectoryPlannerROS does")
    stop_time_buffer: float = parameter(0.2, 's: a trajectory must stop this long before an obstacle', non_negative,
                                        's', live=True)
    scaling_speed: float = parameter(0.25, 'm/s: above it the footprint is scaled up', non_negative, 'm/s', live=True)
    max_scaling_factor: float = parameter(0.2, 'up to 1 + this', non_negative, live=True)
    oscillation_reset_dist: float = parameter(0.05, 'm: moving this far resets the oscillation flags', non_negative,
                                              'm', live=True)
    oscillation_reset_angle: float = parameter(0.2, 'rad: turning this far resets them too', non_negative, 'rad',
                                               live=True)
    trans_stopped_vel: float = parameter(0.1, 'm/s: slower counts as stopped', non_negative, 'm/s', live=True)
    theta_stopped_vel: float = parameter(0.1, 'rad/s: slower counts as stopped', non_negative, 'rad/s', live=True)

    def check_together(self):
        if self.min_vel_x > self.max_vel_x:
            fail('min_vel_x', self.min_vel_x, 'must not exceed ~max_vel_x (%r)' % self.max_vel_x)

    @property
    def sim_period(self):
        return 1.0 / self.controller_frequency


#: dwa_local_planner_params_<model>.yaml where they differ from the Burger's.
MODELS = {'burger': {},
          'waffle': dict(max_vel_x=0.26, min_vel_x=-0.26, max_vel_trans=0.26, min_vel_trans=0.13,
                         max_vel_theta=1.82, min_vel_theta=0.9, sim_time=2.0)}
MODELS['waffle_pi'] = MODELS['waffle']


def dwa_config(model='burger', move_forward_only=False, **overrides):
    """TurtleBot3's DwaConfig for `model`; move_forward_only sets min_vel_x 0, as its move_base.launch."""
    if model not in MODELS:
        raise ValueError('model must be one of %s, not %r' % (', '.join(sorted(MODELS)), model))
    values = dict(MODELS[model], **({'min_vel_x': 0.0} if move_forward_only else {}))
    values.update(overrides)
    return DwaConfig(**values)
