"""ROBOTIS' machine-learning stages without ROS: actions, state, reward, the end of an episode, goals.

The facts are those of turtlebot3_machine_learning's environment_stage_N.py and
respawnGoal.py (2018 and noetic): five actions at 0.15 m/s turning
((5 - 1) / 2 - action) * 0.75 rad/s; a state of the 24 lidar ranges (inf read as
3.5 m, NaN as 0), the heading to the goal and the distance to it (rounded to
0.01), and from stage 2 on the nearest range and its beam; a collision when a
range lies between 0 and 0.13 m; a goal within 0.2 m; a reward shaped by the
heading for the action taken, times 2 ** (distance / the distance when the goal
appeared); a collision's and a goal's rewards per stage. Everything here is a
pure function or a small class, so each is tested against ROBOTIS' formulas.
"""
import math
import random
from dataclasses import dataclass

from tb3_common.pose2d import normalize_angle

ACTION_SIZE = 5
LINEAR_SPEED = 0.15        # m/s, whatever the action
MAX_ANGULAR_SPEED = 1.5    # rad/s; each action turns ((ACTION_SIZE - 1) / 2 - action) * MAX_ANGULAR_SPEED / 2
COLLISION_RANGE = 0.13     # m: a range below this (and above 0) is a collision
GOAL_RANGE = 0.2           # m from the goal
SCAN_RANGE_MAX = 3.5       # m: what a beam that met nothing (inf) reads as
BEAMS = 24                 # the chapter's lidar: "modify it to 24"
INITIAL_GOAL = (0.6, 0.0)  # respawnGoal's first goal, in every stage
#: respawnGoal's stage 1-3 goals: x and y in tenths of a metre from -1.2 to 1.2, none within 0.4 m
#: (in x and in y) of stage 2's cylinders or of the spawn, none within 1 m (in both) of the last goal.
GOAL_TENTHS = range(-12, 13)
GOAL_KEEP_OUT = ((0.6, 0.6), (0.6, -0.6), (-0.6, 0.6), (-0.6, -0.6), (0.0, 0.0))
GOAL_KEEP_OUT_RANGE = 0.4
GOAL_MIN_STEP = 1.0
#: respawnGoal's stage 4 goals, between the plaza's walls.
STAGE_4_GOALS = ((0.6, 0.0), (1.9, -0.5), (0.5, -1.9), (0.2, 1.5), (-0.8, -0.9), (-1.0, 1.0), (-1.9, 1.1),
                 (0.5, -1.5), (2.0, 1.5), (0.5, 1.8), (0.0, -1.0), (-0.1, 1.6), (-2.0, -0.8))


@dataclass(frozen=True)
class Stage:
    """What differs from stage to stage: the state's obstacle terms, the rewards."""
    number: int
    obstacle_terms: bool      # the nearest range and its beam at the state's end
    collision_reward: float
    goal_reward: float
    near_range: float = 0.0   # stage 4: a nearest range below this ...
    near_reward: float = 0.0  # ... adds this to each step's reward

    @property
    def state_size(self):
        return BEAMS + 2 + (2 if self.obstacle_terms else 0)


STAGES = {1: Stage(1, False, -200.0, 200.0),
          2: Stage(2, True, -150.0, 200.0),
          3: Stage(3, True, -150.0, 200.0),
          4: Stage(4, True, -500.0, 1000.0, near_range=0.5, near_reward=-5.0)}


def twist(action, action_size=ACTION_SIZE):
    """(linear m/s, angular rad/s) of an action: 0 turns left fastest, the middle one goes straight."""
    return LINEAR_SPEED, ((action_size - 1) / 2.0 - action) * MAX_ANGULAR_SPEED * 0.5


def ranges_of(ranges, range_min):
    """A scan's ranges as the state takes them: inf as SCAN_RANGE_MAX, NaN as 0. Gazebo's ray
    sensor gives no -inf; this simulator gives it for a wall nearer than the lidar's range_min
    (REP 117), and it reads as range_min here, nearer than COLLISION_RANGE: the collision it is."""
    taken = []
    for value in ranges:
        if math.isnan(value):
            taken.append(0.0)
        elif value == math.inf:
            taken.append(SCAN_RANGE_MAX)
        elif value == -math.inf:
            taken.append(float(range_min))
        else:
            taken.append(float(value))
    return taken


def heading_to(pose, goal):
    """The goal's bearing from the robot's heading (rad, rounded to 0.01), in [-pi, pi) (ROBOTIS' wraps
    once into [-pi, pi]: the same but at pi itself)."""
    x, y, yaw = pose
    return round(normalize_angle(math.atan2(goal[1] - y, goal[0] - x) - yaw), 2)


def distance_to(pose, goal):
    return round(math.hypot(goal[0] - pose[0], goal[1] - pose[1]), 2)


def observe(stage, ranges, pose, goal):
    """(state, collided, at_goal) of a scan's ranges (ranges_of's), the robot's pose (x, y, yaw) and
    the goal (x, y)."""
    distance = distance_to(pose, goal)
    state = list(ranges) + [heading_to(pose, goal), distance]
    if stage.obstacle_terms:
        nearest = min(ranges)
        state += [round(nearest, 2), ranges.index(nearest)]
    collided = COLLISION_RANGE > min(ranges) > 0
    return state, collided, distance < GOAL_RANGE


def heading_rewards(heading, action_size=ACTION_SIZE):
    """Each action's heading term, 1 when it turns straight at the goal, down to -1 away from it."""
    terms = []
    for action in range(action_size):
        angle = -math.pi / 4 + heading + (math.pi / 8 * action) + math.pi / 2
        terms.append(1 - 4 * math.fabs(0.5 - math.modf(0.25 + 0.5 * angle % (2 * math.pi) / math.pi)[0]))
    return terms


def reward(stage, state, action, start_distance, collided, at_goal):
    """ROBOTIS' setReward: the heading term of `action` times 2 ** (distance / start_distance);
    a collision's reward if collided, the goal's if at the goal (the goal's wins if both)."""
    if stage.obstacle_terms:
        heading, distance, nearest = state[-4], state[-3], state[-2]
    else:
        heading, distance, nearest = state[-2], state[-1], math.inf
    value = round(heading_rewards(heading)[action] * 5, 2) * 2 ** (distance / max(start_distance, 1e-9))
    if nearest < stage.near_range:
        value += stage.near_reward
    if collided:
        value = stage.collision_reward
    if at_goal:
        value = stage.goal_reward
    return value


class Goals(object):
    """Where the goals appear (respawnGoal.getPosition), from a random.Random of its own."""

    def __init__(self, stage_number, seed=None):
        self.stage = stage_number
        self.random = random.Random(seed)
        self.goal = INITIAL_GOAL
        self._index = 0  # stage 4: the list's entry of the goal

    def next(self):
        """The next goal (x, y), as respawnGoal picks it after a goal is reached."""
        if self.stage == 4:
            index = self._index
            while index == self._index:
                index = self.random.randrange(0, len(STAGE_4_GOALS))
            self._index = index
            self.goal = STAGE_4_GOALS[index]
            return self.goal
        last = self.goal
        while True:
            x = self.random.choice(GOAL_TENTHS) / 10.0
            y = self.random.choice(GOAL_TENTHS) / 10.0
            kept_out = any(abs(x - ox) <= GOAL_KEEP_OUT_RANGE and abs(y - oy) <= GOAL_KEEP_OUT_RANGE
                           for ox, oy in GOAL_KEEP_OUT)
            if not kept_out and not (abs(x - last[0]) < GOAL_MIN_STEP and abs(y - last[1]) < GOAL_MIN_STEP):
                self.goal = (x, y)
                return self.goal
