#!/usr/bin/env python3
"""Gazebo's /gazebo/reset_world and /gazebo/reset_simulation, judged by ground truth.

On one simulator (tb3_empty_world.launch, spawn (0, 0), yaw 0), in order:
1. reset_world while the robot drives an arc: ground truth back at the spawn
   pose (1 cm, 1 deg) and at rest, odom back at the spawn pose too, and /clock
   runs on: it never goes back;
2. reset_simulation while the robot drives: /clock jumps back to near zero and
   then increases again, ground truth is at the spawn pose and at rest, and a
   tf2_ros.TransformListener and a tf.TransformListener made before the jump
   give odom -> base_footprint again, with post-jump stamps, within a few
   seconds (they must clear their buffers on the jump);
3. reset_simulation, and once time has run on a step, again (a learning
   agent's set-up, then its first episode), and at once `rosrun tb3_sim_nav
   odom_out_and_back.py`: after each reset a scan comes at the first step, as
   after a start; the script drives 1 m out and back and ends within 5 cm and
   5 deg of where it started.
Each phase runs once (setUpClass); each test method checks one promise of one
phase, and says so if its phase could not run.
"""
import math
import threading
import time

import rospy
import rostest
import tf
import tf2_ros
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty

from script_test_case import ScriptTestCase
from tb3_test_utils import (
    Child,
    GroundTruth,
    Sample,
    after_jump_back,
    in_frame_of,
    init_test_node,
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


class Resets(ScriptTestCase):
    script = 'odom_out_and_back.py'
    script_sim_seconds = 35.0

    @classmethod
    def setUpClass(cls):
        cls.truth_all = GroundTruth()
        cls.odom = Recorder('/odom', Odometry, odom_sample)
        cls.clock = Recorder('/clock', Clock, lambda message: message.clock.to_sec())
        cls.scan = Recorder('/scan', LaserScan, lambda message: message.header.stamp.to_sec())
        # Made before any reset: they must cope with the jump of sim time.
        cls.tf2_buffer = tf2_ros.Buffer()
        cls.tf2_listener = tf2_ros.TransformListener(cls.tf2_buffer)
        cls.tf_listener = tf.TransformListener()
        cls.cmd_vel = rospy.Publisher('/cmd_vel', Twist, queue_size=10)
        cls.errors = {}
        cls.child = None
        for phase in ('reset_world', 'reset_simulation', 'script'):
            try:
                getattr(cls, '_phase_' + phase)()
            except Exception as error:  # reported by the phase's tests, with its cause
                cls.errors[phase] = '%s: %s' % (type(error).__name__, error)
            finally:
                cls.cmd_vel.publish(Twist())
                if cls.child is not None:
                    cls.child.stop()
            if rospy.is_shutdown():
                break

    def setUp(self):
        pass  # each test checks its own phase (need)

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

    def test_reset_world_puts_ground_truth_back_at_spawn(self):
        self.need('reset_world')
        driven = off_spawn(self.world_driven)
        worst = max((off_spawn(s) for s in self.world_after), key=lambda e: e[0])
        worst_heading = max(off_spawn(s)[1] for s in self.world_after)
        report('reset_world_ground_truth', driven_off_m=driven[0], driven_off_deg=driven[1],
               worst_after_m=worst[0], worst_after_deg=worst_heading, samples=len(self.world_after))
        self.assertGreater(driven[0], 0.2, 'set-up: the robot did not drive away before the reset')
        self.assertGreater(len(self.world_after), 30)
        self.assertLessEqual(worst[0], POSITION_TOLERANCE)
        self.assertLessEqual(worst_heading, HEADING_TOLERANCE)

    def test_reset_world_leaves_the_robot_at_rest(self):
        self.need('reset_world')
        fastest = max(speed(s) for s in self.world_after)
        turning = max(abs(s.wz) for s in self.world_after)
        report('reset_world_rest', max_speed=fastest, max_yaw_rate=turning)
        self.assertLess(fastest, STOPPED_SPEED, 'the drive command survived reset_world')
        self.assertLess(turning, 0.02)

    def test_reset_world_puts_odom_back_at_spawn(self):
        self.need('reset_world')
        self.assertGreater(len(self.world_odom_after), 30)
        worst = max(off_spawn(s)[0] for s in self.world_odom_after)
        worst_heading = max(off_spawn(s)[1] for s in self.world_odom_after)
        report('reset_world_odom', worst_after_m=worst, worst_after_deg=worst_heading)
        self.assertLessEqual(worst, POSITION_TOLERANCE)
        self.assertLessEqual(worst_heading, HEADING_TOLERANCE)

    def test_reset_world_clock_runs_on_never_back(self):
        self.need('reset_world')
        values = self.world_clock
        backwards = [(a, b) for a, b in zip(values, values[1:]) if b < a]
        report('reset_world_clock', first=values[0], last=values[-1], messages=len(values),
               backwards=len(backwards))
        self.assertEqual(backwards, [], '/clock went back on reset_world')
        self.assertGreater(values[-1], self.world_called + AFTER_RESET)

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

    def test_reset_simulation_clock_jumps_back_near_zero_then_increases(self):
        self.need('reset_simulation')
        values = self.sim_clock_after
        backwards = [(a, b) for a, b in zip(values, values[1:]) if b < a]
        report('reset_simulation_clock', before=self.sim_before, first_after=self.first_after_jump,
               last=values[-1], messages_after=len(values))
        self.assertLess(self.first_after_jump, NEAR_ZERO)
        self.assertGreater(self.first_after_jump, 0.0, '/clock published zero')
        self.assertEqual(backwards, [], '/clock went back again after the jump')
        self.assertGreater(values[-1], self.first_after_jump + AFTER_RESET)

    def test_reset_simulation_puts_ground_truth_back_at_spawn_at_rest(self):
        self.need('reset_simulation')
        after = self.sim_truth_after
        self.assertGreater(len(after), 30, 'ground truth did not jump back with /clock')
        worst = max(off_spawn(s)[0] for s in after)
        worst_heading = max(off_spawn(s)[1] for s in after)
        fastest = max(speed(s) for s in after)
        report('reset_simulation_ground_truth', first_stamp=after[0].t, worst_m=worst,
               worst_deg=worst_heading, max_speed=fastest)
        self.assertLess(after[0].t, NEAR_ZERO)
        self.assertLessEqual(worst, POSITION_TOLERANCE)
        self.assertLessEqual(worst_heading, HEADING_TOLERANCE)
        self.assertLess(fastest, STOPPED_SPEED)

    def test_reset_simulation_puts_odom_back_at_spawn(self):
        self.need('reset_simulation')
        after = self.sim_odom_after
        self.assertGreater(len(after), 30, 'odom did not jump back with /clock')
        worst = max(off_spawn(s)[0] for s in after)
        self.assertLessEqual(worst, POSITION_TOLERANCE)
        self.assertLessEqual(max(off_spawn(s)[1] for s in after), HEADING_TOLERANCE)

    def check_listener(self, name, seen, later):
        self.need('reset_simulation')
        seconds, answer = seen
        report('%s_after_jump' % name, wall_seconds=seconds, answer=answer, later=later)
        self.assertIsNotNone(seconds, '%s gave no post-jump odom -> base_footprint within %.0f wall s of '
                             'the jump; last answer: %s (sim time before the reset %.2f)'
                             % (name, TF_WITHIN, answer, self.sim_before))
        stamp, x, y = answer
        self.assertLess(math.hypot(x, y), POSITION_TOLERANCE, '%s: odom -> base_footprint at %.2f s is '
                        '(%.3f, %.3f), not the spawn pose' % (name, stamp, x, y))
        # And it keeps up afterwards: its latest transform follows /clock.
        self.assertIsInstance(later, tuple, '%s: no transform %.1f s (sim) after the jump: %s'
                              % (name, AFTER_RESET, later))
        self.assertGreater(later[0], self.first_after_jump + AFTER_RESET - 0.5,
                           '%s: latest odom -> base_footprint is stamped %.2f s, /clock is past %.2f s'
                           % (name, later[0], self.first_after_jump + AFTER_RESET))

    def test_reset_simulation_tf2_ros_listener_recovers_within_5s(self):
        self.check_listener('tf2_ros', self.tf2_seen, self.tf2_later)

    def test_reset_simulation_tf_listener_recovers_within_5s(self):
        self.check_listener('tf', self.tf_seen, self.tf_later)

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

    def test_script_after_reset_simulation_starts_at_spawn(self):
        self.need('script')
        self.assertLess(off_spawn(self.start)[0], POSITION_TOLERANCE)
        self.assertLess(self.start.t, NEAR_ZERO + 1.0, 'the path does not start at the jump')

    def test_a_scan_comes_at_the_first_step_after_each_reset_simulation(self):
        self.need('script')
        self.assertEqual(len(self.first_scans), 2, 'scans stamped before %g s after two resets: %s'
                         % (FIRST_STEP, self.first_scans))

    def test_script_after_reset_simulation_exits_with_code_0(self):
        self.need('script')
        self.check_exit_code_0()

    def test_script_after_reset_simulation_drives_about_1m_out_and_back(self):
        self.need('script')
        self.check_out_and_back_path()

    def test_script_after_reset_simulation_ends_within_5cm_and_5deg_of_start(self):
        self.need('script')
        self.check_back_at_start(0.05, 5.0)


if __name__ == '__main__':
    init_test_node('test_resets')
    rostest.rosrun('tb3_sim_nav', 'resets', Resets)
