"""tb3_navigation.navigator: move_base's outcomes, timers and recovery order with a
fake clock, a fake planner and a fake controller; then the whole stack (costmaps,
planner, DWA) in turtlebot3_world: a goal inside a pillar, a box in the way (no ROS)."""
import math

import numpy as np
import pytest

from tb3_common.pose2d import compose, quaternion_of_yaw
from tb3_harness.nav_sim import MAP_IN_ODOM, Lidar, Unicycle, costmaps, footprint_clearance, update_costmaps, world_cut
from tb3_navigation.controller import Command, DwaController
from tb3_navigation.costmap import BURGER_FOOTPRINT
from tb3_navigation.dwa_config import dwa_config
from tb3_navigation.navigator import (
    ABORTED,
    CLEARING,
    CONTROLLING,
    PLANNING,
    PREEMPTED,
    STOP,
    SUCCEEDED,
    Navigator,
    NavigatorConfig,
    RotateRecoveryConfig,
    goal_error,
)
from tb3_navigation.planner import GlobalPlanner
from tb3_sim_nav.world_file import Obstacle

PERIOD = 0.1
UP = quaternion_of_yaw(0.0)


class FakePlanner(object):
    def __init__(self, works=True):
        self.works, self.calls = works, []

    def make_plan(self, costmap, start, goal, tolerance=None):
        self.calls.append((tuple(start), tuple(goal), tolerance))
        return [tuple(start), tuple(goal)] if self.works else None


class FakeController(object):
    def __init__(self, works=True):
        self.works, self.reached, self.resets = works, False, 0

    def reset(self):
        self.resets += 1

    def is_goal_reached(self, pose, velocity, plan):
        return self.reached

    def compute(self, pose, velocity, plan):
        return Command(0.2, 0.1, True) if self.works else Command(0.0, 0.0, False, reason='fake')


class FakeCostmap(object):
    def __init__(self):
        self.clears, self.resets, self.blocked = [], 0, False

    def clear_obstacles(self, centre, size):
        self.clears.append((tuple(np.round(centre, 6)), size))

    def reset(self):
        self.resets += 1

    def footprint_cost(self, poses):
        return np.full(len(poses), -1.0 if self.blocked else 0.0)


class Run(object):
    """The navigator at 10 Hz with a robot that turns as told (and drives, if `moving`)."""

    def __init__(self, planner=None, controller=None, config=NavigatorConfig(), moving=True):
        self.planner, self.controller = planner or FakePlanner(), controller or FakeController()
        self.global_costmap, self.local_costmap = FakeCostmap(), FakeCostmap()
        self.navigator = Navigator(config, self.planner, self.controller, self.global_costmap, self.local_costmap)
        self.now, self.pose, self.moving, self.steps = 0.0, np.array([1.0, 2.0, 0.0]), moving, []

    def goal(self, x=3.0, y=2.0, **kwargs):
        return self.navigator.set_goal(self.now, (x, y, 0.0), kwargs.pop('orientation', UP), **kwargs)

    def step(self):
        step = self.navigator.step(self.now, tuple(self.pose), (0.0, 0.0), MAP_IN_ODOM)
        if step.cmd is not None:
            assert all(math.isfinite(value) for value in step.cmd)
            v, w = step.cmd
            self.pose += (v * PERIOD * math.cos(self.pose[2]) * self.moving, v * PERIOD * math.sin(self.pose[2])
                          * self.moving, w * PERIOD)
            self.pose[2] = (self.pose[2] + math.pi) % (2 * math.pi) - math.pi
        self.now = round(self.now + PERIOD, 9)
        self.steps.append((self.now - PERIOD, step))
        return step

    def until_outcome(self, seconds):
        for _ in range(int(round(seconds / PERIOD))):
            step = self.step()
            if step.outcome is not None:
                return step
        raise AssertionError('no outcome within %g s' % seconds)


# --- outcomes -------------------------------------------------------------------------------

def test_goal_reached_succeeds_and_then_the_robot_is_stopped_once():
    run = Run()
    assert run.goal() == []
    step = run.step()
    assert step.state == CONTROLLING and step.cmd == (0.2, 0.1) and step.plan == [(1.0, 2.0, 0.0), (3.0, 2.0, 0.0)]
    run.controller.reached = True
    step = run.step()
    assert step.outcome.status == SUCCEEDED and step.outcome.text == 'Goal reached.' and step.cmd == STOP
    assert step.outcome.goal == (3.0, 2.0, 0.0)
    assert run.step().cmd == STOP  # one more stop after the end...
    assert run.step().cmd is None  # ...then nothing while idle
    assert not run.navigator.active


def test_a_new_goal_preempts_the_current_one_and_a_cancel_preempts_and_stops():
    run = Run()
    run.goal()
    run.step()
    outcomes = run.goal(x=4.0)
    assert [outcome.status for outcome in outcomes] == [PREEMPTED] and outcomes[0].goal == (3.0, 2.0, 0.0)
    assert run.navigator.state == PLANNING and run.navigator.goal[0] == 4.0
    step = run.step()
    assert step.state == CONTROLLING and run.planner.calls[-1][1] == (4.0, 2.0, 0.0)
    outcome = run.navigator.cancel()
    assert outcome.status == PREEMPTED and outcome.goal == (4.0, 2.0, 0.0)
    assert run.step().cmd == STOP and run.step().cmd is None
    assert run.navigator.cancel() is None


@pytest.mark.parametrize('position, orientation, fragment', [
    ((float('nan'), 2.0, 0.0), UP, 'non-finite position'),
    ((3.0, 2.0, float('inf')), UP, 'non-finite position'),
    ((3.0, 2.0, 0.0), (0.0, 0.0, float('nan'), 1.0), 'nans or infs'),
    ((3.0, 2.0, 0.0), (0.0, 0.0, 0.0, 0.0), 'length close to zero'),
    ((3.0, 2.0, 0.0), (0.0, 0.0, 0.0, 2.0), 'not normalised'),
    ((3.0, 2.0, 0.0), (0.0, 0.0, 0.7, 0.7), 'not normalised'),
    ((3.0, 2.0, 0.0), (math.sin(0.25), 0.0, 0.0, math.cos(0.25)), 'z axis not vertical'),
])
def test_a_bad_goal_is_aborted_at_once_with_a_message(position, orientation, fragment):
    run = Run()
    run.goal()
    run.step()
    outcomes = run.navigator.set_goal(run.now, position, orientation)
    assert [outcome.status for outcome in outcomes] == [PREEMPTED, ABORTED]
    assert fragment in outcomes[1].text and outcomes[1].text.startswith('Aborting on goal')
    assert not run.navigator.active and run.step().cmd == STOP and run.step().cmd is None


def test_goal_frames_known_unknown_and_with_a_leading_slash():
    run = Run()
    odom_in_map = (1.0, 0.0, math.pi / 2)
    known = {'odom': odom_in_map}.get
    assert run.navigator.set_goal(0.0, (1.0, 0.0, 0.0), UP, frame='odom', frame_to_global=known) == []
    assert run.navigator.goal == pytest.approx((1.0, 1.0, math.pi / 2))
    assert run.navigator.set_goal(0.0, (1.0, 0.0, 0.0), UP, frame='/map')[0].status == PREEMPTED
    assert run.navigator.goal == pytest.approx((1.0, 0.0, 0.0))
    outcomes = run.navigator.set_goal(0.0, (1.0, 0.0, 0.0), UP, frame='base_scan', frame_to_global=known)
    assert outcomes[-1].status == ABORTED and "'base_scan' cannot be transformed into 'map'" in outcomes[-1].text
    assert run.navigator.set_goal(0.0, (1.0, 0.0, 0.0), UP, frame='')[-1].status == ABORTED


def test_goal_error_accepts_what_rviz_and_rbx1_send():
    assert goal_error((1.0, 2.0, 0.0), quaternion_of_yaw(2.5)) is None
    assert goal_error((1.0, 2.0, 0.0), (0.0, 0.0, 0.7071, 0.7071)) is None  # four decimals, as typed
    assert goal_error((1.0, 2.0, 0.0), (0.0, 0.0, -1.0, 0.0)) is None


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


def test_make_plan_and_clear_costmaps_services():
    run = Run()
    assert run.navigator.make_plan((0.0, 0.0, 0.0), (1.0, 1.0, 0.0)) == [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0)]
    run.planner.works = False
    assert run.navigator.make_plan((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), tolerance=0.5) == []
    run.goal()
    assert run.navigator.make_plan((0.0, 0.0, 0.0), (1.0, 1.0, 0.0)) is None  # refused while active
    run.navigator.clear_costmaps()
    assert run.global_costmap.resets == run.local_costmap.resets == 1


def test_make_plan_adds_an_unreachable_goal_only_if_asked():
    run = Run(planner=FakePlanner(works=False))
    run.planner.make_plan = lambda costmap, start, goal, tolerance=None: [tuple(start)] if tolerance else None
    assert run.navigator.make_plan((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), tolerance=0.5) == [(0.0, 0.0, 0.0),
                                                                                       (1.0, 1.0, 0.0)]
    assert run.navigator.make_plan((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), 0.5, add_unreachable_goal=False) == \
        [(0.0, 0.0, 0.0)]


def test_config_validation_names_the_parameter():
    with pytest.raises(ValueError, match='planner_patience'):
        NavigatorConfig(planner_patience=-1.0)
    with pytest.raises(ValueError, match='controller_frequency'):
        NavigatorConfig(controller_frequency=0.0)
    with pytest.raises(ValueError, match='recovery_behaviors'):
        NavigatorConfig(recovery_behaviors=('conservative_reset', 'dance'))
    with pytest.raises(ValueError, match='global_frame'):
        NavigatorConfig(global_frame='')
    with pytest.raises(ValueError, match='~sim_granularity = 0.0: must be > 0'):
        RotateRecoveryConfig(sim_granularity=0.0)


# --- the whole stack in turtlebot3_world ----------------------------------------------------

def stack(obstacles, start):
    global_costmap, local_costmap = costmaps(obstacles, start)
    navigator = Navigator(NavigatorConfig(), GlobalPlanner(), DwaController(local_costmap, dwa_config()),
                          global_costmap, local_costmap)
    return navigator, global_costmap, local_costmap


def run_stack(navigator, global_costmap, local_costmap, robot, lidar, seconds, judged=None):
    """Steps the stack at 10 Hz (scans at 5 Hz) until an outcome; (outcome, steps, the
    closest approach of the robot's footprint to each of the `judged` groups of obstacles
    (default: all the lidar sees))."""
    judged = judged or dict(all=lidar.obstacles)
    now, steps, clearance = 0.0, [], dict((name, math.inf) for name in judged)
    for tick in range(int(seconds / PERIOD)):
        if tick % 2 == 0:
            update_costmaps(global_costmap, local_costmap, robot.pose, lidar.scan(robot.pose))
        step = navigator.step(now, tuple(robot.pose), tuple(robot.velocity), MAP_IN_ODOM)
        steps.append(step)
        if step.outcome is not None:
            return step.outcome, steps, clearance
        assert step.cmd is not None and all(math.isfinite(value) for value in step.cmd)
        robot.run(step.cmd, PERIOD)
        now += PERIOD
        for name, group in judged.items():
            clearance[name] = min(clearance[name], footprint_clearance(group, BURGER_FOOTPRINT, robot.pose))
    return None, steps, clearance


def test_a_goal_inside_a_pillar_is_aborted_after_the_recoveries():
    obstacles = world_cut()
    start = (-0.55, -0.55, 0.0)
    navigator, global_costmap, local_costmap = stack(obstacles, start)
    robot = Unicycle(start)
    navigator.set_goal(0.0, (0.0, 0.0, 0.0), UP)  # the centre pillar
    outcome, steps, clearance = run_stack(navigator, global_costmap, local_costmap, robot, Lidar(obstacles), 90.0)
    assert outcome.status == ABORTED and 'valid plan' in outcome.text
    assert [step.recovery for step in steps if step.recovery] == ['conservative_reset', 'rotate_recovery',
                                                                   'aggressive_reset', 'rotate_recovery']
    assert math.hypot(robot.pose[0] - start[0], robot.pose[1] - start[1]) < 0.01  # turned in place only
    assert clearance['all'] >= 0.09


def test_a_box_put_in_the_way_is_driven_around():
    """The map has no box; the lidar sees one in the lane between the west wall and the
    pillars, on the straight line to the goal (0.65 m free west of it, 0.25 m east)."""
    obstacles = world_cut()
    start, goal = (-1.65, -1.3, math.pi / 2), (-1.65, 1.3, math.pi / 2)
    navigator, global_costmap, local_costmap = stack(obstacles, start)
    box = Obstacle('box', (0.3, 0.3, 0.4), (-1.65, 0.0, 0.2), 0.0, None)
    lidar = Lidar(obstacles + [box])
    robot = Unicycle(start)
    navigator.set_goal(0.0, goal, quaternion_of_yaw(goal[2]))
    outcome, steps, clearances = run_stack(navigator, global_costmap, local_costmap, robot, lidar, 60.0,
                                           dict(world=obstacles, box=[box]))
    assert outcome is not None and outcome.status == SUCCEEDED
    assert math.hypot(robot.pose[0] - goal[0], robot.pose[1] - goal[1]) <= 0.05
    assert not any(step.recovery for step in steps)
    # The pillars and walls are on the map and inflated from the start; the box only as far
    # as the lidar has seen it (its hidden sides not at all), and lethal cells are all DWA refuses.
    assert clearances['world'] >= 0.09 and clearances['box'] >= 0.05
    print('box driven around in %.1f s: footprint at least %.3f m from the pillars and walls, %.3f m from the box'
          % (len(steps) * PERIOD, clearances['world'], clearances['box']))
