"""move_base's parameters as ROS's tutorials write them, driving (no ROS): the ROS wiki tutorial's
TrajectoryPlannerROS values and robot_radius, mapped onto this node's DWA, take the whole stack (costmaps,
global planner, navigator) around turtlebot3_world's pillars on tb3_harness.nav_sim's unicycle; and ROS by
Example's 6 x 6 m local costmap at 0.01 m works beside TurtleBot3's 3 x 3 m at 0.05 m, one update and one
command of each timed. The parameter trees are move_base_param_trees.py's.
"""
import math
import time

import numpy as np
from move_base_param_trees import RBX1, WIKI, launch

from move_base import planners
from move_base.settings import construct, resolve, trajectory_dwa
from tb3_common.pose2d import compose
from tb3_harness import nav_sim
from tb3_navigation.controller import DwaController
from tb3_navigation.costmap import BURGER_FOOTPRINT, Costmap, CostmapConfig
from tb3_navigation.dwa_config import DwaConfig
from tb3_navigation.footprint import circle_footprint
from tb3_navigation.navigator import SUCCEEDED, Navigator
from tb3_navigation.planner import GlobalPlanner

# --- they drive: the wiki's TrajectoryPlannerROS around turtlebot3_world's pillars -------------

START = (-2.0, -0.5, 0.0)
GOALS = [(-0.55, -0.55, 0.0), (0.55, 0.55, math.pi / 2)]


def test_the_wiki_tutorials_trajectory_planner_drives_around_the_pillars():
    """The whole stack on the unicycle with the tutorial's TrajectoryPlannerROS values (its biases per
    cell: no meter_scoring) and robot_radius, at move_base's controller_frequency (TurtleBot3's 10 Hz).
    (ROS by Example's weights, per metre with occdist_scale 0.1, stop at the gap between the pillars and
    turn in place: entering the gap costs 0.1 x 150 for the footprint's cells, more than the 0.6 x 0.3 m
    one step nearer the goal saves. base_local_planner scores them the same way.)"""
    resolved = resolve(launch(*WIKI, base_local_planner=planners.TRAJECTORY))
    frequency = resolved.navigator.controller_frequency
    dwa = trajectory_dwa(resolved.trajectory, 0.05, frequency, {})
    obstacles = nav_sim.world_cut()
    global_costmap, local_costmap = nav_sim.costmaps(obstacles, START, resolved.local_costmap.config)
    navigator = Navigator(resolved.navigator, GlobalPlanner(resolved.planner), DwaController(local_costmap, dwa),
                          global_costmap, local_costmap, resolved.rotation)
    robot, lidar = nav_sim.Unicycle(START), nav_sim.Lidar(obstacles)
    now = 0.0
    for goal in GOALS:
        navigator.set_goal(now, goal[:2] + (0.0,), (0.0, 0.0, math.sin(goal[2] / 2), math.cos(goal[2] / 2)))
        outcome, least, since = None, math.inf, now
        while outcome is None and now - since < 90.0:
            nav_sim.update_costmaps(global_costmap, local_costmap, robot.pose, lidar.scan(robot.pose))
            step = navigator.step(now, tuple(robot.pose), tuple(robot.velocity), nav_sim.MAP_IN_ODOM)
            outcome = step.outcome
            robot.run(step.cmd or (0.0, 0.0), 1.0 / frequency)
            now += 1.0 / frequency
            least = min(least, nav_sim.footprint_clearance(obstacles, BURGER_FOOTPRINT, robot.pose))
        error = math.hypot(robot.pose[0] - goal[0], robot.pose[1] - goal[1])
        print('MEASURED the wiki\'s TrajectoryPlannerROS to %s: %s in %.1f s, %.3f m off, footprint %.3f m from '
              'the world' % (goal, outcome and outcome.status, now - since, error, least))
        assert outcome is not None and outcome.status == SUCCEEDED
        assert error <= dwa.xy_goal_tolerance and least > 0.05


def test_a_local_costmap_at_0_01_m_works_and_what_it_costs():
    """ROS by Example's 6 x 6 m local costmap at 0.01 m (360,000 cells) against TurtleBot3's 3 x 3 m at
    0.05 m (3,600): one update and one command each, timed."""
    obstacles = nav_sim.world_cut()
    lidar = nav_sim.Lidar(obstacles)
    pose = np.array(START)
    plan = GlobalPlanner().make_plan(nav_sim.costmaps(obstacles, START)[0], START, GOALS[0])
    times = {}
    for size, resolution in ((3.0, 0.05), (6.0, 0.01)):
        config = CostmapConfig(footprint=circle_footprint(0.165), inflation_radius=0.3)
        costmap = Costmap.rolling(config, size, size, resolution, centre=pose[:2])
        controller = DwaController(costmap, construct(DwaConfig, '', planners.dwa_of_trajectory_planner(
            resolve(launch(*RBX1)).trajectory, resolution, 3.0)))
        started = time.process_time()
        costmap.update(pose, lidar.scan(pose), tuple(compose(pose, nav_sim.SCAN_POSE)))
        updated = time.process_time()
        command = controller.compute(pose, (0.0, 0.0), plan)
        times[resolution] = (updated - started, time.process_time() - updated)
        assert command.ok and command.v >= 0.0
    print('MEASURED local costmap update / DWA command, CPU s: 3 x 3 m at 0.05 m %.3f / %.3f; 6 x 6 m at 0.01 m '
          '%.3f / %.3f' % (times[0.05] + times[0.01]))
