"""tb3_navigation.exploration and the frontiers of real maps: the Explorer's loop on a hand-drawn room (an
aborted goal blacklisted, progress_timeout, a reached goal waiting for a newer map, the end for good);
the frontiers of a partial map of turtlebot3_house made from a recorded drive, judged against the world
file, and what a search on the SLAM's 20 m map costs; and exploration in a closed loop (explore_sim) that
maps turtlebot3_world's floor. No ROS."""
import math

import numpy as np
import pytest
from frontier_maps import room
from scipy import ndimage

from tb3_common.pose2d import compose
from tb3_harness import ROOT as REPO
from tb3_harness.drives import HOUSE_TOUR, HOUSE_TOUR_START, record_drive
from tb3_harness.explore_sim import ExploreLoop
from tb3_harness.map_quality import measure
from tb3_navigation.costmap import Costmap, CostmapConfig
from tb3_navigation.exploration import ABORTED, DONE, KEEP, SEND, SUCCEEDED, WAIT, Explorer
from tb3_navigation.frontiers import NAVFN, FrontierSearch
from tb3_navigation.occupancy import OccupancyGrid
from tb3_navigation.planner import GlobalPlanner, plan_length
from tb3_navigation.scan import Scan
from tb3_sim_nav import world_map
from tb3_sim_nav.world_file import load_world

# --- the explorer's loop ---------------------------------------------------------------------

def test_an_aborted_goal_is_blacklisted_and_another_sent():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    explorer, robot = Explorer(), (0.25, 0.5, 0.0)
    first = explorer.decide(0.0, grid, values, robot)
    assert first.action == SEND and explorer.goals_sent == 1
    assert explorer.decide(3.0, grid, values, robot).action == KEEP
    explorer.result(4.0, first.goal, ABORTED)
    assert explorer.blacklist == [first.goal[:2]]
    second = explorer.decide(4.0, grid, values, robot)
    assert second.action == SEND and math.hypot(second.goal[0] - first.goal[0], second.goal[1] - first.goal[1]) > 0.25
    explorer.result(5.0, first.goal, ABORTED)  # the old goal again: not the current one, ignored
    assert len(explorer.blacklist) == 1


def test_no_progress_for_progress_timeout_blacklists_the_target():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    explorer, robot = Explorer(), (0.25, 0.5, 0.0)
    first = explorer.decide(0.0, grid, values, robot).goal
    for now in (10.0, 20.0, 30.0):
        assert explorer.decide(now, grid, values, robot).action == KEEP
    assert not explorer.blacklist
    late = explorer.decide(30.5, grid, values, robot)
    assert explorer.blacklist == [first[:2]] and 'no progress' in explorer.take_notes()[0]
    assert late.action == SEND and late.goal != first


def test_getting_nearer_is_progress():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    explorer = Explorer()
    for step, now in enumerate(np.arange(0.0, 90.0, 3.0)):
        x = 0.25 + min(step, 20) * 0.05 if now < 60.0 else 1.25  # stands still at 1.25 m from 60 s on
        explorer.decide(now, grid, values, (x, 0.5, 0.0))
        assert not explorer.blacklist or now > 90.0
    assert explorer.decide(95.0, grid, values, (1.25, 0.5, 0.0)).action == SEND  # 30 s still: given up
    assert len(explorer.blacklist) == 1


def test_a_reached_goal_waits_for_a_newer_map_and_is_not_visited_twice():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    explorer = Explorer()
    goal = explorer.decide(0.0, grid, values, (0.25, 0.5, 0.0), map_time=0.0).goal
    explorer.result(6.0, goal, SUCCEEDED)
    at_goal = (goal[0], goal[1], 0.0)
    assert explorer.decide(6.0, grid, values, at_goal, map_time=5.0).action == WAIT
    assert explorer.decide(10.9, grid, values, at_goal, map_time=5.0).action == WAIT
    again = explorer.decide(8.0, grid, values, at_goal, map_time=7.0)  # still a frontier there
    assert explorer.blacklist == [goal[:2]] and 'reached' in explorer.take_notes()[0]
    assert again.action == SEND and math.hypot(again.goal[0] - goal[0], again.goal[1] - goal[1]) > 0.25


def test_no_newer_map_waits_5_s_at_most():
    grid, values = room(3.0, 1.0, unknown_from=1.5)
    explorer = Explorer()
    goal = explorer.decide(0.0, grid, values, (0.25, 0.5, 0.0), map_time=0.0).goal
    explorer.result(6.0, goal, SUCCEEDED)
    assert explorer.decide(10.9, grid, values, goal, map_time=0.0).action == WAIT
    assert explorer.decide(11.1, grid, values, goal, map_time=0.0).action == SEND


def test_done_is_for_good():
    grid, values = room(3.0, 1.0)
    explorer = Explorer()
    done = explorer.decide(0.0, grid, values, (0.25, 0.5, 0.0))
    assert done.action == DONE and explorer.done and 'closed' in done.text
    _, opened = room(3.0, 1.0, unknown_from=1.5)
    assert explorer.decide(3.0, grid, opened, (0.25, 0.5, 0.0)).action == DONE


# --- maps of the worlds ----------------------------------------------------------------------

@pytest.fixture(scope='module')
def house_entry():
    """The map of turtlebot3_house after the first three waypoints of the house tour (across the
    living room and into the corridor), from the scans on the true poses."""
    drive = record_drive('turtlebot3_house', HOUSE_TOUR_START, HOUSE_TOUR[:3])
    grid_map = OccupancyGrid.around(0.05, -10.0, -10.0, 10.0, 10.0)
    for truth, ranges in zip(drive.truth, drive.ranges):
        scan = Scan(drive.angle_min, drive.angle_increment, ranges, drive.range_min, drive.range_max)
        grid_map.add_scan(compose(truth, drive.scan_pose), scan, 3.0, 3.5)
    return drive, grid_map.grid, grid_map.values()


def test_frontiers_of_a_partial_map_open_onto_unseen_floor(house_entry):
    """Each candidate's goal is truly free with room for the robot; the unknown cells beside each
    candidate are mostly truly open floor (a frontier says "more floor beyond"); a plan on navfn's
    costs reaches the best goal, as long as the frontier says, and move_base's (keeping its
    obstacle_clearance) reaches it too."""
    drive, grid, values = house_entry
    cut = world_map.in_plane(load_world('turtlebot3_house', str(REPO / 'worlds')).obstacles)
    robot = tuple(drive.truth[-1])
    search = FrontierSearch().search(grid, values, robot)
    candidates = search.candidates
    print('MEASURED partial house map: %d frontiers, %d candidates: %s' % (
        len(search.frontiers), len(candidates),
        ', '.join('%.1f m at %.1f m (%.1f, %.1f)' % ((f.size, f.distance) + f.goal[:2]) for f in candidates)))
    assert len(candidates) >= 3
    goals = np.array([frontier.goal[:2] for frontier in candidates])
    assert world_map.signed_distance(cut, goals).min() > 0.1
    unknown = values < 0
    for frontier in candidates:
        cells = grid.to_cells(frontier.points)
        beside = np.zeros(values.shape, dtype=bool)
        beside[cells[:, 1], cells[:, 0]] = True
        beside = ndimage.binary_dilation(beside, structure=ndimage.generate_binary_structure(2, 1)) & unknown
        centres = grid.all_centres()[beside]
        open_share = np.mean(world_map.signed_distance(cut, centres) > 0)
        assert open_share > 0.8, (frontier.centroid, open_share)
    best = search.best
    costmap = Costmap(grid, CostmapConfig(), static=values)
    plan = GlobalPlanner(NAVFN).make_plan(costmap, robot, best.goal)
    assert plan is not None and plan_length(plan) == pytest.approx(best.distance, rel=0.1)
    assert GlobalPlanner().make_plan(costmap, robot, best.goal) is not None


def test_the_search_on_the_slam_s_20_m_map_costs_what_its_known_part_does(house_entry):
    """known_window: the planner searches the known part and a margin, not gmapping's 20 x 20 m."""
    import time
    _, grid, values = house_entry
    search = FrontierSearch()
    search.search(grid, values, (1.2, 0.4, 0.0))
    started = time.process_time()
    search.search(grid, values, (1.2, 0.4, 0.0))
    took = time.process_time() - started
    print('MEASURED one search of the partial house map: %.3f s of CPU on a window of %d x %d cells (of 400 x 400)'
          % (took, search.costmap.grid.width, search.costmap.grid.height))
    assert search.costmap.grid.width * search.costmap.grid.height < 0.5 * grid.width * grid.height


def test_exploring_turtlebot3_world_in_a_closed_loop_maps_its_floor():
    """The Explorer, a stand-in for move_base and a ray-cast lidar: from the spawn pose it ends by
    itself, with the reachable free floor mapped as free (goal >= 90 %), every goal in the open."""
    obstacles = load_world('turtlebot3_world', str(REPO / 'worlds')).obstacles
    loop = ExploreLoop(world_map.in_plane(obstacles), (-2.0, -0.5, 0.0))
    decision = loop.run()
    quality = measure(loop.map.grid, loop.values(), obstacles, (-2.0, -0.5))
    goals = np.array([goal[:2] for goal in loop.goals()])
    travelled = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(loop.path, loop.path[1:]))
    print('MEASURED closed loop in turtlebot3_world: %s after %d goals, %.1f m in %.1f s; blacklisted %d; %s'
          % (decision.text, len(goals), travelled, loop.now, len(loop.explorer.blacklist), quality.summary()))
    assert decision.action == DONE and 'no frontier' in decision.text
    assert quality.free_floor_mapped >= 0.90
    assert world_map.signed_distance(world_map.in_plane(obstacles), goals).min() > 0.0
