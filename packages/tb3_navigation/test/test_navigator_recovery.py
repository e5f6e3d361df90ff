"""tb3_navigation.navigator's planning and recovery, timed as move_base times them, with a fake clock, a
fake planner and a fake controller (navigator_fakes.py): no plan or no control met by the recovery
behaviours in move_base's order and then an abort, rotate_recovery's turn and its limits, the renewal at
planner_frequency, planner and controller patience, oscillation_timeout, max_planning_retries, and
recovery switched off (no ROS)."""
import math

import pytest
from navigator_fakes import PERIOD, FakeController, FakePlanner, Run

from tb3_common.pose2d import compose
from tb3_harness.nav_sim import MAP_IN_ODOM
from tb3_navigation.navigator import (
    ABORTED,
    CLEARING,
    CONTROLLING,
    PLANNING,
    STOP,
    NavigatorConfig,
    RotateRecoveryConfig,
)

# --- planning, recovery and their order -----------------------------------------------------

def recoveries(run):
    return [(round(time, 1), step.recovery) for time, step in run.steps if step.recovery]


def test_no_plan_recovers_in_move_base_s_order_then_aborts():
    run = Run(planner=FakePlanner(works=False))
    run.goal()
    step = run.until_outcome(120.0)
    assert step.outcome.status == ABORTED
    assert step.outcome.text == 'Failed to find a valid plan. Even after executing recovery behaviors.'
    order = recoveries(run)
    assert [name for _, name in order] == ['conservative_reset', 'rotate_recovery', 'aggressive_reset',
                                           'rotate_recovery']
    # planner_patience 5 s before each behaviour (planning again after each).
    assert 5.0 < order[0][0] <= 5.2
    assert order[1][0] - order[0][0] == pytest.approx(5.1, abs=0.15)
    assert order[3][0] - order[2][0] == pytest.approx(5.1, abs=0.15)
    # The resets: both costmaps, around the robot (the local one in odom), 3 m then 4 x 0.46 m.
    assert [size for _, size in run.global_costmap.clears] == [3.0, pytest.approx(1.84)]
    assert run.global_costmap.clears[0][0] == (1.0, 2.0)
    assert run.local_costmap.clears[0][0] == pytest.approx(tuple(compose(MAP_IN_ODOM, (1.0, 2.0, 0.0))[:2]))
    # Every command while planning or clearing holds still or turns in place.
    assert all(step.cmd is None or step.cmd[0] == 0.0 for _, step in run.steps)


def test_rotate_recovery_turns_a_full_turn_left_within_its_limits():
    run = Run(planner=FakePlanner(works=False))
    run.goal()
    turned, speeds, started = 0.0, [], False
    for _ in range(400):
        step = run.step()
        if step.recovery == 'rotate_recovery':
            started = True
        if started and step.state == CLEARING:
            if step.cmd == STOP:
                break
            speeds.append(step.cmd[1])
            turned += step.cmd[1] * PERIOD
    assert 2 * math.pi - 0.1 - 1e-9 <= turned <= 2 * math.pi + 0.1  # back within its yaw_goal_tolerance
    assert min(speeds) >= 0.4 and max(speeds) <= 1.0
    assert run.navigator.state == PLANNING


def test_rotate_recovery_takes_the_limits_it_is_given():
    run = Run(planner=FakePlanner(works=False))
    run.navigator.rotation = RotateRecoveryConfig(max_vel_theta=0.6, min_in_place_vel_theta=0.3)
    run.goal()
    speeds = [step.cmd[1] for step in (run.step() for _ in range(400))
              if step.state == CLEARING and step.cmd not in (None, STOP)]
    assert speeds and min(speeds) >= 0.3 and max(speeds) <= 0.6


def test_rotation_ends_when_the_footprint_would_hit_something():
    run = Run(planner=FakePlanner(works=False))
    run.local_costmap.blocked = True
    run.goal()
    step = run.until_outcome(120.0)
    assert step.outcome.status == ABORTED
    assert all(step.cmd in (None, STOP) for _, step in run.steps)  # never turned


def test_planning_retries_stop_early_when_max_planning_retries_is_set():
    run = Run(planner=FakePlanner(works=False), config=NavigatorConfig(max_planning_retries=3))
    run.goal()
    for _ in range(4):
        run.step()
    assert recoveries(run) == [(0.3, 'conservative_reset')]  # the fourth failure


def test_the_plan_is_renewed_at_planner_frequency_and_a_failed_renewal_keeps_controlling():
    run = Run()
    run.goal()
    for _ in range(20):
        run.step()
    assert len(run.planner.calls) == 10  # 5 Hz over 2 s
    run.planner.works = False
    for _ in range(20):
        assert run.step().state == CONTROLLING
    assert run.navigator.plan is not None


def test_no_control_replans_then_recovers_after_controller_patience_then_aborts():
    run = Run(controller=FakeController(works=False), config=NavigatorConfig(oscillation_timeout=0.0))
    run.goal()
    step = run.step()
    assert step.state == PLANNING and step.cmd == STOP  # back to planning, the robot stopped
    assert run.step().state == PLANNING and len(run.planner.calls) == 2  # and planned again at once
    step = run.until_outcome(200.0)
    assert step.outcome.text == 'Failed to find a valid control. Even after executing recovery behaviors.'
    first = recoveries(run)[0]
    assert first[1] == 'conservative_reset' and 15.0 < first[0] <= 15.3


def test_with_turtlebot3_s_values_a_robot_that_finds_no_command_is_oscillating_first():
    """oscillation_timeout 10 s comes before controller_patience 15 s: a robot held still
    by a controller that finds nothing is first taken for oscillating, as in move_base;
    past 15 s without a command the lack of control is what the recoveries answer, and
    what the abort names."""
    run = Run(controller=FakeController(works=False))
    run.goal()
    step = run.until_outcome(200.0)
    assert 10.0 < recoveries(run)[0][0] <= 10.3
    assert step.outcome.text == 'Failed to find a valid control. Even after executing recovery behaviors.'


def test_oscillation_timeout_recovers_unless_the_robot_moves_oscillation_distance():
    moving = Run()
    moving.goal(x=50.0)
    for _ in range(200):
        assert moving.step().recovery is None  # 0.2 m/s: 0.2 m every second
    stuck = Run(moving=False)
    stuck.goal(x=50.0)
    step = stuck.until_outcome(200.0)
    assert step.outcome.text == 'Robot is oscillating. Even after executing recovery behaviors.'
    assert 10.0 < recoveries(stuck)[0][0] <= 10.3


def test_recovery_can_be_switched_off_and_non_finite_poses_stop_the_robot():
    run = Run(planner=FakePlanner(works=False), config=NavigatorConfig(recovery_behavior_enabled=False))
    run.goal()
    assert run.until_outcome(10.0).outcome.status == ABORTED and not recoveries(run)
    run = Run()
    run.goal()
    step = run.navigator.step(0.0, (float('nan'), 0.0, 0.0), (0.0, 0.0))
    assert step.cmd == STOP and run.navigator.active
