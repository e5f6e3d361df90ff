"""The simulator's private parameters: a typed, frozen Config, with defaults, units, validation.

`resolve(lookup)` reads each parameter once through `lookup(name, default)`
(rospy.get_param on '~name' in the node, a dict in tests) and returns a
Config, checked, or raises ParameterError naming the parameter and the value.

A realism profile (`~profile`) only chooses defaults: every knob it sets is
a parameter of its own, and a value given explicitly wins. The drive's
limits default to the robot model's own (its URDF's <drive_limits>).
"""
import dataclasses
from typing import Optional

from tb3_common.cfg import live_fields
from tb3_common.params import (
    ParameterError,
    checked,
    fail,
    frame_id,
    non_negative,
    number,
    one_of,
    optional_frame_id,
    parameter,
    positive,
)

from .robot import KINDS
from .robot_model import model_problem
from .world_file import WorldError, parse_robots

#: Where a default comes from when the field's default is None.
FROM_PROFILE, FROM_MODEL = 'profile', 'model'

_fraction = number(-0.5, 0.5, low_open=True, high_open=True)
_correction = number(0.5, 2.0)


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
    """A field of Config (tb3_common.params's rules); `origin`: where a default of None comes from; `live`: it
    may change while the simulator runs (dynamic_reconfigure)."""
    return parameter(default, doc, check, unit, origin=origin, live=live)


@dataclasses.dataclass(frozen=True)
class Config(object):
    """Every parameter of the simulator node, resolved and checked."""
    model: str = _p('burger',
                    'the robot (when ~robots is empty): burger, waffle, waffle_pi or the path of a URDF; its geometry,'
                    ' limits and cameras come from its URDF', _model)
    robots: tuple = _p((),
                       'robots with namespaces, instead of the one robot of ~model: a list of {name, model, position: '
                       '[x, y(, z)], yaw} as in world files', _robots)
    world: str = _p('empty',
                    "world by name (worlds/NAME.yaml) or path to a world file or to a map_server map's YAML (its "
                    'occupied cells become walls)')
    map_wall_height: float = _p(0.5,
                                'height of the walls a map world raises on its occupied cells (above the lidar: Burger'
                                ' 0.182 m)', positive, 'm')
    x_pos: float = _p(0.0, 'spawn position x', unit='m')
    y_pos: float = _p(0.0, 'spawn position y', unit='m')
    z_pos: float = _p(0.0, 'spawn height of base_footprint', unit='m')
    yaw: float = _p(0.0, 'spawn heading', unit='rad')
    gui: bool = _p(False, "open pybullet's own window (needs a display)")
    real_time_factor: float = _p(1.0, 'simulated seconds per wall second; 0 = as fast as possible', non_negative)
    paused: bool = _p(False, 'start with physics paused (/gazebo/unpause_physics resumes)')
    physics_rate: float = _p(100.0,
                             'physics steps per simulated second; /clock is published every step (Gazebo publishes it '
                             'at 100 Hz)', positive, 'Hz')
    lockstep: bool = _p(True,
                        'hold each step until the local nodes publishing cmd_vel have reacted to it, so their commands'
                        ' land at the same sim time at any factor')
    lockstep_timeout: float = _p(0.5,
                                 'longest a step waits for such a node; one that takes longer is not waited for until '
                                 'it waits again', positive, 's (wall)')
    startup_hold: float = _p(0.3, 'sim time holds this long when a node subscribes to /clock, so it can connect first',
                             non_negative, 's (wall)')
    odom_rate: float = _p(30.0, 'rate of odom, tf and base_pose_ground_truth (sim time)', positive, 'Hz')
    joint_states_rate: float = _p(30.0, 'rate of joint_states (sim time)', positive, 'Hz')
    max_linear_speed: Optional[float] = _p(None,
                                           "commands beyond this are clamped; unset: the model's, from its URDF's "
                                           '<drive_limits> (burger 0.22, waffle and waffle_pi 0.26)',
                                           positive, 'm/s', FROM_MODEL)
    max_angular_speed: Optional[float] = _p(None, 'the same for turning (burger 2.84, waffle and waffle_pi 1.82)',
                                            positive, 'rad/s', FROM_MODEL)
    wheel_torque: float = _p(1.5, 'stall torque of each wheel motor (Dynamixel XL430 at 12 V)', positive, 'N m')
    wheel_acceleration: float = _p(1.0, "limit on each wheel rim's acceleration, as TurtleBot3's Gazebo set-up "
                                   '(wheelAcceleration 1); 0 = none', non_negative, 'm/s^2', live=True)
    odom_frame: str = _p('odom',
                         'frame of odom and of its tf parent (a robot with a name gets it as a prefix: tb3_0/odom)',
                         frame_id)
    base_frame: str = _p('base_footprint', 'child frame of odom and its tf (prefixed as odom_frame)', frame_id)
    world_frame: str = _p('world',
                          "the world's frame: the simulator publishes tf from it to each robot's odom frame (the "
                          'truth: the identity while odom is the true pose, the drift of encoder odometry otherwise) '
                          "and draws the world's obstacles in it on world_markers; empty: neither (when a localization"
                          " node publishes odom's parent)", optional_frame_id)
    robot_state_publisher: bool = _p(True,
                                     'publish what a robot_state_publisher with tf_prefix would for each robot with a '
                                     'name (its fixed joints on /tf_static, its wheels on /tf); false: only set '
                                     'NAME/robot_description, for nodes of your own')
    scan: bool = _p(True, 'publish the LDS-01 lidar on scan')
    scan_rate: float = _p(5.0, 'scan rate (sim time)', positive, 'Hz')
    scan_samples: int = _p(360, 'beams per turn', number(3))
    scan_range_min: float = _p(0.12, 'closer hits read -inf', non_negative, 'm')
    scan_range_max: float = _p(3.5, 'beams reaching no wall within it read +inf', positive, 'm')
    scan_noise: float = _p(0.01, 'standard deviation of Gaussian range noise; 0 = none', non_negative, 'm', live=True)
    imu: bool = _p(True, 'publish the IMU on imu')
    imu_rate: float = _p(100.0,
                         'IMU rate (sim time); at most ~physics_rate: the real Burger and its Gazebo model give 200 '
                         'Hz, with ~physics_rate 200', positive, 'Hz')
    camera_width: Optional[int] = _p(None,
                                     "image width of the Waffle (Pi) camera; unset: the model's, at most 640 (the "
                                     "height follows the model's aspect)", number(1, 4096), 'pixels', FROM_MODEL)
    camera_height: Optional[int] = _p(None, "image height (unset: from the width and the model's aspect)",
                                      number(1, 4096), 'pixels', FROM_MODEL)
    camera_horizontal_fov: Optional[float] = _p(None, "horizontal field of view; unset: the model's (waffle 1.3439, "
                                                'waffle_pi 1.085595)', number(0.1, 3.0), 'rad', FROM_MODEL)
    camera_rate: Optional[float] = _p(None,
                                      "camera rate (sim time), at most ~physics_rate; unset: the model's (Gazebo's "
                                      '30), at most 15, to keep real time with rviz on 2 cores',
                                      positive, 'Hz', FROM_MODEL)
    seed: int = _p(-1, 'seed of every noise source; -1 = different each run', number(-1))
    profile: str = _p('gazebo', 'realism profile: chooses the defaults below', one_of(*sorted(PROFILES)))
    odom_source: str = _p(None, 'odom from the true pose (Gazebo) or integrated from wheel encoders (firmware)',
                          one_of('world', 'encoders'), origin=FROM_PROFILE)
    ground_friction: float = _p(None, 'Coulomb friction of wheel on ground', positive, origin=FROM_PROFILE, live=True)
    caster_friction: float = _p(None, 'Coulomb friction of the ball caster on ground (drags when turning)',
                                non_negative, origin=FROM_PROFILE, live=True)
    left_motor_error: float = _p(None,
                                 'the left wheel turns this much faster than commanded (negative: slower), as a loaded'
                                 ' motor does', _fraction, 'fraction', FROM_PROFILE, live=True)
    right_motor_error: float = _p(None, 'the same for the right wheel', _fraction, 'fraction', FROM_PROFILE, live=True)
    odom_wheel_radius_error: float = _p(None, 'encoder odometry assumes a wheel this much bigger than the real one',
                                        _fraction, 'fraction', FROM_PROFILE, live=True)
    odom_wheel_separation_error: float = _p(None,
                                            'encoder odometry assumes wheels this much further apart than they act',
                                            _fraction, 'fraction', FROM_PROFILE, live=True)
    odom_linear_scale_correction: float = _p(1.0, "encoder odometry's distances are multiplied by this, as a base "
                                             "controller's calibration (ROS by Example's calibrate_linear.py measures "
                                             "it); the gazebo profile's odometry is the true pose and ignores it",
                                             _correction, 'factor', live=True)
    odom_angular_scale_correction: float = _p(1.0,
                                              "encoder odometry's turns are multiplied by this (calibrate_angular.py)",
                                              _correction, 'factor', live=True)
    encoder_noise: float = _p(None, 'standard deviation of Gaussian noise on each wheel-angle reading',
                              non_negative, 'rad', FROM_PROFILE, live=True)
    cmd_vel_timeout: float = _p(None,
                                'stop when no cmd_vel came for this long (firmware: 0.5); 0 = hold the last command '
                                'forever', non_negative, 's', FROM_PROFILE, live=True)
    imu_gyro_noise: float = _p(None, 'standard deviation of angular-velocity noise',
                               non_negative, 'rad/s', FROM_PROFILE, live=True)
    imu_accel_noise: float = _p(None, 'standard deviation of linear-acceleration noise',
                                non_negative, 'm/s^2', FROM_PROFILE, live=True)

    def replace(self, **changes):
        """A copy with `changes` (unchecked: for tests and tools)."""
        return dataclasses.replace(self, **changes)


#: The parameters in the node's order (Config's fields: name, default, metadata), for the README table and the tests.
PARAMETERS = dataclasses.fields(Config)
_BY_NAME = dict((field.name, field) for field in PARAMETERS)
#: Those that may change while the simulator runs.
LIVE = live_fields(Config)


def check(name, value):
    """`value` typed and checked for parameter `name` (tb3_common.params's rules), or ParameterError."""
    return checked(_BY_NAME[name], value)


def changed(config, changes):
    """`config` with `changes` {name: value} of LIVE parameters, each checked; ParameterError
    (and nothing changed) if any is not live or not valid."""
    live = set(field.name for field in LIVE)
    typed = {}
    for name, value in changes.items():
        if name not in live:
            raise ParameterError('parameter ~%s cannot change while the simulator runs' % name)
        typed[name] = check(name, value)
    return config.replace(**typed)


def resolve(lookup, parameters=PARAMETERS):
    """Every parameter, checked: a Config."""
    resolved = {}
    for field in parameters:
        default = field.default
        if field.metadata['origin'] == FROM_PROFILE:
            default = PROFILES[resolved['profile']][field.name]
        resolved[field.name] = check(field.name, lookup(field.name, default))
    for rate in [kind.rate_parameter for kind in KINDS]:  # every sensor's rate
        if resolved[rate] is not None and resolved[rate] > resolved['physics_rate']:
            fail(rate, resolved[rate], 'must not exceed ~physics_rate = %r' % resolved['physics_rate'])
    if resolved['scan_range_min'] >= resolved['scan_range_max']:
        fail('scan_range_min', resolved['scan_range_min'], 'must be below ~scan_range_max = %r'
             % resolved['scan_range_max'])
    resolved['robots'] = tuple(parse_robots(resolved['robots']))
    return Config(**resolved)
