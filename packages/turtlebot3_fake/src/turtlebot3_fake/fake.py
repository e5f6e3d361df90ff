"""turtlebot3_fake_node's robot, as ROBOTIS' turtlebot3_fake.cpp moves it: no physics, no sensors. No ROS here.

Each cmd_vel sets the two wheels' speeds (v -+ w * wheel_separation / 2);
each update, 30 a second, turns the wheels by speed / WHEEL_RADIUS times the
time since the last, and moves the pose by the arc they make (the midpoint
heading), as the robot's firmware integrates its encoders. A second
without a cmd_vel stops the wheels (ROBOTIS' cmd_vel_timeout). The
velocities reported are the wheels' (ROBOTIS divides the step's motion by
its duration, which gives the same, and NaN when sim time stands still).

Departures, for input ROBOTIS' code does not meet: a command with NaN or
inf stops the wheels (ROBOTIS' zeroes a NaN step, and an inf runs the pose
off to inf); time that goes back (a simulation reset) moves nothing.
"""
import dataclasses
import math

from tb3_common.params import Checked, frame_id, one_of, parameter

WHEEL_RADIUS = 0.033   # m
#: ROBOTIS' wheel_seperation_ of each model (m).
WHEEL_SEPARATION = {'burger': 0.160, 'waffle': 0.287, 'waffle_pi': 0.287}
CMD_VEL_TIMEOUT = 1.0  # s without a cmd_vel before the wheels stop
#: ROBOTIS' covariance of the odometry's pose and twist (x, y, z, roll, pitch, yaw; row by row).
COVARIANCE = (0.1, 0, 0, 0, 0, 0,
              0, 0.1, 0, 0, 0, 0,
              0, 0, 1e6, 0, 0, 0,
              0, 0, 0, 1e6, 0, 0,
              0, 0, 0, 0, 1e6, 0,
              0, 0, 0, 0, 0, 0.2)
LEFT, RIGHT = 0, 1


def joint_name(value):
    return None if value and not any(character.isspace() for character in value) else \
        'must be a joint name (no spaces, not empty)'


@dataclasses.dataclass(frozen=True)
class FakeConfig(Checked):
    """turtlebot3_fake_node's parameters by ROBOTIS' names and defaults; its node reads them in its
    namespace, as ROBOTIS' does (turtlebot3_fake.launch sets tb3_model there)."""
    tb3_model: str = parameter('burger', 'the model, for its wheel separation (ROBOTIS: no default; here '
                               '$TURTLEBOT3_MODEL, else burger)', one_of(*sorted(WHEEL_SEPARATION)))
    wheel_left_joint_name: str = parameter('wheel_left_joint', 'the left wheel in joint_states', joint_name)
    wheel_right_joint_name: str = parameter('wheel_right_joint', 'the right wheel in joint_states', joint_name)
    joint_states_frame: str = parameter('base_footprint', "joint_states' frame", frame_id)
    odom_frame: str = parameter('odom', "odometry's frame, the parent in tf", frame_id)
    base_frame: str = parameter('base_footprint', "the robot's frame, the child in tf", frame_id)


class FakeRobot(object):
    """The robot's state: wheels commanded and turned, the pose in odom, the time of the last update."""

    def __init__(self, wheel_separation):
        self.wheel_separation = wheel_separation
        self.wheel_speed_cmd = [0.0, 0.0]      # m/s at each wheel's rim
        self.last_cmd_time = -math.inf         # s of the last cmd_vel
        self.last_update = None                # s of the last update
        self.pose = [0.0, 0.0, 0.0]            # x, y (m), yaw (rad) in odom
        self.velocity = (0.0, 0.0)             # m/s ahead, rad/s about z
        self.wheel_position = [0.0, 0.0]       # rad each wheel has turned
        self.wheel_velocity = [0.0, 0.0]       # rad/s

    def command(self, linear, angular, now):
        """A cmd_vel's linear.x (m/s) and angular.z (rad/s) at `now` (s). False if not finite: the
        wheels stop."""
        self.last_cmd_time = now
        if not (math.isfinite(linear) and math.isfinite(angular)):
            self.wheel_speed_cmd = [0.0, 0.0]
            return False
        half_turn = angular * self.wheel_separation / 2.0
        self.wheel_speed_cmd = [linear - half_turn, linear + half_turn]
        return True

    def update(self, now):
        """The wheels turned and the pose moved from the last update to `now` (s)."""
        step = 0.0 if self.last_update is None else max(0.0, now - self.last_update)
        self.last_update = now
        if now - self.last_cmd_time > CMD_VEL_TIMEOUT:
            self.wheel_speed_cmd = [0.0, 0.0]
        self.wheel_velocity = [speed / WHEEL_RADIUS for speed in self.wheel_speed_cmd]
        turned = [velocity * step for velocity in self.wheel_velocity]
        self.wheel_position = [position + angle for position, angle in zip(self.wheel_position, turned)]
        ahead = WHEEL_RADIUS * (turned[RIGHT] + turned[LEFT]) / 2.0
        rotation = WHEEL_RADIUS * (turned[RIGHT] - turned[LEFT]) / self.wheel_separation
        x, y, yaw = self.pose
        self.pose = [x + ahead * math.cos(yaw + rotation / 2.0), y + ahead * math.sin(yaw + rotation / 2.0),
                     yaw + rotation]
        left, right = self.wheel_speed_cmd
        self.velocity = ((left + right) / 2.0, (right - left) / self.wheel_separation)
