"""The calibration walkthrough's arithmetic (tb3_harness/calibration.py, its half without rospy)."""
import math

import pytest

from tb3_common.pose2d import normalize_angle
from tb3_harness import calibration, report
from tb3_harness.processes import RunError


def turning_path(degrees, steps=90, start=0.0, x=0.0):
    """(stamp, x, y, yaw) samples of a turn in place by `degrees`, one per 0.1 s."""
    return [(start + 0.1 * i, x, 0.0, normalize_angle(math.radians(degrees * i / steps))) for i in range(steps + 1)]


def test_measure_sums_the_turn_through_the_wrap_around():
    distance, turned = calibration.measure(turning_path(360.0), 0.0, 9.0)
    assert distance == 0.0
    assert math.degrees(turned) == pytest.approx(360.0)
    _, turned = calibration.measure(turning_path(-354.8), 0.0, 9.0)
    assert math.degrees(turned) == pytest.approx(-354.8)


def test_measure_takes_only_the_interval_and_the_straight_line():
    path = [(t * 0.1, 0.02 * t, 0.0, 0.0) for t in range(60)]   # 0.2 m/s along x
    distance, turned = calibration.measure(path, 1.0, 4.0)
    assert distance == pytest.approx(0.6)
    assert turned == 0.0
    with pytest.raises(RunError, match='fewer than 2 samples'):
        calibration.measure(path, 100.0, 101.0)


def test_correction_is_the_present_one_times_truth_over_odometry():
    assert calibration.correction(1.0, 354.78, 360.02) == pytest.approx(0.98545, abs=1e-5)
    assert calibration.correction(0.99, -1.0, -1.01) == pytest.approx(0.99 / 1.01)
    with pytest.raises(RunError, match='odometry measured nothing'):
        calibration.correction(1.0, 1.0, 0.0)


def test_the_table_shows_the_measurements_and_the_error_before_and_after():
    out_and_back = [(0.0, 0.0, 0.0, 0.0), (10.0, 1.0, 0.0, 0.0), (20.0, 0.01, 0.0, math.pi)]
    odom_before = [(0.0, 0.0, 0.0, 0.0), (10.0, 1.0, 0.0, 0.0), (20.0, 0.0, -0.04, math.pi - 0.09)]
    before = report.RunResult('before', out_and_back, odom_before, 30.0, 20.0, 0, None)
    after = report.RunResult('after', out_and_back, out_and_back, 30.0, 20.0, 0, None)
    text = '\n'.join(calibration.table(before, after, (1.006, 1.0017), (math.radians(360.02), math.radians(354.78)),
                                       (0.9957, 0.9854), 1.0))
    assert 'seed %d' % calibration.SEED in text
    assert '1.0060 m' in text and '1.0017 m' in text and '360.02 deg' in text and '354.78 deg' in text
    assert '0.9957' in text and '0.9854' in text
    drift = [line for line in text.splitlines() if line.startswith('odometry off the truth at the end')][0]
    assert drift.split()[-2:] == ['%.4f' % math.hypot(0.01, 0.04), '0.0000']
