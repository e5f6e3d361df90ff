"""What the keyboard teleop's system tests share: the teleop run in a pseudo-terminal, its keys typed,
what it publishes read, and the simulator it drives.

The teleop runs in a session of its own whose controlling terminal is a pty whose master side the
test holds (util-linux `setsid --ctty`), as a shell's job in a terminal window: the byte \\x03 typed
there is Ctrl+C (SIGINT), and closing the master side hangs the terminal up (SIGHUP). What the
teleop publishes and where the robot goes are read by `rostopic echo -p` (CSV) on /cmd_vel and
/base_pose_ground_truth. test_teleop.py and test_teleop_launch.py load it as a pytest plugin for
its fixtures (`master`, `truth`, the autouse `unbuffered`).
"""
import math
import os
import pty
import select
import subprocess
import termios
import threading
import time

import pytest

from tb3_system_utils import Echo, harness, poses, wait_until

TELEOP = ['rosrun', 'tb3_sim_nav', 'tb3_teleop_key']
MULTI = ['roslaunch', 'turtlebot3_gazebo', 'multi_turtlebot3.launch']  # the e-manual's, for several robots
ROBOTIS = ['roslaunch', 'turtlebot3_teleop', 'turtlebot3_teleop_key.launch']
#: ROBOTIS' e-manual, typed as it is there.
EMANUAL = ['bash', '-c', 'export TURTLEBOT3_MODEL=burger && roslaunch turtlebot3_teleop turtlebot3_teleop_key.launch']
NAMESPACED = 'ROS_NAMESPACE=tb3_0 rosrun turtlebot3_teleop turtlebot3_teleop_key'  # the e-manual's, for one of them
LIMITS = {'burger': (0.22, 2.84), 'waffle': (0.26, 1.82), 'waffle_pi': (0.26, 1.82)}
LINEAR_HALF_STEP = 0.005   # m/s: the profile's change per message
ANGULAR_HALF_STEP = 0.05   # rad/s
ZERO = (0.0,) * 6

START_WITHIN = 30.0   # wall s for the teleop to show its keys (rospy start-up)
KEY_REPEAT = 1.0 / 25.0  # wall s between typed keys: a held key's autorepeat (X's default rate, 25 a second)
SIM_READY = 60.0      # wall s for the simulator's first ground truth
PRINT_WITHIN = 5.0    # wall s for a key's target line to be printed
REACH_WITHIN = 20.0   # wall s for cmd_vel to reach a target (0.1 s per half step)
EXIT_WITHIN = 10.0    # wall s for the teleop to exit once asked
CTRL_C_WITHIN = 2.0   # wall s from Ctrl+C on roslaunch to the end of the node (every node of ours)
REST_WITHIN = 10.0    # wall s for the robot to be at rest after the teleop exited
TURN = 0.6            # rad the robot must turn left before its path is judged


class PtyProcess(harness.Process):
    """harness.Process (own process group, stopped by group) whose controlling
    terminal is a new pty: the test types on the master side and reads there
    what the child prints (also written to the log file)."""

    def __init__(self, name, argv, log_dir):
        self.name = name
        self.log = os.path.join(log_dir, name + '.log')
        self.master, self.slave = pty.openpty()
        self.settings_before = termios.tcgetattr(self.slave)
        self._output = b''
        self._lock = threading.Lock()
        self._reading = True
        # setsid(1) does not fork here (the child is no process group leader), so the
        # session, the process group and popen.pid are the teleop's own.
        self.popen = subprocess.Popen(['setsid', '--ctty'] + list(argv), stdin=self.slave,
                                      stdout=self.slave, stderr=self.slave)
        self._reader = threading.Thread(target=self._read)
        self._reader.start()

    def _read(self):
        with open(self.log, 'wb') as log:
            while self._reading:
                if not select.select([self.master], [], [], 0.1)[0]:
                    continue
                try:
                    data = os.read(self.master, 4096)
                except OSError:
                    return
                log.write(data)
                log.flush()
                with self._lock:
                    self._output += data

    def output(self):
        with self._lock:
            return self._output.decode(errors='replace').replace('\r\n', '\n')

    def type(self, keys):
        """Keys one after another at a held key's autorepeat rate (KEY_REPEAT), as a
        person types them: written all at once, the teleop's loop published one
        message a key within a millisecond, and on a busy machine its publisher
        (queue_size=10, as ROBOTIS') dropped some before rostopic echo saw them."""
        for index, key in enumerate(keys):
            if index:
                time.sleep(KEY_REPEAT)
            os.write(self.master, key.encode())

    def settings(self):
        return termios.tcgetattr(self.slave)

    def hang_up(self):
        """Close the master side, as closing the terminal window does."""
        self._reading = False
        self._reader.join()
        os.close(self.master)
        self.master = None

    def stop(self, timeout=harness.STOP_TIMEOUT):
        code = super(PtyProcess, self).stop(timeout)
        if self.master is not None:
            self.hang_up()
        os.close(self.slave)
        return code


def twists(echo):
    """cmd_vel messages as (linear x, y, z, angular x, y, z)."""
    names = ['field.linear.x', 'field.linear.y', 'field.linear.z',
             'field.angular.x', 'field.angular.y', 'field.angular.z']
    return [tuple(float(row[name]) for name in names) for row in echo.rows()]


def last(items):
    return items[-1] if items else None


def close(a, b, tolerance=1e-9):
    return a is not None and all(abs(x - y) <= tolerance for x, y in zip(a, b))


def at_rest(echo):
    """The robot has not moved over the last 0.5 s of sim time, and says so."""
    path = poses(echo)
    if not path:
        return False
    now = path[-1]
    earlier = [p for p in path if p['t'] <= now['t'] - 0.5]
    if not earlier:
        return False
    then = earlier[-1]
    return (math.hypot(now['x'] - then['x'], now['y'] - then['y']) < 1e-3 and
            abs(now['yaw'] - then['yaw']) < 1e-3 and now['speed'] < 1e-3 and abs(now['turn']) < 1e-3)


def target_line(linear, angular):
    return 'target: linear %.2f m/s, angular %.2f rad/s' % (linear, angular)


@pytest.fixture(autouse=True)
def unbuffered(monkeypatch):
    """rostopic echo's lines reach its log file as they are printed."""
    monkeypatch.setenv('PYTHONUNBUFFERED', '1')


@pytest.fixture
def master(shared_master):
    """The file's roscore, its parameters as it started (conftest.py)."""
    return shared_master


@pytest.fixture
def truth(master, processes):
    """The simulator, started; ground truth read until the test ends."""
    sim = processes.start('sim', ['roslaunch', 'tb3_sim_bringup', 'tb3_empty_world.launch'])
    echo = Echo(processes, '/base_pose_ground_truth')
    ready = wait_until(lambda: poses(echo) or not sim.running(), SIM_READY)
    assert ready and sim.running(), 'no ground truth within %.0f s; %s:\n%s' % (
        SIM_READY, sim.log, harness.tail(sim.log))
    return echo


def start_teleop(processes, tmp_path, cmd_vel, argv=TELEOP, name='teleop'):
    """The teleop in a pty, once it shows its keys and /cmd_vel's reader has its messages."""
    teleop = PtyProcess(name, argv, str(tmp_path))
    processes.add(teleop)
    ready = wait_until(lambda: ('Ctrl+C' in teleop.output() and twists(cmd_vel)) or not teleop.running(),
                       START_WITHIN)
    assert ready and teleop.running(), 'the teleop did not start within %.0f s; it printed:\n%s' % (
        START_WITHIN, teleop.output())
    return teleop


def type_and_see(teleop, keys, linear, angular):
    teleop.type(keys)
    line = target_line(linear, angular)
    assert wait_until(lambda: line in teleop.output(), PRINT_WITHIN), \
        'after %r, no %r within %.0f s; the teleop printed:\n%s' % (keys, line, PRINT_WITHIN, teleop.output())


def wait_for_twist(cmd_vel, linear, angular):
    expected = (linear, 0.0, 0.0, 0.0, 0.0, angular)
    reached = wait_until(lambda: close(last(twists(cmd_vel)), expected), REACH_WITHIN)
    assert reached, 'cmd_vel did not reach %s within %.0f s: last %s' % (
        expected, REACH_WITHIN, last(twists(cmd_vel)))


def assert_profile(sent):
    """Each message changes each speed by at most half a key step; only x and yaw rate move."""
    for before, after in zip(sent, sent[1:]):
        assert after[1:5] == (0.0,) * 4, 'a cmd_vel with linear y/z or angular x/y: %s' % (after,)
        assert abs(after[0] - before[0]) <= LINEAR_HALF_STEP + 1e-9 and \
            abs(after[5] - before[5]) <= ANGULAR_HALF_STEP + 1e-9, \
            'cmd_vel jumped from %s to %s (more than %g m/s or %g rad/s)' % (
                before, after, LINEAR_HALF_STEP, ANGULAR_HALF_STEP)
