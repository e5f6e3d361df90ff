"""The keyboard teleop started as the e-manual and ROBOTIS' launch file start it, typed at through a
pseudo-terminal (teleop_pty.py): roslaunch gives the node the terminal, a killed roslaunch leaves no
teleop behind, one robot of three driven in its namespace, and Ctrl+C on ROBOTIS' launch. The keys
themselves are test_teleop.py's. Every wait is on the wall clock with a deadline, and every process
is stopped by its process group when the test ends, also when it fails.
"""
import math
import os
import re
import signal
import time

from teleop_pty import (
    CTRL_C_WITHIN,
    EMANUAL,
    MULTI,
    NAMESPACED,
    REACH_WITHIN,
    REST_WITHIN,
    SIM_READY,
    ZERO,
    at_rest,
    last,
    start_teleop,
    twists,
    type_and_see,
    wait_for_twist,
)

from tb3_system_utils import Echo, alive, harness, poses, run, wait_until

pytest_plugins = ['teleop_pty']  # the fixtures master, truth and the autouse unbuffered


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
