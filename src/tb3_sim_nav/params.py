"""The simulator's private parameters: defaults, units, validation.

`resolve(lookup)` reads each parameter once through `lookup(name, default)`
(rospy.get_param on '~name' in the node, a dict in tests) and returns them
checked, or raises ParameterError naming the parameter and the value.

A realism profile (`~profile`) only chooses defaults: every knob it sets is
a parameter of its own, and a value given explicitly wins.
"""
import math
import os
from collections import OrderedDict, namedtuple

Parameter = namedtuple('Parameter', 'name default kind check unit doc')


class ParameterError(ValueError):
    pass


def _positive(value):
    return None if value > 0 else 'must be > 0'


def _non_negative(value):
    return None if value >= 0 else 'must be >= 0'


def _fraction(value):
    return None if -0.5 < value < 0.5 else 'must be between -0.5 and 0.5'


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
        return None if value in choices else 'must be one of: %s' % ', '.join(choices)
    return check


def _at_least(minimum):
    def check(value):
        return None if value >= minimum else 'must be >= %s' % minimum
    return check


#: The defaults each profile gives its knobs. 'gazebo' is TurtleBot3's
#: Gazebo set-up: perfect odometry, no slip, commands held forever;
#: 'realistic' is closer to a real Burger on a floor.
PROFILES = {
    'gazebo': dict(odom_source='world', ground_friction=1.0, caster_friction=0.0,
                   left_motor_error=0.0, right_motor_error=0.0,
                   odom_wheel_radius_error=0.0, odom_wheel_separation_error=0.0,
                   encoder_noise=0.0, cmd_vel_timeout=0.0,
                   imu_gyro_noise=2e-4, imu_accel_noise=1.7e-2),
    'realistic': dict(odom_source='encoders', ground_friction=0.8, caster_friction=0.3,
                      left_motor_error=-0.04, right_motor_error=-0.035,
                      odom_wheel_radius_error=0.005, odom_wheel_separation_error=-0.01,
                      encoder_noise=0.002, cmd_vel_timeout=0.5,
                      imu_gyro_noise=2e-3, imu_accel_noise=5e-2),
}

PARAMETERS = [
    Parameter('urdf_file', '', str, _existing_file, '', 'URDF of the robot, loaded into pybullet; wheel geometry comes from it'),
    Parameter('world', 'empty', str, None, '', 'world by name (worlds/NAME.yaml) or path to a world file'),
    Parameter('x_pos', 0.0, float, None, 'm', 'spawn position x'),
    Parameter('y_pos', 0.0, float, None, 'm', 'spawn position y'),
    Parameter('z_pos', 0.0, float, None, 'm', 'spawn height of base_footprint'),
    Parameter('yaw', 0.0, float, None, 'rad', 'spawn heading'),
    Parameter('gui', False, bool, None, '', "open pybullet's own window (needs a display)"),
    Parameter('real_time_factor', 1.0, float, _non_negative, '', 'simulated seconds per wall second; 0 = as fast as possible'),
    Parameter('paused', False, bool, None, '', 'start with physics paused (/gazebo/unpause_physics resumes)'),
    Parameter('physics_rate', 100.0, float, _positive, 'Hz', 'physics steps per simulated second; /clock is published every step (Gazebo publishes it at 100 Hz)'),
    Parameter('lockstep', True, bool, None, '', 'hold each step until the local nodes publishing cmd_vel have reacted to it, so their commands land at the same sim time at any factor'),
    Parameter('lockstep_timeout', 0.5, float, _positive, 's (wall)', 'longest a step waits for such a node; one that takes longer is not waited for until it waits again'),
    Parameter('startup_hold', 0.3, float, _non_negative, 's (wall)', 'sim time holds this long when a node subscribes to /clock, so it can connect first'),
    Parameter('odom_rate', 30.0, float, _positive, 'Hz', 'rate of odom, tf and base_pose_ground_truth (sim time)'),
    Parameter('joint_states_rate', 30.0, float, _positive, 'Hz', 'rate of joint_states (sim time)'),
    Parameter('max_linear_speed', 0.22, float, _positive, 'm/s', 'commands beyond this are clamped'),
    Parameter('max_angular_speed', 2.84, float, _positive, 'rad/s', 'commands beyond this are clamped'),
    Parameter('wheel_torque', 1.5, float, _positive, 'N m', 'stall torque of each wheel motor (Dynamixel XL430 at 12 V)'),
    Parameter('wheel_acceleration', 1.0, float, _non_negative, 'm/s^2', "limit on each wheel rim's acceleration, as TurtleBot3's Gazebo set-up (wheelAcceleration 1); 0 = none"),
    Parameter('odom_frame', 'odom', str, _frame_id, '', 'frame of odom and of its tf parent'),
    Parameter('base_frame', 'base_footprint', str, _frame_id, '', 'child frame of odom and its tf'),
    Parameter('scan', True, bool, None, '', 'publish the LDS-01 lidar on scan'),
    Parameter('scan_rate', 5.0, float, _positive, 'Hz', 'scan rate (sim time)'),
    Parameter('scan_samples', 360, int, _at_least(3), '', 'beams per turn'),
    Parameter('scan_range_min', 0.12, float, _non_negative, 'm', 'closer hits read -inf'),
    Parameter('scan_range_max', 3.5, float, _positive, 'm', 'beams reaching no wall within it read +inf'),
    Parameter('scan_noise', 0.01, float, _non_negative, 'm', 'standard deviation of Gaussian range noise; 0 = none'),
    Parameter('imu', True, bool, None, '', 'publish the IMU on imu'),
    Parameter('imu_rate', 100.0, float, _positive, 'Hz', 'IMU rate (sim time); at most ~physics_rate: the real Burger and its Gazebo model give 200 Hz, with ~physics_rate 200'),
    Parameter('seed', -1, int, _at_least(-1), '', 'seed of every noise source; -1 = different each run'),
    Parameter('profile', 'gazebo', str, _one_of(*sorted(PROFILES)), '', 'realism profile: chooses the defaults below'),
    Parameter('odom_source', None, str, _one_of('world', 'encoders'), '', 'odom from the true pose (Gazebo) or integrated from wheel encoders (firmware)'),
    Parameter('ground_friction', None, float, _positive, '', 'Coulomb friction of wheel on ground'),
    Parameter('caster_friction', None, float, _non_negative, '', 'Coulomb friction of the ball caster on ground (drags when turning)'),
    Parameter('left_motor_error', None, float, _fraction, 'fraction', 'the left wheel turns this much faster than commanded (negative: slower), as a loaded motor does'),
    Parameter('right_motor_error', None, float, _fraction, 'fraction', 'the same for the right wheel'),
    Parameter('odom_wheel_radius_error', None, float, _fraction, 'fraction', 'encoder odometry assumes a wheel this much bigger than the real one'),
    Parameter('odom_wheel_separation_error', None, float, _fraction, 'fraction', 'encoder odometry assumes wheels this much further apart than they act'),
    Parameter('encoder_noise', None, float, _non_negative, 'rad', 'standard deviation of Gaussian noise on each wheel-angle reading'),
    Parameter('cmd_vel_timeout', None, float, _non_negative, 's', 'stop when no cmd_vel came for this long (firmware: 0.5); 0 = hold the last command forever'),
    Parameter('imu_gyro_noise', None, float, _non_negative, 'rad/s', 'standard deviation of angular-velocity noise'),
    Parameter('imu_accel_noise', None, float, _non_negative, 'm/s^2', 'standard deviation of linear-acceleration noise'),
]


def _typed(parameter, value):
    """`value` as the parameter's type, or ParameterError."""
    kind = parameter.kind
    if isinstance(value, bool) != (kind is bool):
        pass  # a bool is an int in python, but never a number here
    elif kind is float and isinstance(value, (int, float)) and math.isfinite(value):
        return float(value)
    elif kind is not float and isinstance(value, kind):
        return value
    raise ParameterError('parameter ~%s = %r (%s): must be a%s %s'
                         % (parameter.name, value, type(value).__name__,
                            ' finite' if kind is float else '', kind.__name__))


def resolve(lookup, parameters=PARAMETERS):
    """Every parameter, checked: an OrderedDict name -> value."""
    resolved = OrderedDict()
    for parameter in parameters:
        default = parameter.default
        if default is None:  # a knob of the realism profile
            default = PROFILES[resolved['profile']][parameter.name]
        value = _typed(parameter, lookup(parameter.name, default))
        problem = parameter.check(value) if parameter.check else None
        if problem:
            raise ParameterError('parameter ~%s = %r: %s' % (parameter.name, value, problem))
        resolved[parameter.name] = value
    for rate in ('odom_rate', 'joint_states_rate', 'scan_rate', 'imu_rate'):
        if resolved[rate] > resolved['physics_rate']:
            raise ParameterError('parameter ~%s = %r: must not exceed ~physics_rate = %r'
                                 % (rate, resolved[rate], resolved['physics_rate']))
    if resolved['scan_range_min'] >= resolved['scan_range_max']:
        raise ParameterError('parameter ~scan_range_min = %r: must be below ~scan_range_max = %r'
                             % (resolved['scan_range_min'], resolved['scan_range_max']))
    return resolved
