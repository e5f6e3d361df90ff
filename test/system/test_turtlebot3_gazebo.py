"""ROBOTIS' e-manual's simulation commands, typed as the e-manual types them (issue 29).

Each command through bash, after `export TURTLEBOT3_MODEL=burger`, as a
learner types them, on a master of the file's own (conftest.py):

    roslaunch turtlebot3_gazebo turtlebot3_empty_world.launch    (and the six other worlds)
    roslaunch turtlebot3_gazebo turtlebot3_simulation.launch      (the robot wanders by itself)
    roslaunch turtlebot3_gazebo turtlebot3_gazebo_rviz.launch
    roslaunch turtlebot3_fake turtlebot3_fake.launch

rviz opens on a screen of the test's own (Xvfb). Each launch ends with
Ctrl+C as a terminal sends it (SIGINT to the launch's process group, so to
roslaunch, which stops its nodes): every node of ours must be gone within
2 s, and nothing the launch started may be left (tb3_harness.leftovers).
(The teleop's launch is typed in test_teleop_launch.py, which drives through a
terminal.)
"""
import math
import os
import signal
import time

import pytest
import rospkg

from tb3_harness import leftovers
from tb3_harness.navigating import BURGER_FOOTPRINT, clearance
from tb3_harness.screen import save_png, screenshot

from tb3_system_utils import Echo, alive, poses, run, wait_until

EXPORT = 'export TURTLEBOT3_MODEL=burger'
READY = 60.0          # wall s for a launch's first message
GONE_WITHIN = 2.0     # wall s from Ctrl+C to the end of every node of ours
#: Our nodes' programs: what must end within GONE_WITHIN (rviz and robot_state_publisher are Debian's).
OURS = ('tb3_sim_node', 'turtlebot3_drive', 'turtlebot3_fake_node')
#: Each world launch: the e-manual's command (as the README shows it) and ROBOTIS' spawn pose (x_pos, y_pos).
WORLDS = {'turtlebot3_empty_world': ('roslaunch turtlebot3_gazebo turtlebot3_empty_world.launch', (0.0, 0.0)),
          'turtlebot3_world': ('roslaunch turtlebot3_gazebo turtlebot3_world.launch', (-2.0, -0.5)),
          'turtlebot3_house': ('roslaunch turtlebot3_gazebo turtlebot3_house.launch', (-3.0, 1.0)),
          'turtlebot3_stage_1': ('roslaunch turtlebot3_gazebo turtlebot3_stage_1.launch', (0.0, 0.0)),
          'turtlebot3_stage_2': ('roslaunch turtlebot3_gazebo turtlebot3_stage_2.launch', (0.0, 0.0)),
          'turtlebot3_stage_3': ('roslaunch turtlebot3_gazebo turtlebot3_stage_3.launch', (0.0, 0.0)),
          'turtlebot3_stage_4': ('roslaunch turtlebot3_gazebo turtlebot3_stage_4.launch', (-0.7, 0.0))}
SPAWN_TOLERANCE = 0.01   # m from ROBOTIS' spawn pose
WANDER_SECONDS = 60.0    # s of sim time turtlebot3_drive wanders
WANDER_AT_LEAST = 5.0    # m it must cover meanwhile (about 10 in a run; 13 at a Burger's top speed, all ahead)
SHOTS = os.path.join(rospkg.get_ros_home(), 'test_results', 'tb3_sim_nav', 'turtlebot3_gazebo')


def bash(command):
    return ['bash', '-c', '%s && %s' % (EXPORT, command)]


@pytest.fixture
def master(shared_master):
    return shared_master


@pytest.fixture
def launches(processes):
    """start(name, command): the command typed through bash in a terminal of its own, its processes
    tagged (leftovers.TAG) so that Ctrl+C's check finds them all."""
    def start(name, command):
        tag = '%s.%d.%d' % (name, os.getpid(), time.monotonic_ns())
        launch = processes.start(name, bash(command), env=dict(os.environ, PYTHONUNBUFFERED='1',
                                                               **{leftovers.TAG: tag}))
        launch.tag = tag
        return launch
    return start


@pytest.fixture
def display(screen):
    """A screen of the test's own for rviz (DISPLAY set for what the test starts)."""
    return screen


def ours(launch):
    """{pid: command line} of the nodes of ours that `launch` started (running now)."""
    return dict((pid, command) for pid, command in leftovers.tagged(launch.tag)
                if any(program in command for program in OURS))


def ctrl_c(launch, what):
    """Ctrl+C in the launch's terminal: every node of ours gone within GONE_WITHIN, then the whole launch.
    The seconds it took."""
    nodes = ours(launch)
    assert nodes, 'no node of ours is running under %s; %s' % (what, launch.describe())
    launch.signal_group(signal.SIGINT)
    pressed = time.monotonic()
    gone = wait_until(lambda: not any(alive(pid) for pid in nodes), 20.0, poll=0.02)
    took = time.monotonic() - pressed
    print('MEASURED Ctrl+C on %s: %s gone after %.2f s' % (what, ', '.join(
        sorted(next(program for program in OURS if program in command) for command in nodes.values())), took))
    assert gone and took <= GONE_WITHIN, '%s: %s still running %.1f s after Ctrl+C; %s' % (
        what, [command for pid, command in nodes.items() if alive(pid)], took, launch.describe())
    assert launch.wait(30.0) is not None, launch.describe()
    left = leftovers.check(launch.tag, 'Ctrl+C on ' + what)
    assert not left, 'left running after Ctrl+C on %s: %s' % (what, left)
    return took


def colour_pixels(image, colour, tolerance):
    import numpy as np
    return int((np.abs(image - np.array(colour)).max(axis=2) <= tolerance).sum())


def test_every_world_launch_spawns_the_robot_where_robotis_does(master, launches, processes):
    truth = Echo(processes, '/base_pose_ground_truth')
    for name, (command, spawn) in WORLDS.items():
        mark = truth.count()
        world = launches(name, command)
        first = truth.after(mark, READY)
        assert first is not None, 'no ground truth from %s within %.0f s; %s' % (name, READY, world.describe())
        pose = poses(truth, [first])[0]
        print('MEASURED %s: spawned at (%.3f, %.3f), yaw %.3f' % (name, pose['x'], pose['y'], pose['yaw']))
        assert math.hypot(pose['x'] - spawn[0], pose['y'] - spawn[1]) < SPAWN_TOLERANCE, (name, pose)
        assert abs(pose['yaw']) < 0.01, (name, pose)
        # As ROBOTIS' world launches: no robot_state_publisher (turtlebot3_remote.launch starts it).
        assert not [command for _, command in leftovers.tagged(world.tag) if 'robot_state_publisher' in command]
        ctrl_c(world, name + '.launch')


def test_turtlebot3_simulation_wanders_turtlebot3_world_without_touching_anything(master, launches, processes):
    from tb3_sim_nav.world_file import load_world
    world = launches('world', 'roslaunch turtlebot3_gazebo turtlebot3_world.launch real_time_factor:=0')
    truth = Echo(processes, '/base_pose_ground_truth')
    cmd_vel = Echo(processes, '/cmd_vel')
    assert wait_until(lambda: truth.rows() or not world.running(), READY), world.describe()
    drive = launches('drive', 'roslaunch turtlebot3_gazebo turtlebot3_simulation.launch')
    assert wait_until(lambda: cmd_vel.rows() or not drive.running(), READY), drive.describe()
    # From the drive's first command on: the simulator ran ahead meanwhile (factor 0, and lockstep
    # waits only for nodes that publish cmd_vel).
    start = len(truth.rows())
    began = poses(truth)[start - 1]
    assert wait_until(lambda: poses(truth)[-1]['t'] - began['t'] >= WANDER_SECONDS or not drive.running(), 300.0), \
        'not %.0f s of sim time within 300 s; %s' % (WANDER_SECONDS, drive.describe())
    path = [[p['t'], p['x'], p['y'], p['yaw']] for p in poses(truth)[start - 1:]]
    obstacles = load_world('turtlebot3_world', os.path.join(rospkg.RosPack().get_path('tb3_sim_nav'), 'worlds'))
    least = clearance(path, obstacles.obstacles, BURGER_FOOTPRINT)
    covered = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(path, path[1:]))
    xs, ys = [p[1] for p in path], [p[2] for p in path]
    print('MEASURED turtlebot3_drive: %.1f s of sim time, %.2f m driven over %.2f x %.2f m, footprint at least '
          '%.3f m from the world' % (path[-1][0] - path[0][0], covered, max(xs) - min(xs), max(ys) - min(ys), least))
    assert least > 0.0, 'the robot touched the world: footprint %.3f m from it' % least
    assert covered >= WANDER_AT_LEAST and max(xs) - min(xs) > 1.0 and max(ys) - min(ys) > 1.0, (covered, xs, ys)
    speeds = set((float(row['field.linear.x']), float(row['field.angular.z'])) for row in cmd_vel.rows())
    assert speeds <= {(0.3, 0.0), (0.0, 1.5), (0.0, -1.5), (0.0, 0.0)}, speeds   # ROBOTIS' three commands
    ctrl_c(drive, 'turtlebot3_simulation.launch')
    # As ROBOTIS' destructor: the last command is a stop.
    assert wait_until(lambda: cmd_vel.rows()[-1]['field.linear.x'] == '0.0', 5.0), cmd_vel.rows()[-1]
    ctrl_c(world, 'turtlebot3_world.launch')


def test_gazebo_rviz_gives_the_robot_its_tree_and_rviz_shows_the_scan(master, launches, display):
    world = launches('world', 'roslaunch turtlebot3_gazebo turtlebot3_world.launch')
    view = launches('gazebo_rviz', 'roslaunch turtlebot3_gazebo turtlebot3_gazebo_rviz.launch')
    seen = []

    def scan_drawn():
        image = screenshot(display)
        seen[:] = [image, colour_pixels(image, (0, 255, 0), 40)]
        return seen[1] > 200
    # The scan is drawn in frame odom only through base_footprint -> base_scan: robot_state_publisher's.
    drawn = wait_until(lambda: scan_drawn() or not view.running(), 120.0, poll=1.0)
    print('MEASURED turtlebot3_gazebo_rviz: %d scan pixels' % seen[1])
    assert drawn and view.running(), 'no scan in rviz (%d pixels); %s' % (seen[1], view.describe())
    publishers = [command for _, command in leftovers.tagged(view.tag) + leftovers.tagged(world.tag)
                  if 'robot_state_publisher' in command]
    assert len(publishers) == 1, publishers
    time.sleep(5.0)
    assert view.running() and world.running(), view.describe()
    os.makedirs(SHOTS, exist_ok=True)
    save_png(screenshot(display), os.path.join(SHOTS, 'turtlebot3_gazebo_rviz.png'))
    view.signal_group(signal.SIGINT)
    assert view.wait(30.0) is not None and not leftovers.check(view.tag, 'Ctrl+C on turtlebot3_gazebo_rviz.launch')
    ctrl_c(world, 'turtlebot3_world.launch')


def test_fake_turns_cmd_vel_into_odom_and_tf_and_stays_up(master, launches, processes, display):
    fake = launches('fake', 'roslaunch turtlebot3_fake turtlebot3_fake.launch')
    odom = Echo(processes, '/odom')
    tf = Echo(processes, '/tf')
    assert wait_until(lambda: odom.rows() or not fake.running(), READY), fake.describe()
    command = processes.start('cmd_vel', ['rostopic', 'pub', '-r', '10', '/cmd_vel', 'geometry_msgs/Twist',
                                          '{linear: {x: 0.2}, angular: {z: 0.5}}'])
    assert wait_until(lambda: poses(odom)[-1]['speed'] > 0.1, READY), poses(odom)[-1]
    driving = len(odom.rows())
    time.sleep(4.0)
    command.stop()
    # ROBOTIS' cmd_vel timeout: the wheels stop a second after the last command.
    assert wait_until(lambda: poses(odom)[-1]['speed'] == 0.0, 5.0), poses(odom)[-1]
    moving = [p for p in poses(odom)[driving:] if p['speed'] > 0.0]
    x, y = moving[-1]['x'], moving[-1]['y']
    stamps = [p['t'] for p in moving]
    rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    print('MEASURED turtlebot3_fake: odom at %.1f Hz, at (%.3f, %.3f) after %d messages'
          % (rate, x, y, len(moving)))
    assert moving[-1]['speed'] == pytest.approx(0.2) and moving[-1]['turn'] == pytest.approx(0.5)
    assert math.hypot(x, y - 0.4) == pytest.approx(0.4, abs=0.005)   # on the circle of radius v / w
    assert 20.0 < rate < 40.0, rate   # ROBOTIS' 30 Hz, of wall time
    # tf odom -> base_footprint says what odom says, with its stamp.
    odom_by_stamp = dict((row['field.header.stamp'], row) for row in odom.rows())
    transforms = [row for row in tf.rows() if row.get('field.transforms0.child_frame_id') == 'base_footprint'
                  and row['field.transforms0.header.stamp'] in odom_by_stamp]
    assert len(transforms) > 30 and all(row['field.transforms0.header.frame_id'] == 'odom' for row in transforms)
    for row in transforms[-10:]:
        match = odom_by_stamp[row['field.transforms0.header.stamp']]
        assert float(row['field.transforms0.transform.translation.x']) == float(match['field.pose.pose.position.x'])
    # A command with NaN in it stops the robot, and the node goes on.
    mark = odom.count()
    nan = run(['rostopic', 'pub', '-1', '/cmd_vel', 'geometry_msgs/Twist', '{linear: {x: .nan}, angular: {z: 0.5}}'],
              30.0)
    assert nan.returncode == 0, nan.stdout
    after = odom.after(mark + 30, 10.0)
    assert after is not None and fake.running(), fake.describe()
    assert all(math.isfinite(value) for value in poses(odom, [after])[0].values()) and poses(odom)[-1]['speed'] == 0.0
    assert 'NaN or inf' in fake.output(None), fake.output()
    image = screenshot(display)
    os.makedirs(SHOTS, exist_ok=True)
    save_png(image, os.path.join(SHOTS, 'turtlebot3_fake.png'))
    arrows = colour_pixels(image, (255, 25, 0), 60)
    print('MEASURED turtlebot3_fake in rviz: %d odometry arrow pixels' % arrows)
    assert arrows > 300, arrows
    assert fake.running() and len(leftovers.tagged(fake.tag)) >= 4, leftovers.tagged(fake.tag)
    ctrl_c(fake, 'turtlebot3_fake.launch')


@pytest.mark.parametrize('command, parameter', [
    ('rosrun turtlebot3_gazebo turtlebot3_drive _cmd_vel_topic_name:="a b"', "cmd_vel_topic_name = 'a b'"),
    ('rosparam set /tb3_model turtlebot4 && rosrun turtlebot3_fake turtlebot3_fake_node', "tb3_model = 'turtlebot4'")])
def test_a_bad_parameter_ends_the_node_at_start_naming_it(command, parameter, master):
    result = run(bash(command), 60.0)
    print('MEASURED %s: status %s, %r' % (command, result.returncode, result.stdout.strip()[-200:]))
    assert result.returncode == 2 and parameter in result.stdout and 'cannot start' in result.stdout, result.stdout
