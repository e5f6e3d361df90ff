"""fake_localization's arithmetic and parameters. No master."""
import math

import pytest

from fake_localization.localizer import FakeLocalizationConfig, FakeLocalizer
from tb3_common import pose2d
from tb3_common.params import ParameterError


def test_the_original_s_defaults():
    config = FakeLocalizationConfig()
    assert (config.odom_frame_id, config.base_frame_id, config.global_frame_id) == ('odom', 'base_link', 'map')
    assert (config.delta_x, config.delta_y, config.delta_yaw, config.transform_tolerance) == (0, 0, 0, 0.1)


def test_frames_lose_a_leading_slash():
    assert FakeLocalizationConfig(global_frame_id='/map', base_frame_id='/base_footprint').global_frame_id == 'map'


@pytest.mark.parametrize('name, value', [('transform_tolerance', -0.1), ('delta_x', math.nan), ('delta_yaw', 'a'),
                                         ('odom_frame_id', ''), ('base_frame_id', 'base link')])
def test_a_bad_value_names_its_parameter(name, value):
    with pytest.raises(ParameterError, match='~%s' % name):
        FakeLocalizationConfig(**{name: value})


def _check_odom(odom_in_global, base_in_odom, estimate):
    """map -> odom puts the base on the estimate."""
    assert pose2d.compose(odom_in_global, base_in_odom) == pytest.approx(estimate, abs=1e-12)


def test_the_estimate_is_the_truth_and_the_base_lands_on_it():
    localizer = FakeLocalizer(FakeLocalizationConfig())
    truth, base_in_odom = (1.0, -2.0, 0.7), (0.9, -1.8, 0.6)  # odometry drifted
    estimate, odom_in_global = localizer.update(truth, base_in_odom)
    assert estimate == pytest.approx(truth)
    _check_odom(odom_in_global, base_in_odom, estimate)


def test_the_deltas_move_the_estimate_back():
    """The offset is (-delta_x, -delta_y, -delta_yaw), applied before the truth (offset * truth)."""
    config = FakeLocalizationConfig(delta_x=2.0, delta_y=1.0, delta_yaw=math.pi / 2)
    estimate, odom_in_global = FakeLocalizer(config).update((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert estimate == pytest.approx((-2.0, -1.0, -math.pi / 2))
    estimate, _ = FakeLocalizer(config).update((1.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert estimate == pytest.approx((-2.0, -2.0, -math.pi / 2))  # the truth turned by -90 degrees, then moved


def test_an_initial_pose_moves_the_estimate_there_and_it_follows_the_truth_from_there():
    localizer = FakeLocalizer(FakeLocalizationConfig())
    localizer.update((1.0, 1.0, 0.0), (1.0, 1.0, 0.0))
    localizer.set_pose((3.0, 0.0, math.pi / 2))
    estimate, odom_in_global = localizer.update((1.0, 1.0, 0.0), (1.0, 1.0, 0.0))
    assert estimate == pytest.approx((3.0, 0.0, math.pi / 2))
    _check_odom(odom_in_global, (1.0, 1.0, 0.0), estimate)
    estimate, _ = localizer.update((2.0, 1.0, 0.0), (2.0, 1.0, 0.0))  # a metre ahead, as the robot heads
    assert estimate == pytest.approx((3.0, 1.0, math.pi / 2))


def test_an_initial_pose_before_any_truth_is_refused():
    with pytest.raises(ValueError, match='no ground truth'):
        FakeLocalizer(FakeLocalizationConfig()).set_pose((0.0, 0.0, 0.0))


@pytest.mark.parametrize('truth, base', [((math.nan, 0.0, 0.0), (0.0, 0.0, 0.0)),
                                         ((0.0, 0.0, 0.0), (0.0, math.inf, 0.0))])
def test_non_finite_input_is_refused_and_changes_nothing(truth, base):
    localizer = FakeLocalizer(FakeLocalizationConfig())
    localizer.update((1.0, 2.0, 0.0), (1.0, 2.0, 0.0))
    with pytest.raises(ValueError):
        localizer.update(truth, base)
    with pytest.raises(ValueError):
        localizer.set_pose((0.0, math.nan, 0.0))
    assert localizer.estimate == pytest.approx((1.0, 2.0, 0.0))
