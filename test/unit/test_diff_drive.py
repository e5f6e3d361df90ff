"""Differential-drive maths: command limits, wheel speeds, encoder odometry."""
import math

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tb3_common.pose2d import normalize_angle
from tb3_sim_nav.diff_drive import (
    BURGER_LIMITS,
    EncoderOdometry,
    Limits,
    body_twist,
    sanitize_twist,
    wheel_speeds,
)
from tb3_sim_nav.frames import quaternion_of_yaw, yaw_of

RADIUS, SEPARATION = 0.033, 0.160
NON_FINITE = [math.nan, math.inf, -math.inf]


def command(v=0.0, w=0.0, **others):
    """(linear, angular) triples of a Twist; others: ly, lz, ax, ay."""
    return ((v, others.get('ly', 0.0), others.get('lz', 0.0)),
            (others.get('ax', 0.0), others.get('ay', 0.0), w))


def is_positive_zero_or_nonzero(value):
    return value != 0.0 or math.copysign(1.0, value) > 0


# --- sanitize_twist -----------------------------------------------------------

@pytest.mark.parametrize('v, w, expected_v, expected_w', [
    (1.0, 5.0, 0.22, 2.84),
    (-1.0, -5.0, -0.22, -2.84),
    (0.5, 0.0, 0.22, 0.0),
    (0.0, -3.0, 0.0, -2.84),
])
def test_sanitize_twist_clamps_to_limits_keeping_sign_and_complains(v, w, expected_v, expected_w):
    got_v, got_w, complaints = sanitize_twist(*command(v, w), limits=BURGER_LIMITS)
    assert (got_v, got_w) == (expected_v, expected_w)
    assert len(complaints) == (v != expected_v) + (w != expected_w)
    assert all('clamped' in complaint for complaint in complaints)


@pytest.mark.parametrize('field', range(6), ids=['lin.x', 'lin.y', 'lin.z', 'ang.x', 'ang.y', 'ang.z'])
@pytest.mark.parametrize('bad', NON_FINITE, ids=['nan', 'inf', '-inf'])
def test_sanitize_twist_stops_on_non_finite_value_in_any_field(field, bad):
    values = [0.1, 0.0, 0.0, 0.0, 0.0, -0.5]
    values[field] = bad
    v, w, complaints = sanitize_twist(values[:3], values[3:], BURGER_LIMITS)
    assert (v, w) == (0.0, 0.0)
    assert is_positive_zero_or_nonzero(v) and is_positive_zero_or_nonzero(w)
    assert complaints and 'non-finite' in complaints[0]


def test_sanitize_twist_turns_negative_zero_into_positive_zero():
    v, w, complaints = sanitize_twist(*command(-0.0, -0.0), limits=BURGER_LIMITS)
    assert math.copysign(1.0, v) == 1.0 and math.copysign(1.0, w) == 1.0
    assert complaints == []


@pytest.mark.parametrize('field', ['ly', 'lz', 'ax', 'ay'])
def test_sanitize_twist_ignores_non_planar_fields_with_a_complaint(field):
    v, w, complaints = sanitize_twist(*command(0.1, -0.5, **{field: 0.7}), limits=BURGER_LIMITS)
    assert (v, w) == (0.1, -0.5)
    assert len(complaints) == 1 and 'ignored' in complaints[0]


@pytest.mark.parametrize('v, w', [(0.1, -0.5), (0.0, 0.0), (0.22, 2.84), (-0.22, -2.84), (-0.05, 1.0)])
def test_sanitize_twist_passes_in_limit_command_unchanged_without_complaint(v, w):
    assert sanitize_twist(*command(v, w), limits=BURGER_LIMITS) == (v, w, [])


any_float = st.floats(allow_nan=True, allow_infinity=True)
some_limit = st.floats(min_value=1e-6, max_value=1e6)


@given(st.tuples(any_float, any_float, any_float), st.tuples(any_float, any_float, any_float),
       some_limit, some_limit)
@example((math.nan, 0.0, 0.0), (0.0, 0.0, 0.0), 0.22, 2.84)
@example((1e308, 0.0, 0.0), (0.0, 0.0, -1e308), 0.22, 2.84)
@example((-math.inf, 0.0, 0.0), (0.0, 0.0, math.inf), 0.22, 2.84)
@example((-0.0, -0.0, -0.0), (-0.0, -0.0, -0.0), 0.22, 2.84)
@example((-1e308, 1e308, -1e308), (1e308, -1e308, 1e308), 0.22, 2.84)
def test_sanitize_twist_always_returns_finite_values_within_limits(linear, angular, max_v, max_w):
    v, w, complaints = sanitize_twist(linear, angular, Limits(max_v, max_w))
    assert isinstance(v, float) and isinstance(w, float)
    assert math.isfinite(v) and math.isfinite(w)
    assert abs(v) <= max_v and abs(w) <= max_w
    assert is_positive_zero_or_nonzero(v) and is_positive_zero_or_nonzero(w)
    assert isinstance(complaints, list)


# --- wheel_speeds and body_twist ------------------------------------------------

def test_wheel_speeds_straight_and_in_place_turn():
    assert wheel_speeds(0.2, 0.0, RADIUS, SEPARATION) == pytest.approx((0.2 / RADIUS, 0.2 / RADIUS))
    # Turning left (w > 0) in place: the left wheel runs backwards.
    assert wheel_speeds(0.0, 1.0, RADIUS, SEPARATION) == pytest.approx((-0.08 / RADIUS, 0.08 / RADIUS))


@pytest.mark.parametrize('v, w', [(0.2, 0.0), (0.0, 1.0), (0.1, -0.5), (-0.22, 2.84)])
def test_body_twist_inverts_wheel_speeds(v, w):
    left, right = wheel_speeds(v, w, RADIUS, SEPARATION)
    assert body_twist(left, right, RADIUS, SEPARATION) == pytest.approx((v, w), abs=1e-12)


bounded = st.floats(min_value=-100.0, max_value=100.0)


@given(bounded, bounded, st.floats(min_value=0.005, max_value=1.0),
       st.floats(min_value=0.05, max_value=2.0))
def test_wheel_speeds_and_body_twist_round_trip(v, w, radius, separation):
    left, right = wheel_speeds(v, w, radius, separation)
    back_v, back_w = body_twist(left, right, radius, separation)
    scale = 1.0 + abs(v) + abs(w) * separation
    assert back_v == pytest.approx(v, rel=1e-9, abs=1e-12 * scale / separation)
    assert back_w == pytest.approx(w, rel=1e-9, abs=1e-12 * scale / separation)
    again_left, again_right = wheel_speeds(back_v, back_w, radius, separation)
    assert (again_left, again_right) == pytest.approx((left, right), rel=1e-9, abs=1e-9 * scale / radius)


# --- yaw helpers ----------------------------------------------------------------

@given(st.floats(min_value=-math.pi, max_value=math.pi))
@example(math.pi)
@example(-math.pi)
def test_yaw_of_inverts_quaternion_of_yaw_in_half_open_interval_once_wrapped(yaw):
    back = normalize_angle(yaw_of(quaternion_of_yaw(yaw)))
    assert -math.pi <= back < math.pi, 'documented range is [-pi, pi)'
    assert math.remainder(back - yaw, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


# --- EncoderOdometry --------------------------------------------------------------

def drive(odometry, left_speed, right_speed, duration, steps, start=(0.0, 0.0)):
    """Feed `steps` equal updates of constant wheel speeds (rad/s); returns the trace."""
    trace = []
    for step in range(1, steps + 1):
        elapsed = duration * step / steps
        trace.append(odometry.update(start[0] + left_speed * elapsed, start[1] + right_speed * elapsed))
    return trace


def fresh_odometry(**pose):
    odometry = EncoderOdometry(RADIUS, SEPARATION, **pose)
    odometry.update(0.0, 0.0)
    return odometry


def test_encoder_odometry_first_update_only_takes_the_reference():
    odometry = EncoderOdometry(RADIUS, SEPARATION, x=1.0, y=2.0, yaw=0.5)
    assert odometry.update(123.0, -45.0) == (1.0, 2.0, 0.5)


def test_encoder_odometry_integrates_a_straight_line():
    odometry = fresh_odometry()
    x, y, yaw = drive(odometry, 0.2 / RADIUS, 0.2 / RADIUS, duration=5.0, steps=150)[-1]
    assert (x, y, yaw) == pytest.approx((1.0, 0.0, 0.0), abs=1e-12)


def test_encoder_odometry_straight_line_follows_initial_heading():
    odometry = fresh_odometry(x=1.0, y=-1.0, yaw=math.pi / 2)
    x, y, yaw = drive(odometry, 0.2 / RADIUS, 0.2 / RADIUS, duration=5.0, steps=150)[-1]
    assert (x, y, yaw) == pytest.approx((1.0, 0.0, math.pi / 2), abs=1e-12)


def test_encoder_odometry_in_place_turn_wraps_yaw_into_half_open_interval():
    left, right = wheel_speeds(0.0, 1.0, RADIUS, SEPARATION)
    odometry = fresh_odometry()
    trace = drive(odometry, left, right, duration=1.5 * math.pi, steps=300)  # 270 deg left
    assert all(-math.pi < yaw <= math.pi for _x, _y, yaw in trace)
    x, y, yaw = trace[-1]
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert yaw == pytest.approx(-math.pi / 2, abs=1e-9)


@pytest.mark.parametrize('w', [1.0, -1.0], ids=['left', 'right'])
def test_encoder_odometry_half_turn_reads_pi(w):
    """The project's one angle wrap ([-pi, pi), tb3_common.pose2d) holds at its edge: half a turn either way
    reads pi or -pi, the same heading."""
    left, right = wheel_speeds(0.0, w, RADIUS, SEPARATION)
    odometry = fresh_odometry()
    _x, _y, yaw = odometry.update(left * math.pi, right * math.pi)
    assert -math.pi <= yaw < math.pi
    assert abs(yaw) == pytest.approx(math.pi, abs=1e-9)


@pytest.mark.parametrize('v, w', [(0.1, 0.5), (0.1, -0.5), (-0.2, 1.0)])
def test_encoder_odometry_full_circle_returns_to_start(v, w):
    left, right = wheel_speeds(v, w, RADIUS, SEPARATION)
    odometry = fresh_odometry(x=0.3, y=-0.4, yaw=0.2)
    trace = drive(odometry, left, right, duration=2 * math.pi / abs(w), steps=500)
    assert trace[-1] == pytest.approx((0.3, -0.4, 0.2), abs=1e-9)
    diameter = max(math.hypot(x - 0.3, y + 0.4) for x, y, _yaw in trace)
    assert diameter == pytest.approx(2 * abs(v / w), rel=1e-3)
