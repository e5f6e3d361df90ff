"""The particle set's operations: amcl's diff motion model, KLD's limit, low-variance resampling, clusters, stats."""
import math

import numpy as np
import pytest

from tb3_common.pose2d import compose, normalize_angle, relative
from tb3_navigation import particles as pf


def cloud(rng, count, mean, std):
    return np.column_stack((rng.normal(mean[0], std[0], count), rng.normal(mean[1], std[1], count),
                            normalize_angle(rng.normal(mean[2], std[2], count))))


@pytest.mark.parametrize('old, new', [((0, 0, 0), (0.2, 0.05, 0.3)), ((1.0, -2.0, 2.9), (0.8, -2.1, -3.0)),
                                      ((0.5, 0.5, 1.0), (0.5, 0.5, 1.4)), ((0, 0, 0), (-0.2, 0.0, 0.0))])
def test_without_noise_every_particle_moves_as_odometry_moved_in_its_own_frame(old, new):
    rng = np.random.default_rng(1)
    poses = cloud(rng, 20, (3.0, -1.0, 0.5), (1.0, 1.0, 2.0))
    moved = pf.sample_diff_motion(poses, old, new, (0, 0, 0, 0), False, rng)
    step = relative(old, new)  # the motion in the robot's frame
    assert np.allclose(moved[:, :2], compose(poses, step)[:, :2], atol=1e-12)
    assert np.allclose(normalize_angle(moved[:, 2] - compose(poses, step)[:, 2]), 0, atol=1e-12)


def test_diff_noise_is_a_variance_used_as_sigma_and_diff_corrected_its_root():
    rng = np.random.default_rng(2)
    poses = np.zeros((20000, 3))
    alphas = (0.1, 0.1, 0.1, 0.1)
    for corrected, expected in ((False, 0.1 * 0.2 ** 2), (True, math.sqrt(0.1 * 0.2 ** 2))):
        moved = pf.sample_diff_motion(poses, (0, 0, 0), (0.2, 0, 0), alphas, corrected, rng)
        # Straight ahead: rot1 = rot2 = 0, so x carries the translation noise alone.
        assert np.std(moved[:, 0]) == pytest.approx(expected, rel=0.03)
        assert np.mean(moved[:, 0]) == pytest.approx(0.2, abs=3 * expected / math.sqrt(len(poses)) + 1e-4)


def test_turning_in_place_has_no_bearing_and_noise_from_the_turn():
    rng = np.random.default_rng(3)
    poses = np.zeros((5000, 3))
    moved = pf.sample_diff_motion(poses, (1, 1, 0), (1.004, 1, 0.4), (0.1, 0.1, 0.1, 0.1), True, rng)
    assert np.mean(moved[:, 2]) == pytest.approx(0.4, abs=0.01)
    # rot1 is 0 (moved under 1 cm), rot2 the whole turn: its noise alone, sqrt(alpha1 0.4^2 + alpha2 trans^2).
    assert np.std(moved[:, 2]) == pytest.approx(math.sqrt(0.1 * 0.4 ** 2 + 2 * 0.1 * 0.004 ** 2), rel=0.05)


def test_kld_limit_follows_fox_between_min_and_max():
    k = np.arange(1, 400)
    limit = pf.kld_limit(k, 500, 3000, 0.02, 0.99)
    assert limit[0] == 500 and np.all(limit >= 500) and np.all(limit <= 3000)
    assert np.all(np.diff(limit) >= 0) and limit[-1] == 3000
    # Fox's bound for 20 bins, by hand: (k-1)/(2 err) (1 - 2/(9(k-1)) + sqrt(2/(9(k-1))) z)^3.
    x = 1 - 2 / (9 * 19.0) + math.sqrt(2 / (9 * 19.0)) * 0.99
    assert pf.kld_limit(20, 1, 3000, 0.02, 0.99) == math.ceil(19 / 0.04 * x ** 3)


def test_low_variance_resampling_keeps_the_weights_shares():
    rng = np.random.default_rng(4)
    poses = np.array([[0.0, 0, 0], [5.0, 0, 0], [10.0, 0, 0], [15.0, 0, 0]])
    weights = np.array([0.1, 0.2, 0.3, 0.4])
    drawn, new_weights = pf.resample(poses, weights, 1000, 1000, 0.02, 0.99, rng)
    shares = np.array([np.sum(drawn[:, 0] == x) for x in poses[:, 0]]) / 1000.0
    assert np.allclose(shares, weights, atol=1.0 / 1000)  # systematic: off by at most one particle each
    assert np.allclose(new_weights, 1.0 / 1000)


def test_kld_asks_few_particles_for_a_tight_cloud_and_many_for_a_wide_one():
    rng = np.random.default_rng(5)
    tight = cloud(rng, 3000, (0.26, 0.26, 0.1), (0.05, 0.05, 0.03))
    wide = cloud(rng, 3000, (0, 0, 0), (3.0, 3.0, 3.0))
    weights = np.full(3000, 1.0 / 3000)
    assert len(pf.resample(tight, weights, 500, 3000, 0.02, 0.99, rng)[0]) == 500
    assert len(pf.resample(wide, weights, 500, 3000, 0.02, 0.99, rng)[0]) == 3000
    middle = cloud(rng, 3000, (0, 0, 0), (0.25, 0.25, 0.1))
    count = len(pf.resample(middle, weights, 100, 3000, 0.02, 0.99, rng)[0])
    k = len(np.unique(pf.bins(middle), axis=0))
    assert 100 < count < 3000 and count <= pf.kld_limit(k, 100, 3000, 0.02, 0.99)


def test_random_share_replaces_that_share_of_the_draws():
    rng = np.random.default_rng(6)
    poses = np.zeros((100, 3))
    drawn, _ = pf.resample(poses, np.full(100, 0.01), 2000, 2000, 0.02, 0.99, rng, random_share=0.25,
                           random_poses=lambda count: np.tile([9.0, 9.0, 0.0], (count, 1)))
    assert np.mean(drawn[:, 0] == 9.0) == pytest.approx(0.25, abs=0.03)


def test_clusters_join_neighbouring_bins_and_wrap_yaw():
    rng = np.random.default_rng(7)
    one = cloud(rng, 200, (1.0, 1.0, 0.0), (0.1, 0.1, 0.05))
    two = cloud(rng, 100, (4.0, -3.0, 1.0), (0.1, 0.1, 0.05))
    across = cloud(rng, 100, (-2.0, 2.0, math.pi), (0.05, 0.05, 0.08))  # straddles +-180 degrees
    labels, count = pf.clusters(np.concatenate((one, two, across)))
    assert count == 3
    assert len(set(labels[:200])) == len(set(labels[200:300])) == len(set(labels[300:])) == 1


def test_stats_weigh_poses_and_average_yaw_on_the_circle():
    poses = np.array([[0.0, 0.0, math.pi - 0.1], [2.0, 0.0, -math.pi + 0.1], [0.0, 4.0, math.pi]])
    weights = np.array([1.0, 1.0, 2.0])
    stats = pf.stats(poses, weights)
    assert np.allclose(stats.mean[:2], (0.5, 2.0))
    assert abs(normalize_angle(stats.mean[2] - math.pi)) < 1e-12
    centred = poses[:, :2] - (0.5, 2.0)
    expected = (centred * (weights / 4.0)[:, None]).T.dot(centred)
    assert np.allclose(stats.covariance[:2, :2], expected)
    resultant = (2 * math.cos(0.1) + 2) / 4.0
    assert stats.covariance[2, 2] == pytest.approx(-2 * math.log(resultant))
    assert stats.weight == 4.0 and stats.count == 3
