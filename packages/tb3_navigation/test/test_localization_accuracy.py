"""How well amcl's filter localises on recorded drives of the simulated Burger (profile realistic),
judged against the truth, as a ROS user sees it: map -> odom from the filter composed with the odometry
of the same scan (tf's map -> base_footprint). Tracking within 5 cm over the loop while odometry drifts,
the cloud following the scan match when odometry turns wrong, recovery from a wrong initial pose, global
localization in the house and in the symmetric world, the recovery alphas, the estimate matched to the
map. The maps, made from the world files (a cell whose centre lies within half a cell of an obstacle cut
at the lidar's height is occupied, any other free), and the loop are localization_drives.py's; the
filter sees only the scans and the drifting odometry.
"""
import math

import numpy as np
import pytest

from tb3_common.map_files import load_map
from tb3_common.pose2d import compose, inverse, normalize_angle
from tb3_harness import ROOT as REPO
from tb3_harness.drives import TIGHT, record_drive, run, scan, travelled
from tb3_navigation import localization
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import RVIZ_COVARIANCE, Amcl

pytest_plugins = ['localization_drives']


#: Through the house's west room, the corridor and the east room from tb3_house.launch's spawn pose.
HOUSE_START = (-3.0, 1.0, 0.0)
HOUSE_ROUTE = [(-1.0, 1.0), (-1.0, 3.5), (-3.5, 3.8), (-4.2, 1.5), (-2.5, 0.6), (0.0, 0.5), (3.0, 0.5), (3.0, 4.3),
               (6.5, 4.3)]


@pytest.fixture(scope='module')
def house_drive():
    return record_drive('turtlebot3_house', HOUSE_START, HOUSE_ROUTE)


def after(errors, distance, threshold):
    """The distance driven after which the error stays under `threshold` (inf if it ends over it)."""
    over = np.nonzero(errors >= threshold)[0]
    if not len(over):
        return 0.0
    return math.inf if over[-1] + 1 == len(errors) else float(distance[over[-1] + 1])


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
