"""The planners move_base may be asked for, and how each one's parameters map onto this node's. No ROS here.

`~base_local_planner`:

- dwa_local_planner/DWAPlannerROS (TurtleBot3's): tb3_navigation's DWA,
  reading `~DWAPlannerROS/` by dwa_local_planner's names (DwaConfig);
- base_local_planner/TrajectoryPlannerROS (the ROS wiki's navigation
  tutorials, ROS by Example): the same controller, reading
  `~TrajectoryPlannerROS/` by base_local_planner's names
  (TrajectoryPlannerConfig), mapped by `dwa_of_trajectory_planner`.

`~base_global_planner`: navfn/NavfnROS (`~NavfnROS/`) or
global_planner/GlobalPlanner (`~GlobalPlanner/`), both tb3_navigation's
planner (PlannerConfig) with the planner's own defaults.

Each has UNHONOURED parameters, {name: why}: the original reads them, this
node takes them without effect, and says so at start when one is set to a
value other than its HARMLESS one (the value that does what this node does).
"""
import dataclasses

from tb3_common.params import Checked, fail, non_negative, number, parameter, positive

DWA, TRAJECTORY = 'dwa_local_planner/DWAPlannerROS', 'base_local_planner/TrajectoryPlannerROS'
NAVFN, GLOBAL_PLANNER = 'navfn/NavfnROS', 'global_planner/GlobalPlanner'
LOCAL_PLANNERS, GLOBAL_PLANNERS = (DWA, TRAJECTORY), (NAVFN, GLOBAL_PLANNER)


def namespace_of(planner):
    """The parameter namespace (and topic prefix) of a planner: its class name, as move_base loads it."""
    return planner.rsplit('/', 1)[-1]


def _differential(value):
    return "must be false: a TurtleBot3 is a differential base (it cannot drive sideways)" if value else None


@dataclasses.dataclass(frozen=True)
class TrajectoryPlannerConfig(Checked):
    """base_local_planner's TrajectoryPlannerROS parameters as noetic takes them: those of its
    BaseLocalPlanner.cfg with the .cfg's defaults (its dynamic_reconfigure server starts from them and
    overrides what initialize() read), the rest with initialize()'s. `live` ones are the .cfg's."""
    max_vel_x: float = parameter(0.55, 'm/s: the fastest forward speed', positive, 'm/s', live=True)
    min_vel_x: float = parameter(0.0, 'm/s: the slowest forward speed of a trajectory that drives', non_negative,
                                 'm/s', live=True)
    max_vel_theta: float = parameter(1.0, 'rad/s: the fastest turn to the left', non_negative, 'rad/s', live=True)
    min_vel_theta: float = parameter(-1.0, 'rad/s: the fastest turn to the right (negative)', number(high=0.0),
                                     'rad/s', live=True)
    min_in_place_vel_theta: float = parameter(0.4, 'rad/s: the slowest turn in place', non_negative, 'rad/s',
                                              live=True)
    acc_lim_x: float = parameter(2.5, 'm/s^2', non_negative, 'm/s^2', live=True)
    acc_lim_theta: float = parameter(3.2, 'rad/s^2', non_negative, 'rad/s^2', live=True)
    holonomic_robot: bool = parameter(False, 'true is refused here (the original\'s default: a TurtleBot3 cannot '
                                             'strafe)', _differential, live=True)
    xy_goal_tolerance: float = parameter(0.10, 'm: the goal is reached this near', non_negative, 'm')
    yaw_goal_tolerance: float = parameter(0.05, 'rad: and turned this near', non_negative, 'rad')
    latch_xy_goal_tolerance: bool = parameter(False, 'true: once near enough, only turn')
    sim_time: float = parameter(1.7, 's each sampled trajectory is simulated', positive, 's', live=True)
    sim_granularity: float = parameter(0.025, 'm between checks along a trajectory', positive, 'm', live=True)
    angular_sim_granularity: float = parameter(0.025, 'rad between checks along a turn', positive, 'rad', live=True)
    vx_samples: int = parameter(20, 'speeds sampled', number(1), live=True)
    vtheta_samples: int = parameter(20, 'turn rates sampled', number(1), live=True)
    path_distance_bias: float = parameter(0.6, 'weight of staying on the global plan (pdist_scale, its old name)',
                                          non_negative, live=True)
    goal_distance_bias: float = parameter(0.8, 'weight of getting to the local goal (gdist_scale)', non_negative,
                                          live=True)
    occdist_scale: float = parameter(0.01, 'weight of keeping off obstacles', non_negative, live=True)
    heading_lookahead: float = parameter(0.325, 'm: of the turns in place, the one facing a point this far ahead '
                                               'nearest the goal wins', non_negative, 'm', live=True)
    meter_scoring: bool = parameter(False, "true: the two biases are per metre, false: per cell of the local "
                                           "costmap (unset, the original's is undefined: false here)")
    oscillation_reset_dist: float = parameter(0.05, 'm: moving this far resets the oscillation flags', non_negative,
                                              'm', live=True)
    stop_time_buffer: float = parameter(0.2, 's: read and ignored, as the original ignores it', non_negative, 's')

    def check_together(self):
        if self.min_vel_x > self.max_vel_x:
            fail('min_vel_x', self.min_vel_x, 'must not exceed ~max_vel_x (%r)' % self.max_vel_x)


#: TrajectoryPlannerROS's deprecated names still read: the new name -> the old.
TRAJECTORY_RENAMED = {'path_distance_bias': 'pdist_scale', 'goal_distance_bias': 'gdist_scale'}
#: base_local_planner's stopped speeds (trans_stopped_velocity_, rot_stopped_velocity_).
TRAJECTORY_STOPPED = 1e-2

_ESCAPE = ('no escape manoeuvre here: with no valid trajectory the robot stops and move_base plans anew, '
           'then recovers')
_CLOUD = 'its debugging point cloud is not published here'
TRAJECTORY_UNHONOURED = {
    'dwa': 'false asks for trajectory rollout (velocities reachable within sim_time, trajectories that '
           'accelerate); the window here is always one controller period, as with dwa: true',
    'escape_vel': _ESCAPE, 'escape_reset_dist': _ESCAPE, 'escape_reset_theta': _ESCAPE,
    'heading_scoring': 'true scores the heading towards the plan; not here',
    'simple_attractor': 'true scores the straight distance to the goal; not here',
    'prune_plan': 'the plan is not pruned behind the robot; it is made anew from the robot at planner_frequency',
    'publish_cost_grid_pc': _CLOUD, 'world_model': 'the costmap is the only world model, as in noetic',
}
TRAJECTORY_HARMLESS = {'dwa': True, 'heading_scoring': False, 'simple_attractor': False, 'prune_plan': False,
                       'publish_cost_grid_pc': False, 'world_model': 'costmap'}

DWA_UNHONOURED = {
    'use_dwa': 'false asks for velocities reachable within sim_time; the window here is always one period',
    'prune_plan': TRAJECTORY_UNHONOURED['prune_plan'],
    'twirling_scale': 'no twirling critic here', 'acc_lim_trans': 'the speed is limited by acc_lim_x alone',
    'publish_traj_pc': _CLOUD, 'publish_cost_grid_pc': _CLOUD, 'global_frame_id': _CLOUD,
    'sum_scores': "the critics' costs are summed here", 'cheat_factor': 'no cheat factor here',
}
DWA_HARMLESS = {'use_dwa': True, 'prune_plan': False, 'twirling_scale': 0.0, 'publish_traj_pc': False,
                'publish_cost_grid_pc': False, 'sum_scores': True}

#: global_planner's defaults (GlobalPlanner.cfg) where they differ from navfn's (PlannerConfig's).
GLOBAL_PLANNER_DEFAULTS = dict(cost_factor=3.0, lethal_cost=253, orientation_window_size=1)
_SAME_PLAN = 'the plan here is always the cheapest path from cell to neighbour cell'
_NOT_PUBLISHED = "the planner's potential is not published here"
GLOBAL_UNHONOURED = {
    NAVFN: {'visualize_potential': _NOT_PUBLISHED,
            'planner_window_x': 'the search always spans the whole costmap',
            'planner_window_y': 'the search always spans the whole costmap'},
    GLOBAL_PLANNER: {'use_dijkstra': _SAME_PLAN, 'use_quadratic': _SAME_PLAN, 'use_grid_path': _SAME_PLAN,
                     'old_navfn_behavior': _SAME_PLAN, 'publish_potential': _NOT_PUBLISHED,
                     'publish_scale': _NOT_PUBLISHED, 'outline_map': 'the costmap\'s edge is not made lethal here',
                     'planner_window_x': 'the search always spans the whole costmap',
                     'planner_window_y': 'the search always spans the whole costmap'}}
GLOBAL_HARMLESS = {'visualize_potential': False, 'publish_potential': False, 'planner_window_x': 0.0,
                   'planner_window_y': 0.0, 'use_dijkstra': True, 'use_grid_path': True,
                   'old_navfn_behavior': False}


def turn_limit(config):
    """(rad/s the controller turns at most either way, a note if the two limits differ): DWA turns
    as fast both ways, TrajectoryPlannerROS from min_vel_theta to max_vel_theta; the slower wins."""
    limit = min(config.max_vel_theta, -config.min_vel_theta)
    if config.max_vel_theta == -config.min_vel_theta:
        return limit, None
    return limit, ('~TrajectoryPlannerROS/min_vel_theta %r and max_vel_theta %r differ: both ways turn at most '
                   '%r rad/s here' % (config.min_vel_theta, config.max_vel_theta, limit))


def dwa_of_trajectory_planner(config, resolution, controller_frequency, **ours):
    """The DwaConfig values (a dict) that drive as TrajectoryPlannerROS with `config` would, on a
    local costmap of `resolution` m: never backwards (the original backs up only to escape);
    forward trajectories at least min_vel_x, turns in place at least min_in_place_vel_theta; the
    biases scaled as base_local_planner scales them (per metre with meter_scoring, else per cell:
    DWA's are per metre); its trajectory's end alone scored, turns in place told apart by the goal
    distance heading_lookahead ahead (forward_point_distance, without forward-point scoring); no footprint
    scaling; stopped below 0.01 m/s and rad/s; no
    obstacle_clearance of ours unless `ours` asks for one (with a round footprint, whose inscribed
    radius exceeds it, every step into a gap counted as too close and the robot turned in place
    before the pillars until oscillation_timeout). `ours` pass through."""
    per = 1.0 if config.meter_scoring else 1.0 / resolution
    return dict(
        max_vel_x=config.max_vel_x, max_vel_trans=config.max_vel_x, min_vel_x=0.0, min_vel_trans=config.min_vel_x,
        max_vel_theta=turn_limit(config)[0], min_vel_theta=config.min_in_place_vel_theta,
        acc_lim_x=config.acc_lim_x, acc_lim_theta=config.acc_lim_theta,
        xy_goal_tolerance=config.xy_goal_tolerance, yaw_goal_tolerance=config.yaw_goal_tolerance,
        latch_xy_goal_tolerance=config.latch_xy_goal_tolerance, sim_time=config.sim_time,
        sim_granularity=config.sim_granularity, angular_sim_granularity=config.angular_sim_granularity,
        vx_samples=config.vx_samples, vth_samples=config.vtheta_samples, controller_frequency=controller_frequency,
        path_distance_bias=config.path_distance_bias * per, goal_distance_bias=config.goal_distance_bias * per,
        occdist_scale=config.occdist_scale, forward_point_scoring=False,
        forward_point_distance=config.heading_lookahead, max_scaling_factor=0.0,
        oscillation_reset_dist=config.oscillation_reset_dist,
        stop_time_buffer=config.stop_time_buffer, trans_stopped_vel=TRAJECTORY_STOPPED,
        theta_stopped_vel=TRAJECTORY_STOPPED, **dict(dict(obstacle_clearance=0.0), **ours))
