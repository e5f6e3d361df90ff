"""tb3_navigation.matcher: scans put back where they were taken on maps of known rooms."""
import math

import numpy as np
import pytest

from tb3_common.pose2d import compose
from tb3_navigation import matcher, wall_shapes
from tb3_navigation.occupancy import OccupancyGrid
from tb3_navigation.scan import Scan
from tb3_sim_nav import world_map
from tb3_sim_nav.world_file import Obstacle

SIGMA = 0.05  # turtlebot3_slam's sigma
RANGE_MIN, RANGE_MAX, MAX_URANGE = 0.12, 3.5, 3.0
SENSOR = (-0.032, 0.0, 0.0)  # base_scan on the Burger


def box(x, y, size_x, size_y, yaw=0.0):
    return Obstacle(kind='box', size=(size_x, size_y, 0.4), position=(x, y, 0.2), yaw=yaw, color=None)


def cylinder(x, y, radius):
    return Obstacle(kind='cylinder', size=(radius, 0.4), position=(x, y, 0.2), yaw=0.0, color=None)


#: A room 4 x 3 m with a pillar and a box in it, walls 0.1 m thick.
ROOM = [box(0.0, 1.55, 4.2, 0.1), box(0.0, -1.55, 4.2, 0.1), box(2.05, 0.0, 0.1, 3.0), box(-2.05, 0.0, 0.1, 3.0),
        cylinder(0.8, 0.6, 0.15), box(-1.0, -0.8, 0.4, 0.3, yaw=0.5)]
#: A corridor 1 m wide and 12 m long: from its middle its ends are out of range.
CORRIDOR = [box(0.0, 0.55, 12.0, 0.1), box(0.0, -0.55, 12.0, 0.1)]


def ray_cast(obstacles, sensor, rng, beams=360, noise=0.01):
    """A scan of `obstacles` from `sensor` (x, y, yaw): sphere tracing on the signed distance."""
    angles = sensor[2] + np.arange(beams) * 2 * math.pi / beams
    directions = np.stack((np.cos(angles), np.sin(angles)), axis=-1)
    travelled = np.zeros(beams)
    for _ in range(200):
        distance = world_map.signed_distance(obstacles, np.asarray(sensor[:2]) + travelled[:, None] * directions)
        travelled = np.where(distance > 1e-4, travelled + distance, travelled)
    ranges = np.where(travelled < RANGE_MAX, travelled + rng.normal(0.0, noise, beams), math.inf)
    return Scan(0.0, 2 * math.pi / beams, ranges, RANGE_MIN, RANGE_MAX)


def field_of(obstacles, poses, rng):
    """The likelihood field of the map made of scans taken at the base's `poses`."""
    grid_map = OccupancyGrid.around(0.05, -3.0, -3.0, 7.0, 3.0)
    for pose in poses:
        sensor = tuple(compose(pose, SENSOR))
        grid_map.add_scan(sensor, ray_cast(obstacles, sensor, rng), MAX_URANGE, RANGE_MAX)
    return matcher.WallField(wall_shapes.WallShapes.of_map(grid_map.grid, *grid_map.walls()), SIGMA)


def points_at(obstacles, pose, rng):
    """A scan taken with the base at `pose`, as end points in the base frame."""
    return ray_cast(obstacles, tuple(compose(pose, SENSOR)), rng).hit_points(SENSOR, max_range=MAX_URANGE)


@pytest.fixture(scope='module')
def room():
    rng = np.random.default_rng(3)
    return field_of(ROOM, [(-1.0, 0.5, 0.0), (1.0, -0.6, 2.0), (0.0, 0.0, -1.0)], rng)


def error(pose, truth):
    return math.hypot(pose[0] - truth[0], pose[1] - truth[1]), abs(pose[2] - truth[2])


def test_the_score_counts_the_points_on_walls(room):
    truth = (0.3, -0.2, 0.4)
    points = points_at(ROOM, truth, np.random.default_rng(4))
    assert room.score(matcher.place(truth, points)) > 0.9 * len(points)
    assert room.score(matcher.place((0.6, 0.1, 0.4), points)) < 0.2 * len(points)


@pytest.mark.parametrize('offset', [(0.03, -0.02, 0.02), (-0.04, 0.01, -0.03), (0.0, 0.0, 0.04)])
def test_refine_puts_a_scan_back_where_it_was_taken(room, offset):
    truth = (0.3, -0.2, 0.4)
    points = points_at(ROOM, truth, np.random.default_rng(5))
    pose, score = matcher.refine(room, points, np.add(truth, offset), iterations=10)
    distance, turn = error(pose, truth)
    assert distance < 0.005 and turn < math.radians(0.2)
    assert score > 0.9 * len(points)


def test_the_search_lands_on_the_node_of_its_grid_at_the_truth(room):
    truth = (-0.5, 0.4, -0.7)
    points = points_at(ROOM, truth, np.random.default_rng(6))
    prior = np.add(truth, (0.1, -0.05, 0.1))  # a node of the search's grid: 2 steps, 1 step, 2 steps
    start, score = matcher.search(room, points, prior, 0.1, 0.1, 0.05, 0.05)
    distance, turn = error(start, truth)
    assert distance < 1e-9 and turn < 1e-9
    assert score > 2 * room.score(matcher.place(prior, points))


def test_the_search_stays_within_its_reach(room):
    truth = (-0.5, 0.4, -0.7)
    points = points_at(ROOM, truth, np.random.default_rng(6))
    prior = np.add(truth, (0.2, 0.0, 0.0))
    start, _ = matcher.search(room, points, prior, 0.1, 0.1, 0.05, 0.05)
    assert start[0] == pytest.approx(prior[0] - 0.1)  # as near the truth as it may go


def test_along_a_corridor_the_prior_holds_the_pose():
    """Nothing in range tells where along the corridor the robot is: the prior's
    pull keeps that, while the walls correct the rest."""
    rng = np.random.default_rng(7)
    corridor = field_of(CORRIDOR, [(x, 0.0, 0.0) for x in np.arange(-2.0, 6.1, 1.0)], rng)
    truth = (2.0, 0.1, 0.05)
    points = points_at(CORRIDOR, truth, rng)
    prior = (2.04, 0.07, 0.08)
    pose, _ = matcher.refine(corridor, points, prior, iterations=10, prior=prior, prior_weight=20.0)
    assert pose[0] == pytest.approx(prior[0], abs=0.002)  # along: kept
    assert pose[1] == pytest.approx(truth[1], abs=0.005)  # across: corrected
    assert pose[2] == pytest.approx(truth[2], abs=math.radians(0.3))


def test_a_wall_seen_from_one_side_does_not_pull_a_scan_of_its_other_face():
    """A wall 0.12 m thick (the house's inner walls) mapped from the north; the robot south of it sees its
    south face, 0.12 m from the mapped one, within the pairing's reach. Paired with it, the scan pulled
    the pose 9 cm north of the truth; the side the cells were seen from keeps it where the prior holds it."""
    rng = np.random.default_rng(9)
    world = [box(0.0, 0.0, 6.0, 0.12), box(0.0, 1.5, 6.0, 0.1)]
    north = [(x, 0.7, 0.0) for x in np.arange(-2.0, 2.1, 0.5)]
    grid_map = OccupancyGrid.around(0.05, -3.0, -3.0, 7.0, 3.0)
    for pose in north:
        sensor = tuple(compose(pose, SENSOR))
        grid_map.add_scan(sensor, ray_cast(world, sensor, rng), MAX_URANGE, RANGE_MAX)
    truth = (0.0, -0.5, 0.0)
    points = points_at(world, truth, rng)
    moved = {}
    for sides, views in (('known', grid_map.hit_views()), ('unknown', None)):
        field = matcher.WallField.of_map(grid_map.grid, grid_map.occupied(), SIGMA, grid_map.hit_means(), views)
        pose, _ = matcher.refine(field, points, truth, iterations=10, prior=truth, prior_weight=20.0)
        moved[sides] = error(pose, truth)[0]
    assert moved['known'] < 0.005 and moved['unknown'] > 0.05, moved


def test_an_empty_map_leaves_the_prior_alone():
    empty = OccupancyGrid.around(0.05, -3.0, -3.0, 3.0, 3.0)
    field = matcher.WallField.of_map(empty.grid, empty.occupied(), SIGMA, empty.hit_means())
    points = points_at(ROOM, (0.0, 0.0, 0.0), np.random.default_rng(8))
    prior = (0.1, 0.2, 0.3)
    assert field.empty
    assert matcher.search(field, points, prior, 0.1, 0.1, 0.05, 0.05) == (prior, 0.0)
    pose, score = matcher.refine(field, points, prior, iterations=5)
    assert pose == pytest.approx(prior) and score == 0.0


def test_shapes_kept_up_to_date_scan_by_scan_are_those_of_the_whole_map():
    """WallShapes refits only the cells near those a scan changed; after each scan its wall points
    and pairing matrices are those made from the whole map at once, and so are a field's over a
    box and its matches."""
    rng = np.random.default_rng(9)
    grid_map = OccupancyGrid.around(0.05, -3.0, -3.0, 7.0, 3.0)
    grid_map.take_touched()
    shapes = wall_shapes.WallShapes(grid_map.grid)
    for pose in [(-1.0, 0.5, 0.0), (1.0, -0.6, 2.0), (0.0, 0.0, -1.0), (0.5, 0.8, 2.5)]:
        sensor = tuple(compose(pose, SENSOR))
        grid_map.add_scan(sensor, ray_cast(ROOM, sensor, rng), MAX_URANGE, RANGE_MAX)
        cells = grid_map.take_touched()
        assert 0 < len(cells) < grid_map.hits.size // 4  # a scan changes only the cells it saw
        shapes.update(cells, *grid_map.walls(cells=cells))
        whole = wall_shapes.WallShapes.of_map(grid_map.grid, *grid_map.walls())
        np.testing.assert_array_equal(shapes.points, whole.points)
        np.testing.assert_array_equal(shapes.pairing, whole.pairing)
        np.testing.assert_array_equal(shapes.views, whole.views)
    assert shapes.has_point(np.flatnonzero(grid_map.occupied())).all()
    truth = (0.3, -0.2, 0.4)
    points = points_at(ROOM, truth, np.random.default_rng(4))
    around = matcher.WallField(shapes, SIGMA, box=(0, grid_map.grid.height, 0, 80))  # x up to 1 m: the room's part
    everywhere = matcher.WallField(whole, SIGMA)
    assert around.covers((10, 20, 10, 20)) and not around.covers((10, 20, 70, 90))
    prior = np.add(truth, (0.05, -0.05, 0.05))
    inside = points[np.hypot(*matcher.place(prior, points).T - np.array([[-1.0], [0.0]])) < 1.5]
    assert len(inside) > 30
    for field in (around, everywhere):
        pose, _ = matcher.refine(field, inside, prior, iterations=10)
        assert error(pose, truth)[0] < 0.01
    assert (matcher.search(around, inside, prior, 0.1, 0.1, 0.05, 0.05)
            == matcher.search(everywhere, inside, prior, 0.1, 0.1, 0.05, 0.05))
