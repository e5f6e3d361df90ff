"""The keyboard teleop (turtlebot3_teleop's turtlebot3_teleop_key; scripts/tb3_teleop_key and
tb3_sim_bringup's tb3_teleop_key.launch run the same node), typed at through a pseudo-terminal.

These: the keys, the exits, the models' limits, and no terminal; roslaunch's terminal, a namespace
and ROBOTIS' launch are test_teleop_launch.py's, what both use teleop_pty.py's.

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
import os
import signal
import termios
import time

import pytest
from teleop_pty import (
    EXIT_WITHIN,
    LIMITS,
    LINEAR_HALF_STEP,
    REACH_WITHIN,
    REST_WITHIN,
    ROBOTIS,
    START_WITHIN,
    TELEOP,
    TURN,
    ZERO,
    PtyProcess,
    assert_profile,
    at_rest,
    close,
    last,
    start_teleop,
    target_line,
    twists,
    type_and_see,
    wait_for_twist,
)

from tb3_system_utils import Echo, poses, run, wait_until

pytest_plugins = ['teleop_pty']  # the fixtures master, truth and the autouse unbuffered


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
