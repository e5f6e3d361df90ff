"""amcl takes every parameter amcl's node reads, as it reads them, and its live ones by AMCL.cfg's names (no ROS).

The parameter server is faked by the dict a launch file's <param> lines
make (rospy's get_param('~') gives the node the same).
"""
import math

import numpy as np
import pytest

from amcl.config import (
    HARMLESS,
    LIVE,
    MODEL,
    UNHONOURED,
    AmclNodeConfig,
    amcl_values,
    changed,
    live_fields,
    node_values,
    reconfigured,
    unhonoured,
)
from tb3_common.params import ParameterError
from tb3_harness import nav_sim
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import Amcl
from tb3_sim_nav import world_map

#: Every parameter amcl's node reads (ros-planning/navigation noetic, amcl/src/amcl_node.cpp).
AMCL_NODE = ('bag_scan_period', 'base_frame_id', 'beam_skip_distance', 'beam_skip_error_threshold',
             'beam_skip_threshold', 'do_beamskip', 'first_map_only', 'force_update_after_initialpose',
             'force_update_after_set_map', 'global_frame_id', 'gui_publish_rate', 'initial_cov_aa', 'initial_cov_xx',
             'initial_cov_yy', 'initial_pose_a', 'initial_pose_x', 'initial_pose_y', 'kld_err', 'kld_z',
             'laser_lambda_short', 'laser_likelihood_max_dist', 'laser_max_beams', 'laser_max_range',
             'laser_min_range', 'laser_model_type', 'laser_sigma_hit', 'laser_z_hit', 'laser_z_max', 'laser_z_rand',
             'laser_z_short', 'max_particles', 'min_particles', 'odom_alpha1', 'odom_alpha2', 'odom_alpha3',
             'odom_alpha4', 'odom_alpha5', 'odom_frame_id', 'odom_model_type', 'recovery_alpha_fast',
             'recovery_alpha_slow', 'resample_interval', 'save_pose_rate', 'selective_resampling',
             'std_warn_level_x', 'std_warn_level_y', 'std_warn_level_yaw', 'tf_broadcast', 'transform_tolerance',
             'update_min_a', 'update_min_d', 'use_map_topic')
#: AMCL.cfg's parameters (noetic), restore_defaults aside.
AMCL_CFG = ('min_particles', 'max_particles', 'kld_err', 'kld_z', 'update_min_d', 'update_min_a', 'resample_interval',
            'transform_tolerance', 'recovery_alpha_slow', 'recovery_alpha_fast', 'do_beamskip', 'beam_skip_distance',
            'beam_skip_threshold', 'tf_broadcast', 'force_update_after_initialpose', 'force_update_after_set_map',
            'gui_publish_rate', 'save_pose_rate', 'use_map_topic', 'first_map_only', 'laser_min_range',
            'laser_max_range', 'laser_max_beams', 'laser_z_hit', 'laser_z_short', 'laser_z_max', 'laser_z_rand',
            'laser_sigma_hit', 'laser_lambda_short', 'laser_likelihood_max_dist', 'laser_model_type',
            'odom_model_type', 'odom_alpha1', 'odom_alpha2', 'odom_alpha3', 'odom_alpha4', 'odom_alpha5',
            'odom_frame_id', 'base_frame_id', 'global_frame_id')
#: ROS by Example's tb_amcl.launch's values (rbx1 indigo-devel), frames written as ROS 1 launch files did.
RBX1 = dict(use_map_topic=False, odom_model_type='diff', odom_alpha5=0.1, gui_publish_rate=10.0, laser_max_beams=60,
            laser_max_range=12.0, min_particles=500, max_particles=2000, kld_err=0.05, kld_z=0.99, odom_alpha1=0.2,
            odom_alpha2=0.2, odom_alpha3=0.2, odom_alpha4=0.2, laser_z_hit=0.5, laser_z_short=0.05, laser_z_max=0.05,
            laser_z_rand=0.5, laser_sigma_hit=0.2, laser_lambda_short=0.1, laser_model_type='likelihood_field',
            laser_likelihood_max_dist=2.0, update_min_d=0.25, update_min_a=0.2, odom_frame_id='/odom',
            resample_interval=1, transform_tolerance=1.0, recovery_alpha_slow=0.0, recovery_alpha_fast=0.0)
FRAMES = dict(odom_frame_id='odom', base_frame_id='base_footprint', global_frame_id='map')


def read(tree, frames=FRAMES):
    return AmclConfig(**amcl_values(tree, frames)), AmclNodeConfig(**node_values(tree)), unhonoured(tree)


def test_every_parameter_of_amcls_node_is_taken_once():
    fields = lambda cls: set(cls.__dataclass_fields__)  # noqa: E731
    groups = [fields(AmclConfig), fields(AmclNodeConfig), set(UNHONOURED)]
    for name in AMCL_NODE:
        assert sum(name in group for group in groups) == 1, name
    assert fields(AmclConfig) - set(AMCL_NODE) == {'refine_estimate'}  # ours
    assert fields(AmclNodeConfig) - set(AMCL_NODE) == {'seed'}         # ours


def test_ros_by_examples_amcl_launch_is_taken_as_written():
    config, node, named = read(RBX1)
    assert (config.min_particles, config.max_particles, config.kld_err, config.laser_max_beams) == (500, 2000, 0.05, 60)
    assert (config.update_min_d, config.transform_tolerance, config.gui_publish_rate) == (0.25, 1.0, 10.0)
    assert config.odom_alphas == (0.2, 0.2, 0.2, 0.2)
    assert (config.odom_frame_id, config.base_frame_id, config.global_frame_id) == ('odom', 'base_footprint', 'map')
    assert not node.use_map_topic and node.save_pose_rate == 0.5
    assert list(named) == ['odom_alpha5'] and 'omni' in named['odom_alpha5']


def test_turtlebot3s_values_hold_where_nothing_is_set_and_frames_follow_the_namespace():
    config, node, named = read({}, dict(odom_frame_id='tb3_0/odom', base_frame_id='tb3_0/base_footprint',
                                        global_frame_id='map'))
    assert config == AmclConfig(odom_frame_id='tb3_0/odom', base_frame_id='tb3_0/base_footprint')
    assert node == AmclNodeConfig() and named == {}
    assert read(dict(base_frame_id='/base_link'))[0].base_frame_id == 'base_link'  # set: taken, slash dropped


def test_settings_that_do_what_this_node_does_are_not_named():
    assert read(dict(do_beamskip=False, selective_resampling=False))[2] == {}
    assert set(read(dict(do_beamskip=True, beam_skip_distance=0.5))[2]) == {'do_beamskip', 'beam_skip_distance'}
    assert set(HARMLESS) <= set(UNHONOURED)


@pytest.mark.parametrize('name, value, problem', [
    ('min_particles', 0, 'must be >= 1'), ('laser_model_type', 'beam', 'must be one of: likelihood_field'),
    ('odom_model_type', 'omni', 'must be one of: diff, diff-corrected'), ('kld_err', -0.1, 'must be'),
    ('laser_max_beams', 30.5, 'must be a whole number'), ('save_pose_rate', 'often', 'must be a number'),
    ('use_map_topic', 'yes', 'must be true or false'), ('base_frame_id', 'base link', 'frame id'),
    ('seed', -2, 'must be >= -1')])
def test_a_bad_value_is_refused_naming_it(name, value, problem):
    with pytest.raises(ParameterError) as raised:
        read({name: value})
    assert str(raised.value).startswith('parameter ~%s = %r: ' % (name, value)) and problem in str(raised.value)
    with pytest.raises(ParameterError, match=r'~max_particles = 100: must be >= min_particles \(500\)'):
        read(dict(max_particles=100))


def test_live_parameters_are_amcl_cfgs():
    names = [field.name for _, field in live_fields()]
    assert set(names) <= set(AMCL_CFG) and len(names) == len(set(names))
    # Every AMCL.cfg parameter this node honours is live, but where the map comes from.
    honoured = set(AmclConfig.__dataclass_fields__) | set(AmclNodeConfig.__dataclass_fields__)
    assert set(AMCL_CFG) & honoured - set(names) == {'use_map_topic', 'first_map_only'}
    assert set(MODEL) <= set(LIVE)


def test_a_live_change_is_checked_and_says_whether_the_laser_model_changed():
    config, node, _ = read(RBX1)
    values = dict((field.name, getattr(config if cls is AmclConfig else node, field.name)) for cls, field in
                  live_fields())
    same = changed(config, node, values)
    assert same[:3] == (config, node, {}) and not same[3]
    new, new_node, changes, model = changed(config, node, dict(values, update_min_d=0.1, save_pose_rate=0.0))
    assert (new.update_min_d, new_node.save_pose_rate, changes, model) == \
        (0.1, 0.0, {'update_min_d': 0.1, 'save_pose_rate': 0.0}, False)
    assert changed(config, node, dict(values, laser_sigma_hit=0.1))[3]
    for bad, named in ((dict(laser_max_beams=-1), 'laser_max_beams'), (dict(min_particles=5000), 'max_particles'),
                       (dict(odom_model_type='omni'), 'odom_model_type')):
        with pytest.raises(ParameterError, match='~%s = ' % named):
            changed(config, node, dict(values, **bad))


@pytest.fixture(scope='module')
def world():
    obstacles = nav_sim.world_cut()
    grid, values = world_map.map_of_world(obstacles)
    return obstacles, grid, values


def test_a_new_laser_model_makes_the_filter_anew_around_its_estimate_and_other_changes_keep_it(world):
    obstacles, grid, values = world
    pose = (-2.0, -0.5, 0.0)
    config = AmclConfig(initial_pose_x=pose[0], initial_pose_y=pose[1], min_particles=200, max_particles=500)
    amcl = Amcl(config, grid, values, seed=3)
    lidar = nav_sim.Lidar(obstacles)
    for _ in range(3):
        amcl.request_nomotion_update()
        assert amcl.update((0.0, 0.0, 0.0), lidar.scan(pose), nav_sim.SCAN_POSE)
    before = amcl.estimate()
    kept = reconfigured(amcl, config.replace(update_min_d=0.1), False, grid, values)
    assert kept is amcl and kept.config.update_min_d == 0.1 and kept.estimate() == before
    fresh = reconfigured(amcl, config.replace(laser_sigma_hit=0.1), True, grid, values, seed=4)
    assert fresh is not amcl and fresh.model.sigma_hit == 0.1 and len(fresh.particles) == 500
    assert math.hypot(*(np.array(fresh.estimate().pose[:2]) - before.pose[:2])) < 0.05
