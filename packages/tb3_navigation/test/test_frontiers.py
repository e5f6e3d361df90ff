"""tb3_navigation.frontiers on hand-drawn grids: frontier cells and frontiers, their size, centroid and
goal, explore_lite's cost rule, the distance along the path, reachability, room for the robot, a frontier
in the open or outside explore_bounds, the blacklist, a closed map, the explored area and the checks of
ExploreConfig. The Explorer's loop and the maps of the worlds are test_exploration.py's. No ROS."""
import math

import numpy as np
import pytest
from frontier_maps import RESOLUTION, picture, room
from scipy import ndimage

from tb3_common.grid import Grid
from tb3_harness.nav_sim import world_cut
from tb3_navigation.costmap import Costmap, CostmapConfig
from tb3_navigation.frontiers import (
    BLACKLISTED,
    CANDIDATE,
    IN_THE_OPEN,
    NO_ROOM,
    OUTSIDE,
    TOO_SMALL,
    UNREACHABLE,
    ExploreConfig,
    FrontierSearch,
    explored_area,
    frontier_cells,
    label_frontiers,
)
from tb3_navigation.planner import GlobalPlanner, plan_length
from tb3_sim_nav import world_map

# --- frontier cells and frontiers ------------------------------------------------------------

def naive_frontier_cells(values):
    height, width = values.shape
    cells = np.zeros(values.shape, dtype=bool)
    for iy in range(height):
        for ix in range(width):
            if values[iy, ix] != 0:
                continue
            for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                if 0 <= iy + dy < height and 0 <= ix + dx < width and values[iy + dy, ix + dx] < 0:
                    cells[iy, ix] = True
    return cells


@pytest.mark.parametrize('seed', range(5))
def test_frontier_cells_are_the_free_cells_with_an_unknown_four_neighbour(seed):
    """Against a cell-by-cell reading of the definition, on random maps (each cell free, occupied
    or unknown); and the frontiers are the 8-connected groups of those cells."""
    rng = np.random.default_rng(seed)
    values = rng.choice(np.array([0, 0, 0, 100, -1], dtype=np.int8), size=(30, 40))
    cells = frontier_cells(values)
    assert np.array_equal(cells, naive_frontier_cells(values))
    labels, count = label_frontiers(values)
    assert np.array_equal(labels > 0, cells)
    for index in range(1, count + 1):  # each group is one piece, 8-connected, and no two touch
        group = labels == index
        assert ndimage.label(group, structure=np.ones((3, 3)))[1] == 1
        grown = ndimage.binary_dilation(group, structure=np.ones((3, 3)))
        assert not np.any(grown & cells & ~group)


def test_a_diagonal_unknown_cell_and_the_map_edge_make_no_frontier():
    grid, values, _ = picture("""
        ....
        ...#
        ..#?
    """)
    assert not frontier_cells(values).any()  # the free cells touch the unknown ones only diagonally
    grid, values, _ = picture("""
        ....
        .R..
    """)
    assert not frontier_cells(values).any()  # off the grid is not unknown


def test_size_centroid_and_goal_of_a_straight_frontier():
    """A 3 x 1 m room whose east half is unknown: one frontier, the 20 free cells of the column
    beside the unknown part, 1.0 m; the goal is its cell nearest along the plan, in the middle."""
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    robot = (0.25, 0.5, 0.0)
    search = FrontierSearch().search(grid, values, robot)
    assert len(search.frontiers) == 1
    frontier = search.best
    assert frontier.status == CANDIDATE
    assert len(frontier.points) == 20 and frontier.size == pytest.approx(1.0)
    assert frontier.centroid == pytest.approx((1.475, 0.5))
    assert np.allclose(frontier.points[:, 0], 1.475)
    assert frontier.goal[0] == pytest.approx(1.475) and abs(frontier.goal[1] - 0.5) <= RESOLUTION
    assert frontier.goal[2] == pytest.approx(0.0, abs=0.2)  # it faces on, into the unknown part
    # In an open room the cheapest path is the shortest: along 8 neighbours, as long as the octile distance.
    start, end = grid.to_cells(np.array(robot[:2])), grid.to_cells(np.array(frontier.goal[:2]))
    dx, dy = np.abs(end - start)
    octile = RESOLUTION * (max(dx, dy) + (math.sqrt(2) - 1) * min(dx, dy))
    assert frontier.distance == pytest.approx(octile)
    assert frontier.cost == pytest.approx(3.0 * frontier.distance - 1.0 * frontier.size)


def two_frontiers():
    """A 4 x 3 m room seen up to x = 3 m, but for a 0.6 m doorway-sized gap in the west wall
    that opens on unknown space (a small frontier 0.5 m from the robot)."""
    grid, values = room(4.0, 3.0, unknown_from=3.0)
    gap = grid.to_cells(np.array([[-0.01, 1.2], [-0.01, 1.75]]))
    values[gap[0, 1]:gap[1, 1] + 1, 0] = -1
    return grid, values, (0.5, 1.5, 0.0)


def test_the_cost_rule_weighs_distance_against_size():
    """cost = potential_scale * distance - gain_scale * size: the near 0.6 m gap wins with
    explore_lite's weights, the far 3 m frontier once size weighs enough."""
    grid, values, robot = two_frontiers()
    search = FrontierSearch().search(grid, values, robot)
    near, far = sorted(search.candidates, key=lambda frontier: frontier.distance)
    assert near.size == pytest.approx(0.6) and far.size == pytest.approx(3.0)
    for frontier in (near, far):
        assert frontier.cost == pytest.approx(3.0 * frontier.distance - frontier.size)
    assert search.best is near
    heavier = FrontierSearch(ExploreConfig(gain_scale=4.0)).search(grid, values, robot)
    assert heavier.best.size == pytest.approx(3.0)
    closer = FrontierSearch(ExploreConfig(potential_scale=0.0)).search(grid, values, robot)
    assert closer.best.size == pytest.approx(3.0)
    turned = FrontierSearch(ExploreConfig(orientation_scale=10.0)).search(grid, values, (0.5, 1.5, math.pi))
    assert turned.best.size == pytest.approx(0.6)  # facing west, the gap is straight ahead
    assert turned.best.turn < 0.5 and turned.frontiers[1].turn > 2.5


def test_the_distance_is_the_path_s_not_the_straight_line_s():
    """A frontier 1 m east of the robot behind a wall is 3 m away by the path round the wall's
    end; another 2.5 m away in a straight line, in the open, is nearer and chosen."""
    grid, values, robot = picture('\n'.join(
        ['#' * 80] + ['#' + '.' * 40 + '#' + '?' * 37 + '#'] * 5 + ['#' + '.' * 40 + '#' + '.' * 37 + '#'] * 15 +
        ['#' + '.' * 78 + '#'] * 20 + ['#' * 80]))
    robot = (1.0, 1.75, 0.0)
    behind = FrontierSearch().search(grid, values, robot)
    frontier = behind.best
    straight = math.hypot(frontier.goal[0] - robot[0], frontier.goal[1] - robot[1])
    plan = GlobalPlanner().make_plan(Costmap(grid, CostmapConfig(), static=values), robot, frontier.goal)
    assert frontier.distance > straight + 0.5
    assert frontier.distance == pytest.approx(plan_length(plan), rel=0.1)


def test_a_frontier_no_plan_reaches_is_not_chosen():
    """A closed room beside the robot's holds a frontier (a cell its lidar saw free through a
    window, beside unknown floor): nearer and bigger than the open one, but out of reach."""
    grid, values = room(6.0, 2.0, unknown_from=5.0)
    values[:, 41] = 100  # a wall at x = 2 m, closed: the room east of it is sealed
    values[5:35, 45:60] = -1  # unknown floor in it, free around: frontier cells all round
    search = FrontierSearch().search(grid, values, (0.5, 1.0, 0.0))
    sealed = [frontier for frontier in search.frontiers if frontier.centroid[0] > 2.0]
    assert sealed and all(frontier.status == UNREACHABLE for frontier in sealed)
    assert search.best is None or search.best.centroid[0] < 2.0
    assert 'boxed in' in search.why_none()


def test_a_frontier_where_the_robot_does_not_fit_and_a_small_one_are_not_chosen():
    """North of a closed room, a strip of floor 0.15 m wide along its wall, seen (through a window)
    with unknown space all round: no cell of it is 0.213 m (a cell beyond the Burger's circumscribed
    radius) from the wall. In the room, an unknown patch of 1 x 3 cells: a frontier of 8 cells, 0.4 m."""
    values = np.full((30, 60), -1, dtype=np.int8)
    values[0:21, 0:60] = 100
    values[1:20, 1:59] = 0
    values[21:24, 10:51] = 0
    values[8:11, 30] = -1
    grid = Grid(RESOLUTION, 60, 30)
    search = FrontierSearch().search(grid, values, (0.5, 0.5, 0.0))
    statuses = sorted((frontier.status, round(frontier.size, 2)) for frontier in search.frontiers)
    assert statuses == [(NO_ROOM, 2.25), (TOO_SMALL, 0.4)], statuses
    assert search.best is None and 'no frontier worth visiting' in search.why_none()
    assert 'boxed in' not in search.why_none()
    smaller = FrontierSearch(ExploreConfig(min_frontier_size=0.4)).search(grid, values, (0.5, 0.5, 0.0))
    assert smaller.best is not None and smaller.best.size == pytest.approx(0.4)


def test_a_goal_leaves_a_cell_to_spare_beyond_the_circumscribed_radius():
    """The robot on a strip of floor 0.20 m wide along a wall, unknown beyond: the strip's outer cells'
    centres lie 0.20 m from the wall's, beyond the circumscribed radius (0.163 m) but within a cell of
    it. Move_base's costmap draws a wall a cell nearer as often as not, and a robot sent there could not
    turn (frontiers.TURN_MARGIN): no room. On a strip 0.25 m wide the outer edge has room."""
    grid = Grid(RESOLUTION, 60, 30)
    for rows, status in ((4, NO_ROOM), (5, CANDIDATE)):
        values = np.full((30, 60), -1, dtype=np.int8)
        values[10, :] = 100
        values[11:11 + rows, 5:55] = 0
        robot = (30.5 * RESOLUTION, (11 + rows - 0.5) * RESOLUTION, 0.0)
        statuses = [frontier.status for frontier in FrontierSearch().search(grid, values, robot).frontiers]
        assert statuses == [status], (rows, statuses)


def test_a_frontier_far_from_every_wall_is_in_the_open():
    """A 12 x 3 m corridor walled only on its west end and its sides for the first 4 m, seen up
    to 8 m east: its frontier at x = 8 m is 4 m from the last wall (more than max_wall_distance,
    2.5 m), so the robot is not sent out where the lidar would see no wall. With the limit
    at 0 (none) it is a candidate; a wall seen near it makes it one too."""
    grid, values = room(12.0, 3.0, unknown_from=8.0)
    values[[0, -1], 81:] = 0  # no side walls east of x = 4 m
    values[[0, -1], 161:] = -1
    search = FrontierSearch().search(grid, values, (1.0, 1.5, 0.0))
    assert [frontier.status for frontier in search.frontiers if frontier.size > 1.0] == [IN_THE_OPEN]
    assert 'in the open' in search.why_none()
    assert FrontierSearch(ExploreConfig(max_wall_distance=0.0)).search(grid, values, (1.0, 1.5, 0.0)).best
    values[-1, 140:150] = 100  # a piece of wall seen 1 m before the frontier
    assert FrontierSearch().search(grid, values, (1.0, 1.5, 0.0)).best is not None


def test_a_frontier_outside_explore_bounds_is_not_chosen():
    """A 3 x 1 m room seen up to x = 1.5 m: with explore_bounds ending at x = 1.2 m its frontier
    (x = 1.475 m) is outside and exploration is over; bounds reaching past it change nothing."""
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    robot = (0.25, 0.5, 0.0)
    outside = FrontierSearch(ExploreConfig(explore_bounds=(-1.0, -1.0, 1.2, 2.0))).search(grid, values, robot)
    assert outside.best is None and outside.frontiers[0].status == OUTSIDE
    assert 'outside explore_bounds' in outside.why_none()
    inside = FrontierSearch(ExploreConfig(explore_bounds=(-1.0, -1.0, 2.0, 2.0))).search(grid, values, robot)
    assert inside.best.goal == FrontierSearch().search(grid, values, robot).best.goal
    for bounds in ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 1.0), (0.0, 0.0, float('inf'), 1.0)):
        with pytest.raises(ValueError, match='explore_bounds'):
            ExploreConfig(explore_bounds=bounds)


def test_the_blacklist_rules_out_goals_within_its_radius():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    search = FrontierSearch()
    first = search.search(grid, values, (0.25, 0.5, 0.0)).best.goal
    second = search.search(grid, values, (0.25, 0.5, 0.0), blacklist=[first[:2]]).best
    assert second.status == CANDIDATE
    assert math.hypot(second.goal[0] - first[0], second.goal[1] - first[1]) > 0.25
    everywhere = [(1.475, y) for y in np.arange(0.0, 1.01, 0.2)]
    left = search.search(grid, values, (0.25, 0.5, 0.0), blacklist=everywhere)
    assert left.best is None and left.frontiers[0].status == BLACKLISTED
    assert 'blacklisted' in left.why_none() and 'boxed in' not in left.why_none()


def test_a_closed_map_has_no_frontier():
    grid, values = world_map.map_of_world(world_cut('turtlebot3_world'))
    search = FrontierSearch().search(grid, values, (-2.0, -0.5, 0.0))
    assert search.frontiers == () and search.best is None
    assert 'closed' in search.why_none()


def test_explored_area():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    free, occupied, known = explored_area(grid, values)
    assert free == pytest.approx(30 * 20 * RESOLUTION ** 2)  # 1.5 x 1.0 m
    assert occupied == pytest.approx((31 * 2 + 20) * RESOLUTION ** 2)  # walls round the known part
    assert known == pytest.approx(1.0)  # the known part is a rectangle


def test_config_checks_name_the_parameter():
    for name, value in (('planner_frequency', 0.0), ('progress_timeout', -1.0), ('gain_scale', float('nan')),
                        ('min_frontier_size', True), ('max_wall_distance', -0.1)):
        with pytest.raises(ValueError, match=name):
            ExploreConfig(**{name: value})
