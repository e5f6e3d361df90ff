"""The simulator outlives its ROS master, and a new master on the same port
gets everything back: /use_sim_time, the simulator's topics, and new nodes
that can drive the robot.

roscore on a free loopback port, `roslaunch tb3_sim_bringup
tb3_empty_world.launch` against it; roscore killed (SIGINT to its process
group); 3 s later the simulator must still run; a new roscore on the same
port; within 10 s /use_sim_time must be true and `rostopic list` must show
/odom; then a new node (`rostopic pub -1 /cmd_vel ...`, a process started
after the restart) drives the robot, as `rostopic echo -n 1
/base_pose_ground_truth` (another new node) shows.
"""
import math
import os
import time

import yaml

from tb3_system_utils import master_pid, master_uri, run, wait_until

SIM_READY = 60.0        # wall s for the first simulator to publish
DEAD_WAIT = 3.0         # wall s without a master
RECOVER_WITHIN = 10.0   # wall s after the new master answers
DRIVE = 0.1             # m/s
DRIVE_WALL = 3.0        # wall s of driving after `rostopic pub -1` returned
ROSOUT_TOPICS = '/rosout_disable_topics_generation'  # set by the simulator (doc/design.md, lockstep)


def topics():
    result = run(['rostopic', 'list'], timeout=10.0)
    return result.stdout.split() if result.returncode == 0 else []


def ground_truth():
    """(x, y) of one /base_pose_ground_truth message read by a new node, or None."""
    result = run(['rostopic', 'echo', '-n', '1', '/base_pose_ground_truth'], timeout=20.0)
    if result.returncode != 0:
        return None
    documents = [d for d in yaml.safe_load_all(result.stdout) if d]
    if not documents:
        return None
    position = documents[0]['pose']['pose']['position']
    return position['x'], position['y']


def parameter(port, name):
    """A parameter's value on the master at `port`; None when it is unset or the master does not answer."""
    import rosgraph
    try:
        return rosgraph.Master('/tb3_system_test', master_uri=master_uri(port)).getParam(name)
    except Exception:
        return None


def use_sim_time(port):
    return parameter(port, '/use_sim_time') is True


def children_of(pid):
    """Command lines of the live child processes of `pid` (roslaunch puts each node
    in a session of its own, so they are not in its process group)."""
    children = []
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open('/proc/%s/stat' % entry) as stat:
                fields = stat.read().rsplit(')', 1)[1].split()
            if int(fields[1]) != pid or fields[0] == 'Z':
                continue
            with open('/proc/%s/cmdline' % entry, 'rb') as cmdline:
                children.append(cmdline.read().replace(b'\0', b' ').decode(errors='replace'))
        except (OSError, IndexError, ValueError):
            continue
    return children


def test_simulator_survives_master_restart_and_new_nodes_drive_it(ros_port, processes):
    port = ros_port
    first = processes.start_master('roscore_1', port)
    sim = processes.start('sim', ['roslaunch', 'tb3_sim_bringup', 'tb3_empty_world.launch'])
    assert wait_until(lambda: ground_truth() is not None or not sim.running(), SIM_READY) and sim.running(), \
        'the simulator did not publish ground truth; %s' % sim.log
    old_pid = master_pid(port)
    # Set to its default so that a node's log message does not ask the master (lockstep, doc/design.md).
    assert parameter(port, ROSOUT_TOPICS) is False

    first.stop()
    assert master_pid(port) is None, 'the first master still answers'
    time.sleep(DEAD_WAIT)
    members = children_of(sim.popen.pid)
    assert sim.running(), 'roslaunch exited when the master went away; its log ends with:\n%s' % \
        open(sim.log).read()[-3000:]
    assert any('tb3_sim_node' in member for member in members), \
        'the simulator node is gone %.0f s after the master; roslaunch\'s children: %s' % (DEAD_WAIT, members)

    processes.start_master('roscore_2', port)
    restarted = time.monotonic()
    assert master_pid(port) != old_pid
    sim_time_back = wait_until(lambda: use_sim_time(port), RECOVER_WITHIN)
    sim_time_after = time.monotonic() - restarted
    odom_back = wait_until(lambda: '/odom' in topics(), max(0.0, restarted + RECOVER_WITHIN - time.monotonic()))
    odom_after = time.monotonic() - restarted
    print('MEASURED master_restart: use_sim_time after %.2f s, /odom listed after %.2f s'
          % (sim_time_after, odom_after))
    assert sim_time_back, '/use_sim_time not true %.0f s after the new master came up' % RECOVER_WITHIN
    assert parameter(port, ROSOUT_TOPICS) is False, 'the simulator did not set %s again' % ROSOUT_TOPICS
    assert odom_back, '`rostopic list` without /odom %.0f s after the new master came up: %s' % (
        RECOVER_WITHIN, topics())

    before = ground_truth()
    assert before is not None, 'a new node could not read /base_pose_ground_truth'
    published = run(['rostopic', 'pub', '-1', '/cmd_vel', 'geometry_msgs/Twist',
                     '{linear: {x: %g, y: 0, z: 0}, angular: {x: 0, y: 0, z: 0}}' % DRIVE], timeout=30.0)
    assert published.returncode == 0, published.stdout
    time.sleep(DRIVE_WALL)
    after = ground_truth()
    run(['rostopic', 'pub', '-1', '/cmd_vel', 'geometry_msgs/Twist', '{}'], timeout=30.0)
    assert after is not None, 'a new node could not read /base_pose_ground_truth after driving'
    moved = math.hypot(after[0] - before[0], after[1] - before[1])
    print('MEASURED master_restart_drive: moved %.3f m (%.0f wall s at %.2f m/s after rostopic pub -1 '
          'returned)' % (moved, DRIVE_WALL, DRIVE))
    assert moved > 0.5 * DRIVE * DRIVE_WALL, \
        'the robot moved %.3f m after `rostopic pub -1` from a node started after the restart' % moved
