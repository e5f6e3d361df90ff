"""rbx1_nav.transform_utils (PyKDL-based) and the top-level transform_utils alias."""
import math

import pytest
from geometry_msgs.msg import Quaternion

import rbx1_nav.transform_utils as rbx1_transform_utils
from rbx1_nav.transform_utils import normalize_angle, quat_to_angle


def yaw_quaternion(yaw):
    return Quaternion(0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


@pytest.mark.parametrize('yaw', [0.0, 0.3, -1.0, math.pi / 2, -math.pi / 2, 3.0, -3.0])
def test_quat_to_angle_gives_yaw(yaw):
    assert quat_to_angle(yaw_quaternion(yaw)) == pytest.approx(yaw, abs=1e-9)


def test_quat_to_angle_at_half_turn():
    assert abs(quat_to_angle(yaw_quaternion(math.pi))) == pytest.approx(math.pi, abs=1e-9)


def test_quat_to_angle_accepts_tf_tuple_order():
    # The scripts do quat_to_angle(Quaternion(*rot)) with rot = (x, y, z, w) from tf.
    rot = (0.0, 0.0, math.sin(0.25), math.cos(0.25))
    assert quat_to_angle(Quaternion(*rot)) == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize('turns', [-3, -2, -1, 0, 1, 2, 3, 10])
def test_normalize_angle_of_whole_turns_is_zero(turns):
    assert normalize_angle(2 * math.pi * turns) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize('turns', [-3, -1, 1, 4])
@pytest.mark.parametrize('angle', [1.0, -2.5, 3.0])
def test_normalize_angle_removes_whole_turns(angle, turns):
    assert normalize_angle(angle + 2 * math.pi * turns) == pytest.approx(angle, abs=1e-9)


@pytest.mark.parametrize('angle', [math.pi, -math.pi, 0.0, 1.0, -1.0])
def test_normalize_angle_leaves_angles_in_range_unchanged(angle):
    assert normalize_angle(angle) == angle


def test_top_level_transform_utils_serves_the_same_functions():
    from transform_utils import normalize_angle as top_normalize
    from transform_utils import quat_to_angle as top_quat
    assert top_quat is rbx1_transform_utils.quat_to_angle
    assert top_normalize is rbx1_transform_utils.normalize_angle
