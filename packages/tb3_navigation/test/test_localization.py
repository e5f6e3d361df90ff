"""amcl's filter on recorded drives of the simulated Burger (profile realistic), judged against the truth.

The maps are made here from the world files (a cell whose centre lies within
half a cell of an obstacle cut at the lidar's height is occupied, any other
free); the filter sees only the scans and the drifting odometry. A pose is
judged as a ROS user sees it: map -> odom from the filter composed with the
odometry of the same scan (tf's map -> base_footprint).
"""
import math

import numpy as np
import pytest

from tb3_common.map_files import load_map
from tb3_common.pose2d import compose, inverse, normalize_angle
from tb3_harness import ROOT as REPO
from tb3_harness.drives import TIGHT, WORLD_LOOP, WORLD_LOOP_START, record_drive, run, scan, travelled, world_grid
from tb3_navigation import localization
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import RVIZ_COVARIANCE, Amcl, covariance_3x3, covariance_6x6
from tb3_navigation.scan import Scan, endpoints

#: Through the house's west room, the corridor and the east room from tb3_house.launch's spawn pose.
HOUSE_START = (-3.0, 1.0, 0.0)
HOUSE_ROUTE = [(-1.0, 1.0), (-1.0, 3.5), (-3.5, 3.8), (-4.2, 1.5), (-2.5, 0.6), (0.0, 0.5), (3.0, 0.5), (3.0, 4.3),
               (6.5, 4.3)]


@pytest.fixture(scope='module')
def world():
    return world_grid('turtlebot3_world')


@pytest.fixture(scope='module')
def loop():
    return record_drive('turtlebot3_world', WORLD_LOOP_START, WORLD_LOOP)


@pytest.fixture(scope='module')
def house():
    return world_grid('turtlebot3_house')


@pytest.fixture(scope='module')
def house_drive():
    return record_drive('turtlebot3_house', HOUSE_START, HOUSE_ROUTE)


def after(errors, distance, threshold):
    """The distance driven after which the error stays under `threshold` (inf if it ends over it)."""
    over = np.nonzero(errors >= threshold)[0]
    if not len(over):
        return 0.0
    return math.inf if over[-1] + 1 == len(errors) else float(distance[over[-1] + 1])


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


# -- localising: the requirement ---------------------------------------------------------------------------------------

def test_tracking_holds_5_cm_over_the_loop_while_odometry_drifts(world, loop):
    amcl = Amcl(AmclConfig(), *world, seed=9)
    amcl.initialise(loop.truth[0], TIGHT)
    errors, updates = run(amcl, loop)
    odometry = np.hypot(*(loop.odom[:, :2] - loop.truth[:, :2]).T)
    assert odometry[-1] > 0.15  # the drift the filter has to undo (~18 cm over the 13.6 m loop)
    assert len(updates) > 60
    assert np.mean(updates[:, 1] < 0.05) >= 0.95 and errors[-1] < 0.05
    assert np.mean(errors < 0.05) >= 0.95  # between updates too, through tf
    assert np.percentile(updates[:, 2], 95) < math.radians(3.0)
    # KLD: a converged cloud needs no more than min_particles.
    assert np.all((updates[:, 3] >= 500) & (updates[:, 3] <= 3000)) and np.median(updates[:, 3]) == 500


EXTRA_TURN = 0.04  # of every turn: the realistic Burger's odometry turns 3.5-4 % too far when its caster drags


def turning_wrong(drive, extra):
    """The drive's odometry (n, 3) with every turn `extra` (a share) too large, as the realistic Burger's
    odometry turns when its caster drags, and with each later step in the heading that error gives."""
    odom = [tuple(drive.odom[0])]
    for a, b in zip(drive.odom[:-1], drive.odom[1:]):
        step = compose(inverse(a), b)
        odom.append(tuple(compose(odom[-1], (step[0], step[1], step[2] * (1.0 + extra)))))
    return np.array(odom)


def test_the_cloud_follows_the_match_when_odometry_turns_wrong(loop):
    """The drift seen in test_navigation (the cloud 11 cm and 0.12 rad off, past what the match may move it),
    made here with every turn EXTRA_TURN too large: the published pose stays on the truth."""
    loaded = load_map(str(REPO / 'maps' / 'turtlebot3_world.yaml'))
    odom = turning_wrong(loop, EXTRA_TURN)
    worst = {}
    for follow in (0.0, localization.REFINE_FOLLOW):
        localization.REFINE_FOLLOW, kept = follow, localization.REFINE_FOLLOW
        try:
            amcl = Amcl(AmclConfig(), loaded.grid, loaded.values, seed=5)
            amcl.initialise(loop.truth[0], TIGHT)
            errors = []
            for at, odom_pose in enumerate(odom):
                amcl.update(odom_pose, scan(loop, at), loop.scan_pose)
                seen = compose(amcl.map_to_odom(), odom_pose)
                errors.append(math.hypot(seen[0] - loop.truth[at][0], seen[1] - loop.truth[at][1]))
            worst[follow] = max(errors)
        finally:
            localization.REFINE_FOLLOW = kept
    print('MEASURED worst tf error with turns %.0f %% too large: cloud left alone %.3f m, moved towards the match '
          '%.3f m' % (100 * EXTRA_TURN, worst[0.0], worst[localization.REFINE_FOLLOW]))
    assert worst[0.0] > 0.05  # the drift is there to undo
    assert worst[localization.REFINE_FOLLOW] < 0.03


#: Where rviz's 2D Pose Estimate may put a filter: half a metre off in four directions, turned 30 degrees.
RECOVERY_STARTS = [(0, 30), (135, -30), (200, 30), (270, -30)]


@pytest.fixture(scope='module')
def recoveries(world, loop):
    """{(direction, turn): tf errors at every scan} of a filter started there off the loop's start (seeded by
    its direction), with rviz's covariance."""
    runs = {}
    for direction, turn in RECOVERY_STARTS:
        angle = math.radians(direction)
        amcl = Amcl(AmclConfig(), *world, seed=direction)
        amcl.initialise(loop.truth[0] + (0.5 * math.cos(angle), 0.5 * math.sin(angle), math.radians(turn)),
                        RVIZ_COVARIANCE)
        runs[direction, turn] = run(amcl, loop)[0]
    return runs


# The bounds come from 120 starts (these four, and 116 of random direction, turn and seed; 2026-11-23, the
# simulator's rays meeting the shapes' exact surfaces from the link poses of the current step). Within 20 cm
# after 0.36 m driven at the median and 3.3 m at worst. The last centimetres take longer, as a likelihood
# this flat pulls a cloud in slowly: at the end of the 13.6 m loop 2.0 cm at the median (mean 2.2), 3.8 cm
# at the 95th percentile, 6.9 cm at worst, 2 of 120 over 5 cm. (With pybullet's rays, up to 6 mm short of
# a cylinder: 40 starts, median 2.2 cm, worst 5.3 cm, 1 of 40 over 5 cm: the same filter.)
@pytest.mark.parametrize('direction, turn', RECOVERY_STARTS)
def test_recovery_from_half_a_metre_and_30_degrees_off(recoveries, loop, direction, turn):
    errors = recoveries[direction, turn]
    assert errors[0] > 0.3
    assert after(errors, travelled(loop), 0.20) < 4.0  # metres driven
    assert errors[-1] < 0.075  # past the worst of the 120


def test_recoveries_end_within_3_5_cm_on_average(recoveries):
    # Four starts drawn from those 120 average over 3.5 cm in 1.4 % of draws (bootstrap).
    assert np.mean([errors[-1] for errors in recoveries.values()]) < 0.035


def test_global_localization_in_the_house(house, house_drive):
    # TurtleBot3's "diff" noise (4 mm per 0.2 m) keeps particles from exploring: from a uniform cloud the
    # filter settled in a wrong place in 5 of 8 seeds. amcl's diff-corrected (63 mm) found it in 8 of 8.
    distance = travelled(house_drive)
    for seed in (0, 1, 2):
        amcl = Amcl(AmclConfig(odom_model_type='diff-corrected'), *house, seed=seed)
        amcl.global_localization()
        errors, _ = run(amcl, house_drive)
        assert errors[0] > 1.0, seed  # it did start lost
        assert after(errors, distance, 0.25) < 10.0, seed
        assert errors[-1] < 0.10, seed


def test_global_localization_in_the_symmetric_world_ends_at_the_truth_or_its_twin(world, loop):
    # turtlebot3_world (hexagon, 3 x 3 pillars) looks the same turned by 180 degrees about its centre: the
    # scans cannot tell the pose (x, y, yaw) from (-x, -y, yaw + pi), and the filter settles on either.
    end = loop.truth[-1]
    twin = (-end[0], -end[1], normalize_angle(end[2] + math.pi))
    reading = scan(loop, len(loop.times) - 1)
    points = reading.hit_points(loop.scan_pose, 3.5, reading.subsample(180))
    weights = Amcl(AmclConfig(), *world, seed=0).model.weights(np.array([end, twin]), points, 3.5)
    assert weights[1] == pytest.approx(weights[0], rel=0.03)
    for seed in (0, 4):
        amcl = Amcl(AmclConfig(odom_model_type='diff-corrected'), *world, seed=seed)
        amcl.global_localization()
        run(amcl, loop)
        pose = compose(amcl.map_to_odom(), loop.odom[-1])
        to_truth, to_twin = (math.hypot(pose[0] - end[0], pose[1] - end[1]),
                             math.hypot(pose[0] - twin[0], pose[1] - twin[1]))
        assert min(to_truth, to_twin) < 0.10, seed  # which of the two depends on the seed and the map


def test_recovery_alphas_add_random_particles_when_the_likelihood_drops(world, loop):
    # Odometry jumps 0.7 m at scan 100 (a slip); the scans then fit the particles worse.
    odom = loop.odom + np.where(np.arange(len(loop.times)) >= 100, 0.7, 0.0)[:, None] * (1.0, 0.0, 0.0)
    spread = {}
    for alphas in ((0.0, 0.0), (0.001, 0.1)):
        amcl = Amcl(AmclConfig(recovery_alpha_slow=alphas[0], recovery_alpha_fast=alphas[1]), *world, seed=10)
        amcl.initialise(loop.truth[0], TIGHT)
        far = []
        for index in range(len(loop.times)):
            if amcl.update(odom[index], scan(loop, index), loop.scan_pose):
                centre = np.array(amcl.estimate().pose[:2])
                far.append(np.mean(np.hypot(*(amcl.particles[:, :2] - centre).T) > 1.0))
        spread[alphas] = max(far)
    assert spread[(0.0, 0.0)] < 0.01 and spread[(0.001, 0.1)] > 0.05


def test_the_estimate_matched_to_the_map_is_nearer_the_truth_than_the_clouds_mean(loop):
    """On the shipped map (a perfect SLAM's, walls one cell thick), after the loop's first quarter."""
    loaded = load_map(str(REPO / 'maps' / 'turtlebot3_world.yaml'))
    quarter = travelled(loop)[-1] / 4.0
    errors = {}
    for refine in (False, True):
        found = []
        for seed in (3, 4):
            amcl = Amcl(AmclConfig(refine_estimate=refine), loaded.grid, loaded.values, seed=seed)
            amcl.initialise(loop.truth[0], TIGHT)
            _, updates = run(amcl, loop)
            late = travelled(loop)[updates[:, 0].astype(int)] > quarter
            found.append(updates[late, 1])
        errors[refine] = np.concatenate(found)
    figures = {refine: np.percentile(values, [50, 95, 100]) for refine, values in errors.items()}
    print('MEASURED estimate error, cm (median, p95, worst): the cloud\'s mean %s, matched %s'
          % tuple(np.round(100 * figures[refine], 1).tolist() for refine in (False, True)))
    # Issue 28's bounds: p95 2 cm, worst 3 cm (measured 0.3, 0.8, 0.9 cm; the mean 3.6, 5.2, 5.7 cm).
    assert figures[True][0] < 0.01 and figures[True][1] < 0.02 and figures[True][2] < 0.03
    assert figures[True][1] < figures[False][1] / 3.0
