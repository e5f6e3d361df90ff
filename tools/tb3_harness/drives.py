"""Recorded drives of a simulated Burger, for the tests of the navigation cores (no ROS).

record_drive() drives the pybullet Burger of tb3_sim_nav's core through
waypoints in a world file, steering on the true pose (the test's driver,
not the code under test), and records at the lidar's 5 Hz what a node on
the robot would get: the scan, the odometry (the profile's: the true pose
under 'gazebo', drifting wheel odometry under 'realistic') and, for the
test's judgement only, the true pose. The navigation cores see only scans
and odometry.
"""
import math
from collections import namedtuple

import numpy as np

from tb3_common.grid import Grid
from tb3_common.pose2d import compose, normalize_angle
from tb3_navigation.scan import Scan
from tb3_sim_nav import world_map
from tb3_sim_nav.frames import planar, yaw_of
from tb3_sim_nav.params import resolve
from tb3_sim_nav.robot_model import load_model
from tb3_sim_nav.simulation import build
from tb3_sim_nav.world_file import load_world

from . import ROOT as REPO
from .waypoints import (  # noqa: F401
    HOUSE_OUTSIDE,
    HOUSE_TOUR,
    HOUSE_TOUR_START,
    WORLD_GOALS,
    WORLD_GOALS_ROUTE,
    WORLD_LOOP,
    WORLD_LOOP_START,
    Route,
    path_length,  # (for the tests)
)

#: base_scan in base_footprint on the Burger (x, y, yaw): (-0.032, 0, 0.182) in 3-D.
BURGER_SCAN_POSE = (-0.032, 0.0, 0.0)
SCAN_PERIOD_NS = 200000000  # 5 Hz
CONTROL_PERIOD_NS = 30000000  # a command every 30 ms of sim time

#: One drive: times (n,) s; truth and odom (n, 3) (x, y, yaw); ranges (n, beams);
#: the scan's angle_min, angle_increment, range_min, range_max; the sensor's pose in the base frame.
Drive = namedtuple('Drive', 'times truth odom ranges angle_min angle_increment range_min range_max scan_pose')


def _pose(pose):
    (x, y, _), orientation = pose
    return x, y, yaw_of(orientation)


def record_drive(world, start, waypoints, profile='realistic', seed=7, speed=0.18, turn_speed=1.0,
                 reach=0.05, settle=1.0, overrides=None):
    """The Drive of a Burger spawned at `start` (x, y, yaw) in `world` (a name in
    worlds/ or a path) going through `waypoints` [(x, y)], each reached within
    `reach` m, then standing `settle` s."""
    values = dict(profile=profile, seed=seed, **(overrides or {}))
    config = resolve(lambda name, default: values.get(name, default))
    obstacles = load_world(world, str(REPO / 'worlds')).obstacles
    model = load_model(str(REPO / 'urdf' / 'turtlebot3_burger.urdf'))
    simulation = build(config, obstacles, [('', model, planar(start[0], start[1], 0.0, start[2]))])
    try:
        robot = simulation.robots['']
        lidar = robot.lidar
        times, truth, odom, ranges = [], [], [], []
        route = Route(waypoints, reach)
        standing_until = None
        while True:
            now = simulation.now_ns
            if now % CONTROL_PERIOD_NS == 0:
                robot.command(*route.command(_pose(robot.truth()[0]), speed, turn_speed), now_ns=now)
                if route.done and standing_until is None:
                    standing_until = now + int(settle * 1e9)
            if now % SCAN_PERIOD_NS == 0:
                true_pose, _ = robot.truth()
                odom_pose, _ = robot.odometry()
                times.append(now * 1e-9)
                truth.append(_pose(true_pose))
                odom.append(_pose(odom_pose))
                ranges.append(robot.scan())
            if standing_until is not None and now >= standing_until:
                break
            simulation.step()
        return Drive(np.array(times), np.array(truth), np.array(odom), np.array(ranges), 0.0,
                     lidar.angle_increment, lidar.range_min, lidar.range_max, BURGER_SCAN_POSE)
    finally:
        simulation.close()


# -- amcl on a drive (the localization tests and tools/bench_amcl.py) ----------------------------------------

TIGHT = np.diag([1e-4, 1e-4, 1e-4])  # 1 cm and 0.6 degrees: "the filter starts where the robot is"


def world_grid(world, resolution=0.05, margin=0.3):
    """(Grid, int8 values) of a world file's obstacles cut at the Burger's lidar height."""
    obstacles = world_map.in_plane(load_world(world, str(REPO / 'worlds')).obstacles)
    grid = Grid.around(resolution, *world_map.bounds(obstacles, margin))
    distance = world_map.signed_distance(obstacles, grid.all_centres().reshape(-1, 2)).reshape(grid.shape)
    return grid, np.where(distance <= resolution / 2.0, 100, 0).astype(np.int8)


def scan(drive, index):
    return Scan(drive.angle_min, drive.angle_increment, drive.ranges[index], drive.range_min, drive.range_max)


def travelled(drive):
    return np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(drive.truth[:, :2], axis=0).T))))


def run(amcl, drive, odom=None):
    """Feed every scan; (tf errors (n,) m at every scan, [(index, estimate error m, yaw error, particles)]
    at every update)."""
    odom = drive.odom if odom is None else odom
    errors, updates = [], []
    for index in range(len(drive.times)):
        truth = drive.truth[index]
        if amcl.update(odom[index], scan(drive, index), drive.scan_pose):
            pose = amcl.estimate().pose
            updates.append((index, math.hypot(pose[0] - truth[0], pose[1] - truth[1]),
                            abs(normalize_angle(pose[2] - truth[2])), len(amcl.particles)))
        seen = compose(amcl.map_to_odom(), odom[index])
        errors.append(math.hypot(seen[0] - truth[0], seen[1] - truth[1]))
    return np.array(errors), np.array(updates)
