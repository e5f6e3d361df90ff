"""tb3_navigation.controller: DWA driving a unicycle with the Burger's accelerations at
10 Hz around turtlebot3_world's pillars, judged against the world's true outlines
(no ROS). The global planner gives the plan, renewed at 5 Hz as move_base renews it;
the local costmap sees what the simulated LDS-01 sees."""
import math

import numpy as np
import pytest

from tb3_common.pose2d import compose, normalize_angle
from tb3_harness.nav_sim import Lidar, Unicycle, costmaps, footprint_clearance, odom_of, update_costmaps, world_cut
from tb3_navigation.controller import STALLED, Command, DwaController
from tb3_navigation.costmap import BURGER_FOOTPRINT, Costmap, CostmapConfig
from tb3_navigation.dwa_config import DwaConfig, dwa_config
from tb3_navigation.planner import GlobalPlanner
from tb3_navigation.trajectory_scoring import _densify, velocity_samples

PERIOD = 0.1  # s: controller_frequency 10
CLEARANCE = 0.09  # m: the footprint never nearer to an obstacle
#: Goals around the pillars (1.1 m apart, 0.15 m radius), from tb3_world.launch's spawn pose.
START = (-2.0, -0.5, 0.0)
GOALS = [(-0.55, -0.55, 0.0), (0.55, 0.55, math.pi / 2), (1.65, -0.55, -math.pi / 2), (-0.55, 1.65, math.pi)]


@pytest.fixture(scope='module')
def obstacles():
    return world_cut()


def drive(obstacles, goals, config, seconds_per_goal=60.0):
    """Drives the unicycle through `goals`; returns a record per goal and every command
    with the velocity measured when it was given."""
    global_costmap, local_costmap = costmaps(obstacles, START)
    planner, controller = GlobalPlanner(), DwaController(local_costmap, config)
    robot, lidar = Unicycle(START), Lidar(obstacles)
    record, commands, now = [], [], 0.0
    for goal in goals:
        reached, clearance, plan, since = False, math.inf, None, now
        while now - since < seconds_per_goal:
            if round(now / PERIOD) % 2 == 0:  # the lidar's 5 Hz
                update_costmaps(global_costmap, local_costmap, robot.pose, lidar.scan(robot.pose))
            if plan is None or round(now / PERIOD) % 2 == 0:  # planner_frequency 5, and at once for a goal
                plan = planner.make_plan(global_costmap, tuple(robot.pose), goal) or plan
                controller.reset()
            local_plan = compose(odom_of((0.0, 0.0, 0.0)), np.array(plan))
            pose = odom_of(robot.pose)
            if controller.is_goal_reached(pose, robot.velocity, local_plan):
                reached = True
                break
            command = controller.compute(pose, robot.velocity, local_plan)
            commands.append((command, robot.velocity.copy()))
            robot.run((command.v, command.w), PERIOD)
            now += PERIOD
            clearance = min(clearance, footprint_clearance(obstacles, BURGER_FOOTPRINT, robot.pose))
        record.append(dict(goal=goal, reached=reached, seconds=now - since, clearance=clearance,
                           error=math.hypot(robot.pose[0] - goal[0], robot.pose[1] - goal[1]),
                           yaw_error=abs(normalize_angle(robot.pose[2] - goal[2]))))
    return record, commands


def check_commands(commands, config):
    """Every command finite and within the velocity limits; a command the controller
    stands by is reachable from the measured velocity within one period's accelerations."""
    for command, velocity in commands:
        assert math.isfinite(command.v) and math.isfinite(command.w)
        assert config.min_vel_x - 1e-9 <= command.v <= config.max_vel_x + 1e-9
        assert abs(command.v) <= config.max_vel_trans + 1e-9 and abs(command.w) <= config.max_vel_theta + 1e-9
        if command.ok:
            assert abs(command.v - velocity[0]) <= config.acc_lim_x * PERIOD + 1e-9
            assert abs(command.w - velocity[1]) <= config.acc_lim_theta * PERIOD + 1e-9
        else:
            assert (command.v, command.w) == (0.0, 0.0)


@pytest.mark.parametrize('forward_only', [False, True], ids=['burger', 'move_forward_only'])
def test_reaches_goals_around_the_pillars_within_tolerances_and_clear_of_them(obstacles, forward_only):
    config = dwa_config('burger', move_forward_only=forward_only)
    record, commands = drive(obstacles, GOALS if not forward_only else GOALS[:2], config)
    for leg in record:
        print('goal %s: %s in %.1f s, %.3f m and %.3f rad off, footprint clearance %.3f m'
              % (leg['goal'], 'reached' if leg['reached'] else 'NOT reached', leg['seconds'], leg['error'],
                 leg['yaw_error'], leg['clearance']))
        assert leg['reached']
        assert leg['error'] <= config.xy_goal_tolerance and leg['yaw_error'] <= config.yaw_goal_tolerance
        assert leg['clearance'] >= CLEARANCE
    check_commands(commands, config)
    if forward_only:
        assert min(command.v for command, _ in commands) >= 0.0
    else:
        assert max(command.v for command, _ in commands) == pytest.approx(config.max_vel_x, abs=0.02)
    assert sum(not command.ok for command, _ in commands) <= 0.02 * len(commands)


# --- the parts ------------------------------------------------------------------------------

def test_velocity_samples_as_velocity_iterator():
    assert list(velocity_samples(-0.22, 0.22, 5)) == pytest.approx([-0.22, -0.11, 0.0, 0.11, 0.22])
    samples = velocity_samples(-0.1, 0.3, 4)  # -0.1, 0.033, 0.167, 0.3 and 0 put between
    assert len(samples) == 5 and 0.0 in samples and samples[0] == -0.1 and samples[-1] == 0.3
    assert list(velocity_samples(0.2, 0.2, 20)) == [0.2]
    assert len(velocity_samples(0.0, 0.25, 0)) == 2


def open_field(config=DwaConfig()):
    costmap = Costmap.rolling(CostmapConfig())
    return costmap, DwaController(costmap, config)


def straight_plan(length=1.2, yaw=0.0):
    steps = np.arange(0.0, length + 1e-9, 0.05)
    return np.stack((steps * math.cos(yaw), steps * math.sin(yaw), np.full_like(steps, yaw)), axis=-1)


def test_oscillation_flags_rule_out_the_velocities_they_name():
    """base_local_planner's OscillationCostFunction: with left_only set, no sample turning right."""
    _, controller = open_field()
    plan = straight_plan(yaw=-0.6)
    assert controller.compute((0.0, 0.0, 0.0), (0.1, 0.0), plan).w < 0
    controller._flags['left_only'] = True
    command = controller.compute((0.0, 0.0, 0.0), (0.1, 0.0), plan)
    assert command.ok and command.w >= 0


def test_follows_a_straight_plan_at_full_speed_within_the_dynamic_window():
    _, controller = open_field()
    command = controller.compute((0.0, 0.0, 0.0), (0.0, 0.0), straight_plan())
    assert command.ok and 0.11 <= command.v <= 0.22 + 1e-9 and abs(command.w) <= 0.32 + 1e-9
    command = controller.compute((0.0, 0.0, 0.0), (0.2, 0.0), straight_plan())
    assert command.ok and command.v == pytest.approx(0.22) and abs(command.w) < 0.05
    # The trajectory it will follow, along the plan: 14 steps of 0.025 m (sim_granularity)
    # over sim_time 1.5 s, its last point one step short of the end, as DWA's.
    assert command.trajectory[:, 0] == pytest.approx(np.arange(14) * 0.22 * 1.5 / 14, abs=1e-9)
    assert np.abs(command.trajectory[:, 1]).max() < 0.01


def test_at_the_goal_it_stops_then_turns_in_place_then_holds():
    config = DwaConfig()
    _, controller = open_field(config)
    plan = straight_plan(0.5, 0.0)
    plan[-1, 2] = math.pi / 2  # the goal's yaw
    at_goal = (0.5 - 0.005, 0.0, 0.0)  # within ARRIVAL (0.3) of xy_goal_tolerance: the approach is over
    command = controller.compute(at_goal, (0.2, 0.0), plan)  # still moving: slow down first
    assert command.ok and command.w == 0.0 and command.v == pytest.approx(0.0)
    assert not controller.is_goal_reached(at_goal, (0.2, 0.0), plan)
    turns = [controller.compute(at_goal, (0.0, w), plan).w for w in (0.0, 0.32, 0.64)]
    assert turns == pytest.approx([0.32, 0.64, 0.96])  # stopped: turn left, within acc_lim_theta
    # Within the yaw tolerance (0.17) but not yet within ARRIVAL of it: it turns on, just what is left.
    nearly = (0.5 - 0.005, 0.0, math.pi / 2 - 0.1)
    command = controller.compute(nearly, (0.0, 0.3), plan)
    # 0.1 rad left: 1.0 rad/s would turn it in one period, but from 0.3 rad/s acc_lim_theta allows 0.62.
    assert command.v == 0.0 and command.w == pytest.approx(0.3 + 0.32)
    assert not controller.is_goal_reached(nearly, (0.0, 0.0), plan)
    facing = (0.5 - 0.005, 0.0, math.pi / 2 - 0.03)
    command = controller.compute(facing, (0.0, 0.5), plan)
    assert (command.v, command.w) == (0.0, pytest.approx(0.5 - 0.32))  # brakes as hard as acc_lim_theta allows
    assert controller.is_goal_reached(facing, (0.0, 0.05), plan)
    assert not controller.is_goal_reached(facing, (0.0, 0.3), plan)  # not stopped yet


def test_a_new_plan_neither_brakes_the_turn_to_the_goal_nor_restarts_the_approach():
    # move_base hands DWA a new plan at 5 Hz, and every amcl update moves the goal a little in the
    # odom frame. Forgetting the turn braked every other period (a quarter of the turning speed); taking
    # the moved goal for a new one forgot the approach (the robot dithered 2-3 cm from the goal, until
    # move_base's oscillation_timeout).
    config = DwaConfig()
    _, controller = open_field(config)
    plan = straight_plan(0.5, 0.0)
    plan[-1, 2] = 2.5  # most of half a turn to go, to the left
    at_goal = (0.5 - 0.005, 0.0, 0.0)
    assert controller.compute(at_goal, (0.0, 0.0), plan).w == pytest.approx(0.32)  # stopped: it turns
    controller.reset()
    assert controller.compute(at_goal, (0.0, 0.32), plan).w == pytest.approx(0.64)  # and turns on
    # Passing 1.8 cm from the goal (within PASSED of the tolerance) and going away again ends the
    # approach, though each period's goal is 5 mm away from the last one's.
    _, controller = open_field(config)
    for shift, x in enumerate((0.47, 0.49, 0.52)):
        moved = straight_plan(0.5, 0.0) + (0.0, 0.005 * shift, 0.0)
        controller.reset()
        controller.compute((x, 0.02, 0.0), (0.11, 0.0), moved)
    assert controller.is_position_reached((0.52, 0.02, 0.0), moved)  # 2.2 cm off


def test_within_the_tolerance_an_approach_that_no_longer_comes_nearer_is_over():
    # 4.8 cm from the goal (within xy_goal_tolerance, outside ARRIVAL and PASSED of it), stepping back
    # and forth: after STALLED periods without coming 1 mm nearer the approach is over, as DWA stops.
    _, controller = open_field()
    plan = straight_plan(0.5, 0.0)
    reached = []
    for period in range(STALLED + 2):
        pose = (0.452 + 0.0005 * (period % 2), 0.0, 0.0)
        controller.compute(pose, (0.11, 0.0), plan)
        reached.append(controller.is_position_reached(pose, plan))
    assert reached.index(True) == STALLED and all(reached[STALLED:])
    # Outside the tolerance it never is.
    _, controller = open_field()
    for period in range(3 * STALLED):
        controller.compute((0.44, 0.0, 0.0), (0.11, 0.0), plan)
    assert not controller.is_position_reached((0.44, 0.0, 0.0), plan)


def test_refuses_what_would_collide_and_fails_when_boxed_in():
    from tb3_navigation.costmap import LETHAL_OBSTACLE
    costmap, controller = open_field()
    costmap.obstacles[:, 35] = LETHAL_OBSTACLE  # a wall across x = 0.25..0.30
    costmap.update_costs()
    command = controller.compute((0.0, 0.0, 0.0), (0.0, 0.0), straight_plan())
    if command.ok:  # whatever it does, its footprint stays legal all along
        assert np.all(costmap.footprint_cost(command.trajectory) >= 0)
    costmap.obstacles[:, 31] = LETHAL_OBSTACLE  # x = 0.05..0.10: now under the footprint's front edge
    costmap.update_costs()
    command = controller.compute((0.0, 0.0, 0.0), (0.1, 0.0), straight_plan())
    assert not command.ok and (command.v, command.w) == (0.0, 0.0) and command.reason


def test_non_finite_input_gives_a_stop_never_a_non_finite_command():
    _, controller = open_field()
    nan = float('nan')
    for pose, velocity, plan in (((nan, 0.0, 0.0), (0.0, 0.0), straight_plan()),
                                 ((0.0, 0.0, 0.0), (float('inf'), 0.0), straight_plan()),
                                 ((0.0, 0.0, 0.0), (0.0, 0.0), np.full((3, 3), nan)),
                                 ((0.0, 0.0, 0.0), (0.0, 0.0), np.zeros((0, 3))),
                                 ((9.0, 9.0, 0.0), (0.0, 0.0), straight_plan())):
        command = controller.compute(pose, velocity, plan)
        assert isinstance(command, Command) and not command.ok and (command.v, command.w) == (0.0, 0.0)


def test_turtlebot3_values_and_validation():
    burger = dwa_config('burger')
    assert (burger.max_vel_x, burger.min_vel_x, burger.max_vel_theta, burger.min_vel_theta) == (0.22, -0.22, 2.75, 1.37)
    assert (burger.acc_lim_x, burger.acc_lim_theta, burger.sim_time, burger.vx_samples, burger.vth_samples) == \
        (2.5, 3.2, 1.5, 20, 40)
    assert (burger.path_distance_bias, burger.goal_distance_bias, burger.occdist_scale,
            burger.forward_point_distance) == (32.0, 20.0, 0.02, 0.325)
    assert burger.sim_period == pytest.approx(0.1)
    waffle = dwa_config('waffle_pi', move_forward_only=True)
    assert (waffle.max_vel_x, waffle.min_vel_x, waffle.max_vel_theta, waffle.sim_time) == (0.26, 0.0, 1.82, 2.0)
    with pytest.raises(ValueError, match='max_vel_y'):
        DwaConfig(max_vel_y=0.1)
    with pytest.raises(ValueError, match='controller_frequency'):
        DwaConfig(controller_frequency=0.0)
    with pytest.raises(ValueError, match='min_vel_x'):
        DwaConfig(min_vel_x=0.3)
    with pytest.raises(ValueError, match='acc_lim_x'):
        DwaConfig(acc_lim_x=float('nan'))
    with pytest.raises(ValueError, match='model'):
        dwa_config('turtlebot2')


def test_new_parameters_take_effect_at_the_next_command_and_the_followed_plan_is_given():
    _, controller = open_field()
    plan = straight_plan()
    assert controller.compute((0.0, 0.0, 0.0), (0.2, 0.0), plan).v == pytest.approx(0.22)
    controller.configure(dwa_config(max_vel_x=0.15))
    command = controller.compute((0.0, 0.0, 0.0), (0.2, 0.0), plan)
    assert command.v == pytest.approx(0.15) and controller.scorer.config.max_vel_x == 0.15
    assert command.followed[0] == pytest.approx(plan[0]) and len(command.followed) == len(plan)


def test_without_forward_point_scoring_the_turn_in_place_faces_the_goal():
    """TrajectoryPlannerROS's critics score a trajectory's end alone, so every turn in place costs the same;
    its heading_lookahead (here forward_point_distance) picks the one facing the goal: a plan behind the
    robot to its left makes it turn left, one to its right, right (the first sampled, right, would win)."""
    config = DwaConfig(forward_point_scoring=False, min_vel_x=0.0, min_vel_trans=0.1, min_vel_theta=0.1)
    for side in (1.0, -1.0):
        _, controller = open_field(config)
        plan = straight_plan(1.0, side * 2.5)
        command = controller.compute((0.0, 0.0, 0.0), (0.0, 0.0), plan)
        assert command.ok and command.v == 0.0 and math.copysign(1.0, command.w) == side


def test_the_plan_is_densified_as_map_grid_does_it():
    """MapGrid::adjustPlanResolution: every point of the plan kept as it is and in order, points
    inserted evenly on each segment longer than the resolution, none left more than it apart."""
    plan = np.array([[0.0, 0.0], [0.05, 0.0], [0.05, 0.0], [0.3, 0.1], [0.32, 0.1], [0.32, -0.5]])
    dense = _densify(plan, 0.05)
    gaps = np.hypot(*np.diff(dense, axis=0).T)
    assert gaps.max() <= 0.05 + 1e-12
    kept = [int(np.flatnonzero((dense == point).all(axis=1))[-1]) for point in plan[[0, 1, 3, 4, 5]]]
    assert kept == sorted(kept) and kept[0] == 0 and kept[-1] == len(dense) - 1
    # 0.269 m from (0.05, 0) to (0.3, 0.1): ceil(5.39) = 6 steps, 5 points between at k / 6 of it.
    between = dense[kept[1] + 1:kept[2]]  # kept[1]: the second of the two equal points
    assert len(between) == 5
    assert between == pytest.approx(np.array([0.05, 0.0]) + np.outer(np.arange(1, 6) / 6.0, [0.25, 0.1]))
    assert len(dense) == 1 + 1 + 1 + 6 + 1 + 12  # the points, and 5 + 11 inserted
    assert _densify(plan[:1], 0.05).tolist() == [[0.0, 0.0]]
