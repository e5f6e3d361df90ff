"""tb3_navigation.slam on recorded drives of the simulated Burger (realistic profile: drifting odometry).

The SLAM sees scans and odometry only; the true poses and the world file judge it. Its answers to odd
input (bad beams, odometry that jumps or slips, resets) are test_slam_input.py's.
"""
import dataclasses
import math

import numpy as np
import pytest
from slam_drives import errors, obstacles, quality, run, scans_of

from tb3_common.params import ParameterError
from tb3_common.pose2d import IDENTITY, compose, relative
from tb3_harness.drives import (
    HOUSE_OUTSIDE,
    HOUSE_TOUR,
    HOUSE_TOUR_START,
    WORLD_LOOP_START,
    path_length,
    record_drive,
)
from tb3_harness.map_quality import QualityConfig, measure
from tb3_navigation.occupancy import OccupancyGrid
from tb3_navigation.slam import REDRAW_PER_SCAN, Slam
from tb3_navigation.slam_config import SlamConfig

pytest_plugins = ['localization_drives']  # its loop

#: turtlebot3_slam's gmapping_params.yaml (ROBOTIS-GIT/turtlebot3, noetic), the values we share.
TURTLEBOT3_GMAPPING = dict(map_update_interval=2.0, maxUrange=3.0, sigma=0.05, lstep=0.05, astep=0.05,
                           iterations=5, lskip=0, minimumScore=50, linearUpdate=1.0, angularUpdate=0.2,
                           temporalUpdate=0.5, xmin=-10.0, ymin=-10.0, xmax=10.0, ymax=10.0, delta=0.05)


@pytest.fixture(scope='module')
def loop_slam(loop):
    return run(loop)


@pytest.fixture(scope='module')
def world():
    return obstacles('turtlebot3_world')


def test_the_loop_ends_within_5_cm_and_2_degrees_while_odometry_does_not(loop, loop_slam):
    _, poses, _ = loop_slam
    distance, turn = errors(poses[-1:], loop.truth[-1:])
    odom_distance, odom_turn = errors(loop.odom[-1:], loop.truth[-1:])
    assert path_length(loop.truth) > 13.0
    assert odom_distance[0] > 0.10  # what the SLAM has to correct (measured: 0.18 m, 2.8 degrees)
    assert distance[0] < 0.05 and turn[0] < math.radians(2.0)  # measured: 0.2 cm, 0.00 degree
    assert distance[0] < odom_distance[0] / 5


def test_the_pose_stays_within_5_cm_and_2_degrees_all_the_way(loop, loop_slam):
    """Not only at the end: every scan's pose (measured: at most 0.5 cm and 0.55 degree, the
    degrees while turning, when the simulated lidar lags its base by one physics step)."""
    _, poses, _ = loop_slam
    distance, turn = errors(poses, loop.truth)
    assert distance.max() < 0.05 and turn.max() < math.radians(2.0)


def test_at_start_map_is_odom(loop):
    slam = Slam()
    first = slam.update(0.0, loop.odom[0], scans_of(loop)[0], loop.scan_pose)
    assert slam.map_to_odom == IDENTITY
    assert first == pytest.approx(tuple(loop.odom[0]))


def test_map_to_odom_maps_odometry_onto_the_pose(loop, loop_slam):
    slam, poses, _ = loop_slam
    assert compose(slam.map_to_odom, loop.odom[-1]) == pytest.approx(poses[-1], abs=1e-9)


def test_the_maps_walls_lie_on_the_worlds_walls_thin_and_single(loop_slam, world):
    """The issue's goals (tb3_harness.map_quality): >= 95 % of the occupied cells within
    0.10 m of a surface, >= 80 % of the surface facing the free space with an occupied cell
    within 0.10 m, walls a median 2 cells thick or less; and, for no doubled or smeared wall,
    under 0.5 % of the surface doubled and under 5 % thicker than 2 cells. Measured: 100 %,
    100 %, 1 cell, 0 % doubled, 0.6 % thicker."""
    slam, _, _ = loop_slam
    measured = quality(slam, world, WORLD_LOOP_START)
    assert not measured.failures(), measured.summary()
    assert measured.occupied_cells > 500 and measured.surface_points > 1000
    assert measured.doubled_wall_share < 0.005 and measured.thick_wall_share < 0.05, measured.summary()


def test_the_measures_see_what_odometry_alone_draws(loop, world):
    """The bounds above can fail: the map drawn at the odometry's poses (matches never
    accepted, no loop closed) meets the issue's goals (96 % near a surface) but doubles 1.5 % of the
    surface and makes 14 % of it thicker than 2 cells."""
    slam, _, _ = run(loop, slam=Slam(SlamConfig(minimumScore=1e9, do_loop_closing=False)))
    measured = quality(slam, world, WORLD_LOOP_START)
    assert measured.doubled_wall_share > 0.005 and measured.thick_wall_share > 0.05, measured.summary()


def test_a_loop_closed_after_a_blind_stretch_corrects_the_drift_and_the_map(loop, world):
    """Scans 150 to 300 of the loop's 444 see nothing (as in the house's open yard) while the odometry turns
    0.1 rad wrong (a wheel slipping): the pose drifts with it, and when the walls come back the SLAM snaps
    back onto them from 26 cm off. Without loop closure the map keeps what it drew on the way back
    (measured: 91.7 % of the occupied cells near a surface, 6.1 % of the surface doubled); with it, the
    scans that come back near old ones close the loop, the graph spreads the correction and the map is
    drawn anew (100 %, 0 %; the end 0.6 cm off)."""
    ranges = loop.ranges.copy()
    ranges[150:300] = np.inf
    odom = slipped(loop.odom, 150, 300, 0.1)
    results = {}
    for closing in (False, True):
        slam, poses, _ = run(loop, odom=odom, ranges=ranges, slam=Slam(SlamConfig(do_loop_closing=closing)))
        results[closing] = slam, errors(poses, loop.truth)[0], quality(slam, world, WORLD_LOOP_START)
    (_, drifted, before), (closed, corrected, after) = results[False], results[True]
    assert drifted[299] > 0.15 and before.doubled_wall_share > 0.02, before.summary()  # what there is to correct
    assert closed.loops.closures >= 1 and closed.loops.moved > 0.0  # (the last closure 4 mm: the first took the drift)
    assert corrected[-1] < 0.03
    # (A third of the world was never seen: its surface is not covered.)
    assert after.occupied_near_surface > 0.99 and after.doubled_wall_share < 0.005, after.summary()
    assert after.occupied_near_surface > before.occupied_near_surface + 0.05


def slipped(odom, first, last, angle):
    """`odom` (n, 3) turned by `angle` more from scan `first` to `last` (linearly), and so on after."""
    out = np.array(odom, dtype=float)
    for k in range(first, len(out)):
        turn = angle * min(1.0, (k - first) / float(last - first))
        step = relative(odom[first], odom[k])
        cos, sin = math.cos(turn), math.sin(turn)
        out[k] = compose(odom[first], (cos * step[0] - sin * step[1], sin * step[0] + cos * step[1], step[2] + turn))
    return out


def test_a_closures_redraw_is_spread_over_the_scans_after_it_and_ends_as_one_at_once(loop):
    """The map after a closure is drawn anew REDRAW_PER_SCAN scans of the graph at a time (all at once
    took 2 s of CPU in one scan's update on a drive round the house): at the end it is the map every
    scan of the graph draws at its pose, and meanwhile the pose follows the odometry, matched by nothing."""
    ranges = loop.ranges.copy()
    ranges[150:300] = np.inf
    slam, drawn, unmatched = Slam(), [], []
    draw, update = slam.loops.draw, slam.update

    def counted_draw(grid, indices):
        drawn.append(len(indices))
        draw(grid, indices)

    def watched_update(*args):
        redrawing = slam._redraw is not None
        pose = update(*args)
        if redrawing:
            unmatched.append(not slam.matched)
        return pose
    slam.loops.draw, slam.update = counted_draw, watched_update
    run(loop, ranges=ranges, slam=slam)
    assert slam.loops.closures >= 1 and len(drawn) > slam.loops.closures  # spread: more than one draw a closure
    assert max(drawn) <= REDRAW_PER_SCAN and unmatched and all(unmatched)
    assert slam._redraw is None  # done before the drive's end
    whole = OccupancyGrid(slam.grid)
    draw(whole, range(len(slam.loops.graph)))
    assert np.array_equal(whole.hits, slam.map.hits) and np.array_equal(whole.visits, slam.map.visits)


def test_without_a_blind_stretch_no_loop_moves_anything(loop_slam):
    """On the loop as driven the walls never leave the lidar's range: the graph always agrees with
    itself, and no closure moves a pose or redraws the map."""
    slam, _, _ = loop_slam
    assert slam.loops.closures == 0 and len(slam.loops.graph) == slam.map_updates


def test_the_same_input_gives_the_same_map(loop, loop_slam):
    first, poses, _ = loop_slam
    second, again, _ = run(loop)
    assert np.array_equal(first.map_values(), second.map_values())
    assert np.array_equal(poses, again)


@pytest.mark.parametrize('config, motion, added', [
    (dict(), (0.0, 0.0), [0, 3, 6, 9, 12, 15, 18]),  # standing: every 0.5 s (temporalUpdate), so every third scan
    (dict(temporalUpdate=-1.0), (0.0, 0.0), [0]),  # standing, no temporal rule: the first only
    (dict(temporalUpdate=-1.0), (0.1, 0.0), [0, 10]),  # 0.1 m a scan: every 1 m (linearUpdate)
    (dict(temporalUpdate=-1.0), (0.0, 0.06), [0, 4, 8, 12, 16]),  # 0.06 rad a scan: every 0.2 rad (angularUpdate)
])
def test_scans_are_added_by_gmappings_rule(loop, config, motion, added):
    """One scan fed over and over at 5 Hz, the odometry moving by `motion` (m, rad) each
    time; matching is off (minimumScore out of reach) so that the pose follows it."""
    slam = Slam(SlamConfig(minimumScore=1e9, **config))
    scan = scans_of(loop)[0]
    when = []
    for step in range(20):
        updates = slam.map_updates
        slam.update(0.2 * step, (motion[0] * step, 0.0, motion[1] * step), scan, loop.scan_pose)
        if slam.map_updates > updates:
            when.append(step)
    assert when == added


def test_defaults_are_turtlebot3s_and_bad_values_are_named():
    config = SlamConfig()
    assert {name: getattr(config, name) for name in TURTLEBOT3_GMAPPING} == TURTLEBOT3_GMAPPING
    assert config.occ_thresh == 0.25  # gmapping's own default; turtlebot3_slam keeps it
    for name, value in (('maxUrange', -1.0), ('delta', 0.0), ('xmax', -20.0), ('occ_thresh', 1.5),
                        ('iterations', 2.5), ('sigma', math.nan), ('lskip', -1), ('maxRange', 2.0)):
        with pytest.raises(ParameterError, match=r'parameter ~%s = %r' % (name, value)):
            SlamConfig(**{name: value})
    with pytest.raises(ParameterError, match="parameter ~maxUrange = 'far': must be a number"):
        SlamConfig(maxUrange='far')
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.delta = 0.1


def test_a_config_takes_ints_and_floats_as_a_launch_file_gives_them():
    config = SlamConfig(maxUrange=4, iterations=8.0)
    assert config.maxUrange == 4.0 and isinstance(config.maxUrange, float)
    assert config.iterations == 8 and isinstance(config.iterations, int)
    assert config.delta == 0.05


@pytest.fixture(scope='module')
def tour():
    """turtlebot3_house from the living room to the south-east room, 33 m (see drives.HOUSE_TOUR)."""
    return record_drive('turtlebot3_house', HOUSE_TOUR_START, HOUSE_TOUR)


def test_a_tour_of_the_house_drifts_too_little_to_double_walls(tour):
    """A bound of 0.10 m (two cells) and 2 degrees on the pose all the way: a wall seen
    again from a pose off by more than the matcher's reach (0.15 m) would be drawn anew
    beside the old one. Measured: at most 1.7 cm (gained in the corridor, which tells
    little along itself, and kept from there on: the map has no loop to close) and 0.23
    degree; odometry ends 25 cm and 2 degrees off. And the map, with the loop's bounds: 100 %
    of its occupied cells near a surface, walls 1 cell, 0 % doubled, 0.3 % thicker than 2
    cells (the issue's coverage is for a whole house: this tour sees 41 %); within 0.05 m
    100 % too (97.6 % while a scan of a wall's far face could pair with its near one)."""
    slam, poses, jumps = run(tour)
    assert path_length(tour.truth) > 30.0 and not jumps.any()
    distance, turn = errors(poses, tour.truth)
    assert distance.max() < 0.10 and turn.max() < math.radians(2.0)
    house = obstacles('turtlebot3_house')
    measured = quality(slam, house, HOUSE_TOUR_START)
    assert measured.occupied_near_surface >= 0.95 and measured.wall_thickness <= 2, measured.summary()
    assert measured.doubled_wall_share < 0.005 and measured.thick_wall_share < 0.05, measured.summary()
    closely = measure(slam.grid, slam.map_values(), house, HOUSE_TOUR_START[:2], QualityConfig(tolerance=0.05))
    assert closely.occupied_near_surface >= 0.99, closely.summary()


def test_round_the_outside_of_the_house_the_closure_spreads_the_drift_a_relocation_met():
    """Out through the yard and round the outside of the house (drives.HOUSE_OUTSIDE, 70 m of it): with no wall
    seen before in range the pose drifts, and back in through the yard the match no longer finds the old
    walls within its reach: the SLAM relocates, 16 cm at once. The graph's chain takes that step from a
    match against the scans added just before (the odometry's 10 cm), not the relocation's 26 cm, so the
    closures that follow spread the drift over the way round. When the chain took the relocation's step,
    the closures agreed with it and the outside kept its drift: the graph's poses 20 cm off the truth, 4.3 %
    of the occupied cells farther than 0.10 m from a surface; now 6.4 cm at most and none (2026-11-29)."""
    back_in = HOUSE_OUTSIDE[:17]  # back in the hall, at (1.2, 0.4): the loop has closed (the rest costs 4 s)
    assert back_in[-1] == (1.2, 0.4)
    drive = record_drive('turtlebot3_house', HOUSE_TOUR_START, back_in)
    slam, scan_of_node, running = Slam(), [], []
    update, add, running_step = slam.update, slam.loops.add, slam.loops._running_step

    def counted_update(*args):
        scan_of_node.append(None)
        return update(*args)

    def indexed_add(*args, **kwargs):
        scan_of_node[-1] = len(scan_of_node) - 1  # this scan is the graph's next node
        return add(*args, **kwargs)

    def watched_running_step(*args):
        running.append(running_step(*args))
        return running[-1]
    slam.update, slam.loops.add, slam.loops._running_step = counted_update, indexed_add, watched_running_step
    run(drive, slam=slam)
    nodes = [index for index in scan_of_node if index is not None]
    assert len(nodes) == len(slam.loops.graph)
    assert any(step is not None for step in running) and slam.loops.closures >= 1  # what this is about
    distance, turn = errors(slam.loops.graph.poses, drive.truth[nodes])
    assert distance.max() < 0.08 and turn.max() < math.radians(1.0), (distance.max(), math.degrees(turn.max()))
    measured = quality(slam, obstacles('turtlebot3_house'), HOUSE_TOUR_START)
    assert measured.occupied_near_surface > 0.99 and measured.doubled_wall_share < 0.005, measured.summary()


def test_along_a_hallway_the_pose_keeps_the_odometrys_position():
    """A hallway 14 m long with door frames every 2.5 m (the house's hallways: two walls that tell
    nothing along them, a few frames that tell a little), driven on perfect odometry. The frames' few
    points once slid the pose along as the map grew: 6.5 cm off at worst over 11 m (slam.SURE
    0); the odometry now holds what the scan tells too little of: 1.4 cm (2026-11-29)."""
    from test_matcher import SENSOR, box, ray_cast
    hallway = [box(5.0, 0.65, 14.0, 0.1), box(5.0, -0.65, 14.0, 0.1)]
    hallway += [box(x, 0.55 * side, 0.1, 0.1) for x, side in ((1.5, 1), (4.0, -1), (6.5, 1), (9.0, -1))]
    rng, slam, along = np.random.default_rng(3), Slam(), []
    for step, x in enumerate(np.arange(-1.0, 10.0, 0.05)):
        pose = slam.update(0.2 * step, (x, 0.0, 0.0), ray_cast(hallway, tuple(compose((x, 0.0, 0.0), SENSOR)), rng),
                           SENSOR)
        along.append(pose[0] - x)
    assert slam.matched and np.abs(along).max() < 0.03, np.abs(along).max()
