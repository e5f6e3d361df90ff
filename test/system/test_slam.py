"""The mapping chapter as a learner runs it, measured against the world file (issue 19).

tb3_world.launch with profile:=realistic (odometry drifts), tb3_slam.launch,
a drive of the ~14 m loop around turtlebot3_world's pillars (steered on the
truth, where a learner uses the teleop), `rosrun map_server map_saver -f`,
all through tb3_harness.mapping, which `make demo DEMO_ARGS=--slam` runs too.
Once as fast as possible and once at real time: the SLAM must correct
odometry (the pose in map within 5 cm and 2 degrees of the truth at the end,
odometry further off), its map must lie on the world's walls, and lockstep
must make the two runs agree.
"""
import numpy as np
import pytest

from tb3_harness import mapping
from tb3_harness.processes import start_master
from tb3_harness.report import figure, map_figures

POSE_ERROR = (0.05, 2.0)     # m, deg: the pose in map against the truth at the end of the loop
SAME_POSE = 0.01             # m between the two factors' ends in map
SAME_MAP_SHARE = 0.95        # of the occupied cells of one run with an occupied cell within 1 cell in the other


@pytest.fixture(scope='module')
def runs(tmp_path_factory):
    """The loop mapped at factor 0 and at factor 1, each against a master of its own."""
    made = {}
    for factor in (0.0, 1.0):
        folder = tmp_path_factory.mktemp('slam_%g' % factor)
        master = start_master(str(folder))
        try:
            made[factor] = mapping.map_world(str(folder), str(folder), factor=factor)
        finally:
            master.stop()
    return made


@pytest.mark.parametrize('factor', [0.0, 1.0])
def test_the_slam_corrects_odometry_and_its_map_lies_on_the_walls(runs, factor):
    run = runs[factor]
    quality = run.quality
    print('MEASURED factor %g: loop of %.1f m in %.1f s sim, %.1f s wall; pose in map off the truth %.3f m %.2f deg, '
          'odometry %.3f m %.2f deg; SLAM CPU %.0f %% of a core; map: %s'
          % (factor, mapping.path_length(run.truth), run.sim_seconds, run.wall_seconds, run.map_error[0],
             run.map_error[1], run.odom_error[0], run.odom_error[1], 100 * run.slam_cpu, quality.summary()))
    figure('slam_pose_error', run.map_error[0], 'max', 'm')
    figure('slam_heading_error', abs(run.map_error[1]), 'max', 'deg')
    map_figures('slam_map', quality)
    assert run.map_error[0] < POSE_ERROR[0] and abs(run.map_error[1]) < POSE_ERROR[1], run.map_error
    assert run.odom_error[0] > run.map_error[0], (run.odom_error, run.map_error)
    assert not quality.failures(), quality.failures()


def test_lockstep_gives_the_same_map_at_factors_1_and_0(runs):
    fast, real = runs[0.0], runs[1.0]
    moved = np.hypot(fast.map[-1][1] - real.map[-1][1], fast.map[-1][2] - real.map[-1][2])
    shares = [near_share(a, b) for a, b in ((fast, real), (real, fast))]
    print('MEASURED factors 0 and 1: ends in map %.4f m apart; occupied cells with a match within a cell: '
          '%.3f and %.3f' % (moved, shares[0], shares[1]))
    figure('lockstep_ends_apart', moved, 'max', 'm')
    figure('lockstep_cells_matched', 100 * min(shares), 'min', '%')
    assert moved < SAME_POSE
    assert min(shares) >= SAME_MAP_SHARE, shares


def near_share(a, b):
    """The share of `a`'s occupied cells with an occupied cell of `b` within one cell (same grid)."""
    from scipy import ndimage
    assert a.grid == b.grid
    near = ndimage.binary_dilation(b.values >= 65, np.ones((3, 3), bool))
    mine = a.values >= 65
    return float((mine & near).sum()) / max(1, int(mine.sum()))
