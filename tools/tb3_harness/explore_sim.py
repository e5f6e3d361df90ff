"""Exploration in a small closed loop, for the tests of the exploration cores (no ROS, no pybullet).

The Explorer decides on the map as the robot sees it; a stand-in for
move_base plans (tb3_navigation.planner, on a costmap of that map whose
footprint is padded by DRIVE_PADDING, so that its plans keep the robot's
centre 0.15 m off the walls, as DWA's footprint check keeps the robot off
them) and the robot follows the plan in steps of STEP m, its LDS-01 (nav_sim.Lidar, a ray
cast of the world's cut) scanning after each step into an occupancy grid on
the true pose (the SLAM's map without its errors), re-planning when the map
changes. A decision comes every 1 / planner_frequency s of the robot's
travel at 0.22 m/s and when a goal ends. The judge keeps the true path.
"""
import dataclasses
import math

import numpy as np

from tb3_common.pose2d import compose
from tb3_navigation.costmap import Costmap
from tb3_navigation.exploration import ABORTED, DONE, SEND, SUCCEEDED, WAIT, Explorer
from tb3_navigation.frontiers import known_window
from tb3_navigation.occupancy import OccupancyGrid
from tb3_navigation.planner import GlobalPlanner

from .nav_sim import SCAN_POSE, Lidar

SPEED = 0.22     # m/s: the Burger's top speed, for the sim time of a step
STEP = 0.1       # m between two scans
MAX_URANGE = 3.0  # turtlebot3_slam's maxUrange
PLANNER_PATIENCE = 5.0  # s: TurtleBot3's move_base gives up on a goal it finds no plan to for this long
DRIVE_PADDING = 0.11  # m: the Burger's inscribed radius becomes 0.151 m, under the explorer's 0.213 for goals


class ExploreLoop(object):
    """The robot at `start` (x, y, yaw) in the world's cut `obstacles`, exploring."""

    def __init__(self, obstacles, start, explorer=None, seed=3, extent=10.0):
        self.obstacles = obstacles
        self.lidar = Lidar(obstacles, seed=seed)
        self.map = OccupancyGrid.around(0.05, -extent, -extent, extent, extent)
        self.explorer = explorer or Explorer()
        self.planner = GlobalPlanner()
        self.drive_config = dataclasses.replace(self.explorer.frontier_search.costmap_config,
                                                footprint_padding=DRIVE_PADDING)
        self.pose = tuple(float(v) for v in start)
        self.now = 0.0
        self._no_plan = 0.0  # s spent without a plan to the goal
        self.path = [self.pose]
        self.decisions = []
        self.scan()

    def scan(self):
        self.map.add_scan(compose(self.pose, SCAN_POSE), self.lidar.scan(self.pose), MAX_URANGE)
        self.map_time = self.now

    def values(self):
        return self.map.values()

    def drive(self, goal, seconds):
        """Follow plans to `goal` for `seconds` of sim time: SUCCEEDED (within half a step of it),
        ABORTED (no plan for PLANNER_PATIENCE s), or None (still on the way)."""
        end = self.now + seconds
        while self.now < end:
            if math.hypot(goal[0] - self.pose[0], goal[1] - self.pose[1]) < 0.5 * STEP:
                return SUCCEEDED
            grid, values = known_window(self.map.grid, self.values(), self.pose, 1.5)
            plan = self.planner.make_plan(Costmap(grid, self.drive_config, static=values), self.pose, goal)
            if plan is None:  # move_base holds the robot still, and gives up after planner_patience
                self._no_plan += end - self.now
                self.now = end
                return ABORTED if self._no_plan >= PLANNER_PATIENCE else None
            self._no_plan = 0.0
            points = np.array(plan)[:, :2]
            along = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))))
            reach = min(STEP, along[-1])
            x, y = np.interp(reach, along, points[:, 0]), np.interp(reach, along, points[:, 1])
            heading = math.atan2(y - self.pose[1], x - self.pose[0]) if reach > 0 else self.pose[2]
            self.pose = (float(x), float(y), heading)
            self.now += max(reach, 0.01) / SPEED
            self.path.append(self.pose)
            self.scan()
        return None

    def run(self, max_decisions=400):
        """Explore until the Explorer is done (or `max_decisions`); the last Decision."""
        config = self.explorer.config
        decision = None
        for _ in range(max_decisions):
            decision = self.explorer.decide(self.now, self.map.grid, self.values(), self.pose, self.map_time)
            self.decisions.append(decision)
            if decision.action == DONE:
                return decision
            if decision.action == WAIT:
                self.now += 0.5
                self.scan()
                continue
            goal = self.explorer.goal
            if decision.action == SEND:
                self._no_plan = 0.0
            status = self.drive(goal, 1.0 / config.planner_frequency)
            if status is not None:
                self.explorer.result(self.now, goal, status)
        return decision

    def goals(self):
        return [decision.goal for decision in self.decisions if decision.action == SEND]
