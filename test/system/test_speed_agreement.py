"""The tutorial's scripts end in the same place at real_time_factor 0 (as fast
as possible) as at 1 (real time): within 1 cm and 1 degree.

One roscore of this module's own (tools/demo.py's start_master, a free
loopback port) and this process as a rospy node (as `make demo` is); for each
script and each factor, tools/demo.py's run_script: a fresh `roslaunch
tb3_sim_bringup tb3_empty_world.launch real_time_factor:=F`, `rosrun
tb3_sim_nav SCRIPT`, the ground-truth pose recorded until after its exit, the
simulator stopped. The end poses (the last ground-truth sample) are compared.
"""
import argparse
import math
import sys

import pytest

from tb3_system_utils import demo
import demo_report  # noqa: E402  (tools/, put on sys.path by tb3_system_utils)

POSITION_TOLERANCE = 0.01   # m
HEADING_TOLERANCE = 1.0     # deg
FACTORS = (1.0, 0.0)

# rospy calls the deprecated Condition.notifyAll() on every /clock message: recording
# each of those warnings would only load this process while it records.
pytestmark = pytest.mark.filterwarnings('ignore:notifyAll:DeprecationWarning')


@pytest.fixture(scope='module')
def demo_node(tmp_path_factory):
    """A master and this process as a rospy node following /clock, as in `make demo`."""
    log_dir = str(tmp_path_factory.mktemp('speed_agreement_logs'))
    master = None
    try:
        master = demo.start_master(log_dir)
        import rospy
        rospy.init_node('tb3_speed_agreement', anonymous=True, argv=[sys.argv[0]], disable_signals=True)
        assert not rospy.rostime.is_wallclock(), 'the test node did not pick up /use_sim_time'
        yield log_dir
    finally:
        if master is not None:
            import rospy
            if rospy.core.is_initialized():
                rospy.signal_shutdown('speed agreement test done')
            master.stop()


@pytest.mark.parametrize('script,expected', demo.SCRIPTS)
def test_script_ends_within_1cm_1deg_at_factor_0_of_factor_1(script, expected, demo_node, monkeypatch):
    # run_script (tools/demo.py at 63270c4) counts a script's sim time from `rosrun`:
    # at factor 0 the simulator runs free while python starts the script (1-2 wall s,
    # 40-80 sim s), which its limit of 4x the expected sim time did not allow for.
    # This test is about where the scripts end: a limit that cannot cut them short.
    monkeypatch.setattr(demo, 'TIMEOUT_FACTOR', 10.0)
    ends, walls = {}, {}
    for factor in FACTORS:
        options = argparse.Namespace(real_time_factor=factor, profile=None)
        result, error = demo.run_script(script, expected, options, demo_node)
        assert error is None, '%s at real_time_factor %g: %s' % (script, factor, error)
        summary = demo_report.summarize(result)
        assert summary is not None, '%s at real_time_factor %g: no ground truth recorded' % (script, factor)
        ends[factor], walls[factor] = summary.end, (result.wall_time, result.sim_time)
    (_, x1, y1, yaw1), (_, x0, y0, yaw0) = ends[1.0], ends[0.0]
    apart = math.hypot(x0 - x1, y0 - y1)
    turned = abs(math.degrees(demo_report.normalize(yaw0 - yaw1)))
    print('MEASURED speed_agreement %s: apart %.4f m, %.3f deg; ends factor 1 (%+.4f, %+.4f, %+.2f deg), '
          'factor 0 (%+.4f, %+.4f, %+.2f deg); wall/sim s factor 1 %.1f/%.1f, factor 0 %.1f/%.1f'
          % (script, apart, turned, x1, y1, math.degrees(yaw1), x0, y0, math.degrees(yaw0),
             walls[1.0][0], walls[1.0][1], walls[0.0][0], walls[0.0][1]), flush=True)
    assert apart <= POSITION_TOLERANCE, '%s ends %.4f m apart at factor 0 and 1' % (script, apart)
    assert turned <= HEADING_TOLERANCE, '%s ends %.3f deg apart at factor 0 and 1' % (script, turned)
