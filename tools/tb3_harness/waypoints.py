"""A test's driver: steer a robot through waypoints on its true pose (the judge's view, not the robot's).

Tests of mapping and navigation need a robot that drives a known route
whatever the code under test believes: the driver steers on ground truth
(base_pose_ground_truth, or the simulator core's pose) towards each
waypoint in turn, turning in place when facing away.
"""
import math

#: A loop of about 14 m around turtlebot3_world's pillars from tb3_world.launch's
#: spawn pose (-2.0, -0.5): up the west side, across the north, down the east,
#: back along the south, and home; 0.4 m or more from every pillar and wall.
WORLD_LOOP_START = (-2.0, -0.5, 0.0)
WORLD_LOOP = [(-1.65, -0.5), (-1.65, 1.65), (0.55, 1.65), (1.65, 1.65), (1.65, -0.55), (1.65, -1.65),
              (-0.55, -1.65), (-1.65, -1.65), (-1.65, -0.5), (-2.0, -0.5)]

#: test_navigation's four goals (x, y, yaw) around and between the pillars, in its order from the spawn pose,
#: and a route through them with the corners that keep the straight legs 0.4 m or more from the pillars.
WORLD_GOALS = [(-0.55, -0.55, 0.0), (0.55, 0.55, math.pi / 2), (1.65, -0.55, -math.pi / 2), (-0.55, 1.65, math.pi)]
WORLD_GOALS_ROUTE = [(-0.55, -0.55), (0.55, -0.55), (0.55, 0.55), (1.65, 0.55), (1.65, -0.55), (1.65, 1.65),
                     (-0.55, 1.65)]

#: A tour of about 33 m through turtlebot3_house from tb3_house.launch's spawn pose
#: (-3.0, 1.0): across the living room into the corridor, through the door at
#: x = 2.3 into the east room, through the door at its north-west corner into
#: the room behind (x -0.05..2.3) and back, round the marble table, and through
#: the south door into the south-east room, 14 m of walls away from the start.
#: Every waypoint and the straight legs between them stay 0.39 m or more from
#: every obstacle of the lidar's cut.
HOUSE_TOUR_START = (-3.0, 1.0, 0.0)
HOUSE_TOUR = [(-1.0, 1.2), (-1.0, 0.4), (1.2, 0.4), (3.0, 0.4), (3.0, 4.6), (1.0, 4.6), (1.0, 1.6), (1.0, 4.6),
              (3.0, 4.6), (6.5, 4.0), (6.8, 1.0), (6.2, 0.5), (6.2, -1.0), (5.6, -1.5), (5.6, -4.5)]
#: From HOUSE_TOUR_START out of the house through the open south side into the yard, round the outside of
#: the house and back in (85 m): where no wall seen before is in range the SLAM drifts (49 cm at worst on
#: the north and east sides).
HOUSE_OUTSIDE = [(-1.0, 0.4), (1.2, 0.4), (1.2, -1.4), (-2.5, -4.5), (-4.5, -5.6), (-8.3, -4.8), (-8.6, 6.0),
                 (-7.5, 6.5), (7.5, 6.5), (8.7, 5.5), (8.7, -6.0), (7.5, -6.8), (5.0, -6.8), (3.5, -5.0), (2.5, -2.0),
                 (1.2, -1.4), (1.2, 0.4), (-1.0, 0.4), (-3.0, 1.0), (-4.4, 3.3), (-1.0, 4.0), (-1.0, 1.2), (-3.0, 1.0)]


def steer(pose, target, speed=0.18, turn_speed=1.0):
    """(v, w) from `pose` (x, y, yaw) towards `target` (x, y): turn in place when facing
    more than 0.4 rad away, slow down over the last 0.15 m."""
    dx, dy = target[0] - pose[0], target[1] - pose[1]
    error = math.atan2(dy, dx) - pose[2]
    error = (error + math.pi) % (2 * math.pi) - math.pi
    w = max(-turn_speed, min(turn_speed, 2.5 * error))
    v = 0.0 if abs(error) > 0.4 else speed * max(0.0, math.cos(error)) * min(1.0, math.hypot(dx, dy) / 0.15 + 0.3)
    return v, w


class Route(object):
    """Waypoints, each passed when the robot is within `reach` m of it."""

    def __init__(self, waypoints, reach=0.05):
        self.left = list(waypoints)
        self.reach = reach

    def command(self, pose, speed=0.18, turn_speed=1.0):
        """(v, w) for the robot at `pose`; (0, 0) once every waypoint is passed (done)."""
        while self.left and math.hypot(self.left[0][0] - pose[0], self.left[0][1] - pose[1]) < self.reach:
            self.left.pop(0)
        return steer(pose, self.left[0], speed, turn_speed) if self.left else (0.0, 0.0)

    @property
    def done(self):
        return not self.left


def path_length(points):
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(points, points[1:]))
