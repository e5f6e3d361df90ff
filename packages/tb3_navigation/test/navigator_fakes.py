"""The navigator's tests' stand-ins (no ROS): a fake planner, controller and costmap that do as they are
set to and count their calls, and Run, the navigator stepped at 10 Hz (nav_sim.PERIOD, move_base's
controller_frequency) with them and a robot that turns (and drives, if moving) as told; UP, the goal
orientation of yaw 0.
"""
import math

import numpy as np

from tb3_common.pose2d import quaternion_of_yaw
from tb3_harness.nav_sim import MAP_IN_ODOM, PERIOD
from tb3_navigation.controller import Command
from tb3_navigation.navigator import Navigator, NavigatorConfig

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
