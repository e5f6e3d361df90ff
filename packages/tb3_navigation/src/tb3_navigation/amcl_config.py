"""amcl's parameters by amcl's names (AmclConfig), each checked, with TurtleBot3's values. No ROS.

The localization core (tb3_navigation.localization) takes an AmclConfig; the
node (amcl.node) reads one from the parameter server.
"""
import dataclasses
import math

import numpy as np

from tb3_common.params import Checked, fail, frame_id, non_negative, number, one_of, parameter, positive

LASER_MODELS = ('likelihood_field',)
ODOM_MODELS = ('diff', 'diff-corrected')


@dataclasses.dataclass(frozen=True)
class AmclConfig(Checked):
    """amcl's parameters by amcl's names, with TurtleBot3's values (turtlebot3_navigation/launch/amcl.launch,
    noetic) and amcl's defaults for those it leaves out."""
    min_particles: int = parameter(500, 'fewest particles KLD-sampling keeps', number(1))
    max_particles: int = parameter(3000, 'most particles (and the count after an initial pose)', number(1))
    kld_err: float = parameter(0.02, 'largest KL distance of the particles to the truth',
                               number(0.0, 1.0, low_open=True))
    kld_z: float = parameter(0.99, 'upper standard normal quantile for (1 - p), as amcl uses it', positive)
    update_min_d: float = parameter(0.20, 'translation (m) before a filter update', non_negative)
    update_min_a: float = parameter(0.20, 'rotation (rad) before a filter update', non_negative)
    resample_interval: int = parameter(1, 'filter updates between two resamplings', number(1))
    transform_tolerance: float = parameter(0.5, 'the node post-dates map -> odom by this (s)', non_negative)
    recovery_alpha_slow: float = parameter(0.0, 'decay of the slow average weight; 0 = no random particles',
                                           number(0.0, 1.0))
    recovery_alpha_fast: float = parameter(0.0, 'decay of the fast average weight; 0 = no random particles',
                                           number(0.0, 1.0))
    initial_pose_x: float = parameter(0.0, 'initial pose x (m, map)', None)
    initial_pose_y: float = parameter(0.0, 'initial pose y (m, map)', None)
    initial_pose_a: float = parameter(0.0, 'initial yaw (rad, map)', None)
    initial_cov_xx: float = parameter(0.25, "initial variance of x (m^2; amcl's 0.5 * 0.5)", non_negative)
    initial_cov_yy: float = parameter(0.25, 'initial variance of y (m^2)', non_negative)
    initial_cov_aa: float = parameter((math.pi / 12.0) ** 2, 'initial variance of yaw (rad^2)', non_negative)
    gui_publish_rate: float = parameter(50.0, 'most particle clouds a second the node publishes; <= 0: all', None)
    laser_min_range: float = parameter(-1.0, "shorter beams are skipped; <= 0: the scan's range_min", None)
    laser_max_range: float = parameter(3.5, "beams this long or longer are skipped; <= 0: the scan's range_max", None)
    laser_max_beams: int = parameter(180, 'beams of a scan used in an update, spread evenly', number(2))
    laser_z_hit: float = parameter(0.5, "mixture weight of the model's Gaussian on the distance", number(0.0, 1.0))
    laser_z_short: float = parameter(0.05, "weight of short readings (amcl's beam model only)", number(0.0, 1.0))
    laser_z_max: float = parameter(0.05, "weight of max-range readings (amcl's beam model only)", number(0.0, 1.0))
    laser_z_rand: float = parameter(0.5, 'mixture weight of random readings', number(0.0, 1.0))
    laser_sigma_hit: float = parameter(0.2, "standard deviation (m) of the model's Gaussian", positive)
    laser_lambda_short: float = parameter(0.1, "decay of short readings (amcl's beam model only)", positive)
    laser_likelihood_max_dist: float = parameter(2.0, 'the distance field is capped here (m)', positive)
    laser_model_type: str = parameter('likelihood_field', "amcl's beam and likelihood_field_prob: not here",
                                      one_of(*LASER_MODELS))
    odom_model_type: str = parameter('diff', 'the motion model (a Burger is differential: no omni)',
                                     one_of(*ODOM_MODELS))
    odom_alpha1: float = parameter(0.1, "rotation's noise from rotation", non_negative)
    odom_alpha2: float = parameter(0.1, "rotation's noise from translation", non_negative)
    odom_alpha3: float = parameter(0.1, "translation's noise from translation", non_negative)
    odom_alpha4: float = parameter(0.1, "translation's noise from rotation", non_negative)
    odom_frame_id: str = parameter('odom', "odometry's frame", frame_id)
    base_frame_id: str = parameter('base_footprint', "the robot's frame", frame_id)
    global_frame_id: str = parameter('map', "the map's frame", frame_id)
    tf_broadcast: bool = parameter(True, 'publish map -> odom')
    refine_estimate: bool = parameter(True,
                                      "ours: the estimate matched to the map by the scan (see Amcl); false: amcl's "
                                      'mean')

    def check_together(self):
        if self.max_particles < self.min_particles:
            fail('max_particles', self.max_particles, 'must be >= min_particles (%r)' % self.min_particles)
        if self.laser_z_hit + self.laser_z_rand <= 0:
            fail('laser_z_rand', self.laser_z_rand, 'must be > 0 when ~laser_z_hit = %r' % self.laser_z_hit)

    @property
    def odom_alphas(self):
        return self.odom_alpha1, self.odom_alpha2, self.odom_alpha3, self.odom_alpha4

    @property
    def initial_pose(self):
        return self.initial_pose_x, self.initial_pose_y, self.initial_pose_a

    @property
    def initial_covariance(self):
        return np.diag([self.initial_cov_xx, self.initial_cov_yy, self.initial_cov_aa])
