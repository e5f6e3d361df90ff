"""The README's "In your own catkin workspace", typed in a fresh terminal.

HOME is a temporary folder, PATH is Debian's alone (no venv, no workspace
sourced yet), and the README's placeholder for this repository's address is
this repository (`git clone` takes its committed HEAD). The block builds
tb3_sim_nav and every package of packages/ with catkin_make; sourced, the workspace has
the package, gazebo_msgs' python classes and a simulator that serves
Gazebo's services. (`catkin_make run_tests` and `catkin_test_results`, the
README's next two commands, are what `make test` runs in make setup's
workspace: tools/run_tests.sh.)
"""
import os
import subprocess

from tb3_harness.processes import free_port

from tb3_system_utils import master_uri, wait_until

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ADDRESS = "<this repository's address>"
BLOCK = """mkdir -p ~/catkin_ws/src && cd ~/catkin_ws/src
git clone <this repository's address> tb3_sim_nav
ln -s tb3_sim_nav/packages/* .
/usr/bin/python3 -m venv --system-site-packages ~/tb3-venv && ~/tb3-venv/bin/pip install pybullet
cd ~/catkin_ws && catkin_make -DPYTHON_EXECUTABLE=$HOME/tb3-venv/bin/python3
source devel/setup.bash"""
BUILD_TIMEOUT = 1200  # wall s: a venv, pybullet's wheel and gazebo_msgs' five generators
TIMEOUT = 60.0


def test_the_readme_block_builds_a_workspace_that_runs_the_simulator(tmp_path, processes):
    port = free_port()
    fresh_terminal = dict((key, value) for key, value in os.environ.items() if key.startswith('PIP_'))
    fresh_terminal.update(HOME=str(tmp_path), PATH='/usr/local/bin:/usr/bin:/bin', LANG='C.UTF-8',
                          ROS_MASTER_URI=master_uri(port), ROS_HOSTNAME='localhost')
    script = BLOCK.replace(ADDRESS, REPO) + '\nset -e\n' + '\n'.join([
        'rospack find tb3_sim_nav', 'rospack find tb3_sim_bringup',
        'python3 -c "import gazebo_msgs.srv, tb3_common, tb3_navigation, tb3_sim_nav; '
        'print(gazebo_msgs.srv.__file__)"'])
    built = subprocess.run(['bash', '-c', 'set -e\n' + script], env=fresh_terminal, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True, timeout=BUILD_TIMEOUT)
    workspace = str(tmp_path / 'catkin_ws')
    assert built.returncode == 0, built.stdout[-4000:]
    lines = built.stdout.strip().split('\n')
    assert lines[-3] == os.path.join(workspace, 'src', 'tb3_sim_nav')
    assert lines[-2] == os.path.join(workspace, 'src', 'tb3_sim_bringup')
    assert lines[-1].startswith(os.path.join(workspace, 'devel'))

    in_workspace = 'source %s/devel/setup.bash && ' % workspace
    processes.start_master('roscore', port)
    sim = processes.start('sim', ['bash', '-c', in_workspace + 'roslaunch tb3_sim_bringup tb3_empty_world.launch'],
                          env=fresh_terminal)

    def world_properties():
        return subprocess.run(['bash', '-c', in_workspace + 'rosservice call /gazebo/get_world_properties'],
                              env=fresh_terminal, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              universal_newlines=True, timeout=TIMEOUT).stdout
    assert wait_until(lambda: 'turtlebot3_' in world_properties() or not sim.running(), TIMEOUT), sim.describe()
    assert sim.running(), sim.describe()
    # The simulator that runs is the workspace's.
    assert any(workspace in line for line in descendants_command_lines(sim.pid)), \
        descendants_command_lines(sim.pid)


def descendants_command_lines(root):
    """The command lines of every process descended from `root` (roslaunch gives its
    nodes sessions of their own, so not its process group)."""
    parents, command_lines = {}, {}
    for pid in filter(str.isdigit, os.listdir('/proc')):
        try:
            with open('/proc/%s/stat' % pid) as stat:
                parents[int(pid)] = int(stat.read().rsplit(')', 1)[1].split()[1])
            with open('/proc/%s/cmdline' % pid, 'rb') as cmdline:
                command_lines[int(pid)] = cmdline.read().replace(b'\0', b' ').decode(errors='replace')
        except (OSError, IndexError, ValueError):
            continue
    found, frontier = [], [root]
    while frontier:
        children = [pid for pid, parent in parents.items() if parent in frontier]
        found += [command_lines[pid] for pid in children if pid in command_lines]
        frontier = children
    return found
