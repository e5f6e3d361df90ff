"""tb3_navigation.navigator: move_base's outcomes of a goal (reached, preempted, cancelled, a bad goal
or frame aborted at once), its make_plan and clear_costmaps services and the checks of its parameters,
with a fake clock, a fake planner and a fake controller (navigator_fakes.py); then the whole stack
(costmaps, planner, DWA) in turtlebot3_world: a goal inside a pillar, a box in the way; in
turtlebot3_house, through a door that needs a sharp turn, and from where DWA would back away. Planning, the
recoveries and their timers are test_navigator_recovery.py's (no ROS)."""
import math

import pytest
from navigator_fakes import PERIOD, UP, FakePlanner, Run

from tb3_common.pose2d import quaternion_of_yaw
from tb3_harness.nav_sim import Lidar, Unicycle, run_stack, stack, world_cut
from tb3_navigation.navigator import (
    ABORTED,
    CONTROLLING,
    PLANNING,
    PREEMPTED,
    STOP,
    SUCCEEDED,
    NavigatorConfig,
    RotateRecoveryConfig,
    goal_error,
)
from tb3_sim_nav.world_file import Obstacle

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


# --- the services and the parameters -------------------------------------------------------

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


# --- the whole stack in turtlebot3_world (tb3_harness.nav_sim's closed loop) ---------------

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


def test_a_goal_through_the_house_door_with_a_sharp_turn_is_reached_without_recoveries():
    """From the living room through the door to the hall (x 0.65-1.55 m at y -0.15) and west round
    the stand south of it. navfn's plan (obstacle_clearance 0) hugged the door's west frame,
    10-13 cm from the Burger's centre, where DWA cannot turn: it rocked for 60 s and the goal was
    ABORTED after the recoveries (81 s); the plan that keeps its clearance is driven in 47 s."""
    obstacles = world_cut('turtlebot3_house')
    start, goal = (-3.0, 1.0, 0.0), (-2.63, -0.77, 0.0)
    navigator, global_costmap, local_costmap = stack(obstacles, start)
    robot = Unicycle(start)
    navigator.set_goal(0.0, goal, quaternion_of_yaw(goal[2]))
    outcome, steps, clearance = run_stack(navigator, global_costmap, local_costmap, robot, Lidar(obstacles), 90.0)
    print('MEASURED through the house door: %s after %.1f s, footprint at least %.3f m from the walls'
          % (outcome and outcome.text, len(steps) * PERIOD, clearance['all']))
    assert outcome is not None and outcome.status == SUCCEEDED
    assert math.hypot(robot.pose[0] - goal[0], robot.pose[1] - goal[1]) <= 0.05
    assert not any(step.recovery for step in steps)
    assert clearance['all'] >= 0.09


@pytest.mark.parametrize('heading', [3.0, 3.3])
def test_where_dwa_would_back_away_from_the_plan_the_robot_turns_to_face_it(heading):
    """From the hall's east side, facing about west, to a goal beyond the door north of it: DWA turned
    north early, east of the door and facing the wall 0.3 m ahead, where every forward arc comes too near
    and no turn in place is within its window; it backed and drove forward in turn until the recoveries
    ABORTED the goal (68-78 s, headings 3.0-3.3 rad). Turning to face the plan instead of backing, the
    goal is reached (46-95 s there, at most the four recoveries on the way)."""
    obstacles = world_cut('turtlebot3_house')
    start, goal = (2.37, -0.77, heading), (6.54, 1.83, 0.0)
    navigator, global_costmap, local_costmap = stack(obstacles, start)
    robot = Unicycle(start)
    navigator.set_goal(0.0, goal, quaternion_of_yaw(goal[2]))
    outcome, steps, clearance = run_stack(navigator, global_costmap, local_costmap, robot, Lidar(obstacles), 120.0)
    print('MEASURED from the hall\'s east side: %s after %.1f s, recoveries %s, footprint at least %.3f m from the '
          'walls' % (outcome and outcome.text, len(steps) * PERIOD, [s.recovery for s in steps if s.recovery],
                     clearance['all']))
    assert outcome is not None and outcome.status == SUCCEEDED
    assert math.hypot(robot.pose[0] - goal[0], robot.pose[1] - goal[1]) <= 0.05
    assert clearance['all'] >= 0.09


def test_from_a_corner_where_dwa_finds_nothing_the_robot_turns_its_way_out():
    """South of the hall, between the end of the wall west of the door and the mailbox post, facing the
    wall: where the robot turned at an exploration's goal (2026-11-29). Every arc of DWA's window meets the
    wall or the post within sim_time, and no turn in place is within the window from rest: move_base ABORTED
    every goal from there after its four recoveries (31 goals of one exploration). The turn to face the
    plan, tried now also where DWA finds nothing, leaves the corner within a second."""
    obstacles = world_cut('turtlebot3_house')
    start, goal = (0.6012, -0.4201, 2.8485), (-1.37, -2.57, 0.0)
    navigator, global_costmap, local_costmap = stack(obstacles, start)
    robot = Unicycle(start)
    navigator.set_goal(0.0, goal, quaternion_of_yaw(goal[2]))
    outcome, steps, _ = run_stack(navigator, global_costmap, local_costmap, robot, Lidar(obstacles), 60.0)
    print('MEASURED from the corner: %s after %.1f s, recoveries %s' % (
        outcome and outcome.text, len(steps) * PERIOD, [s.recovery for s in steps if s.recovery]))
    assert outcome is not None and outcome.status == SUCCEEDED
    assert not [step.recovery for step in steps if step.recovery]
    assert math.hypot(robot.pose[0] - goal[0], robot.pose[1] - goal[1]) <= 0.05
