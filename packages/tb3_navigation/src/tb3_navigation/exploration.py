"""explore_lite's loop as a pure class fed the time, the map and the robot's pose. No ROS here.

Every 1 / planner_frequency s (and at once when move_base ends a goal) the
node asks decide(); it answers SEND a goal to move_base, KEEP the one it
pursues, WAIT, or DONE with the reason. As explore_lite:

- the cheapest frontier (tb3_navigation.frontiers) is the target; a new
  goal is sent when the target moved off the current goal's cell;
- a goal move_base ABORTS is blacklisted;
- a target the robot makes no progress towards for progress_timeout s is
  blacklisted (progress: the path to it got a cell shorter than it ever
  was, or the target moved more than blacklist_radius, a new target);
- when no frontier is left worth visiting, exploration is DONE, for good.

Two additions, each closing a way to sit still: after a goal SUCCEEDS the
decision WAITs for a map made after it, MAP_WAIT s at most (the SLAM
publishes every map_update_interval, 2 s: the map of the moment still shows
the frontier the robot just went to look at); and a target within blacklist_radius of the goal
just reached, on that newer map, is blacklisted at once (the robot stood
there and saw all it could: explore_lite would sit there for progress_timeout,
30 s, first).
"""
import math
from dataclasses import dataclass

from .costmap import CostmapConfig
from .frontiers import NAVFN, ExploreConfig, FrontierSearch

SEND, KEEP, WAIT, DONE = 'send', 'keep', 'wait', 'done'
MAP_WAIT = 5.0  # s: the longest wait for a map newer than a goal's success (the SLAM's come every 2 s)
SUCCEEDED, ABORTED = 3, 4  # actionlib_msgs/GoalStatus


@dataclass(frozen=True)
class Decision:
    """What to do: action (SEND, KEEP, WAIT, DONE); the goal (x, y, yaw) to pursue; the
    chosen Frontier; the Search it came from; text (why: for WAIT, DONE and blacklisting)."""
    action: str
    goal: tuple = None
    frontier: object = None
    search: object = None
    text: str = ''


class Explorer(object):
    """The exploration's state: the goal pursued, the blacklist, progress, done."""

    def __init__(self, config=ExploreConfig(), costmap_config=CostmapConfig(), planner_config=NAVFN):
        self.config = config
        self.frontier_search = FrontierSearch(config, costmap_config, planner_config)
        self.blacklist = []      # [(x, y)]: goals that failed
        self.goal = None         # (x, y, yaw) sent to move_base, no result yet
        self.goals_sent = 0
        self.done_text = None    # why exploration ended (None while it goes on)
        self.notes = []          # what happened since the last decision, in words (blacklisting)
        self._track = None       # (target (x, y), shortest distance to it so far, sim time of the last progress)
        self._reached = None     # the goal that last SUCCEEDED, until a map newer than that is seen
        self._reached_at = None

    @property
    def done(self):
        return self.done_text is not None

    def add_to_blacklist(self, point, why):
        self.blacklist.append((float(point[0]), float(point[1])))
        self.notes.append('goal (%.2f, %.2f) blacklisted: %s' % (point[0], point[1], why))

    def result(self, now, goal, status):
        """move_base ended `goal` with `status` (actionlib's) at sim time `now`."""
        if self.goal is None or goal is None or _gap(goal, self.goal) > 1e-9:
            return  # a goal replaced since: its end says nothing of the current one
        self.goal = None
        if status == ABORTED:
            self.add_to_blacklist(goal, 'move_base aborted it')
            self._track = None
        elif status == SUCCEEDED:
            self._reached, self._reached_at = goal, now

    def decide(self, now, grid, values, robot_pose, map_time=None):
        """The Decision at sim time `now` on the map `values` [iy, ix] on `grid` (made at
        `map_time`, if known) for the robot at `robot_pose` (x, y, yaw) in the map's frame."""
        if self.done:
            return Decision(DONE, text=self.done_text)
        if self._reached is not None and map_time is not None and map_time <= self._reached_at \
                and now < self._reached_at + MAP_WAIT:
            return Decision(WAIT, text='waiting for a map made after the goal was reached')
        config, resolution = self.config, grid.resolution
        while True:  # each pass either decides or blacklists one more point: it ends
            search = self.frontier_search.search(grid, values, robot_pose, self.blacklist)
            best = search.best
            if best is None:
                self.done_text = search.why_none()
                self.goal = None
                return Decision(DONE, search=search, text=self.done_text)
            target = best.goal
            if self._reached is not None and _gap(target, self._reached) <= config.blacklist_radius:
                self.add_to_blacklist(target, 'reached, and still a frontier from there')
                self._reached = None
                continue
            if self._track is None or _gap(target, self._track[0]) > config.blacklist_radius:
                self._track = (target[:2], best.distance, now)  # a new target
            elif best.distance < self._track[1] - resolution:
                self._track = (target[:2], best.distance, now)  # nearer: progress
            elif now - self._track[2] > config.progress_timeout:
                self.add_to_blacklist(target, 'no progress for %g s' % config.progress_timeout)
                self._track = None
                continue
            else:
                self._track = (target[:2],) + self._track[1:]
            break
        self._reached = None
        if self.goal is not None and _gap(target, self.goal) < resolution / 2.0:
            return Decision(KEEP, self.goal, best, search)
        self.goal = target
        self.goals_sent += 1
        return Decision(SEND, target, best, search)

    def take_notes(self):
        """What happened since the last call (blacklisting), in words; cleared."""
        notes, self.notes = self.notes, []
        return notes


def _gap(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])
