"""Parameter validation: defaults, types and ranges, with messages naming name and value."""
import dataclasses
import math

import pytest

from tb3_common.params import kind_of
from tb3_sim_nav.params import FROM_MODEL, FROM_PROFILE, PARAMETERS, PROFILES, ParameterError, resolve


@pytest.fixture
def resolve_with(burger_urdf):
    """resolve() with a dict standing in for rospy.get_param('~name', default)."""
    def run(**given):
        values = dict(model=str(burger_urdf))
        values.update(given)
        return resolve(lambda name, default: values.get(name, default))
    return run


def test_defaults_resolve(resolve_with, burger_urdf):
    config = resolve_with()
    assert [field.name for field in dataclasses.fields(config)] == [parameter.name for parameter in PARAMETERS]
    for parameter in PARAMETERS:
        value = getattr(config, parameter.name)
        origin = parameter.metadata['origin']
        if origin == FROM_MODEL:  # the robot model's own (its URDF's drive_limits)
            assert value is None
            continue
        if parameter.name == 'model':
            expected = str(burger_urdf)
        elif origin == FROM_PROFILE:  # a realism knob: the gazebo profile's default
            expected = PROFILES['gazebo'][parameter.name]
        else:
            expected = parameter.default
        assert value == expected
        assert type(value) is kind_of(parameter)[0]
    assert config.real_time_factor == 1.0 and config.physics_rate == 100.0
    assert config.odom_frame == 'odom' and config.base_frame == 'base_footprint'


def test_ints_are_accepted_for_floats(resolve_with):
    config = resolve_with(physics_rate=100, imu_rate=100, odom_rate=30, x_pos=-2, real_time_factor=0)
    assert config.physics_rate == 100.0 and type(config.physics_rate) is float
    assert config.x_pos == -2.0 and type(config.x_pos) is float
    assert config.real_time_factor == 0.0 and type(config.real_time_factor) is float


@pytest.mark.parametrize('name, value, shown', [
    # wrong types
    ('real_time_factor', '1.0', "'1.0'"),
    ('x_pos', 'zero', "'zero'"),
    ('gui', 1.0, '1.0'),
    ('paused', 0, '0'),
    ('yaw', True, 'True'),
    ('physics_rate', False, 'False'),
    ('odom_frame', 5, '5'),
    ('model', None, 'None'),
    # non-finite floats
    ('x_pos', math.nan, 'nan'),
    ('max_linear_speed', math.inf, 'inf'),
    ('yaw', -math.inf, '-inf'),
    # out of range
    ('real_time_factor', -1.0, '-1.0'),
    ('real_time_factor', -0.5, '-0.5'),
    ('physics_rate', 0.0, '0.0'),
    ('physics_rate', -200.0, '-200.0'),
    ('odom_rate', 0.0, '0.0'),
    ('joint_states_rate', -30.0, '-30.0'),
    ('max_angular_speed', 0.0, '0.0'),
    ('wheel_torque', -1.5, '-1.5'),
    ('odom_rate', 300.0, '300.0'),  # above physics_rate
    # frames
    ('base_frame', '', "''"),
    ('odom_frame', 'my odom', "'my odom'"),
    ('odom_frame', '', "''"),
])
def test_bad_value_raises_error_naming_parameter_and_value(resolve_with, name, value, shown):
    with pytest.raises(ParameterError) as error:
        resolve_with(**{name: value})
    message = str(error.value)
    assert '~' + name in message
    assert shown in message


def test_frames_with_a_leading_slash_lose_it_and_whole_floats_are_ints(resolve_with):
    # One rule with every node of ours (tb3_common.params): ROS 1 launch files write "/odom"; tf2 refuses it.
    config = resolve_with(odom_frame='/odom', base_frame='/base_footprint', world_frame='/world', scan_samples=360.0)
    assert (config.odom_frame, config.base_frame, config.world_frame) == ('odom', 'base_footprint', 'world')
    assert config.scan_samples == 360 and type(config.scan_samples) is int


def test_odom_rate_above_physics_rate_names_both(resolve_with):
    with pytest.raises(ParameterError) as error:
        resolve_with(physics_rate=100.0, odom_rate=150.0)
    message = str(error.value)
    assert '~odom_rate' in message and '150.0' in message
    assert '~physics_rate' in message and '100.0' in message


def test_odom_rate_equal_to_physics_rate_is_fine(resolve_with):
    assert resolve_with(physics_rate=100.0, imu_rate=100.0, odom_rate=100.0).odom_rate == 100.0


def test_a_sensor_rate_above_the_physics_rate_is_refused(resolve_with):
    with pytest.raises(ParameterError, match='~imu_rate = 200.0: must not exceed ~physics_rate'):
        resolve_with(physics_rate=100.0, imu_rate=200.0)


def test_the_realistic_profile_sets_its_knobs(resolve_with):
    config = resolve_with(profile='realistic')
    for name, value in PROFILES['realistic'].items():
        assert getattr(config, name) == value
    assert config.odom_source == 'encoders' and config.cmd_vel_timeout == 0.5


def test_an_explicit_knob_beats_the_profile(resolve_with):
    config = resolve_with(profile='realistic', cmd_vel_timeout=0.0, odom_source='world')
    assert config.cmd_vel_timeout == 0.0 and config.odom_source == 'world'


@pytest.mark.parametrize('name, value', [('profile', 'gazebo_classic'), ('odom_source', 'gps'),
                                         ('scan_samples', 360.5), ('scan_samples', True),
                                         ('seed', -2), ('scan_range_min', 4.0),
                                         ('odom_wheel_radius_error', 0.7)])
def test_bad_sensor_and_realism_values_name_the_parameter(resolve_with, name, value):
    with pytest.raises(ParameterError) as error:
        resolve_with(**{name: value})
    assert '~' + name in str(error.value) and repr(value) in str(error.value)


@pytest.mark.parametrize('model', ['', 'no/such/robot.urdf', 'wafle'])
def test_a_bad_model_raises_an_error_naming_it(resolve_with, model):
    with pytest.raises(ParameterError) as error:
        resolve_with(model=model)
    assert '~model' in str(error.value) and repr(model) in str(error.value)


def test_an_unknown_model_is_refused_naming_the_three():
    with pytest.raises(ParameterError, match="~model = 'wafle': unknown TurtleBot3 model: the models are burger, "
                                             "waffle, waffle_pi"):
        resolve(lambda name, default: dict(model='wafle').get(name, default))


def test_the_model_defaults_to_the_burger():
    assert resolve(lambda name, default: default).model == 'burger'


@pytest.mark.parametrize('name, value, problem', [
    ('camera_width', 0, 'must be between 1 and 4096'),
    ('camera_width', -640, 'must be between 1 and 4096'),
    ('camera_height', 0, 'must be between 1 and 4096'),
    ('camera_height', 100000, 'must be between 1 and 4096'),
    ('camera_width', 640.5, 'must be a whole number'),
    ('camera_horizontal_fov', 0.0, 'must be between 0.1 and 3'),
    ('camera_horizontal_fov', 3.5, 'must be between 0.1 and 3'),
    ('camera_horizontal_fov', math.nan, 'must be a finite number'),
    ('camera_rate', 0.0, 'must be > 0'),
    ('camera_rate', 200.0, 'must not exceed ~physics_rate = 100.0'),
])
def test_a_camera_parameter_out_of_range_is_refused_by_name(resolve_with, name, value, problem):
    with pytest.raises(ParameterError) as error:
        resolve_with(**{name: value})
    message = str(error.value)
    assert '~' + name in message and problem in message


def test_camera_parameters_unset_are_the_models():
    config = resolve(lambda name, default: default)
    assert (config.camera_width, config.camera_height, config.camera_horizontal_fov, config.camera_rate) == (
        None, None, None, None)
