"""The node takes every parameter slam_gmapping takes: honoured (SlamConfig, NodeConfig) or named as meaning nothing."""
import dataclasses

import pytest

from gmapping.config import METHODS, UNHONOURED, NodeConfig
from tb3_common.params import ParameterError
from tb3_navigation.slam_config import SlamConfig

#: Every parameter ros-perception/slam_gmapping 1.4.2 (Noetic's) reads in gmapping/src/slam_gmapping.cpp.
WRAPPER = ('throttle_scans', 'base_frame', 'map_frame', 'odom_frame', 'transform_publish_period',
           'map_update_interval', 'tf_delay')
GMAPPING = ('minimumScore', 'sigma', 'kernelSize', 'lstep', 'astep', 'iterations', 'lsigma', 'ogain', 'lskip',
            'srr', 'srt', 'str', 'stt', 'linearUpdate', 'angularUpdate', 'temporalUpdate', 'resampleThreshold',
            'particles', 'xmin', 'ymin', 'xmax', 'ymax', 'delta', 'occ_thresh', 'llsamplerange', 'llsamplestep',
            'lasamplerange', 'lasamplestep', 'maxRange', 'maxUrange')
#: Ours, beside gmapping's: the matcher's reach and pull, jumps, turtlebot3_slam's method; loop closure's,
#: the first four under slam_toolbox's names.
OURS = {'odom_weight', 'search_linear', 'search_angular', 'jump_distance', 'jump_angle', 'slam_methods',
        'do_loop_closing', 'loop_search_maximum_distance', 'loop_match_minimum_chain_size',
        'loop_match_minimum_response_fine', 'loop_search_linear', 'loop_search_angular'}


def names(config_class):
    return {field.name for field in dataclasses.fields(config_class)}


def test_every_parameter_of_slam_gmapping_is_taken_once():
    taken = [names(SlamConfig), names(NodeConfig), set(UNHONOURED)]
    for name in WRAPPER + GMAPPING:
        assert sum(name in group for group in taken) == 1, name
    assert len(WRAPPER + GMAPPING) == 37


def test_only_the_particle_filters_parameters_are_unhonoured_and_each_says_why():
    assert set(UNHONOURED) == {'particles', 'resampleThreshold', 'ogain', 'lsigma', 'kernelSize', 'llsamplerange',
                               'llsamplestep', 'lasamplerange', 'lasamplestep'}
    assert all(len(why) > 20 for why in UNHONOURED.values())


def test_our_own_parameters_are_few_and_named_apart():
    assert names(SlamConfig) | names(NodeConfig) == (set(WRAPPER + GMAPPING) - set(UNHONOURED)) | OURS


def test_frames_with_a_leading_slash_are_taken_without_it():
    config = NodeConfig(base_frame='/base_footprint', odom_frame='/tb3_0/odom', map_frame='map')
    assert (config.base_frame, config.odom_frame, config.map_frame) == ('base_footprint', 'tb3_0/odom', 'map')
    assert NodeConfig().base_frame == ''  # the node's default: base_footprint, or NAMESPACE/base_footprint


def test_tf_delay_is_the_publish_period_unless_given():
    assert NodeConfig().stamp_ahead == 0.05
    assert NodeConfig(transform_publish_period=0.1).stamp_ahead == 0.1
    assert NodeConfig(transform_publish_period=0.1, tf_delay=0).stamp_ahead == 0.0


@pytest.mark.parametrize('name, value, problem', [
    ('throttle_scans', 0, 'must be >= 1'), ('throttle_scans', 1.5, 'whole number'),
    ('transform_publish_period', -0.05, 'must be >= 0'), ('tf_delay', -1.0, 'must be >= 0'),
    ('base_frame', 'base footprint', 'frame id'), ('slam_methods', 'rtabmap', ', '.join(METHODS)),
])
def test_bad_values_are_named(name, value, problem):
    with pytest.raises(ParameterError) as raised:
        NodeConfig(**{name: value})
    assert str(raised.value).startswith('parameter ~%s = %r: ' % (name, value)) and problem in str(raised.value)
