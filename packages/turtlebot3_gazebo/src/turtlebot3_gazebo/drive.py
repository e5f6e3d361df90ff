"""turtlebot3_drive's wandering, decided as ROBOTIS' turtlebot3_drive.cpp decides it. No ROS here.

The robot looks along three lidar beams, straight ahead (0 degrees), to the
left (30) and to the right (330), and keeps a state:

    GET_TB3_DIRECTION  ahead clear (> check_forward_dist): a wall near on the left
                       (< check_side_dist) -> TB3_RIGHT_TURN, near on the right ->
                       TB3_LEFT_TURN, else TB3_DRIVE_FORWARD; ahead blocked -> TB3_RIGHT_TURN
    TB3_DRIVE_FORWARD  sends LINEAR_VELOCITY ahead, back to GET_TB3_DIRECTION
    TB3_RIGHT_TURN     sends -ANGULAR_VELOCITY until odometry's yaw has moved escape_range
    TB3_LEFT_TURN      the same to the left

one step of this per turn of the node's loop (ROBOTIS runs it at 125 Hz). A
turn starts from the yaw it had when it was decided and ends when
|yaw at the start - yaw now| reaches escape_range, unwrapped as ROBOTIS
compares it: a turn across +-180 degrees ends early, and the next look
decides again, which turns on if the way is still blocked.

Departures, each for input ROBOTIS' code does not meet in Gazebo: a beam is
picked by its angle (angle_min and angle_increment), not by its index, so a
scan that starts at -180 degrees or has fewer samples still gives the three
directions (ROBOTIS' `ranges.at(330)` throws on a scan of 24 samples, as the
machine-learning chapter cuts it to); a -inf reading (REP 117: closer than
range_min) is read as 0, not as range_max as ROBOTIS' isinf() reads it, so a
pillar at the robot's nose is not taken for open space; a NaN reading or
non-finite odometry leaves the last good value in place.
"""
import dataclasses
import math

from rosgraph.names import is_legal_name

from tb3_common.params import Checked, parameter
from tb3_common.pose2d import yaw_of_quaternion

LINEAR_VELOCITY = 0.3    # m/s ahead (a Burger's simulator clamps it to the model's 0.22)
ANGULAR_VELOCITY = 1.5   # rad/s when turning
CHECK_FORWARD_DIST = 0.7  # m: nearer than this ahead, turn
CHECK_SIDE_DIST = 0.6    # m: nearer than this at 30 degrees left or right, turn away
ESCAPE_RANGE = math.radians(30.0)  # rad a turn lasts
SCAN_ANGLES = (0.0, 30.0, 330.0)   # degrees of the beams CENTER, LEFT, RIGHT
CENTER, LEFT, RIGHT = 0, 1, 2

GET_TB3_DIRECTION, TB3_DRIVE_FORWARD, TB3_RIGHT_TURN, TB3_LEFT_TURN = 0, 1, 2, 3
STATE_NAMES = ('GET_TB3_DIRECTION', 'TB3_DRIVE_FORWARD', 'TB3_RIGHT_TURN', 'TB3_LEFT_TURN')


def topic_name(value):
    """A topic to publish on: a legal ROS name, not empty."""
    return None if value and is_legal_name(value) else 'must be a topic name (letters, digits, _ and /)'


@dataclasses.dataclass(frozen=True)
class DriveConfig(Checked):
    """turtlebot3_drive's one parameter, by ROBOTIS' name. ROBOTIS' node reads it from its namespace,
    where turtlebot3_simulation.launch sets it; without it ROBOTIS' has no topic, this one cmd_vel."""
    cmd_vel_topic_name: str = parameter('cmd_vel', 'the topic the speeds go to', topic_name)


def beam_index(angle, angle_min, angle_increment, samples):
    """The index of the beam nearest `angle` (rad) in a scan of `samples` beams from `angle_min`
    `angle_increment` apart (either way round; a full circle wraps), or None if none points that way."""
    if not (math.isfinite(angle_min) and math.isfinite(angle_increment)) or angle_increment == 0.0 \
            or samples <= 0:
        return None
    step = abs(angle_increment)
    # How far round from the first beam, the way the beams go: angle_min plus a turn is angle_min again.
    offset = ((angle - angle_min) if angle_increment > 0 else (angle_min - angle)) % (2.0 * math.pi)
    index = round(offset / step)
    if index >= samples and round(2.0 * math.pi / step) <= samples:
        index %= samples                            # the last beams of a full circle are the first
    return index if 0 <= index < samples else None


def reading(value, range_max, previous):
    """A beam's range as the decisions take it: +inf (nothing within range_max) as range_max,
    -inf (closer than range_min) as 0, NaN as the `previous` reading."""
    if math.isnan(value):
        return previous
    if math.isinf(value):
        return range_max if value > 0 else 0.0
    return value


class Drive(object):
    """The state machine, fed scans and odometry; step() is one turn of ROBOTIS' control loop."""

    def __init__(self):
        self.state = GET_TB3_DIRECTION
        # As ROBOTIS': 0 until the first scan, so the robot turns right until it has looked.
        self.scan_data = [0.0, 0.0, 0.0]
        self.tb3_pose = 0.0        # yaw (rad) of the last odometry
        self.prev_tb3_pose = 0.0   # yaw when the current turn began
        self.missing = []          # the beams the last scan had no sample for (degrees)

    def on_scan(self, ranges, angle_min, angle_increment, range_max):
        """A LaserScan's ranges and geometry."""
        self.missing = []
        for beam, degrees in enumerate(SCAN_ANGLES):
            index = beam_index(math.radians(degrees), angle_min, angle_increment, len(ranges))
            if index is None:
                self.missing.append(degrees)
                continue
            self.scan_data[beam] = reading(float(ranges[index]), range_max, self.scan_data[beam])

    def on_odom(self, x, y, z, w):
        """An odometry orientation (quaternion); False (and ignored) if not finite."""
        if not all(math.isfinite(value) for value in (x, y, z, w)):
            return False
        self.tb3_pose = yaw_of_quaternion(x, y, z, w)
        return True

    def _turned(self):
        return math.fabs(self.prev_tb3_pose - self.tb3_pose) >= ESCAPE_RANGE

    def _turn(self, state):
        self.prev_tb3_pose = self.tb3_pose
        self.state = state

    def step(self):
        """One turn of the loop: the (linear m/s, angular rad/s) command it sends, or None."""
        state, center = self.state, self.scan_data[CENTER]
        if state == GET_TB3_DIRECTION:
            if center > CHECK_FORWARD_DIST:
                if self.scan_data[LEFT] < CHECK_SIDE_DIST:
                    self._turn(TB3_RIGHT_TURN)
                elif self.scan_data[RIGHT] < CHECK_SIDE_DIST:
                    self._turn(TB3_LEFT_TURN)
                else:
                    self.state = TB3_DRIVE_FORWARD
            if center < CHECK_FORWARD_DIST:
                self._turn(TB3_RIGHT_TURN)
            return None
        if state == TB3_DRIVE_FORWARD:
            self.state = GET_TB3_DIRECTION
            return LINEAR_VELOCITY, 0.0
        if self._turned():
            self.state = GET_TB3_DIRECTION
            return None
        return 0.0, (-ANGULAR_VELOCITY if state == TB3_RIGHT_TURN else ANGULAR_VELOCITY)
