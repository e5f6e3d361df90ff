"""The simulator's private parameters: defaults, units, validation.

`resolve(lookup)` reads each parameter once through `lookup(name, default)`
(rospy.get_param on '~name' in the node, a dict in tests) and returns them
checked, or raises ParameterError naming the parameter and the value.
"""
import math
import os
from collections import OrderedDict, namedtuple

Parameter = namedtuple('Parameter', 'name default kind check doc')


class ParameterError(ValueError):
    pass


def _positive(value):
    return None if value > 0 else 'must be > 0'


def _non_negative(value):
    return None if value >= 0 else 'must be >= 0'


def _existing_file(value):
    return None if os.path.isfile(value) else 'no such file'


def _frame_id(value):
    if not value:
        return 'must not be empty'
    if value.startswith('/'):
        return 'must not start with "/" (tf2 rejects such frame ids)'
    return None


def _one_of(*choices):
    def check(value):
        return None if value in choices else 'must be one of %s' % ', '.join(choices)
    return check


PARAMETERS = [
    Parameter('urdf_file', '', str, _existing_file, 'URDF of the robot, loaded into pybullet; wheel geometry comes from it'),
    Parameter('x_pos', 0.0, float, None, 'spawn position x in odom (m)'),
    Parameter('y_pos', 0.0, float, None, 'spawn position y in odom (m)'),
    Parameter('z_pos', 0.0, float, None, 'spawn height of base_footprint (m)'),
    Parameter('yaw', 0.0, float, None, 'spawn heading (rad)'),
    Parameter('gui', False, bool, None, "open pybullet's own window (needs a display)"),
    Parameter('real_time_factor', 1.0, float, _non_negative, 'simulated seconds per wall second; 0 = as fast as possible'),
    Parameter('paused', False, bool, None, 'start with physics paused (unpause_physics service resumes)'),
    Parameter('physics_rate', 200.0, float, _positive, 'physics steps per simulated second (Hz); /clock is published every step'),
    Parameter('odom_rate', 30.0, float, _positive, 'rate of odom, tf and base_pose_ground_truth (Hz, sim time)'),
    Parameter('joint_states_rate', 30.0, float, _positive, 'rate of joint_states (Hz, sim time)'),
    Parameter('max_linear_speed', 0.22, float, _positive, 'commands beyond this are clamped (m/s)'),
    Parameter('max_angular_speed', 2.84, float, _positive, 'commands beyond this are clamped (rad/s)'),
    Parameter('wheel_torque', 1.5, float, _positive, 'stall torque of each wheel motor (N m, Dynamixel XL430 at 12 V)'),
    Parameter('odom_frame', 'odom', str, _frame_id, 'frame of odom and of its tf parent'),
    Parameter('base_frame', 'base_footprint', str, _frame_id, 'child frame of odom and its tf'),
]


def _typed(parameter, value):
    """`value` as the parameter's type, or ParameterError."""
    kind = parameter.kind
    if kind is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        if math.isfinite(value):
            return float(value)
    elif isinstance(value, kind):
        return value
    raise ParameterError('parameter ~%s = %r (%s): must be a finite %s'
                         % (parameter.name, value, type(value).__name__, kind.__name__))


def resolve(lookup, parameters=PARAMETERS):
    """Every parameter, checked: an OrderedDict name -> value."""
    resolved = OrderedDict()
    for parameter in parameters:
        value = _typed(parameter, lookup(parameter.name, parameter.default))
        problem = parameter.check(value) if parameter.check else None
        if problem:
            raise ParameterError('parameter ~%s = %r: %s' % (parameter.name, value, problem))
        resolved[parameter.name] = value
    if resolved['odom_rate'] > resolved['physics_rate']:
        raise ParameterError('parameter ~odom_rate = %r: must not exceed ~physics_rate = %r'
                             % (resolved['odom_rate'], resolved['physics_rate']))
    return resolved
