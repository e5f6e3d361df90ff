"""The phases of test_resets.py, apart from what its tests check: each drives the simulator through
one reset (a drive, the service call) and keeps what follows as class attributes its tests read.
Resets.setUpClass runs them once, in order; a phase that fails is named by its tests, with its cause."""
import math
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from std_srvs.srv import Empty

from tb3_test_utils import (
    Child,
    GroundTruth,
    Sample,
    after_jump_back,
    in_frame_of,
    report,
    speed,
    unwrapped_turn,
    wait_for,
    wait_for_simulator,
    wall_budget,
    wrap,
    yaw_of,
)

SPAWN = Sample(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
POSITION_TOLERANCE = 0.01    # m
HEADING_TOLERANCE = 1.0      # deg
STOPPED_SPEED = 0.01         # m/s
DRIVE_SECONDS = 2.0          # sim s of driving before each reset
AFTER_RESET = 1.5            # sim s watched after each reset
NEAR_ZERO = 1.0              # sim s: /clock's first value after reset_simulation is below this
FIRST_STEP = 0.05            # sim s: a scan (5 Hz) is due at the first step after a start or reset
TF_WITHIN = 5.0              # wall s for the tf listeners to give a post-jump transform


class Recorder(object):
    """Messages of one topic in arrival order, converted by `convert`."""

    def __init__(self, topic, message_class, convert):
        self.lock = threading.Lock()
        self.items = []
        self._convert = convert
        rospy.Subscriber(topic, message_class, self._on_message, queue_size=None)

    def _on_message(self, message):
        item = self._convert(message)
        with self.lock:
            self.items.append(item)

    def count(self):
        with self.lock:
            return len(self.items)

    def since(self, mark=0):
        with self.lock:
            return self.items[mark:]

    def latest(self):
        with self.lock:
            return self.items[-1] if self.items else None


def odom_sample(message):
    pose = message.pose.pose
    return Sample(message.header.stamp.to_sec(), pose.position.x, pose.position.y, yaw_of(pose.orientation),
                  0.0, 0.0, 0.0)


def off_spawn(sample):
    """(distance m, heading error deg) of a sample from the spawn pose."""
    return (math.hypot(sample.x - SPAWN.x, sample.y - SPAWN.y),
            abs(math.degrees(wrap(sample.yaw - SPAWN.yaw))))


def twist(v, w):
    message = Twist()
    message.linear.x, message.angular.z = v, w
    return message


class ResetPhases(object):
    """The phases, for a TestCase (Resets) whose setUpClass sets the recorders, listeners and cmd_vel
    publisher they use, and the tests' check that their phase ran (need)."""

    def need(self, phase):
        if phase not in self.phase_ran():
            self.fail('phase %s did not run: %s' % (phase, self.errors.get(phase, 'an earlier phase failed')))

    @classmethod
    def phase_ran(cls):
        return [phase for phase in ('reset_world', 'reset_simulation', 'script')
                if phase not in cls.errors and hasattr(cls, 'done_' + phase)]

    @classmethod
    def _drive(cls, v, w):
        truth = cls.truth_all
        cls.cmd_vel.publish(twist(v, w))
        if not wait_for(lambda: speed(truth.latest()) > 0.9 * v, wall_budget(3.0)):
            raise AssertionError('the robot did not start driving')
        truth.wait_sim(DRIVE_SECONDS)

    @classmethod
    def _call(cls, name):
        rospy.wait_for_service(name, 30.0)
        rospy.ServiceProxy(name, Empty)()

    # --- 1. reset_world --------------------------------------------------------------

    @classmethod
    def _phase_reset_world(cls):
        truth = cls.truth_all
        wait_for_simulator(truth, cls.cmd_vel)
        cls._drive(0.2, 0.5)
        cls.world_driven = truth.latest()
        clock_mark = cls.clock.count()
        cls._call('/gazebo/reset_world')   # while the drive command still holds
        called = rospy.get_time()
        # Whatever was published before the call returned is in flight: watch from a bit later.
        if not truth.wait_until(called + 0.1 + AFTER_RESET, wall_budget(AFTER_RESET)):
            raise AssertionError('ground truth stopped after reset_world')
        cls.world_after = truth.samples(start=called + 0.1)
        with cls.odom.lock:
            cls.world_odom_after = [s for s in cls.odom.items if s.t >= called + 0.1]
        cls.world_clock = cls.clock.since(clock_mark)
        cls.world_called = called
        cls.done_reset_world = True

    # --- 2. reset_simulation -----------------------------------------------------------

    @classmethod
    def _wait_for_jump(cls, clock_mark, before):
        """The first /clock value after the jump back, or an AssertionError."""
        def jumped():
            return [value for value in cls.clock.since(clock_mark) if value < before - 1.0]
        found = wait_for(jumped, 10.0)
        if not found:
            raise AssertionError('/clock did not jump back within 10 s of reset_simulation (latest %r, '
                                 'before %.3f)' % (cls.clock.latest(), before))
        return found[0]

    @classmethod
    def _phase_reset_simulation(cls):
        truth = cls.truth_all
        if 'reset_world' in cls.errors:
            raise AssertionError('skipped: the reset_world phase failed')
        cls.cmd_vel.publish(Twist())
        truth.wait_at_rest(timeout=wall_budget(2.0))
        cls._drive(0.2, -0.5)
        cls.sim_before = cls.clock.latest()
        if cls.sim_before < 5.0:
            raise AssertionError('set-up: sim time %.2f s before the reset is too close to zero to see '
                                 'a jump' % cls.sim_before)
        truth_mark, odom_mark, clock_mark = truth.count(), cls.odom.count(), cls.clock.count()
        cls._call('/gazebo/reset_simulation')
        cls.first_after_jump = cls._wait_for_jump(clock_mark, cls.sim_before)
        jump_wall = time.monotonic()
        cls.tf2_seen = cls._wait_tf(cls._tf2_latest, jump_wall)
        cls.tf_seen = cls._wait_tf(cls._tf_latest, jump_wall)
        start = cls.clock.latest()
        if not wait_for(lambda: cls.clock.latest() > start + AFTER_RESET, wall_budget(AFTER_RESET)):
            raise AssertionError('/clock did not advance after the jump')
        clock_after = cls.clock.since(clock_mark)
        cls.sim_clock_after = clock_after[[v < cls.sim_before - 1.0 for v in clock_after].index(True):]
        cls.tf2_later, cls.tf_later = cls._answer(cls._tf2_latest), cls._answer(cls._tf_latest)
        cls.sim_truth_after = after_jump_back(truth.since(truth_mark), cls.sim_before)
        cls.sim_odom_after = after_jump_back(cls.odom.since(odom_mark), cls.sim_before)
        cls.done_reset_simulation = True

    @classmethod
    def _tf2_latest(cls):
        transform = cls.tf2_buffer.lookup_transform('odom', 'base_footprint', rospy.Time(0))
        t = transform.transform.translation
        return transform.header.stamp.to_sec(), t.x, t.y

    @classmethod
    def _tf_latest(cls):
        stamp = cls.tf_listener.getLatestCommonTime('odom', 'base_footprint')
        (x, y, _z), _rotation = cls.tf_listener.lookupTransform('odom', 'base_footprint', rospy.Time(0))
        return stamp.to_sec(), x, y

    @staticmethod
    def _answer(latest):
        try:
            return latest()
        except Exception as error:
            return '%s: %s' % (type(error).__name__, error)

    @classmethod
    def _wait_tf(cls, latest, jump_wall):
        """Wall seconds after the jump until `latest()` gives a post-jump stamp, and what it gave;
        (None, last answer) if it did not within TF_WITHIN."""
        answer = [None]

        def post_jump():
            try:
                answer[0] = latest()
            except Exception as error:  # lookup errors while the buffer refills
                answer[0] = '%s: %s' % (type(error).__name__, error)
                return False
            return answer[0][0] < cls.sim_before - 1.0
        ok = wait_for(post_jump, max(0.0, jump_wall + TF_WITHIN - time.monotonic()), poll=0.02)
        return (time.monotonic() - jump_wall if ok else None), answer[0]

    # --- 3. odom_out_and_back.py right after reset_simulation ----------------------------

    @classmethod
    def _phase_script(cls):
        if 'reset_simulation' in cls.errors:
            raise AssertionError('skipped: the reset_simulation phase failed')
        # The robot rests at the spawn pose since the last reset (phase 2 checked it).
        # A recorder of its own: stamps restart from zero again below.
        truth = cls.truth = GroundTruth()
        if not truth.wait_until(3.0, wall_budget(3.0)):
            raise AssertionError('sim time did not reach 3 s after the last reset')
        before = cls.clock.latest()
        truth_mark, clock_mark, scan_mark = truth.count(), cls.clock.count(), cls.scan.count()
        # Twice, a step or so apart: a reset within a scan's period of the one before once looked
        # like none to the scan's schedule, and its first scan came 0.2 s late (an agent's episode
        # then started a scan later at one real-time factor than at another).
        cls._call('/gazebo/reset_simulation')
        cls.script_first_clock = cls._wait_for_jump(clock_mark, before)
        cls._call('/gazebo/reset_simulation')
        cls.child = Child(['rosrun', 'tb3_sim_nav', cls.script])
        budget = wall_budget(cls.script_sim_seconds)
        cls.exit_code = cls.child.wait(budget)
        cls.output = cls.child.output()
        if cls.exit_code is None:
            raise AssertionError('%s still running after %.0f wall s; %s'
                                 % (cls.script, budget, cls.child.describe()))
        if truth.wait_at_rest(window=0.5, timeout=wall_budget(3.0)) is None:
            raise AssertionError('the robot was still moving 3 s (sim) after %s exited' % cls.script)
        path = after_jump_back(truth.since(truth_mark), before)
        if not path:
            raise AssertionError('ground truth never jumped back')
        cls.start, cls.end = path[0], path[-1]
        cls.first_scans = [stamp for stamp in cls.scan.since(scan_mark) if stamp < FIRST_STEP]
        cls.path = path
        cls.position_error = math.hypot(cls.end.x - cls.start.x, cls.end.y - cls.start.y)
        cls.heading_error = math.degrees(abs(wrap(cls.end.yaw - cls.start.yaw)))
        cls.local_path = [in_frame_of(cls.start, s) for s in path]
        cls.max_excursion = max(math.hypot(x, y) for x, y in cls.local_path)
        cls.total_turn = math.degrees(unwrapped_turn(path))
        report('%s_after_reset_simulation' % cls.script, exit_code=cls.exit_code,
               first_clock=cls.script_first_clock, first_scans=cls.first_scans, start_stamp=cls.start.t,
               sim_seconds=cls.end.t - cls.start.t,
               position_error_m=cls.position_error, heading_error_deg=cls.heading_error,
               max_excursion_m=cls.max_excursion, total_turn_deg=cls.total_turn)
        cls.done_script = True
