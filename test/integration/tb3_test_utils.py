"""Shared helpers of the rostest integration tests (imported, not run).

Everything here is checked against the simulator's ground truth,
/base_pose_ground_truth: odom is what is under test, never the reference.

Waiting: wall-time deadlines around conditions (sim time can stop, e.g. when
physics is paused); sim-time durations are waited for as the condition
"the latest ground-truth stamp has reached t".
"""
import atexit
import math
import os
import sys
import threading
import time
from collections import namedtuple

import rospy
from nav_msgs.msg import Odometry

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', 'tools'))  # the harness
from tb3_harness.processes import Process

GROUND_TRUTH = '/base_pose_ground_truth'

Sample = namedtuple('Sample', 't x y yaw vx vy wz')
#: A Sample with the height and tilt too (GroundTruth3D).
Sample3D = namedtuple('Sample3D', Sample._fields + ('z', 'roll', 'pitch'))


# --- maths -------------------------------------------------------------------
def yaw_of(q):
    """Rotation about z of a geometry_msgs Quaternion."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def roll_pitch_of(q):
    """Roll and pitch (rad) of a geometry_msgs Quaternion (ZYX Euler angles)."""
    roll = math.atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (q.w * q.y - q.z * q.x))))
    return roll, pitch


def wrap(angle):
    """`angle` in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def unwrapped_turn(samples):
    """Total signed yaw change along `samples` (rad), counting full turns."""
    return sum(wrap(b.yaw - a.yaw) for a, b in zip(samples, samples[1:]))


def in_frame_of(origin, sample):
    """(x, y) of `sample` in the frame of the pose `origin` (x ahead, y left)."""
    dx, dy = sample.x - origin.x, sample.y - origin.y
    c, s = math.cos(origin.yaw), math.sin(origin.yaw)
    return c * dx + s * dy, -s * dx + c * dy


def speed(sample):
    return math.hypot(sample.vx, sample.vy)


def finite_difference_speeds(samples, span=3):
    """(t, linear speed, yaw rate) from poses `span` samples apart: the truth's own motion."""
    result = []
    for a, b in zip(samples, samples[span:]):
        dt = b.t - a.t
        if dt > 0:
            result.append((b.t, math.hypot(b.x - a.x, b.y - a.y) / dt, wrap(b.yaw - a.yaw) / dt))
    return result


def all_finite(message):
    """True if every float anywhere in a ROS message (recursively) is finite."""
    if isinstance(message, float):
        return math.isfinite(message)
    if isinstance(message, (list, tuple)):
        return all(all_finite(item) for item in message)
    slots = getattr(message, '__slots__', None)
    if slots is None:
        return True
    return all(all_finite(getattr(message, slot)) for slot in slots)


# --- waiting -----------------------------------------------------------------
def wait_for_simulator(truth, cmd_vel):
    """Ground truth flowing, `cmd_vel` connected to the simulator and the robot
    at rest after spawning: the rest sample, or AssertionError saying which not."""
    if not truth.wait_first(60.0):
        raise AssertionError('no base_pose_ground_truth within 60 s')
    if not wait_for(lambda: cmd_vel.get_num_connections() > 0, 30.0):
        raise AssertionError('the simulator never subscribed to /cmd_vel')
    rest = truth.wait_at_rest(timeout=30.0)
    if rest is None:
        raise AssertionError('the robot did not come to rest after spawning')
    return rest


def wait_for(predicate, timeout, poll=0.005):
    """Poll `predicate` until it is true or `timeout` wall seconds pass; its last value."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value or time.monotonic() >= deadline or rospy.is_shutdown():
            return value
        time.sleep(poll)


def real_time_factor():
    """The ~real_time_factor the .test passed on (0 = as fast as possible)."""
    return float(rospy.get_param('~real_time_factor', 1.0))


def wall_budget(sim_seconds, margin=20.0):
    """Generous wall seconds for `sim_seconds` of simulation on a loaded machine."""
    factor = real_time_factor()
    factor = 1.0 if factor <= 0.0 else min(factor, 1.0)
    return 3.0 * sim_seconds / factor + margin


# --- ground truth --------------------------------------------------------------
class GroundTruth(object):
    """Every /base_pose_ground_truth message since construction, as Samples."""

    def __init__(self, topic=GROUND_TRUTH):
        self._lock = threading.Lock()
        self._samples = []
        self._sub = rospy.Subscriber(topic, Odometry, self._on_message, queue_size=None)

    def _on_message(self, message):
        pose, twist = message.pose.pose, message.twist.twist
        sample = Sample(message.header.stamp.to_sec(), pose.position.x, pose.position.y,
                        yaw_of(pose.orientation), twist.linear.x, twist.linear.y, twist.angular.z)
        with self._lock:
            self._samples.append(sample)

    def samples(self, start=None, end=None):
        with self._lock:
            samples = list(self._samples)
        return [s for s in samples
                if (start is None or s.t >= start) and (end is None or s.t <= end)]

    def count(self):
        """How many samples have arrived: a mark for `since` that survives a jump of sim time."""
        with self._lock:
            return len(self._samples)

    def since(self, mark):
        """The samples that arrived after `count()` returned `mark`, in arrival order."""
        with self._lock:
            return self._samples[mark:]

    def latest(self):
        with self._lock:
            return self._samples[-1] if self._samples else None

    def now(self):
        """Stamp of the latest sample (sim s), or -inf."""
        latest = self.latest()
        return latest.t if latest else -math.inf

    def wait_first(self, timeout=60.0):
        return wait_for(lambda: self.latest() is not None, timeout)

    def wait_until(self, sim_time, timeout):
        """Wait until a sample stamped at or after `sim_time` has arrived."""
        return wait_for(lambda: self.now() >= sim_time, timeout)

    def wait_sim(self, duration, timeout=None):
        """Wait `duration` sim seconds after the latest sample."""
        return self.wait_until(self.now() + duration,
                               timeout if timeout is not None else wall_budget(duration))

    def still_since(self, sim_time, tolerance=0.0005, yaw_tolerance=math.radians(0.05)):
        """True if every sample since `sim_time` is within `tolerance` of the first one."""
        samples = self.samples(start=sim_time)
        if len(samples) < 2:
            return False
        first = samples[0]
        return all(math.hypot(s.x - first.x, s.y - first.y) <= tolerance
                   and abs(wrap(s.yaw - first.yaw)) <= yaw_tolerance for s in samples)

    def wait_at_rest(self, window=0.5, timeout=30.0):
        """Wait until the robot has not moved for `window` sim seconds; the latest sample or None."""
        def at_rest():
            now = self.now()
            history = self.samples(end=now - window)
            return bool(history) and self.still_since(now - window)
        return self.latest() if wait_for(at_rest, timeout, poll=0.02) else None


def after_jump_back(samples, before, jump=0.5):
    """The samples (in arrival order) from the first one stamped more than `jump` s
    before `before`, the sim time when time was reset; [] if there is none."""
    for index, sample in enumerate(samples):
        if sample.t < before - jump:
            return samples[index:]
    return []


class GroundTruth3D(GroundTruth):
    """GroundTruth whose samples also carry z, roll and pitch (Sample3D)."""

    def _on_message(self, message):
        pose, twist = message.pose.pose, message.twist.twist
        roll, pitch = roll_pitch_of(pose.orientation)
        sample = Sample3D(message.header.stamp.to_sec(), pose.position.x, pose.position.y,
                          yaw_of(pose.orientation), twist.linear.x, twist.linear.y, twist.angular.z,
                          pose.position.z, roll, pitch)
        with self._lock:
            self._samples.append(sample)


# --- child processes -------------------------------------------------------------
_children = set()
_children_lock = threading.Lock()


class Child(Process):
    """A command run as the user would run it: the harness's Process, its output
    in a log file of its own, killed by the kernel should this test node be
    killed outright (SIGKILL at rostest's time limit). The environment is
    inherited (ROS_MASTER_URI comes from rostest)."""

    def __init__(self, args):
        super(Child, self).__init__(os.path.basename(args[0]), args, die_with_parent=True)
        with _children_lock:
            _children.add(self)

    def stop(self, timeout=5.0):
        code = super(Child, self).stop(timeout)
        with _children_lock:
            _children.discard(self)
        return code


def stop_all_children():
    with _children_lock:
        children = list(_children)
    for child in children:
        child.stop()


atexit.register(stop_all_children)


def init_test_node(name):
    """rospy.init_node, and every child process stopped when the node shuts down."""
    rospy.init_node(name)
    rospy.on_shutdown(stop_all_children)


def report(name, **values):
    """A line of measured numbers, easy to grep from the test output."""
    text = ', '.join('%s=%s' % (key, ('%.4f' % value) if isinstance(value, float) else value)
                     for key, value in sorted(values.items()))
    line = 'MEASURED %s: %s' % (name, text)
    print(line, flush=True)
    rospy.loginfo(line)
    return line


# --- commands ------------------------------------------------------------------
TURN_TOLERANCE = math.radians(0.5)


def turn_to(truth, publisher, heading, timeout, tolerance=TURN_TOLERANCE):
    """Turn on the spot, closed loop on `truth` (a GroundTruth), until its yaw is
    within `tolerance` of `heading`; True if it got there within `timeout` wall s.
    Leaves the robot commanded to stop."""
    from geometry_msgs.msg import Twist
    command = Twist()
    repeater = Repeater(publisher, command, rate=20.0)
    try:
        def turned():
            error = wrap(heading - truth.latest().yaw)
            command.angular.z = math.copysign(min(1.0, max(0.1, 2.0 * abs(error))), error)
            return abs(error) < tolerance
        return wait_for(turned, timeout, poll=0.01)
    finally:
        repeater.stop()
        publisher.publish(Twist())


class Repeater(object):
    """Publishes `message` on `publisher` at `rate` Hz of wall time until stop(),
    as `rostopic pub -r` would; `message` may be changed while it runs."""

    def __init__(self, publisher, message, rate=20.0):
        self.publisher, self.message, self.period = publisher, message, 1.0 / rate
        self.count = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name='repeater', daemon=True)
        self._thread.start()

    def _run(self):
        next_time = time.monotonic()
        while not self._stop.is_set() and not rospy.is_shutdown():
            self.publisher.publish(self.message)
            self.count += 1
            next_time += self.period
            self._stop.wait(max(0.0, next_time - time.monotonic()))

    def stop(self):
        self._stop.set()
        self._thread.join(2.0)
