"""tb3_navigation.slam on odd input: beams that are no numbers, too few of them, odometry that jumps,
restarts, goes back in time or turns wheels on a robot held still, and a reset. The rest of the SLAM's
unit tests are test_slam.py's.
"""
import math

import numpy as np
import pytest
from slam_drives import errors, obstacles, quality, run, scans_of

from tb3_common.pose2d import IDENTITY, compose, relative
from tb3_harness.drives import WORLD_LOOP_START
from tb3_navigation.scan import Scan
from tb3_navigation.slam import Slam

pytest_plugins = ['localization_drives']  # its loop


@pytest.fixture(scope='module')
def world():
    return obstacles('turtlebot3_world')


def test_nan_and_infinite_beams_are_skipped_one_by_one(loop, world):
    """A third of every scan's beams turned to NaN, +inf or -inf: the pose and the map
    are as good as with the whole scans."""
    rng = np.random.default_rng(12)
    ranges = loop.ranges.copy()
    spoilt = rng.random(ranges.shape) < 1 / 3
    ranges[spoilt] = rng.choice([math.nan, math.inf, -math.inf], size=np.count_nonzero(spoilt))
    slam, poses, _ = run(loop, ranges=ranges)
    distance, turn = errors(poses, loop.truth)
    assert distance.max() < 0.05 and turn.max() < math.radians(2.0)
    assert quality(slam, world, WORLD_LOOP_START).occupied_near_surface >= 0.95


def test_a_scan_with_too_few_valid_beams_does_not_move_the_pose(loop):
    """Fewer valid beams than minimumScore (50) cannot make a match: the correction stays."""
    slam, _, _ = run(loop, indices=range(60))
    before = slam.map_to_odom
    ranges = np.full(len(loop.ranges[60]), math.nan)
    ranges[::8] = loop.ranges[60][::8]  # 45 beams left
    scan = Scan(loop.angle_min, loop.angle_increment, ranges, loop.range_min, loop.range_max)
    pose = slam.update(12.0, loop.odom[60], scan, loop.scan_pose)
    assert not slam.matched
    assert slam.map_to_odom == before
    assert pose == pytest.approx(compose(before, loop.odom[60]))
    blind = Scan(loop.angle_min, loop.angle_increment, np.full(360, math.nan), loop.range_min, loop.range_max)
    values = slam.map_values()
    slam.update(12.6, loop.odom[61], blind, loop.scan_pose)
    assert slam.map_to_odom == before and np.array_equal(slam.map_values(), values)


def test_a_teleport_the_odometry_saw_is_followed(loop):
    """After most of the loop the robot is put back where it was 56 s earlier, and the
    odometry jumps there too (with its drift of then: 14 cm and 2.7 degrees from where
    the map has it): the map takes it there and follows it for 20 s more."""
    indices = list(range(0, 381)) + list(range(100, 200))
    _, poses, jumps = run(loop, indices=indices)
    assert np.flatnonzero(jumps).tolist() == [381]
    distance, turn = errors(poses, loop.truth[indices])
    assert distance.max() < 0.05 and turn.max() < math.radians(2.0)


def test_an_odometry_reset_in_place_does_not_move_the_pose(loop, world):
    """At 40 s the odometry restarts from zero while the robot drives on: the pose in the
    map goes on, map -> odom takes the jump."""
    odom = loop.odom.copy()
    odom[200:] = relative(loop.odom[200], loop.odom[200:])
    slam, poses, jumps = run(loop, odom=odom)
    assert np.flatnonzero(jumps).tolist() == [200]
    distance, turn = errors(poses, loop.truth)
    assert distance.max() < 0.05 and turn.max() < math.radians(2.0)
    assert quality(slam, world, WORLD_LOOP_START).occupied_near_surface >= 0.95


def test_wheels_turning_on_a_robot_held_still_do_not_turn_the_pose(loop, world):
    """At 40 s the robot is held still for 5 s while its wheels turn it at 1 rad/s in the odometry (as a
    Burger stuck on a corner did in an exploration of the house), then drives on. Each scan's prediction
    is then 0.2 rad off, beyond the search's reach: followed, the pose turned 56 degrees for good and
    the map was lost. Found again at any heading where the scan lands on the walls, the pose stays put."""
    held, turn = 25, 0.2  # scans, rad of odometry per scan
    indices = list(range(0, 201)) + [200] * held + list(range(201, len(loop.times)))
    spun = compose(loop.odom[200], (0.0, 0.0, held * turn))
    odom = np.array([loop.odom[k] for k in range(201)]
                    + [compose(loop.odom[200], (0.0, 0.0, (j + 1) * turn)) for j in range(held)]
                    + [compose(spun, relative(loop.odom[200], loop.odom[k])) for k in range(201, len(loop.times))])
    slam, poses, _ = run(loop, indices=range(len(indices)), odom=odom, ranges=loop.ranges[indices])
    distance, heading = errors(poses, loop.truth[indices])
    assert distance.max() < 0.05 and heading.max() < math.radians(2.0), (distance.max(), math.degrees(heading.max()))
    assert quality(slam, world, WORLD_LOOP_START).occupied_near_surface >= 0.95


def test_bad_odometry_and_a_blind_first_scan_change_nothing(loop):
    slam = Slam()
    scans = scans_of(loop)
    blind = Scan(loop.angle_min, loop.angle_increment, np.full(360, math.nan), loop.range_min, loop.range_max)
    slam.update(0.0, loop.odom[0], blind, loop.scan_pose)
    assert slam.map_updates == 0 and np.all(slam.map_values() == -1)
    slam.update(0.2, loop.odom[1], scans[1], loop.scan_pose)
    assert slam.map_updates == 1  # the first scan that shows something starts the map
    pose, values = slam.pose, slam.map_values()
    assert slam.update(0.4, (math.nan, 0.0, 0.0), scans[2], loop.scan_pose) == pose
    assert slam.update(0.6, (0.0, math.inf, 0.0), scans[3], loop.scan_pose) == pose
    assert np.array_equal(slam.map_values(), values) and slam.map_to_odom == IDENTITY


def test_time_going_back_restarts_the_temporal_rule(loop):
    """As when the simulation is reset and its clock starts again at 0."""
    slam, _, _ = run(loop, indices=range(40))  # then straight on up the west side: no turn adds a scan
    scans, added = scans_of(loop), []
    for step, index in enumerate(range(40, 46)):
        updates = slam.map_updates
        slam.update(0.2 * step, loop.odom[index], scans[index], loop.scan_pose)
        added.append(slam.map_updates - updates)
    assert added == [0, 0, 0, 1, 0, 0]  # 0.6 s after the stamp that went back


def test_reset_starts_a_new_map(loop):
    slam, _, _ = run(loop, indices=range(30))
    slam.reset()
    assert slam.pose is None and slam.map_to_odom == IDENTITY
    assert np.all(slam.map_values() == -1)
    pose = slam.update(0.0, loop.odom[30], scans_of(loop)[30], loop.scan_pose)
    assert pose == pytest.approx(tuple(loop.odom[30]))
    assert np.count_nonzero(slam.map_values() == 100) > 100
