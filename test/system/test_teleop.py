"""The keyboard teleop (turtlebot3_teleop's turtlebot3_teleop_key; scripts/tb3_teleop_key and
tb3_sim_bringup's tb3_teleop_key.launch run the same node), typed at through a pseudo-terminal.

The tests share a roscore on a free loopback port, its parameters cleared
between tests (conftest.py's shared_master); the one without a master has a
port of its own with none; the tests that look at the robot start the simulator
(`roslaunch tb3_sim_bringup tb3_empty_world.launch`). The teleop runs in a
session of its own whose controlling terminal is a pty whose master side this
test holds (util-linux `setsid --ctty`), as a shell's job in a terminal
window: the byte \\x03 typed there is Ctrl+C (SIGINT), and closing the master
side hangs the terminal up (SIGHUP). What the teleop publishes and where the
robot goes are read by `rostopic echo -p` (CSV) on /cmd_vel and
/base_pose_ground_truth. Every wait is on the wall clock with a deadline, and
every process is stopped by its process group when the test ends, also when
it fails.
"""
import math
import os
import pty
import re
import select
import signal
import subprocess
import termios
import threading
import time

import pytest

from tb3_system_utils import Echo, alive, harness, poses, run, wait_until

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


def test_keys_set_cmd_vel_smoothly_and_drive_the_robot_forward_and_left(truth, processes, tmp_path, monkeypatch):
    monkeypatch.delenv('TURTLEBOT3_MODEL', raising=False)
    cmd_vel = Echo(processes, '/cmd_vel')
    teleop = start_teleop(processes, tmp_path, cmd_vel)
    assert 'using burger' in teleop.output(), 'no note on the default model:\n%s' % teleop.output()
    start = last(poses(truth))

    typed = time.monotonic()
    type_and_see(teleop, 'wwwww', 0.05, 0.0)
    type_and_see(teleop, 'aaa', 0.05, 0.3)
    wait_for_twist(cmd_vel, 0.05, 0.3)
    reached = time.monotonic() - typed
    sent = twists(cmd_vel)
    moving = sent[[i for i, twist in enumerate(sent) if twist != ZERO][0]:]
    lines = [line for line in teleop.output().splitlines() if line.startswith('target:')]
    print('MEASURED teleop keys: cmd_vel reached (0.05, 0.3) %.2f s after the first key, in %d messages'
          % (reached, len(moving)))
    assert lines == [target_line(0.01 * n, 0.0) for n in range(1, 6)] + \
        [target_line(0.05, 0.1 * n) for n in range(1, 4)], lines
    assert moving[0] == (LINEAR_HALF_STEP, 0.0, 0.0, 0.0, 0.0, 0.0), moving[:3]
    assert_profile(sent)
    # 10 half steps of linear and 6 of angular speed: at least 10 messages to get there.
    assert len([t for t in moving if not close(t, (0.05, 0, 0, 0, 0, 0.3))]) >= 9, moving

    turned = wait_until(lambda: poses(truth)[-1]['yaw'] - start['yaw'] > TURN, 60.0)
    end = last(poses(truth))
    print('MEASURED teleop motion: from (%.3f, %.3f, %.3f) to (%.3f, %.3f, %.3f), %.3f m/s, %.3f rad/s'
          % (start['x'], start['y'], start['yaw'], end['x'], end['y'], end['yaw'], end['speed'], end['turn']))
    assert turned, 'the robot did not turn %.1f rad left within 60 s: %s -> %s' % (TURN, start, end)
    # On a circle of radius 0.05 / 0.3 m, turning TURN rad from heading 0 (+x):
    # forward by R sin(TURN) = 0.094 m and left by R (1 - cos(TURN)) = 0.029 m.
    assert end['x'] - start['x'] > 0.06, 'not forward: %s -> %s' % (start, end)
    assert end['y'] - start['y'] > 0.015, 'not to the left: %s -> %s' % (start, end)
    assert abs(end['speed'] - 0.05) < 0.005 and abs(end['turn'] - 0.3) < 0.03, end


@pytest.mark.parametrize('how', ['ctrl_c', 'hang_up', 'sigterm', 'rosnode_kill'])
def test_exit_publishes_a_stop_the_robot_rests_the_terminal_is_restored(how, truth, processes, tmp_path):
    cmd_vel = Echo(processes, '/cmd_vel')
    teleop = start_teleop(processes, tmp_path, cmd_vel, argv=TELEOP + ['_model:=burger'])
    during = teleop.settings()
    type_and_see(teleop, 'w' * 10 + 'a' * 5, 0.1, 0.5)
    wait_for_twist(cmd_vel, 0.1, 0.5)
    assert wait_until(lambda: poses(truth)[-1]['speed'] > 0.09, REACH_WITHIN), last(poses(truth))

    asked = time.monotonic()
    if how == 'ctrl_c':
        teleop.type('\x03')
    elif how == 'hang_up':
        teleop.hang_up()
    elif how == 'sigterm':
        os.kill(teleop.popen.pid, signal.SIGTERM)
    else:
        assert run(['rosnode', 'kill', '/turtlebot3_teleop'], 30.0).returncode == 0
    ended = wait_until(lambda: not teleop.running(), EXIT_WITHIN)
    exited = time.monotonic() - asked
    assert ended, 'the teleop still runs %.0f s after %s' % (EXIT_WITHIN, how)
    stopped = wait_until(lambda: last(twists(cmd_vel)) == ZERO, 5.0)
    rest = wait_until(lambda: at_rest(truth), REST_WITHIN)
    rested = time.monotonic() - asked
    print('MEASURED teleop %s: exited after %.2f s (status %s); robot %s %.2f s after %s'
          % (how, exited, teleop.popen.returncode, 'at rest' if rest else 'still moving', rested, how))
    assert teleop.popen.returncode == 0, teleop.output()[-2000:]
    assert stopped, 'the last cmd_vel after %s is %s, not all zeros' % (how, last(twists(cmd_vel)))
    assert rest, 'the robot is not at rest %.0f s after %s: %s' % (REST_WITHIN, how, last(poses(truth)))
    if how != 'hang_up':   # a hung-up terminal has no settings left to read
        assert during[3] & termios.ICANON == 0 and during[3] & termios.ECHO == 0, \
            'the teleop did not put the terminal in cbreak mode: lflag %#o' % during[3]
        assert teleop.settings() == teleop.settings_before, \
            'terminal settings not restored after %s: %s, before %s' % (
                how, teleop.settings(), teleop.settings_before)
        assert 'Stopped' in teleop.output(), teleop.output()[-1000:]


@pytest.mark.parametrize('model, via', [('burger', 'param'), ('waffle', 'param'),
                                        ('burger', 'env'), ('waffle_pi', 'env'), ('waffle_pi', 'robotis_launch')])
def test_speeds_held_to_the_model_limits(model, via, master, processes, tmp_path, monkeypatch):
    argv = TELEOP
    if via == 'param':   # ~model wins over an environment that says otherwise
        argv = TELEOP + ['_model:=' + model]
        monkeypatch.setenv('TURTLEBOT3_MODEL', 'waffle' if model == 'burger' else 'burger')
    elif via == 'robotis_launch':   # ROBOTIS' launch gives the node `model` (not ~model): it wins too
        argv = ROBOTIS + ['model:=' + model]
        monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')
    else:
        monkeypatch.setenv('TURTLEBOT3_MODEL', model)
    linear, angular = LIMITS[model]
    cmd_vel = Echo(processes, '/cmd_vel')
    teleop = start_teleop(processes, tmp_path, cmd_vel, argv=argv)
    assert '(%s: at most %.2f m/s and %.2f rad/s)' % (model, linear, angular) in teleop.output(), \
        teleop.output()

    type_and_see(teleop, 'w' * 30 + 'a' * 30, linear, angular)
    wait_for_twist(cmd_vel, linear, angular)
    type_and_see(teleop, 's', 0.0, 0.0)
    type_and_see(teleop, 'x' * 30 + 'd' * 30, -linear, -angular)
    wait_for_twist(cmd_vel, -linear, -angular)
    sent = twists(cmd_vel)
    printed = [line for line in teleop.output().splitlines() if line.startswith('target:')]
    print('MEASURED teleop limits %s via %s: top %.2f m/s, %.2f rad/s in %d messages'
          % (model, via, max(t[0] for t in sent), max(t[5] for t in sent), len(sent)))
    assert printed[29] == target_line(linear, 0.0) and printed[59] == target_line(linear, angular), printed
    assert max(abs(t[0]) for t in sent) == linear and max(abs(t[5]) for t in sent) == angular, \
        'cmd_vel beyond the limits: %s' % max(sent, key=lambda t: (abs(t[0]), abs(t[5])))
    # The s key stops at once; only then does the profile start from zero.
    stop = sent.index(ZERO, [i for i, t in enumerate(sent) if t != ZERO][0])
    assert_profile(sent[:stop])
    assert_profile(sent[stop:])


def test_unknown_model_exits_nonzero_naming_the_three(master, processes, tmp_path, monkeypatch):
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')
    teleop = PtyProcess('teleop', TELEOP + ['_model:=turtlebot4'], str(tmp_path))
    processes.add(teleop)
    ended = wait_until(lambda: not teleop.running(), START_WITHIN)
    # Its output may still be on its way through the pty.
    named = wait_until(lambda: 'turtlebot4' in teleop.output(), 2.0)
    print('MEASURED teleop unknown model: status %s, output %r' % (teleop.popen.returncode, teleop.output()))
    assert ended, 'the teleop still runs with an unknown model'
    assert teleop.popen.returncode not in (0, None)
    assert named and all(name in teleop.output() for name in ('burger', 'waffle', 'waffle_pi')), \
        teleop.output()
    assert teleop.settings() == teleop.settings_before


def test_without_a_terminal_one_line_and_nonzero_without_ros(ros_port):
    # No master on ros_port: a node that tried to register would wait for one, and time out here.
    started = time.monotonic()
    result = run(TELEOP, timeout=30.0)
    print('MEASURED teleop without terminal: status %s after %.2f s, output %r'
          % (result.returncode, time.monotonic() - started, result.stdout))
    assert result.returncode is not None, 'still running after 30 s (waiting for a master?)'
    assert result.returncode != 0
    assert len(result.stdout.splitlines()) == 1 and 'terminal' in result.stdout, result.stdout


def test_roslaunch_gives_the_node_the_terminal(master, processes, tmp_path, monkeypatch):
    """Keys typed in roslaunch's terminal reach the node; the model comes from
    TURTLEBOT3_MODEL; Ctrl+C stops roslaunch, which stops the node: a stop is
    published and the terminal restored."""
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'waffle_pi')
    cmd_vel = Echo(processes, '/cmd_vel')
    launch = start_teleop(processes, tmp_path, cmd_vel, name='roslaunch_teleop',
                          argv=['roslaunch', 'tb3_sim_bringup', 'tb3_teleop_key.launch'])
    assert '(waffle_pi: at most 0.26 m/s and 1.82 rad/s)' in launch.output(), launch.output()
    type_and_see(launch, 'w' * 3 + 'd' * 2, 0.03, -0.2)
    wait_for_twist(cmd_vel, 0.03, -0.2)

    launch.type('\x03')
    ended = wait_until(lambda: not launch.running(), 30.0)
    stopped = wait_until(lambda: last(twists(cmd_vel)) == ZERO, 5.0)
    assert ended, 'roslaunch still runs 30 s after Ctrl+C'
    assert stopped, 'the last cmd_vel is %s' % (last(twists(cmd_vel)),)
    assert 'Stopped' in launch.output(), launch.output()[-2000:]
    assert launch.settings() == launch.settings_before


def test_a_killed_roslaunch_leaves_no_teleop_behind(master, processes, tmp_path, monkeypatch):
    """roslaunch killed outright (SIGKILL: it cannot stop its nodes): the
    teleop notices that its parent is gone, publishes a stop and ends."""
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')
    cmd_vel = Echo(processes, '/cmd_vel')
    launch = start_teleop(processes, tmp_path, cmd_vel, name='roslaunch_teleop',
                          argv=['roslaunch', 'tb3_sim_bringup', 'tb3_teleop_key.launch'])
    type_and_see(launch, 'w' * 3, 0.03, 0.0)
    wait_for_twist(cmd_vel, 0.03, 0.0)
    node = run(['rosnode', 'info', '/turtlebot3_teleop_keyboard'], 30.0).stdout
    pid = int(re.search(r'Pid: (\d+)', node).group(1))
    os.kill(launch.popen.pid, signal.SIGKILL)
    killed = time.monotonic()
    gone = wait_until(lambda: not alive(pid), 10.0)
    took = time.monotonic() - killed
    print('MEASURED teleop ended %.2f s after its roslaunch was killed' % took)
    assert gone and took < 5.0, 'the teleop (pid %d) outlived its roslaunch by %.1f s' % (pid, took)
    assert wait_until(lambda: last(twists(cmd_vel)) == ZERO, 5.0), last(twists(cmd_vel))


def test_in_a_namespace_it_drives_one_robot_of_three(master, processes, tmp_path, monkeypatch):
    """multi_turtlebot3.launch, then the e-manual's
    `ROS_NAMESPACE=tb3_0 rosrun turtlebot3_teleop turtlebot3_teleop_key`:
    tb3_0 (facing +y) drives ahead on /tb3_0/cmd_vel, tb3_1 does not move."""
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')
    sim = processes.start('sim', MULTI)
    truth = dict((name, Echo(processes, '/%s/base_pose_ground_truth' % name)) for name in ('tb3_0', 'tb3_1'))
    ready = wait_until(lambda: all(poses(echo) for echo in truth.values()) or not sim.running(), SIM_READY)
    assert ready and sim.running(), 'no ground truth within %.0f s; %s:\n%s' % (
        SIM_READY, sim.log, harness.tail(sim.log))
    cmd_vel = Echo(processes, '/tb3_0/cmd_vel')
    teleop = start_teleop(processes, tmp_path, cmd_vel, argv=['bash', '-c', NAMESPACED])
    start, other = last(poses(truth['tb3_0'])), last(poses(truth['tb3_1']))
    type_and_see(teleop, 'wwwww', 0.05, 0.0)
    wait_for_twist(cmd_vel, 0.05, 0.0)
    assert wait_until(lambda: last(poses(truth['tb3_0']))['y'] - start['y'] > 0.05, REACH_WITHIN), \
        'tb3_0 did not drive 5 cm ahead: %s -> %s' % (start, last(poses(truth['tb3_0'])))
    now, other_now = last(poses(truth['tb3_0'])), last(poses(truth['tb3_1']))
    print('MEASURED namespaced teleop: tb3_0 (%.3f, %.3f) -> (%.3f, %.3f); tb3_1 moved %.5f m'
          % (start['x'], start['y'], now['x'], now['y'],
             math.hypot(other_now['x'] - other['x'], other_now['y'] - other['y'])))
    assert abs(now['x'] - start['x']) < 0.01  # ahead is +y for tb3_0 (yaw 1.57)
    assert math.hypot(other_now['x'] - other['x'], other_now['y'] - other['y']) < 1e-3
    type_and_see(teleop, 's', 0.0, 0.0)


def test_robotis_launch_typed_as_the_emanual_drives_and_ends_within_2_s_of_ctrl_c(truth, processes, tmp_path):
    """`export TURTLEBOT3_MODEL=burger`, then `roslaunch turtlebot3_teleop turtlebot3_teleop_key.launch`:
    the keys drive the robot ahead; Ctrl+C in that terminal ends the node within 2 s, a stop published
    and the terminal restored."""
    cmd_vel = Echo(processes, '/cmd_vel')
    launch = start_teleop(processes, tmp_path, cmd_vel, name='emanual_teleop', argv=EMANUAL)
    assert '(burger: at most 0.22 m/s and 2.84 rad/s)' in launch.output(), launch.output()
    start = last(poses(truth))
    type_and_see(launch, 'w' * 5, 0.05, 0.0)
    wait_for_twist(cmd_vel, 0.05, 0.0)
    assert wait_until(lambda: last(poses(truth))['x'] - start['x'] > 0.05, REACH_WITHIN), \
        'the robot did not drive 5 cm ahead: %s -> %s' % (start, last(poses(truth)))
    node = run(['rosnode', 'info', '/turtlebot3_teleop_keyboard'], 30.0).stdout
    pid = int(re.search(r'Pid: (\d+)', node).group(1))

    launch.type('\x03')
    pressed = time.monotonic()
    gone = wait_until(lambda: not alive(pid), 10.0, poll=0.02)
    took = time.monotonic() - pressed
    print('MEASURED e-manual teleop: the node ended %.2f s after Ctrl+C' % took)
    assert gone and took <= CTRL_C_WITHIN, 'the teleop ran %.1f s after Ctrl+C' % took
    assert wait_until(lambda: not launch.running(), 30.0), 'roslaunch still runs 30 s after Ctrl+C'
    assert wait_until(lambda: last(twists(cmd_vel)) == ZERO, 5.0), last(twists(cmd_vel))
    assert wait_until(lambda: at_rest(truth), REST_WITHIN), last(poses(truth))
    assert 'Stopped' in launch.output() and launch.settings() == launch.settings_before, launch.output()[-2000:]
