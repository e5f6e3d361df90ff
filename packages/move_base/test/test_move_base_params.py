"""move_base reads its parameters where and as move_base, costmap_2d and the planners read them (no ROS).

The parameter server is faked by the tree a launch file's rosparam loads
make (move_base_param_trees.launch: move_base.settings.Parameters over a
dict): TurtleBot3's own files give TurtleBot3's values; the ROS wiki's
navigation tutorial and ROS by Example's TurtleBot files (TrajectoryPlannerROS,
robot_radius, frames written "/map", a 0.01 m costmap) are mapped onto this
node's planner, controller and costmaps; a value that cannot be honoured is
refused naming the parameter and the value; one taken without effect is named;
what dynamic_reconfigure may change carries the originals' names. The mapped
values driving the whole stack: test_move_base_params_drive.py.
"""
import math

import numpy as np
import pytest
import yaml
from move_base_param_trees import RBX1, WIKI, WIKI_COMMON, WIKI_GLOBAL, Recorder, launch, turtlebot3_files

from move_base import planners
from move_base.costmap_params import ObservationSource
from move_base.live import live_names
from move_base.settings import Parameters, resolve, trajectory_dwa
from tb3_common.params import ParameterError
from tb3_navigation.costmap import BURGER_FOOTPRINT, CostmapConfig
from tb3_navigation.dwa_config import DwaConfig, dwa_config
from tb3_navigation.footprint import circle_footprint, footprint_radii
from tb3_navigation.navigator import NavigatorConfig
from tb3_navigation.planner import PlannerConfig

# --- TurtleBot3's launch: its values, unchanged ------------------------------------------------

@pytest.mark.parametrize('params', [launch(*turtlebot3_files()), Parameters({})], ids=['files', 'nothing set'])
def test_turtlebot3s_files_and_no_files_give_turtlebot3s_values(params):
    record = Recorder()
    resolved = resolve(params, record)
    assert resolved.move_base.base_local_planner == planners.DWA and resolved.local_namespace == 'DWAPlannerROS'
    assert resolved.global_namespace == 'NavfnROS' and resolved.planner == PlannerConfig()
    assert resolved.dwa == dwa_config('burger') and resolved.trajectory is None
    assert resolved.navigator == NavigatorConfig()
    for settings in (resolved.global_costmap, resolved.local_costmap):
        assert settings.config == CostmapConfig() and settings.config.footprint == BURGER_FOOTPRINT
        assert settings.sources == (('scan', ObservationSource(topic='scan', sensor_frame='base_scan',
                                                               data_type='LaserScan', marking=True, clearing=True)),)
    ros = resolved.local_costmap.ros
    assert (ros.global_frame, ros.rolling_window, ros.width, ros.height, ros.resolution) == ('odom', True, 3, 3, 0.05)
    ros = resolved.global_costmap.ros
    assert (ros.global_frame, ros.robot_base_frame, ros.static_map, ros.update_frequency) == \
        ('map', 'base_footprint', True, 10.0)
    # Only the DWA's debugging clouds are named: TurtleBot3's file asks for them.
    assert {name: sorted(found) for name, found in record.unhonoured.items()} == \
        ({'DWAPlannerROS': ['publish_cost_grid_pc', 'publish_traj_pc']} if params.tree else {})
    assert resolved.notes == []


# --- the ROS wiki's tutorial and ROS by Example: TrajectoryPlannerROS, robot_radius, "/map" -----

def test_the_wiki_tutorial_runs_trajectory_planner_ros_by_its_names():
    resolved = resolve(launch(*WIKI, base_local_planner=planners.TRAJECTORY))
    assert resolved.local_namespace == 'TrajectoryPlannerROS'
    tpr, dwa = resolved.trajectory, resolved.dwa
    assert (tpr.max_vel_x, tpr.min_vel_x, tpr.max_vel_theta, tpr.min_vel_theta) == (0.45, 0.1, 1.0, -1.0)
    # The .cfg's defaults where the file sets nothing (noetic's server starts from them).
    assert (tpr.sim_time, tpr.vx_samples, tpr.path_distance_bias, tpr.goal_distance_bias) == (1.7, 20, 0.6, 0.8)
    assert (dwa.max_vel_x, dwa.max_vel_trans, dwa.min_vel_x, dwa.min_vel_trans) == (0.45, 0.45, 0.0, 0.1)
    assert (dwa.max_vel_theta, dwa.min_vel_theta, dwa.acc_lim_x, dwa.acc_lim_theta) == (1.0, 0.4, 2.5, 3.2)
    assert (dwa.xy_goal_tolerance, dwa.yaw_goal_tolerance, dwa.sim_time, dwa.vth_samples) == (0.10, 0.05, 1.7, 20)
    assert not dwa.forward_point_scoring and dwa.max_scaling_factor == 0.0
    assert dwa.trans_stopped_vel == dwa.theta_stopped_vel == 0.01
    # No meter_scoring: the biases count cells of the local costmap (0.05 m), DWA's count metres.
    assert dwa.path_distance_bias == pytest.approx(0.6 / 0.05) and dwa.goal_distance_bias == pytest.approx(0.8 / 0.05)
    assert resolved.global_costmap.ros.global_frame == 'map'
    assert resolved.local_costmap.ros.width == 6.0 and resolved.local_costmap.ros.publish_frequency == 2.0


def test_robot_radius_makes_costmap_2ds_16_corner_polygon():
    resolved = resolve(launch(*WIKI, base_local_planner=planners.TRAJECTORY))
    footprint = np.array(resolved.local_costmap.config.footprint)
    assert footprint.shape == (16, 2) and np.allclose(np.hypot(*footprint.T), 0.15)
    assert np.allclose(footprint[0], (0.15, 0.0)) and np.allclose(footprint[4], (0.0, 0.15))
    assert footprint == pytest.approx(np.array(circle_footprint(0.15)))
    inscribed, circumscribed = footprint_radii(resolved.local_costmap.config.padded_footprint)
    assert 0.15 < inscribed < circumscribed < 0.15 + 0.01 * math.sqrt(2) + 1e-9  # padded by 0.01, as padFootprint
    # A footprint wins over robot_radius; one set above both costmaps is found by both (searchParam).
    both = resolve(launch(*WIKI, footprint=[[-0.1, -0.1], [-0.1, 0.1], [0.1, 0.1], [0.1, -0.1]]))
    assert both.global_costmap.config.footprint == ((-0.1, -0.1), (-0.1, 0.1), (0.1, 0.1), (0.1, -0.1))
    given = launch(*turtlebot3_files())
    given.tree['global_costmap'].update(footprint='[[-0.2, -0.1], [-0.2, 0.1], [0.05, 0.1], [0.05, -0.1]]')
    assert resolve(given).global_costmap.config.footprint[0] == (-0.2, -0.1)  # a string, as costmap_2d reads it


def test_ros_by_examples_turtlebot_files_run_as_written():
    record = Recorder()
    resolved = resolve(launch(*RBX1), record)
    # No base_local_planner: move_base's default, TrajectoryPlannerROS, whose parameters it gives.
    assert resolved.local_namespace == 'TrajectoryPlannerROS'
    assert any('base_local_planner unset' in note for note in resolved.notes)
    dwa, navigator = resolved.dwa, resolved.navigator
    assert navigator.controller_frequency == dwa.controller_frequency == 3.0  # found upwards, as searchParam
    assert not navigator.recovery_behavior_enabled and not navigator.clearing_rotation_allowed
    # pdist_scale and gdist_scale, the old names; meter_scoring: per metre as DWA's.
    assert (dwa.path_distance_bias, dwa.goal_distance_bias, dwa.occdist_scale) == (0.8, 0.6, 0.1)
    assert (dwa.min_vel_trans, dwa.min_vel_theta, dwa.xy_goal_tolerance) == (0.05, 0.5, 0.1)
    # Frames written with a leading "/"; the global costmap's resolution is the map's (a static map).
    assert (resolved.global_costmap.ros.global_frame, resolved.local_costmap.ros.global_frame,
            resolved.local_costmap.ros.robot_base_frame) == ('map', 'odom', 'base_footprint')
    assert resolved.local_costmap.ros.resolution == 0.01
    assert resolved.local_costmap.sources[0][1].topic == '/scan'
    # rotate_recovery reads its limits under TrajectoryPlannerROS.
    assert (resolved.rotation.min_in_place_vel_theta, resolved.rotation.yaw_goal_tolerance) == (0.5, 0.1)
    # Named: what TrajectoryPlannerROS and costmap_2d would do with them and this node does not.
    assert sorted(record.unhonoured['TrajectoryPlannerROS']) == ['escape_vel', 'prune_plan']
    assert sorted(record.unhonoured['local_costmap']) == ['max_obstacle_height']
    assert 'local_costmap/scan' not in record.unhonoured  # expected_update_rate 0: what this node does


def test_a_planner_setting_only_what_it_needs_is_named_once():
    record = Recorder()
    params = launch(*WIKI, base_local_planner=planners.TRAJECTORY, base_global_planner=planners.GLOBAL_PLANNER)
    params.tree['GlobalPlanner'] = dict(use_dijkstra=False, orientation_mode=2)
    params.tree['TrajectoryPlannerROS'].update(dwa=False, path_distance_bias=1.5, pdist_scale=0.1)
    resolved = resolve(params, record)
    assert resolved.trajectory.path_distance_bias == 1.5  # the new name wins over the old
    assert (resolved.planner.cost_factor, resolved.planner.lethal_cost, resolved.planner.orientation_mode,
            resolved.planner.orientation_window_size) == (3.0, 253, 2, 1)  # global_planner's own defaults
    assert set(record.unhonoured) == {'GlobalPlanner', 'TrajectoryPlannerROS'}
    assert list(record.unhonoured['GlobalPlanner']) == ['use_dijkstra']
    assert list(record.unhonoured['TrajectoryPlannerROS']) == ['dwa']
    assert 'trajectory rollout' in record.unhonoured['TrajectoryPlannerROS']['dwa']


def test_different_turn_limits_either_way_are_taken_as_the_slower_and_said():
    params = launch(*WIKI, base_local_planner=planners.TRAJECTORY)
    params.tree['TrajectoryPlannerROS'].update(max_vel_theta=2.0, min_vel_theta=-1.5)
    resolved = resolve(params)
    assert resolved.dwa.max_vel_theta == 1.5
    assert any('both ways turn at most 1.5' in note for note in resolved.notes)


def test_recovery_behaviors_of_move_base_are_taken_by_their_types():
    params = launch(*turtlebot3_files(), recovery_behaviors=[
        {'name': 'conservative_reset', 'type': 'clear_costmap_recovery/ClearCostmapRecovery'},
        {'name': 'rotate_recovery', 'type': 'rotate_recovery/RotateRecovery'},
        {'name': 'aggressive_reset', 'type': 'clear_costmap_recovery/ClearCostmapRecovery'}])
    assert resolve(params).navigator.recovery_behaviors == ('conservative_reset', 'rotate_recovery',
                                                            'aggressive_reset')


# --- refused: the parameter and the value named -----------------------------------------------

def tpr(**values):
    return ('', yaml.safe_dump({'base_local_planner': planners.TRAJECTORY, 'TrajectoryPlannerROS': values}))


@pytest.mark.parametrize('loads, message', [
    ([('', 'base_local_planner: teb_local_planner/TebLocalPlannerROS')],
     "~base_local_planner = 'teb_local_planner/TebLocalPlannerROS': must be one of: "
     'dwa_local_planner/DWAPlannerROS, base_local_planner/TrajectoryPlannerROS'),
    ([('', 'base_global_planner: carrot_planner/CarrotPlanner')], "~base_global_planner = 'carrot_planner/"),
    ([tpr(holonomic_robot=True)], '~TrajectoryPlannerROS/holonomic_robot = True: must be false: a TurtleBot3 is '
                                  'a differential base'),
    ([tpr(max_vel_x=-0.1)], '~TrajectoryPlannerROS/max_vel_x = -0.1: must be > 0'),
    ([tpr(max_vel_x=0.2, min_vel_x=0.3)], '~TrajectoryPlannerROS/min_vel_x = 0.3: must not exceed ~max_vel_x'),
    ([tpr(vtheta_samples=2.5)], '~TrajectoryPlannerROS/vtheta_samples = 2.5: must be a whole number'),
    ([('', 'DWAPlannerROS: {max_vel_y: 0.1}')], '~DWAPlannerROS/max_vel_y = 0.1: must be 0'),
    ([('', 'NavfnROS: {default_tolerance: -1}')], '~NavfnROS/default_tolerance = -1: must be >= 0'),
    ([('', 'base_global_planner: global_planner/GlobalPlanner\nGlobalPlanner: {lethal_cost: 300}')],
     '~GlobalPlanner/lethal_cost = 300: must be between 1 and 255'),
    ([('global_costmap', 'robot_radius: -0.2')], '~global_costmap/robot_radius = -0.2: must be > 0'),
    ([('global_costmap', "footprint: '[[0, 0], [1'")], "~global_costmap/footprint = '[[0, 0], [1': must be a list"),
    ([('global_costmap', 'footprint: [[0, 0], [1, 0]]')], '~global_costmap/footprint = [[0, 0], [1, 0]]: must be '
                                                          'a list of at least 3'),
    ([('local_costmap', 'observation_sources: cloud\ncloud: {data_type: PointCloud2, topic: points}')],
     "~local_costmap/cloud/data_type = 'PointCloud2': must be LaserScan"),
    ([('local_costmap', 'observation_sources: laser\nlaser: {topic: scan}')],
     "~local_costmap/laser/data_type = 'PointCloud': must be LaserScan"),  # costmap_2d's default data_type
    ([('local_costmap', 'resolution: 0')], '~local_costmap/resolution = 0: must be > 0'),
    ([('local_costmap', 'map_type: octomap')], "~local_costmap/map_type = 'octomap': must be one of: costmap, voxel"),
    ([('global_costmap', 'global_frame: my map')], "~global_costmap/global_frame = 'my map': must be a frame id"),
    ([('', 'rotate_recovery: {sim_granularity: 0}')], '~rotate_recovery/sim_granularity = 0: must be > 0'),
    ([('', 'TrajectoryPlannerROS: {acc_lim_th: -1}')], '~TrajectoryPlannerROS/acc_lim_theta = -1: must be > 0'),
    ([('', 'recovery_behaviors: [{name: slow, type: move_slow_and_clear/MoveSlowAndClear}]')],
     "~recovery_behaviors = ('slow (move_slow_and_clear/MoveSlowAndClear)',): unknown behaviour"),
])
def test_a_value_that_cannot_be_honoured_is_refused_naming_it(loads, message):
    with pytest.raises(ParameterError) as raised:
        resolve(launch(*loads))
    assert str(raised.value).startswith('parameter ' + message), str(raised.value)


def test_the_wiki_tutorials_point_cloud_source_is_refused():
    common = WIKI_COMMON.replace('observation_sources: laser_scan_sensor',
                                 'observation_sources: laser_scan_sensor point_cloud_sensor')
    common += 'point_cloud_sensor: {sensor_frame: camera, data_type: PointCloud, topic: points, marking: true}\n'
    with pytest.raises(ParameterError, match="~global_costmap/point_cloud_sensor/data_type = 'PointCloud'"):
        resolve(launch(('global_costmap', common), ('local_costmap', common), ('', WIKI_GLOBAL)))


# --- live: what dynamic_reconfigure may change, by the originals' names ------------------------

#: The originals' .cfg names (dwa_local_planner's DWAPlanner.cfg with LocalPlannerLimits.cfg,
#: base_local_planner's BaseLocalPlanner.cfg, costmap_2d's InflationPlugin.cfg, noetic).
DWA_CFG = {'max_vel_trans', 'min_vel_trans', 'max_vel_x', 'min_vel_x', 'max_vel_y', 'min_vel_y', 'max_vel_theta',
           'min_vel_theta', 'acc_lim_x', 'acc_lim_y', 'acc_lim_theta', 'acc_lim_trans', 'prune_plan',
           'xy_goal_tolerance', 'yaw_goal_tolerance', 'trans_stopped_vel', 'theta_stopped_vel', 'sim_time',
           'sim_granularity', 'angular_sim_granularity', 'path_distance_bias', 'goal_distance_bias', 'occdist_scale',
           'twirling_scale', 'stop_time_buffer', 'oscillation_reset_dist', 'oscillation_reset_angle',
           'forward_point_distance', 'scaling_speed', 'max_scaling_factor', 'vx_samples', 'vy_samples',
           'vth_samples', 'use_dwa', 'restore_defaults'}
TRAJECTORY_CFG = {'acc_lim_x', 'acc_lim_y', 'acc_lim_theta', 'max_vel_x', 'min_vel_x', 'max_vel_theta',
                  'min_vel_theta', 'min_in_place_vel_theta', 'sim_time', 'sim_granularity', 'angular_sim_granularity',
                  'path_distance_bias', 'goal_distance_bias', 'occdist_scale', 'oscillation_reset_dist',
                  'escape_reset_dist', 'escape_reset_theta', 'vx_samples', 'vtheta_samples', 'heading_lookahead',
                  'holonomic_robot', 'escape_vel', 'dwa', 'heading_scoring', 'heading_scoring_timestep',
                  'simple_attractor', 'y_vels', 'restore_defaults'}
INFLATION_CFG = {'enabled', 'cost_scaling_factor', 'inflation_radius', 'inflate_unknown'}


def test_live_parameters_carry_the_originals_names():
    assert set(live_names(DwaConfig)) <= DWA_CFG and len(live_names(DwaConfig)) == 30
    assert set(live_names(planners.TrajectoryPlannerConfig)) <= TRAJECTORY_CFG
    assert 'max_vel_x' in live_names(planners.TrajectoryPlannerConfig)
    assert set(live_names(CostmapConfig)) == {'inflation_radius', 'cost_scaling_factor', 'inflate_unknown'}
    assert set(live_names(CostmapConfig)) <= INFLATION_CFG
    # Unhonoured names are the original's too, never fields here.
    assert not set(planners.DWA_UNHONOURED) & set(f for f in live_names(DwaConfig))
    assert set(planners.TRAJECTORY_UNHONOURED) - {'prune_plan', 'publish_cost_grid_pc', 'world_model'} <= \
        TRAJECTORY_CFG


def test_a_live_change_maps_as_at_start_and_a_bad_one_is_refused():
    resolved = resolve(launch(*RBX1))
    slower = resolved.trajectory.replace(max_vel_x=0.1)
    dwa = trajectory_dwa(slower, 0.01, 3.0, {})
    assert dwa.max_vel_x == dwa.max_vel_trans == 0.1 and dwa.path_distance_bias == 0.8
    for change in (dict(max_vel_x=-1.0), dict(min_vel_x=0.5), dict(holonomic_robot=True), dict(sim_time=math.nan)):
        with pytest.raises(ParameterError, match='~%s = ' % list(change)[0]):
            resolved.trajectory.replace(**change)
    with pytest.raises(ParameterError, match='~inflation_radius = -0.1'):
        resolved.local_costmap.config.replace(inflation_radius=-0.1)
