"""The README's commands, typed as the README shows them, each through bash as a
user's terminal runs it, against a roscore of each test's own on a free
loopback port. What each must do is what the README says it does.

test/unit/test_readme.py checks that every command the README shows is a
literal of some test: these, the teleop's (teleop_pty.py), test_known_worlds.py's and
test_own_workspace.py's; `make test` and `catkin_make run_tests` are in
.ci/run and tools/run_tests.sh.
"""
import math
import os
import re
import signal
import subprocess

import yaml

from tb3_harness.screen import screen_env, start_xvfb

from tb3_system_utils import Echo, poses, run, wait_until

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TIMEOUT = 60.0        # wall s for one short command, one message or a start-up
SCRIPT_TIMEOUT = 240  # wall s for a tutorial script at factor 1 (the square takes about 50)
DEMO_TIMEOUT = 900    # wall s for `make demo`
ORIGIN = (0.0, 0.0)


def bash(command):
    """argv that runs `command` (one line or several) as a terminal's bash would."""
    return ['bash', '-c', command]


def echo(topic, *options):
    """One message of `topic`, as `rostopic echo -n 1 [OPTIONS]` prints it, parsed."""
    printed = run(['rostopic', 'echo', '-n', '1'] + list(options) + [topic], TIMEOUT)
    assert printed.returncode == 0, 'rostopic echo -n 1 %s: %s' % (topic, printed.stdout[-1000:])
    return next(yaml.safe_load_all(printed.stdout))


def call(command):
    """A `rosservice call`'s answer, parsed."""
    printed = run(bash(command), TIMEOUT)
    assert printed.returncode == 0, '%s: %s' % (command, printed.stdout[-1000:])
    return yaml.safe_load(printed.stdout)


def pose_of(message):
    """(x, y, yaw, speed, turn) of an Odometry message."""
    pose, twist = message['pose']['pose'], message['twist']['twist']
    q = pose['orientation']
    return (pose['position']['x'], pose['position']['y'],
            math.atan2(2.0 * (q['w'] * q['z'] + q['x'] * q['y']), 1.0 - 2.0 * (q['y'] ** 2 + q['z'] ** 2)),
            twist['linear']['x'], twist['angular']['z'])


def start(processes, name, command, **popen):
    return processes.start(name, bash(command), **popen)


class Truth(object):
    """/base_pose_ground_truth from one `rostopic echo -p` for the whole test
    (tb3_system_utils.Echo), through the simulator's restarts; each look is a
    tuple (x, y, yaw, speed, turn), the speed unsigned."""

    def __init__(self, processes):
        self.echo = Echo(processes, '/base_pose_ground_truth')

    @staticmethod
    def _tuple(row):
        pose = poses(None, [row])[0]
        return pose['x'], pose['y'], pose['yaw'], pose['speed'], pose['turn']

    def latest(self):
        rows = self.echo.rows()
        return self._tuple(rows[-1]) if rows else None

    def fresh(self):
        """The first message after this call, as `rostopic echo -n 1` would print it."""
        row = self.echo.after(self.echo.count(), TIMEOUT)
        assert row is not None, 'no ground truth within %.0f s' % TIMEOUT
        return self._tuple(row)

    def start_sim(self, processes, command, **popen):
        """The simulator by `command`, once its ground truth comes: its first message
        (its clock starts from zero: a late message of the one before is older)."""
        rows = self.echo.rows()
        before = poses(None, rows[-1:])[0]['t'] if rows else math.inf
        sim = start(processes, 'sim', command, **popen)
        first = self.echo.after(len(rows), TIMEOUT, lambda row: int(row['field.header.stamp']) * 1e-9 < before)
        assert first is not None and sim.running(), sim.describe()
        return sim, self._tuple(first)


def run_script(command):
    done = run(bash(command), SCRIPT_TIMEOUT)
    assert done.returncode == 0, '%s exited %r:\n%s' % (command, done.returncode, done.stdout[-2000:])


def distance(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])


def test_source_setup_bash_gives_debians_rospy_whatever_python_comes_first(tmp_path):
    foreign = tmp_path / 'bin'
    foreign.mkdir()
    (foreign / 'python3').write_text('#!/bin/sh\necho "a python that cannot see rospy" >&2\nexit 3\n')
    (foreign / 'python3').chmod(0o755)
    fresh_terminal = {'HOME': os.environ['HOME'], 'PATH': '%s:/usr/local/bin:/usr/bin:/bin' % foreign}
    command = 'source setup.bash'
    done = subprocess.run(bash(command + ' && python3 -c "import rospy, pybullet, gazebo_msgs.srv; '
                                         'print(rospy.__file__)" && rospack find tb3_sim_bringup'),
                          cwd=REPO, env=fresh_terminal, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stdout
    assert '/usr/lib/python3/dist-packages/rospy' in done.stdout and 'tb3_sim_bringup' in done.stdout


def test_the_tutorial_command_by_command(ros_port, processes):
    processes.start_master('roscore', ros_port)
    truth = Truth(processes)
    sim, _ = truth.start_sim(processes, 'roslaunch tb3_sim_bringup tb3_empty_world.launch')
    xvfb, display = start_xvfb()
    processes.add(xvfb, server=True)
    rviz = start(processes, 'rviz', 'rosrun rviz rviz -d `rospack find tb3_sim_bringup`/rviz/demo.rviz',
                 env=dict(os.environ, **screen_env(display)))

    # 1. The circle holds after Ctrl+C; the empty Twist stops it.
    circle = start(processes, 'circle', "rostopic pub -r 10 /cmd_vel geometry_msgs/Twist "
                                        "'{linear: {x: 0.1, y: 0, z: 0}, angular: {x: 0, y: 0, z: -0.5}}'")
    assert wait_until(lambda: abs(truth.latest()[3] - 0.1) < 0.01, TIMEOUT), \
        'the circle did not start: %s' % (truth.latest(),)
    circle.signal_group(signal.SIGINT)
    assert circle.wait(TIMEOUT) is not None, 'rostopic pub did not end on Ctrl+C'
    x, y, yaw, speed, turn = truth.fresh()
    print('MEASURED after Ctrl+C: speed %.3f m/s, turn %.3f rad/s' % (speed, turn))
    assert abs(speed - 0.1) < 0.01 and abs(turn + 0.5) < 0.05  # the last command holds
    assert abs(math.hypot(x, y + 0.2) - 0.2) < 0.02  # on the circle of radius 0.2 m around (0, -0.2)
    call("rostopic pub -1 /cmd_vel geometry_msgs/Twist '{}'")
    assert wait_until(lambda: abs(truth.latest()[3]) < 1e-3 and abs(truth.latest()[4]) < 1e-3, TIMEOUT), \
        truth.latest()

    # rviz shows demo.rviz, the world's obstacles included.
    assert rviz.running(), rviz.describe()
    readers = run(['rostopic', 'info', '/world_markers'], TIMEOUT).stdout
    assert re.search(r'Subscribers:\s*\n\s*\* /rviz', readers), readers

    # 2. and 3., each after a restart of the simulator; 4. after 3.
    for script, back_within in (('rosrun tb3_sim_nav timed_out_and_back.py', 0.15),
                                ('rosrun tb3_sim_nav odom_out_and_back.py', 0.05)):
        sim.stop()
        sim, first = truth.start_sim(processes, 'roslaunch tb3_sim_bringup tb3_empty_world.launch')
        assert distance(first, ORIGIN) < 1e-3  # back at the origin
        run_script(script)
        end = truth.fresh()
        print('MEASURED %s: ends %.3f m from the start' % (script, distance(end, ORIGIN)))
        assert distance(end, ORIGIN) < back_within
    run_script('rosrun tb3_sim_nav nav_square.py')
    square_end = truth.fresh()
    print('MEASURED nav_square.py: ends %.3f m from its start' % distance(square_end, end))
    assert distance(square_end, end) < 0.1
    assert rviz.running(), rviz.describe()


def test_make_demo(tmp_path):
    """`make demo`: three scripts, a table and a PNG of the paths in demo_output/."""
    env = dict((key, value) for key, value in os.environ.items() if key not in ('MAKEFLAGS', 'MAKELEVEL', 'MFLAGS'))
    summary, picture = os.path.join(REPO, 'demo_output', 'summary.txt'), os.path.join(REPO, 'demo_output',
                                                                                      'demo_paths.png')
    before = max((os.path.getmtime(path) for path in (summary, picture) if os.path.exists(path)), default=0.0)
    done = subprocess.run(['make', 'demo'], cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, timeout=DEMO_TIMEOUT)
    assert done.returncode == 0, done.stdout[-3000:]
    assert os.path.getmtime(summary) > before and os.path.getmtime(picture) > before
    with open(summary) as table:
        text = table.read()
    print(text)
    for script in ('timed_out_and_back.py', 'odom_out_and_back.py', 'nav_square.py'):
        assert script in text


def test_the_realistic_profile_drifts(ros_port, processes):
    """The realistic profile's odometry drifts from the truth; the closed-loop script still comes back."""
    processes.start_master('roscore', ros_port)
    truth = Truth(processes)
    truth.start_sim(processes, 'roslaunch tb3_sim_bringup tb3_empty_world.launch profile:=realistic')
    run_script('rosrun tb3_sim_nav odom_out_and_back.py')
    end, odom = truth.fresh(), pose_of(echo('/odom'))
    print('MEASURED realistic odom_out_and_back.py: ends %.3f m from the start, odometry %.3f m off the truth'
          % (distance(end, ORIGIN), distance(end, odom)))
    assert distance(end, ORIGIN) < 0.1
    assert distance(end, odom) > 0.005


def test_another_model_and_its_camera_in_rviz(ros_port, processes):
    processes.start_master('roscore', ros_port)
    Truth(processes).start_sim(processes,
                               'export TURTLEBOT3_MODEL=waffle_pi\nroslaunch tb3_sim_bringup tb3_world.launch')
    xvfb, display = start_xvfb()
    processes.add(xvfb, server=True)
    rviz = start(processes, 'rviz', 'export TURTLEBOT3_MODEL=waffle_pi\n'
                 'rosrun rviz rviz -d `rospack find tb3_sim_bringup`/rviz/camera.rviz',
                 env=dict(os.environ, **screen_env(display)))
    info = echo('/camera/rgb/camera_info')
    assert (info['width'], info['height']) == (640, 480)
    assert wait_until(lambda: re.search(r'Subscribers:\s*\n\s*\* /rviz',
                                        run(['rostopic', 'info', '/camera/rgb/image_raw'], TIMEOUT).stdout), TIMEOUT)
    # --noarr: the pixels as their count; as YAML, 921,600 numbers took 28 s to parse (measured).
    image = echo('/camera/rgb/image_raw', '--noarr')
    assert (image['width'], image['height'], image['encoding']) == (640, 480, 'rgb8')
    assert image['data'] == '<array type: uint8, length: %d>' % (640 * 480 * 3)
    assert rviz.running(), rviz.describe()


def test_gazebos_model_services_and_a_script_written_for_gazebo(ros_port, processes):
    processes.start_master('roscore', ros_port)
    truth = Truth(processes)
    truth.start_sim(processes, 'roslaunch tb3_sim_bringup tb3_world.launch',
                    env=dict(os.environ, TURTLEBOT3_MODEL='burger'))
    state = call("rosservice call /gazebo/get_model_state '{model_name: turtlebot3_burger}'")
    assert state['success'] is True
    assert distance((state['pose']['position']['x'], state['pose']['position']['y']), (-2.0, -0.5)) < 0.01
    moved = call("rosservice call /gazebo/set_model_state '{model_state: {model_name: turtlebot3_burger, "
                 "pose: {position: {x: -2.0, y: 0.5}, orientation: {w: 1.0}}}}'")
    assert moved['success'] is True, moved
    assert wait_until(lambda: distance(truth.latest(), (-2.0, 0.5)) < 0.01, TIMEOUT), truth.latest()
    assert distance(pose_of(echo('/odom')), (-2.0, 0.5)) < 0.01  # Gazebo's odom jumps with the robot

    goal = start(processes, 'goal_box', 'rosrun tb3_sim_nav goal_box.py', env=dict(os.environ, PYTHONUNBUFFERED='1'))
    assert wait_until(lambda: 'goal at (-1.00, 0.50)' in goal.output() or not goal.running(), TIMEOUT), goal.describe()

    def goal_at():
        answer = call("rosservice call /gazebo/get_model_state '{model_name: goal}'")
        assert answer['success'] is True, answer
        return answer['pose']['position']['x'], answer['pose']['position']['y']
    assert distance(goal_at(), (-1.0, 0.5)) < 1e-3  # 1 m ahead of where the robot rests
    # The robot reaches it (teleported onto it): the goal moves on, to the next corner.
    reached = call("rosservice call /gazebo/set_model_state '{model_state: {model_name: turtlebot3_burger, "
                   "pose: {position: {x: -1.0, y: 0.5}, orientation: {w: 1.0}}}}'")
    assert reached['success'] is True, reached
    assert wait_until(lambda: 'goal 1 reached; the next one is at (-1.00, 1.50)' in goal.output(), TIMEOUT), \
        goal.describe()
    assert distance(goal_at(), (-1.0, 1.5)) < 1e-3
    goal.signal_group(signal.SIGINT)
    assert goal.wait(TIMEOUT) == 0, goal.describe()
    assert 'goal deleted' in goal.output()
    models = call('rosservice call /gazebo/get_world_properties')['model_names']
    assert 'goal' not in models and 'turtlebot3_burger' in models
