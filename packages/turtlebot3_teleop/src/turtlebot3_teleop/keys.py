"""The keyboard teleop's speeds: keys set a target, the speed sent follows it in half steps. No ROS here.

w / x raise / lower the forward target by LINEAR_STEP, a / d turn more to the
left / right by ANGULAR_STEP, both held within the model's limits; s or space
stop at once. Each message sent moves the speed half a key step closer to the
target, so the robot speeds up and slows down smoothly (ROBOTIS' teleop
does the same, its "built in velocity smoother").
"""
import dataclasses

from tb3_common.params import Checked, one_of, parameter

#: Each model's top speeds: (linear m/s, angular rad/s).
LIMITS = {
    'burger': (0.22, 2.84),
    'waffle': (0.26, 1.82),
    'waffle_pi': (0.26, 1.82),
}
LINEAR_STEP = 0.01    # m/s per press of w or x
ANGULAR_STEP = 0.1    # rad/s per press of a or d
SPEED_KEYS = {'w': (LINEAR_STEP, 0.0), 'x': (-LINEAR_STEP, 0.0), 'a': (0.0, ANGULAR_STEP), 'd': (0.0, -ANGULAR_STEP)}
STOP_KEYS = ('s', ' ')


def clamp(value, limit):
    """value held between -limit and +limit."""
    return max(-limit, min(limit, value))


def step_towards(current, target, step):
    """current moved towards target by at most step."""
    if current < target:
        return min(current + step, target)
    return max(current - step, target)


class Speeds(object):
    """The target the keys set and the speed sent, for one model."""

    def __init__(self, model):
        self.max_linear, self.max_angular = LIMITS[model]
        self.target_linear, self.target_angular = 0.0, 0.0   # what the keys ask for
        self.linear, self.angular = 0.0, 0.0                 # what is sent: follows the target

    def press(self, key):
        """A key typed: 'speed' (w, x, a, d), 'stop' (s, space), or None for any other."""
        if key in SPEED_KEYS:
            linear, angular = SPEED_KEYS[key]
            # round(): 0.01 added 3 times is 0.030000000000000002 in floating point.
            self.target_linear = clamp(round(self.target_linear + linear, 2), self.max_linear)
            self.target_angular = clamp(round(self.target_angular + angular, 2), self.max_angular)
            return 'speed'
        if key in STOP_KEYS:
            self.target_linear, self.target_angular = 0.0, 0.0
            self.linear, self.angular = 0.0, 0.0   # a stop is at once, not smooth
            return 'stop'
        return None

    def step(self):
        """The speed of the next message: half a key step closer to the target. (linear, angular)."""
        self.linear = round(step_towards(self.linear, self.target_linear, LINEAR_STEP / 2), 3)
        self.angular = round(step_towards(self.angular, self.target_angular, ANGULAR_STEP / 2), 3)
        return self.linear, self.angular


@dataclasses.dataclass(frozen=True)
class TeleopConfig(Checked):
    """The teleop's one parameter, by ROBOTIS' name."""
    model: str = parameter('burger', 'the TurtleBot3 model, for its top speeds', one_of(*LIMITS))
