"""amcl's parameters by amcl's names (AmclConfig), each checked, with TurtleBot3's values. No ROS.

The localization core (tb3_navigation.localization) takes an AmclConfig; the
node (amcl.node) reads one from the parameter server.
"""
import dataclasses
import math

import numpy as np

LASER_MODELS = ('likelihood_field',)
ODOM_MODELS = ('diff', 'diff-corrected')


def _number(low=-math.inf, high=math.inf, low_open=False):
    def check(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            return 'must be a finite number'
        if value < low or (low_open and value == low) or value > high:
            return 'must be %s %g%s' % ('>' if low_open else '>=', low,
                                        '' if high == math.inf else ' and <= %g' % high)
        return None
    return check


def _integer(low):
    def check(value):
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            return 'must be an integer >= %d' % low
        return None
    return check


def _one_of(*choices):
    return lambda value: None if value in choices else 'must be one of %s' % ', '.join(choices)


def _frame_id(value):
    return None if isinstance(value, str) and value.strip('/') and not any(c.isspace() for c in value) \
        else 'must be a frame id (a name without spaces)'


def _p(default, check, doc):
    return dataclasses.field(default=default, metadata=dict(check=check, doc=doc))


@dataclasses.dataclass(frozen=True)
class AmclConfig(object):
    """amcl's parameters by amcl's names, with TurtleBot3's values (turtlebot3_navigation/launch/amcl.launch,
    noetic) and amcl's defaults for those it leaves out."""
    min_particles: int = _p(500, _integer(1), 'fewest particles KLD-sampling keeps')
    max_particles: int = _p(3000, _integer(1), 'most particles (and the count after an initial pose)')
    kld_err: float = _p(0.02, _number(0.0, 1.0, low_open=True), 'largest KL distance of the particles to the truth')
    kld_z: float = _p(0.99, _number(0.0, low_open=True), 'upper standard normal quantile for (1 - p), as amcl uses it')
    update_min_d: float = _p(0.20, _number(0.0), 'translation (m) before a filter update')
    update_min_a: float = _p(0.20, _number(0.0), 'rotation (rad) before a filter update')
    resample_interval: int = _p(1, _integer(1), 'filter updates between two resamplings')
    transform_tolerance: float = _p(0.5, _number(0.0), 'the node post-dates map -> odom by this (s)')
    recovery_alpha_slow: float = _p(0.0, _number(0.0, 1.0), 'decay of the slow average weight; 0 = no random particles')
    recovery_alpha_fast: float = _p(0.0, _number(0.0, 1.0), 'decay of the fast average weight; 0 = no random particles')
    initial_pose_x: float = _p(0.0, _number(), 'initial pose x (m, map)')
    initial_pose_y: float = _p(0.0, _number(), 'initial pose y (m, map)')
    initial_pose_a: float = _p(0.0, _number(), 'initial yaw (rad, map)')
    initial_cov_xx: float = _p(0.25, _number(0.0), "initial variance of x (m^2; amcl's 0.5 * 0.5)")
    initial_cov_yy: float = _p(0.25, _number(0.0), 'initial variance of y (m^2)')
    initial_cov_aa: float = _p((math.pi / 12.0) ** 2, _number(0.0), 'initial variance of yaw (rad^2)')
    gui_publish_rate: float = _p(50.0, _number(), 'most particle clouds a second the node publishes; <= 0: all')
    laser_min_range: float = _p(-1.0, _number(), "shorter beams are skipped; <= 0: the scan's range_min")
    laser_max_range: float = _p(3.5, _number(), "beams this long or longer are skipped; <= 0: the scan's range_max")
    laser_max_beams: int = _p(180, _integer(2), 'beams of a scan used in an update, spread evenly')
    laser_z_hit: float = _p(0.5, _number(0.0, 1.0), "mixture weight of the model's Gaussian on the distance")
    laser_z_short: float = _p(0.05, _number(0.0, 1.0), "weight of short readings (amcl's beam model only)")
    laser_z_max: float = _p(0.05, _number(0.0, 1.0), "weight of max-range readings (amcl's beam model only)")
    laser_z_rand: float = _p(0.5, _number(0.0, 1.0), 'mixture weight of random readings')
    laser_sigma_hit: float = _p(0.2, _number(0.0, low_open=True), "standard deviation (m) of the model's Gaussian")
    laser_lambda_short: float = _p(0.1, _number(0.0, low_open=True), "decay of short readings (amcl's beam model only)")
    laser_likelihood_max_dist: float = _p(2.0, _number(0.0, low_open=True), 'the distance field is capped here (m)')
    laser_model_type: str = _p('likelihood_field', _one_of(*LASER_MODELS), "amcl's beam and likelihood_field_prob: not here")
    odom_model_type: str = _p('diff', _one_of(*ODOM_MODELS), 'the motion model (a Burger is differential: no omni)')
    odom_alpha1: float = _p(0.1, _number(0.0), "rotation's noise from rotation")
    odom_alpha2: float = _p(0.1, _number(0.0), "rotation's noise from translation")
    odom_alpha3: float = _p(0.1, _number(0.0), "translation's noise from translation")
    odom_alpha4: float = _p(0.1, _number(0.0), "translation's noise from rotation")
    odom_frame_id: str = _p('odom', _frame_id, "odometry's frame")
    base_frame_id: str = _p('base_footprint', _frame_id, "the robot's frame")
    global_frame_id: str = _p('map', _frame_id, "the map's frame")
    tf_broadcast: bool = _p(True, lambda value: None if isinstance(value, bool) else 'must be true or false',
                            'publish map -> odom')
    refine_estimate: bool = _p(True, lambda value: None if isinstance(value, bool) else 'must be true or false',
                               "ours: the estimate matched to the map by the scan (see Amcl); false: amcl's mean")

    def __post_init__(self):
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            problem = field.metadata['check'](value)
            if problem:
                raise ValueError('amcl parameter ~%s = %r: %s' % (field.name, value, problem))
        if self.max_particles < self.min_particles:
            raise ValueError('amcl parameter ~max_particles = %r: must be >= min_particles (%r)'
                             % (self.max_particles, self.min_particles))
        if self.laser_z_hit + self.laser_z_rand <= 0:
            raise ValueError('amcl parameters ~laser_z_hit = %r and ~laser_z_rand = %r: one must be > 0'
                             % (self.laser_z_hit, self.laser_z_rand))

    @property
    def odom_alphas(self):
        return self.odom_alpha1, self.odom_alpha2, self.odom_alpha3, self.odom_alpha4

    @property
    def initial_pose(self):
        return self.initial_pose_x, self.initial_pose_y, self.initial_pose_a

    @property
    def initial_covariance(self):
        return np.diag([self.initial_cov_xx, self.initial_cov_yy, self.initial_cov_aa])
