"""tb3_navigation.planner: navfn's plans on the costmap of turtlebot3_world's and
turtlebot3_house's maps, judged against the worlds' true outlines (no ROS)."""
import math
import time

import numpy as np
import pytest

from tb3_common.grid import Grid
from tb3_harness.nav_sim import world_cut
from tb3_navigation.costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION, Costmap, CostmapConfig
from tb3_navigation.planner import GlobalPlanner, PlannerConfig, orient, plan_length
from tb3_sim_nav import world_map

PILLARS = [(x, y) for x in (-1.1, 0.0, 1.1) for y in (-1.1, 0.0, 1.1)]
PILLAR_RADIUS = 0.15


@pytest.fixture(scope='module')
def world():
    obstacles = world_cut()
    grid, data = world_map.map_of_world(obstacles)
    return obstacles, Costmap(grid, CostmapConfig(), static=data)


def free_points(obstacles, count, seed, clearance=0.25):
    """Points inside turtlebot3_world's hexagon at least `clearance` from every obstacle."""
    rng = np.random.default_rng(seed)
    points = []
    while len(points) < count:
        point = rng.uniform(-2.2, 2.2, 2)
        if np.hypot(*point) < 2.3 and world_map.signed_distance(obstacles, point[None, :])[0] >= clearance:
            points.append(point)
    return points


def check_plan(plan, costmap, start, goal, obstacles):
    """A plan's shape and safety: from start to goal in steps of at most one cell's
    diagonal (between cell centres), never on a lethal or inscribed cell, never inside an obstacle,
    each pose facing the next and the last the goal's yaw."""
    points = np.array(plan)
    assert points[0, :2] == pytest.approx(start[:2]) and points[-1, :2] == pytest.approx(goal[:2])
    steps = np.hypot(*np.diff(points[:, :2], axis=0).T)
    diagonal = costmap.grid.resolution * math.sqrt(2)
    assert steps[1:-1].max() <= diagonal + 1e-9  # cell centre to cell centre
    assert max(steps[0], steps[-1]) <= 1.5 * diagonal  # to and from points within their cells
    assert np.all(costmap.cost_at(points[:, :2]) < INSCRIBED_INFLATED_OBSTACLE)
    assert world_map.signed_distance(obstacles, points[:, :2]).min() > 0.0
    headings = np.arctan2(np.diff(points[:, 1]), np.diff(points[:, 0]))
    assert np.allclose(np.cos(points[:-1, 2] - headings), 1.0)
    assert points[-1, 2] == goal[2]
    return points


def test_plans_between_free_points_keep_off_obstacles(world):
    obstacles, costmap = world
    planner = GlobalPlanner()
    points = free_points(obstacles, 12, seed=4)
    for start, goal in zip(points[::2], points[1::2]):
        start, goal = (start[0], start[1], 0.3), (goal[0], goal[1], -1.0)
        plan = planner.make_plan(costmap, start, goal)
        assert plan is not None
        check_plan(plan, costmap, start, goal, obstacles)
        assert plan_length(plan) >= math.dist(start[:2], goal[:2])


def test_plan_keeps_its_distance_from_the_pillars_as_the_inflation_asks(world):
    """Between two pillars 1.1 m apart the plan takes the middle of the gap: there the
    inflation cost is lowest."""
    obstacles, costmap = world
    plan = GlobalPlanner().make_plan(costmap, (-0.55, -1.6, 1.57), (-0.55, 1.6, 1.57))
    points = check_plan(plan, costmap, (-0.55, -1.6), (-0.55, 1.6, 1.57), obstacles)
    between = points[np.abs(points[:, 1]) <= 1.1]
    assert np.abs(between[:, 0] + 0.55).max() <= 0.05 + 1e-9
    clearance = min(np.hypot(points[:, 0] - x, points[:, 1] - y).min() for x, y in PILLARS) - PILLAR_RADIUS
    assert clearance >= 0.35


def test_the_plan_is_the_cheapest_path_the_potential_knows(world):
    """The plan's cost (navfn's step costs summed along it) is the potential at the goal,
    and no 8-neighbour path costs less (an independent Dijkstra in pure Python)."""
    import heapq
    obstacles, costmap = world
    planner = GlobalPlanner()
    start, goal = (-1.7, -0.5, 0.0), (1.6, 0.6, 0.0)
    plan = planner.make_plan(costmap, start, goal)
    steps = planner.step_costs(costmap.costs)
    grid = costmap.grid
    cells = grid.to_cells(np.array(plan)[:, :2])
    cost = sum(steps[b[1], b[0]] * math.hypot(*(b - a)) for a, b in zip(cells[:-1], cells[1:]))
    assert cost == pytest.approx(planner.potential[cells[-1][1], cells[-1][0]])
    best = {tuple(cells[0][::-1]): 0.0}
    queue = [(0.0, tuple(cells[0][::-1]))]
    target = tuple(cells[-1][::-1])
    while queue:
        distance, (y, x) = heapq.heappop(queue)
        if (y, x) == target or distance > best.get((y, x), math.inf):
            continue
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                ny, nx = y + dy, x + dx
                if (dy or dx) and 0 <= ny < grid.height and 0 <= nx < grid.width and np.isfinite(steps[ny, nx]) \
                        and np.isfinite(steps[y + dy, x]) and np.isfinite(steps[y, x + dx]):
                    candidate = distance + steps[ny, nx] * math.hypot(dx, dy)
                    if candidate < best.get((ny, nx), math.inf):
                        best[(ny, nx)] = candidate
                        heapq.heappush(queue, (candidate, (ny, nx)))
    assert best[target] == pytest.approx(cost)


def test_spread_gives_every_cell_s_plan_cost_in_one_search(world):
    """spread: the potential of the whole costmap from the robot, the same at each goal as the
    plan's own search; inf inside pillars and outside the walls; None from off the map."""
    obstacles, costmap = world
    start = (-2.0, -0.5, 0.0)
    potential, predecessors = GlobalPlanner().spread(costmap, start)
    grid = costmap.grid
    for goal in free_points(obstacles, 6, seed=9):
        planner = GlobalPlanner()
        assert planner.make_plan(costmap, start, (goal[0], goal[1], 0.0)) is not None
        cell = grid.to_cells(goal)
        assert potential[cell[1], cell[0]] == pytest.approx(planner.potential[cell[1], cell[0]])
    for point in ((0.0, 0.0), (0.0, 2.9), (2.8, 0.0)):  # the centre pillar; beyond the north and east walls
        cell = grid.to_cells(np.array(point))
        assert np.isinf(potential[cell[1], cell[0]])
    assert predecessors.shape == grid.shape
    assert GlobalPlanner().spread(costmap, (9.0, 0.0)) is None


def test_no_plan_into_a_pillar_off_the_map_or_from_off_the_map(world):
    _, costmap = world
    planner = GlobalPlanner()
    start = (-2.0, -0.5, 0.0)
    assert planner.make_plan(costmap, start, (0.0, 0.0, 0.0)) is None  # the centre pillar
    assert planner.make_plan(costmap, start, (1.1, -1.1, 0.0)) is None
    assert planner.make_plan(costmap, start, (9.0, 0.0, 0.0)) is None
    assert planner.make_plan(costmap, (9.0, 0.0, 0.0), (-1.5, 0.0, 0.0)) is None
    assert planner.make_plan(costmap, start, (float('nan'), 0.0, 0.0)) is None
    # Outside the hexagon's walls: the map's cells there are free, but no path leads out.
    assert planner.make_plan(costmap, start, (0.0, 2.9, 0.0)) is None


def test_tolerance_ends_the_plan_at_the_reachable_point_nearest_the_goal(world):
    obstacles, costmap = world
    planner = GlobalPlanner(PlannerConfig(default_tolerance=0.3))
    goal = (1.1, 0.0, 2.0)  # a pillar's centre
    plan = planner.make_plan(costmap, (-2.0, -0.5, 0.0), goal)
    end = np.array(plan[-1][:2])
    assert plan[-1][2] == 2.0
    assert np.all(np.abs(end - goal[:2]) <= 0.3 + 1e-9)
    # navfn's search: every sample nearer to the goal within the square is unreachable.
    offsets = np.arange(-6, 7) * 0.05
    samples = np.stack(np.meshgrid(offsets, offsets), -1).reshape(-1, 2) + goal[:2]
    nearer = samples[np.hypot(*(samples - goal[:2]).T) < np.hypot(*(end - goal[:2])) - 1e-9]
    cells = costmap.grid.to_cells(nearer)
    assert not np.any(np.isfinite(planner.potential[cells[:, 1], cells[:, 0]]))
    assert world_map.signed_distance(obstacles, np.array(plan)[:, :2]).min() > 0.0
    assert GlobalPlanner().make_plan(costmap, (-2.0, -0.5, 0.0), goal, tolerance=0.1) is None


def test_unknown_space_is_crossed_only_if_allowed():
    grid = Grid(0.05, 60, 40)
    data = np.zeros(grid.shape, dtype=np.int8)
    data[:, 28:32] = 100       # a wall across the map...
    data[15:25, 28:32] = -1    # ...with a stretch nobody has seen
    costmap = Costmap(grid, CostmapConfig(track_unknown_space=True, inflation_radius=0.2), static=data)
    assert np.all(costmap.costs[16:24, 28:32] == NO_INFORMATION)  # (the rows next to the wall are inscribed)
    start, goal = (0.3, 1.0, 0.0), (2.7, 1.0, 0.0)
    plan = GlobalPlanner().make_plan(costmap, start, goal)
    assert plan is not None and np.any(costmap.cost_at(np.array(plan)[:, :2]) == NO_INFORMATION)
    assert GlobalPlanner(PlannerConfig(allow_unknown=False)).make_plan(costmap, start, goal) is None


def test_no_plan_slips_through_a_diagonal_wall_of_single_cells():
    grid = Grid(0.05, 40, 40)
    data = np.zeros(grid.shape, dtype=np.int8)
    index = np.arange(40)
    data[index, index] = 100  # a staircase of cells touching only at their corners
    costmap = Costmap(grid, CostmapConfig(inflation_radius=0.0), static=data)
    assert GlobalPlanner().make_plan(costmap, (1.5, 0.3, 0.0), (0.3, 1.5, 0.0)) is None
    assert GlobalPlanner().make_plan(costmap, (1.5, 0.3, 0.0), (1.9, 0.9, 0.0)) is not None


def test_a_house_sized_map_plans_across_and_the_time_is_reported(capsys):
    """turtlebot3_house's cut laid on a 400 x 260 grid (20 x 13 m at 0.05 m), planned from
    the west to the east end of the house. The time is measured and printed, not asserted."""
    obstacles = world_cut('turtlebot3_house')
    xmin, ymin, xmax, ymax = world_map.bounds(obstacles)
    grid = Grid(0.05, 400, 260, ((xmin + xmax) / 2 - 10.0, (ymin + ymax) / 2 - 6.5, 0.0))
    inside = world_map.occupied(obstacles, grid.all_centres().reshape(-1, 2)).reshape(grid.shape)
    costmap = Costmap(grid, CostmapConfig(), static=np.where(inside, 100, 0).astype(np.int8))
    planner = GlobalPlanner()
    start, goal = (-6.0, -1.0, 0.0), (6.5, 2.5, 0.0)
    plan = planner.make_plan(costmap, start, goal)  # builds the grid's edges once
    assert plan is not None and plan_length(plan) > math.dist(start[:2], goal[:2])
    assert world_map.signed_distance(obstacles, np.array(plan)[:, :2]).min() > 0.0
    walls, cpu = [], []
    for _ in range(5):
        costmap.costs = costmap.costs.copy()
        costmap.costs[0, 0] ^= 1  # a changed costmap: the graph is rebuilt too
        wall, processor = time.perf_counter(), time.process_time()
        assert planner.make_plan(costmap, start, goal) is not None
        walls.append(time.perf_counter() - wall)
        cpu.append(time.process_time() - processor)
    with capsys.disabled():
        print('\n400 x 260 house plan, %.1f m: median %.0f ms wall, %.0f ms CPU (max %.0f ms wall)'
              % (plan_length(plan), 1e3 * np.median(walls), 1e3 * np.median(cpu), 1e3 * max(walls)))


def test_global_planners_step_costs_with_its_lethal_cost():
    costs = np.array([[0, 100, 251, 252, 253, 254, NO_INFORMATION]], dtype=np.uint8)
    navfn = GlobalPlanner().step_costs(costs)[0]
    assert navfn[:4] == pytest.approx([50.0, 130.0, 250.8, 251.6]) and np.all(np.isinf(navfn[4:6]))
    assert navfn[6] == 253.0  # unknown, allowed: navfn's COST_OBS - 1
    # global_planner's getCost: factor 3 from 50, capped one below lethal_cost, the cell below it at lethal_cost.
    gp = GlobalPlanner(PlannerConfig(cost_factor=3.0, lethal_cost=253)).step_costs(costs)[0]
    assert gp[0] == 50.0 and gp[1] == 252.0 and gp[3] == 253.0 and np.all(np.isinf(gp[4:6])) and gp[6] == 252.0
    with pytest.raises(ValueError, match='~neutral_cost = 200'):
        PlannerConfig(neutral_cost=200, lethal_cost=150)


def test_orientation_modes_as_global_planners_orientation_filter():
    points = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (2.0, 2.0)]
    yaws = lambda mode, **kwargs: [pose[2] for pose in orient(points, 1.0, mode, **kwargs)]  # noqa: E731
    assert yaws(1) == pytest.approx([0.0, 0.0, math.pi / 2, math.pi / 2, 1.0])        # each faces the next
    assert yaws(1, window=1) == pytest.approx([0.0, 0.0, math.pi / 4, math.pi / 2, 1.0])  # from before to after
    assert yaws(0) == pytest.approx([0.0, 0.0, 0.0, 0.0, 1.0])
    assert np.abs(yaws(4)[:2]) == pytest.approx([math.pi, math.pi]) and yaws(5)[0] == pytest.approx(-math.pi / 2)
    assert abs(yaws(6)[2]) == pytest.approx(math.pi)
    assert yaws(2, start_yaw=-0.6) == pytest.approx([-0.6, -0.2, 0.2, 0.6, 1.0])  # start to goal, evenly
    # Forward, then from the third last pose back to the last turn of more than 0.35 rad, interpolated to
    # the goal's heading (here the turn is at the third last pose itself).
    assert yaws(3, start_yaw=-0.6) == pytest.approx([-0.6, 0.0, math.pi / 2, (math.pi / 2 + 1.0) / 2, 1.0])


def test_replans_bounded_by_the_last_plan_are_as_cheap_as_plans_from_scratch(world, monkeypatch):
    """A replan to the same goal bounds its search by what the rest of the last plan costs now: from
    points along it, a cell off it, and after a wall across it (the bound is gone: searched as
    at first), the plan costs what a new planner's costs."""
    obstacles, costmap = world
    goal = (1.6, 0.6, 0.0)
    planner = GlobalPlanner()
    plan = np.array(planner.make_plan(costmap, (-1.7, -0.5, 0.0), goal))
    resolution = costmap.grid.resolution
    starts = [tuple(plan[5]), tuple(plan[20]), (plan[30][0], plan[30][1] + resolution, 0.0), tuple(plan[40])]
    blocked = Costmap(costmap.grid, CostmapConfig(), static=np.asarray(costmap.static, dtype=np.int16) % 256)
    ahead = plan[(40 + len(plan)) // 2]  # between the last start and the goal
    cells = blocked.grid.to_cells(np.array([ahead[:2]]))[0]
    blocked.static[max(0, cells[1] - 30):cells[1] + 30, cells[0]] = 254  # a wall across the plan
    blocked.update_costs()
    limits, bound = [], GlobalPlanner._known_limit
    monkeypatch.setattr(planner, '_known_limit', lambda *args: limits.append(bound(planner, *args)) or limits[-1])
    for start, costs in [(start, costmap) for start in starts] + [(starts[-1], blocked)]:
        replanned = planner.make_plan(costs, start, goal)
        assert (limits[-1] is None) == (costs is blocked), limits  # bounded but when walled off
        fresh = GlobalPlanner()
        first = fresh.make_plan(costs, start, goal)
        assert replanned is not None and first is not None
        end = costs.grid.to_cells(np.array([goal[:2]]))[0]
        assert planner.potential[end[1], end[0]] == pytest.approx(fresh.potential[end[1], end[0]], rel=1e-12)
        assert len(replanned) == len(first)


def test_plans_keep_obstacle_clearance_past_a_door_where_navfn_s_hug_its_frame():
    """turtlebot3_house's door between the living room and the hall (x 0.65-1.55 m at y -0.15, a
    stand 0.4 m south of it): from the north-west corner of the door to a goal south-west of it,
    navfn's plan passes 0.10 m from the west frame (cells beyond the inscribed radius, 0.051 m to
    the padded Burger's front edge, are all it refuses); with obstacle_clearance the plan keeps
    that radius plus 0.12 m, longer by the way round (past the stand's east side)."""
    obstacles = world_cut('turtlebot3_house')
    grid, data = world_map.map_of_world(obstacles)
    costmap = Costmap(grid, CostmapConfig(), static=data)
    start, goal = (0.47, 0.19, -0.36), (-0.3, -1.2, 0.0)
    plans = {clearance: check_plan(GlobalPlanner(PlannerConfig(obstacle_clearance=clearance)).make_plan(
        costmap, start, goal), costmap, start, goal, obstacles) for clearance in (0.0, 0.12)}
    nearest = {clearance: world_map.signed_distance(obstacles, plan[:, :2]).min() for clearance, plan in plans.items()}
    print('MEASURED past the house door: navfn %.3f m from the frame, %.2f m long; with the clearance %.3f m, %.2f m'
          % (nearest[0.0], plan_length(plans[0.0]), nearest[0.12], plan_length(plans[0.12])))
    assert nearest[0.0] < costmap.inscribed_radius + 0.12 <= nearest[0.12]
    assert plan_length(plans[0.12]) < 2.0 * plan_length(plans[0.0])
