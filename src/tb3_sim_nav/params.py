"""The simulator's private parameters: a typed, frozen Config, with defaults, units, validation.

`resolve(lookup)` reads each parameter once through `lookup(name, default)`
(rospy.get_param on '~name' in the node, a dict in tests) and returns a
Config, checked, or raises ParameterError naming the parameter and the value.

A realism profile (`~profile`) only chooses defaults: every knob it sets is
a parameter of its own, and a value given explicitly wins. The drive's
limits default to the robot model's own (its URDF's <drive_limits>).
"""
import dataclasses
import math
from collections import namedtuple
from typing import Optional

from .robot import KINDS
from .robot_model import model_problem
from .world_file import WorldError, parse_robots

Parameter = namedtuple('Parameter', 'name default kind check unit doc origin live')

#: Where a default comes from when the field's default is None.
FROM_PROFILE, FROM_MODEL = 'profile', 'model'


class ParameterError(ValueError):
    pass


def _positive(value):
    return None if value > 0 else 'must be > 0'


def _non_negative(value):
    return None if value >= 0 else 'must be >= 0'


def _fraction(value):
    return None if -0.5 < value < 0.5 else 'must be between -0.5 and 0.5'


def _correction(value):
    return None if 0.5 <= value <= 2.0 else 'must be between 0.5 and 2.0 (a factor near 1)'


def _frame_id(value):
    if not value:
        return 'must not be empty'
    if value.startswith('/'):
        return 'must not start with "/" (tf2 rejects such frame ids)'
    return None


def _optional_frame_id(value):
    return _frame_id(value) if value else None


def _one_of(*choices):
    def check(value):
        return None if value in choices else 'must be one of: %s' % ', '.join(choices)
    return check


def _at_least(minimum):
    def check(value):
        return None if value >= minimum else 'must be >= %s' % minimum
    return check


def _between(low, high, unit=''):
    def check(value):
        return None if low <= value <= high else 'must be between %s and %s%s' % (low, high, unit)
    return check


def _model(value):
    return model_problem(value)


def _robots(value):
    try:
        parse_robots(value, 'the list')
    except WorldError as error:
        return str(error)
    return None


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


def _p(default, doc, check=None, unit='', origin=None, live=False):
    """A field of Config; `live`: it may change while the simulator runs (dynamic_reconfigure)."""
    return dataclasses.field(default=default, metadata=dict(check=check, unit=unit, doc=doc, origin=origin,
                                                            live=live))


@dataclasses.dataclass(frozen=True)
class Config(object):
    """Every parameter of the simulator node, resolved and checked."""
    model: str = _p('burger', 'the robot (when ~robots is empty): burger, waffle, waffle_pi or the path of a URDF; its geometry, limits and cameras come from its URDF', _model)
    robots: tuple = _p((), 'robots with namespaces, instead of the one robot of ~model: a list of {name, model, position: [x, y(, z)], yaw} as in world files', _robots)
    world: str = _p('empty', "world by name (worlds/NAME.yaml) or path to a world file or to a map_server map's YAML (its occupied cells become walls)")
    map_wall_height: float = _p(0.5, 'height of the walls a map world raises on its occupied cells (above the lidar: Burger 0.182 m)', _positive, 'm')
    x_pos: float = _p(0.0, 'spawn position x', unit='m')
    y_pos: float = _p(0.0, 'spawn position y', unit='m')
    z_pos: float = _p(0.0, 'spawn height of base_footprint', unit='m')
    yaw: float = _p(0.0, 'spawn heading', unit='rad')
    gui: bool = _p(False, "open pybullet's own window (needs a display)")
    real_time_factor: float = _p(1.0, 'simulated seconds per wall second; 0 = as fast as possible', _non_negative)
    paused: bool = _p(False, 'start with physics paused (/gazebo/unpause_physics resumes)')
    physics_rate: float = _p(100.0, 'physics steps per simulated second; /clock is published every step (Gazebo publishes it at 100 Hz)', _positive, 'Hz')
    lockstep: bool = _p(True, 'hold each step until the local nodes publishing cmd_vel have reacted to it, so their commands land at the same sim time at any factor')
    lockstep_timeout: float = _p(0.5, 'longest a step waits for such a node; one that takes longer is not waited for until it waits again', _positive, 's (wall)')
    startup_hold: float = _p(0.3, 'sim time holds this long when a node subscribes to /clock, so it can connect first', _non_negative, 's (wall)')
    odom_rate: float = _p(30.0, 'rate of odom, tf and base_pose_ground_truth (sim time)', _positive, 'Hz')
    joint_states_rate: float = _p(30.0, 'rate of joint_states (sim time)', _positive, 'Hz')
    max_linear_speed: Optional[float] = _p(None, "commands beyond this are clamped; unset: the model's, from its URDF's <drive_limits> (burger 0.22, waffle and waffle_pi 0.26)", _positive, 'm/s', FROM_MODEL)
    max_angular_speed: Optional[float] = _p(None, "the same for turning (burger 2.84, waffle and waffle_pi 1.82)", _positive, 'rad/s', FROM_MODEL)
    wheel_torque: float = _p(1.5, 'stall torque of each wheel motor (Dynamixel XL430 at 12 V)', _positive, 'N m')
    wheel_acceleration: float = _p(1.0, "limit on each wheel rim's acceleration, as TurtleBot3's Gazebo set-up (wheelAcceleration 1); 0 = none", _non_negative, 'm/s^2', live=True)
    odom_frame: str = _p('odom', 'frame of odom and of its tf parent (a robot with a name gets it as a prefix: tb3_0/odom)', _frame_id)
    base_frame: str = _p('base_footprint', 'child frame of odom and its tf (prefixed as odom_frame)', _frame_id)
    world_frame: str = _p('world', "the world's frame: the simulator publishes tf from it to each robot's odom frame (the truth: the identity while odom is the true pose, the drift of encoder odometry otherwise) and draws the world's obstacles in it on world_markers; empty: neither (when a localization node publishes odom's parent)", _optional_frame_id)
    robot_state_publisher: bool = _p(True, 'publish what a robot_state_publisher with tf_prefix would for each robot with a name (its fixed joints on /tf_static, its wheels on /tf); false: only set NAME/robot_description, for nodes of your own')
    scan: bool = _p(True, 'publish the LDS-01 lidar on scan')
    scan_rate: float = _p(5.0, 'scan rate (sim time)', _positive, 'Hz')
    scan_samples: int = _p(360, 'beams per turn', _at_least(3))
    scan_range_min: float = _p(0.12, 'closer hits read -inf', _non_negative, 'm')
    scan_range_max: float = _p(3.5, 'beams reaching no wall within it read +inf', _positive, 'm')
    scan_noise: float = _p(0.01, 'standard deviation of Gaussian range noise; 0 = none', _non_negative, 'm', live=True)
    imu: bool = _p(True, 'publish the IMU on imu')
    imu_rate: float = _p(100.0, 'IMU rate (sim time); at most ~physics_rate: the real Burger and its Gazebo model give 200 Hz, with ~physics_rate 200', _positive, 'Hz')
    camera_width: Optional[int] = _p(None, 'image width of the Waffle (Pi) camera; unset: the model\'s, at most 640 (the height follows the model\'s aspect)', _between(1, 4096), 'pixels', FROM_MODEL)
    camera_height: Optional[int] = _p(None, 'image height (unset: from the width and the model\'s aspect)', _between(1, 4096), 'pixels', FROM_MODEL)
    camera_horizontal_fov: Optional[float] = _p(None, "horizontal field of view; unset: the model's (waffle 1.3439, waffle_pi 1.085595)", _between(0.1, 3.0, ' rad'), 'rad', FROM_MODEL)
    camera_rate: Optional[float] = _p(None, "camera rate (sim time), at most ~physics_rate; unset: the model's (Gazebo's 30), at most 15, to keep real time with rviz on 2 cores", _positive, 'Hz', FROM_MODEL)
    seed: int = _p(-1, 'seed of every noise source; -1 = different each run', _at_least(-1))
    profile: str = _p('gazebo', 'realism profile: chooses the defaults below', _one_of(*sorted(PROFILES)))
    odom_source: str = _p(None, 'odom from the true pose (Gazebo) or integrated from wheel encoders (firmware)', _one_of('world', 'encoders'), origin=FROM_PROFILE)
    ground_friction: float = _p(None, 'Coulomb friction of wheel on ground', _positive, origin=FROM_PROFILE, live=True)
    caster_friction: float = _p(None, 'Coulomb friction of the ball caster on ground (drags when turning)', _non_negative, origin=FROM_PROFILE, live=True)
    left_motor_error: float = _p(None, 'the left wheel turns this much faster than commanded (negative: slower), as a loaded motor does', _fraction, 'fraction', FROM_PROFILE, live=True)
    right_motor_error: float = _p(None, 'the same for the right wheel', _fraction, 'fraction', FROM_PROFILE, live=True)
    odom_wheel_radius_error: float = _p(None, 'encoder odometry assumes a wheel this much bigger than the real one', _fraction, 'fraction', FROM_PROFILE, live=True)
    odom_wheel_separation_error: float = _p(None, 'encoder odometry assumes wheels this much further apart than they act', _fraction, 'fraction', FROM_PROFILE, live=True)
    odom_linear_scale_correction: float = _p(1.0, "encoder odometry's distances are multiplied by this, as a base controller's calibration (ROS by Example's calibrate_linear.py measures it); the gazebo profile's odometry is the true pose and ignores it", _correction, 'factor', live=True)
    odom_angular_scale_correction: float = _p(1.0, "encoder odometry's turns are multiplied by this (calibrate_angular.py)", _correction, 'factor', live=True)
    encoder_noise: float = _p(None, 'standard deviation of Gaussian noise on each wheel-angle reading', _non_negative, 'rad', FROM_PROFILE, live=True)
    cmd_vel_timeout: float = _p(None, 'stop when no cmd_vel came for this long (firmware: 0.5); 0 = hold the last command forever', _non_negative, 's', FROM_PROFILE, live=True)
    imu_gyro_noise: float = _p(None, 'standard deviation of angular-velocity noise', _non_negative, 'rad/s', FROM_PROFILE, live=True)
    imu_accel_noise: float = _p(None, 'standard deviation of linear-acceleration noise', _non_negative, 'm/s^2', FROM_PROFILE, live=True)

    def replace(self, **changes):
        """A copy with `changes` (unchecked: for tests and tools)."""
        return dataclasses.replace(self, **changes)


def _kind(field):
    return dict(((Optional[float], float), (Optional[int], int))).get(field.type, field.type)


#: The parameters in the node's order, for the README table and the tests.
PARAMETERS = [Parameter(field.name, field.default, _kind(field), field.metadata['check'], field.metadata['unit'],
                        field.metadata['doc'], field.metadata['origin'], field.metadata['live'])
              for field in dataclasses.fields(Config)]
#: Those that may change while the simulator runs.
LIVE = [parameter for parameter in PARAMETERS if parameter.live]


def _typed(parameter, value):
    """`value` as the parameter's type, or ParameterError."""
    kind = parameter.kind
    if value is None and parameter.origin == FROM_MODEL:
        return None
    if isinstance(value, bool) != (kind is bool):
        pass  # a bool is an int in python, but never a number here
    elif kind is float and isinstance(value, (int, float)) and math.isfinite(value):
        return float(value)
    elif kind is tuple and isinstance(value, (list, tuple)):
        return tuple(value)
    elif kind not in (float, tuple) and isinstance(value, kind):
        return value
    raise ParameterError('parameter ~%s = %r (%s): must be a%s %s'
                         % (parameter.name, value, type(value).__name__,
                            ' finite' if kind is float else '', kind.__name__))


def check(parameter, value):
    """`value` typed and checked for `parameter`, or ParameterError saying why."""
    value = _typed(parameter, value)
    problem = parameter.check(value) if parameter.check and value is not None else None
    if problem:
        raise ParameterError('parameter ~%s = %r: %s' % (parameter.name, value, problem))
    return value


def changed(config, changes):
    """`config` with `changes` {name: value} of LIVE parameters, each checked; ParameterError
    (and nothing changed) if any is not live or not valid."""
    live = dict((parameter.name, parameter) for parameter in LIVE)
    typed = {}
    for name, value in changes.items():
        if name not in live:
            raise ParameterError('parameter ~%s cannot change while the simulator runs' % name)
        typed[name] = check(live[name], value)
    return config.replace(**typed)


def resolve(lookup, parameters=PARAMETERS):
    """Every parameter, checked: a Config."""
    resolved = {}
    for parameter in parameters:
        default = parameter.default
        if parameter.origin == FROM_PROFILE:
            default = PROFILES[resolved['profile']][parameter.name]
        resolved[parameter.name] = check(parameter, lookup(parameter.name, default))
    for rate in [kind.rate_parameter for kind in KINDS]:  # every sensor's rate
        if resolved[rate] is not None and resolved[rate] > resolved['physics_rate']:
            raise ParameterError('parameter ~%s = %r: must not exceed ~physics_rate = %r'
                                 % (rate, resolved[rate], resolved['physics_rate']))
    if resolved['scan_range_min'] >= resolved['scan_range_max']:
        raise ParameterError('parameter ~scan_range_min = %r: must be below ~scan_range_max = %r'
                             % (resolved['scan_range_min'], resolved['scan_range_max']))
    resolved['robots'] = tuple(parse_robots(resolved['robots']))
    return Config(**resolved)
