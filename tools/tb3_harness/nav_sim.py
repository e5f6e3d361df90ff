"""A small closed loop for the navigation cores' tests (no ROS, no pybullet).

A unicycle with TurtleBot3's acceleration limits stands for the Burger, a
2-D ray cast of a world's cut at the lidar's height (tb3_sim_nav.world_map)
for its LDS-01 (360 beams, 0.12-3.5 m, sigma 0.01 m, seeded), and the map is
the cut as world_map.map_of_world draws it for the shipped maps. The odom
frame is set off from the map frame, so that the cores meet two frames as on
the robot. `stack` and `run_stack` drive move_base's cores (costmaps,
planner, DWA, state machine) with TurtleBot3's values in that loop.
"""
import math

import numpy as np

from tb3_common.pose2d import compose, inverse
from tb3_navigation.controller import DwaController
from tb3_navigation.costmap import BURGER_FOOTPRINT, Costmap, CostmapConfig
from tb3_navigation.dwa_config import dwa_config
from tb3_navigation.navigator import Navigator, NavigatorConfig
from tb3_navigation.planner import GlobalPlanner, PlannerConfig
from tb3_navigation.scan import Scan
from tb3_sim_nav import world_map
from tb3_sim_nav.world_file import load_world

from . import ROOT as REPO

SCAN_POSE = (-0.032, 0.0, 0.0)  # base_scan in base_footprint (Burger)
BEAMS, RANGE_MIN, RANGE_MAX, SIGMA = 360, 0.12, 3.5, 0.01
MAP_IN_ODOM = (0.3, -0.2, 0.1)  # the map frame's pose in odom: any fixed offset will do
PERIOD = 0.1  # s: move_base's controller_frequency (TurtleBot3's 10 Hz); scans come every other period


def world_cut(world='turtlebot3_world'):
    """The obstacles of a world file that the Burger's lidar plane cuts."""
    return world_map.in_plane(load_world(world, str(REPO / 'worlds')).obstacles)


class Unicycle(object):
    """A differential base whose velocity follows the command within acceleration limits."""

    def __init__(self, pose, acc_lim_x=2.5, acc_lim_theta=3.2, max_v=0.22, max_w=2.84):
        self.pose = np.array(pose, dtype=float)
        self.velocity = np.zeros(2)
        self.acc = np.array([acc_lim_x, acc_lim_theta])
        self.limits = np.array([max_v, max_w])

    def run(self, command, seconds, substeps=10):
        dt = seconds / substeps
        target = np.clip(np.asarray(command, dtype=float), -self.limits, self.limits)
        for _ in range(substeps):
            self.velocity += np.clip(target - self.velocity, -self.acc * dt, self.acc * dt)
            v, w = self.velocity
            x, y, yaw = self.pose
            if abs(w) < 1e-9:
                x, y = x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw)
            else:
                x += v / w * (math.sin(yaw + w * dt) - math.sin(yaw))
                y -= v / w * (math.cos(yaw + w * dt) - math.cos(yaw))
            self.pose = np.array([x, y, (yaw + w * dt + math.pi) % (2 * math.pi) - math.pi])


class Lidar(object):
    """An LDS-01 on the Burger ray-casting the cut."""

    def __init__(self, obstacles, seed=3):
        self.obstacles = obstacles
        self.rng = np.random.default_rng(seed)
        self.angles = np.arange(BEAMS) * 2.0 * math.pi / BEAMS

    def scan(self, pose):
        """The Scan seen from the robot at `pose` (x, y, yaw, world frame)."""
        sensor = compose(pose, SCAN_POSE)
        ranges = world_map.ray_cast(self.obstacles, sensor[:2], sensor[2] + self.angles)
        ranges = ranges + self.rng.normal(0.0, SIGMA, BEAMS)
        # As the simulator's lidar (REP 117): +inf past range_max, -inf nearer than range_min
        # (a reading the cores skip: a +inf there would clear the cells through the obstacle).
        ranges = np.where(ranges > RANGE_MAX, np.inf, np.where(ranges < RANGE_MIN, -np.inf, ranges))
        return Scan(0.0, 2.0 * math.pi / BEAMS, ranges, RANGE_MIN, RANGE_MAX)


def costmaps(obstacles, start, config=CostmapConfig()):
    """(global costmap in map from the cut's map, local rolling 3 x 3 m costmap in odom)."""
    grid, data = world_map.map_of_world(obstacles)
    local_start = compose(MAP_IN_ODOM, start)
    return Costmap(grid, config, static=data), Costmap.rolling(config, centre=local_start[:2])


def update_costmaps(global_costmap, local_costmap, pose, scan):
    """One update of both: the robot and its lidar seen in map (global) and odom (local)."""
    global_costmap.update(pose, scan, compose(pose, SCAN_POSE))
    local_pose = compose(MAP_IN_ODOM, pose)
    local_costmap.update(local_pose, scan, compose(local_pose, SCAN_POSE))


def footprint_clearance(obstacles, footprint, pose):
    """Distance (m) from the footprint polygon at `pose` to the nearest obstacle
    (negative if they overlap): the least signed distance along its outline."""
    from tb3_navigation.footprint import outline
    points = outline(footprint, 0.005)
    cos, sin = math.cos(pose[2]), math.sin(pose[2])
    world = np.stack((pose[0] + cos * points[:, 0] - sin * points[:, 1],
                      pose[1] + sin * points[:, 0] + cos * points[:, 1]), axis=-1)
    return float(world_map.signed_distance(obstacles, world).min())


def odom_of(pose):
    return compose(MAP_IN_ODOM, pose)


def map_of_odom(pose):
    return compose(inverse(MAP_IN_ODOM), pose)


def stack(obstacles, start, planner_config=PlannerConfig()):
    """(move_base's Navigator with TurtleBot3's values, its global costmap, its local one) for a robot at `start`."""
    global_costmap, local_costmap = costmaps(obstacles, start)
    navigator = Navigator(NavigatorConfig(), GlobalPlanner(planner_config), DwaController(local_costmap, dwa_config()),
                          global_costmap, local_costmap)
    return navigator, global_costmap, local_costmap


def run_stack(navigator, global_costmap, local_costmap, robot, lidar, seconds, judged=None, poses=None):
    """Steps the stack at 10 Hz (scans at 5 Hz) until an outcome; (outcome, steps, the
    closest approach of the robot's footprint to each of the `judged` groups of obstacles
    (default: all the lidar sees)). `poses`, a list: the robot's pose after each period is added."""
    judged = judged or dict(all=lidar.obstacles)
    now, steps, clearance = 0.0, [], dict((name, math.inf) for name in judged)
    for tick in range(int(round(seconds / PERIOD))):
        if tick % 2 == 0:
            update_costmaps(global_costmap, local_costmap, robot.pose, lidar.scan(robot.pose))
        step = navigator.step(now, tuple(robot.pose), tuple(robot.velocity), MAP_IN_ODOM)
        steps.append(step)
        if step.outcome is not None:
            return step.outcome, steps, clearance
        assert step.cmd is not None and all(math.isfinite(value) for value in step.cmd)
        robot.run(step.cmd, PERIOD)
        now += PERIOD
        if poses is not None:
            poses.append(robot.pose.copy())
        for name, group in judged.items():
            clearance[name] = min(clearance[name], footprint_clearance(group, BURGER_FOOTPRINT, robot.pose))
    return None, steps, clearance
