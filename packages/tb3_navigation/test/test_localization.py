"""amcl's filter (tb3_navigation.localization) piece by piece, on recorded drives of the simulated
Burger (profile realistic): its parameters (TurtleBot3's amcl.launch as the defaults, a bad value
refused naming it), the covariances' two layouts, the clouds of an initial pose and of global
localization, and the updates: when they come, a nomotion update, bad beams skipped, map -> odom, a
seed's repeatability. The maps and the drive are localization_drives.py's; how well the filter localises
is test_localization_accuracy.py's. No ROS.
"""
import math

import numpy as np
import pytest

from tb3_common.pose2d import compose, normalize_angle
from tb3_harness.drives import TIGHT, scan
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import RVIZ_COVARIANCE, Amcl, covariance_3x3, covariance_6x6
from tb3_navigation.scan import Scan, endpoints

pytest_plugins = ['localization_drives']


# -- configuration ------------------------------------------------------------------------------------------------

def test_defaults_are_turtlebot3s_amcl_launch():
    config = AmclConfig()
    expected = dict(min_particles=500, max_particles=3000, kld_err=0.02, kld_z=0.99, update_min_d=0.2,
                    update_min_a=0.2, resample_interval=1, transform_tolerance=0.5, recovery_alpha_slow=0.0,
                    recovery_alpha_fast=0.0, initial_pose_x=0.0, initial_pose_y=0.0, initial_pose_a=0.0,
                    gui_publish_rate=50.0, laser_max_range=3.5, laser_max_beams=180, laser_z_hit=0.5,
                    laser_z_short=0.05, laser_z_max=0.05, laser_z_rand=0.5, laser_sigma_hit=0.2,
                    laser_lambda_short=0.1, laser_likelihood_max_dist=2.0, laser_model_type='likelihood_field',
                    odom_model_type='diff', odom_alpha1=0.1, odom_alpha2=0.1, odom_alpha3=0.1, odom_alpha4=0.1,
                    odom_frame_id='odom', base_frame_id='base_footprint', global_frame_id='map')
    assert {name: getattr(config, name) for name in expected} == expected
    assert np.allclose(config.initial_covariance, RVIZ_COVARIANCE)


@pytest.mark.parametrize('name, value, message', [
    ('min_particles', 0, '>= 1'), ('max_particles', 2.5, 'whole number'), ('kld_err', 0.0, '> 0'),
    ('update_min_d', -0.1, '>= 0'), ('resample_interval', 0, '>= 1'), ('laser_max_beams', 1, '>= 2'),
    ('laser_sigma_hit', 0.0, '> 0'), ('laser_z_rand', 1.5, 'between 0 and 1'), ('odom_alpha1', math.nan, 'finite'),
    ('recovery_alpha_fast', 2.0, 'between 0 and 1'), ('laser_model_type', 'beam', 'likelihood_field'),
    ('odom_model_type', 'omni', 'diff, diff-corrected'), ('base_frame_id', '', 'frame id'),
    ('initial_pose_x', math.inf, 'finite'), ('tf_broadcast', 'yes', 'true or false')])
def test_bad_parameters_fail_naming_parameter_and_value(name, value, message):
    with pytest.raises(ValueError) as raised:
        AmclConfig(**{name: value})
    assert '~%s = %r' % (name, value) in str(raised.value) and message in str(raised.value)


def test_max_particles_below_min_particles_is_refused():
    with pytest.raises(ValueError, match='max_particles = 100: must be >= min_particles'):
        AmclConfig(min_particles=500, max_particles=100)


def test_covariances_convert_between_3x3_and_a_messages_36():
    covariance = np.array([[0.25, 0.01, 0.0], [0.01, 0.16, 0.0], [0.0, 0.0, 0.07]])
    full = covariance_6x6(covariance)
    assert len(full) == 36 and full[0] == 0.25 and full[1] == full[6] == 0.01 and full[7] == 0.16
    assert full[35] == 0.07 and sum(abs(value) for value in full) == pytest.approx(0.25 + 0.02 + 0.16 + 0.07)
    assert np.array_equal(covariance_3x3(full), covariance)


# -- initialisation -------------------------------------------------------------------------------------------------

def test_an_initial_pose_spreads_max_particles_as_its_gaussian(world):
    amcl = Amcl(AmclConfig(), *world, seed=1)
    amcl.initialise((-2.0, -0.5, 3.0), RVIZ_COVARIANCE)
    poses = amcl.particles
    assert len(poses) == 3000 and np.allclose(amcl.weights, 1.0 / 3000)
    assert np.allclose(poses[:, :2].mean(axis=0), (-2.0, -0.5), atol=3 * 0.5 / math.sqrt(3000))
    assert np.allclose(poses[:, :2].std(axis=0), 0.5, rtol=0.05)
    turn = normalize_angle(poses[:, 2] - 3.0)  # wrapped at +-pi, yet centred on 3.0
    assert abs(turn.mean()) < 3 * (math.pi / 12) / math.sqrt(3000)
    assert turn.std() == pytest.approx(math.pi / 12, rel=0.05)
    with pytest.raises(ValueError, match='positive semi-definite'):
        amcl.initialise((0, 0, 0), np.diag([0.25, -0.25, 0.1]))
    with pytest.raises(ValueError, match='finite'):
        amcl.initialise((0, math.nan, 0), RVIZ_COVARIANCE)


def test_global_localization_spreads_particles_over_free_cells_only(house):
    grid, values = house
    amcl = Amcl(AmclConfig(), grid, values, seed=2)
    amcl.global_localization()
    cells = grid.to_cells(amcl.particles[:, :2])
    assert len(amcl.particles) == 3000 and np.all(grid.inside(cells))
    assert np.all(values[cells[:, 1], cells[:, 0]] == 0)
    # Spread over the whole house, every heading.
    assert np.ptp(amcl.particles[:, 0]) > 14.0 and np.ptp(amcl.particles[:, 1]) > 10.0
    assert np.histogram(amcl.particles[:, 2], bins=6, range=(-math.pi, math.pi))[0].min() > 400


# -- updates ---------------------------------------------------------------------------------------------------------

def test_updates_wait_for_update_min_d_or_update_min_a(world, loop):
    amcl = Amcl(AmclConfig(), *world, seed=3)
    amcl.initialise(loop.truth[0], TIGHT)
    reading = scan(loop, 0)
    steps = [((0.0, 0.0, 0.0), True),  # the first scan after an initial pose always updates
             ((0.15, 0.0, 0.0), False), ((0.15, 0.1, 0.0), False), ((0.25, 0.0, 0.0), True),
             ((0.25, 0.0, 0.15), False), ((0.25, 0.0, 0.25), True), ((0.25, 0.0, -0.1), True)]
    for odom, expected in steps:
        assert amcl.update(odom, reading, loop.scan_pose) == expected, odom


def test_a_nomotion_update_refines_a_robot_standing_still(world, loop):
    amcl = Amcl(AmclConfig(), *world, seed=4)
    start, reading = loop.truth[0], scan(loop, 0)
    amcl.initialise(start + (0.2, -0.1, 0.1), RVIZ_COVARIANCE)
    assert amcl.update(loop.odom[0], reading, loop.scan_pose)
    first = amcl.estimate()
    assert not amcl.update(loop.odom[0], reading, loop.scan_pose)
    for _ in range(15):
        amcl.request_nomotion_update()
        assert amcl.update(loop.odom[0], reading, loop.scan_pose)
    assert not amcl.update(loop.odom[0], reading, loop.scan_pose)  # a request is good for one update
    last = amcl.estimate()
    def error(estimate):
        return math.hypot(estimate.pose[0] - start[0], estimate.pose[1] - start[1])
    assert error(first) > 0.15 and error(last) < min(0.08, error(first) / 2.5)
    assert np.trace(last.covariance[:2, :2]) < 0.1 * np.trace(first.covariance[:2, :2])
    assert len(amcl.particles) < 1000  # KLD let the particles go as the cloud shrank


def test_nan_inf_and_out_of_range_beams_are_skipped(world, loop):
    config = AmclConfig(resample_interval=3)  # the first two updates weigh without resampling: weights to compare
    amcl = Amcl(config, *world, seed=5)
    amcl.initialise(loop.truth[0], RVIZ_COVARIANCE)
    before = amcl.particles.copy()
    ranges = loop.ranges[0].copy()
    bad = np.arange(len(ranges)) % 3 == 0
    ranges[bad] = np.resize([np.nan, np.inf, -np.inf, 0.05, 3.6, 100.0], int(bad.sum()))
    reading = Scan(loop.angle_min, loop.angle_increment, ranges, loop.range_min, loop.range_max)
    assert amcl.update(loop.odom[0], reading, loop.scan_pose) and not amcl.resampled
    # amcl's 180 beams of 360 are every other one; of those, the good ones alone count.
    used = np.arange(0, len(ranges), 2)
    used = used[~bad[used] & (loop.ranges[0][used] < 3.5)]
    points = endpoints(loop.scan_pose, reading.angles[used], ranges[used])
    expected = amcl.model.weights(before, points, 3.5)
    assert np.allclose(amcl.weights, expected / expected.sum(), rtol=1e-12)
    # A scan of nothing but bad beams leaves the weights as they were, and no NaN anywhere.
    amcl.request_nomotion_update()
    nothing = Scan(loop.angle_min, loop.angle_increment, np.full(360, np.nan), loop.range_min, loop.range_max)
    weights = amcl.weights.copy()
    assert amcl.update(loop.odom[0], nothing, loop.scan_pose) and not amcl.resampled
    assert np.allclose(amcl.weights, weights, rtol=1e-12)
    assert weights.std() > 0  # the first update did weigh: the check above is not vacuous
    assert np.all(np.isfinite(amcl.estimate().covariance)) and np.isfinite(amcl.map_to_odom()).all()
    amcl.request_nomotion_update()
    assert amcl.update(loop.odom[0], nothing, loop.scan_pose) and amcl.resampled  # every third update
    assert np.all(np.isfinite(amcl.particles)) and len(amcl.particles) <= 3000


def test_map_to_odom_puts_the_base_at_the_estimate(world, loop):
    amcl = Amcl(AmclConfig(), *world, seed=6)
    amcl.initialise(loop.truth[0], TIGHT)
    assert amcl.map_to_odom() is None
    for index in range(0, 120):
        if amcl.update(loop.odom[index], scan(loop, index), loop.scan_pose):
            base = compose(amcl.map_to_odom(), loop.odom[index])
            assert np.allclose(base[:2], amcl.estimate().pose[:2], atol=1e-9)
            assert abs(normalize_angle(base[2] - amcl.estimate().pose[2])) < 1e-9


def test_a_seed_makes_the_filter_repeatable(world, loop):
    clouds = []
    for seed in (7, 7, 8):
        amcl = Amcl(AmclConfig(), *world, seed=seed)
        amcl.initialise(loop.truth[0], RVIZ_COVARIANCE)
        for index in range(0, 60):
            amcl.update(loop.odom[index], scan(loop, index), loop.scan_pose)
        clouds.append(amcl.particles.copy())
    assert np.array_equal(clouds[0], clouds[1])
    assert clouds[0].shape != clouds[2].shape or not np.allclose(clouds[0], clouds[2])
