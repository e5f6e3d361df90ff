"""Two hosts: the simulator with its master on one, a tutorial script on the other.

The test makes two network namespaces of this machine, `host A` and `host
B`, joined by a veth pair with private addresses of its own (10.233.N.1 and
10.233.N.2 on a /24 no other test uses), as two computers on a private
network; every process runs in one of them with `ip netns exec`, in a bash
that sources setup.bash, as a user's terminal on that computer would.

1. As doc/network.md says, host A exports ROS_IP (its own
   address) and ROS_MASTER_URI (its master), host B exports its own ROS_IP
   and A's ROS_MASTER_URI, and each applies doc/network.md's firewall block
   trusting the other. odom_out_and_back.py on B drives the robot of A
   across the link (not waited for by lockstep: that follows local nodes
   only) and must end as the tutorial test has it: within 5 cm and 5 deg of
   where it started, after about 1 m ahead and 360 deg of turning in all.
2. What a stranger on the network reaches: host A as doc/network.md sets up
   one machine (setup.bash: ROS_HOSTNAME=localhost, the master on
   localhost). Each TCP port listening in A is tried from B. The master, the
   simulator and every TCPROS port listen on loopback only and refuse; the
   XML-RPC APIs of Debian's roscpp nodes (rosout, robot_state_publisher)
   listen on every interface whatever ROS_HOSTNAME says: B reaches them,
   asks their PID and stops robot_state_publisher. With doc/network.md's
   firewall block (trusting no one) applied in A, B reaches nothing. The
   test asserts exactly this, so doc/network.md's table stays true.
"""
import math
import os
import re
import subprocess

import pytest

from tb3_common.pose2d import yaw_of_quaternion
from tb3_harness import report
from tb3_harness.processes import free_port

from tb3_system_utils import wait_until

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SUBNET = '10.233.%d' % (os.getpid() % 200 + 20)
ADDRESS = {'a': SUBNET + '.1', 'b': SUBNET + '.2'}
LOOPBACK_ONLY = ('rosmaster', 'tb3_sim_node')      # our own: python, bound to loopback
ROSCPP = ('rosout', 'robot_state_pub')            # Debian's roscpp (ss shows 15 characters)
DOC_TRUSTED = '192.168.1.20'                   # the other machine, in doc/network.md's firewall block


def readme_firewall(trusted=None):
    """doc/network.md's firewall block (nft rules), trusting `trusted` or no one."""
    with open(os.path.join(REPO, 'doc', 'network.md')) as page:
        text = page.read()
    block = text.split('<!-- firewall: test/system/test_two_hosts.py runs this block -->\n')[1]
    lines = [line[4:] for line in block.split('\n')]
    rules = '\n'.join(lines[lines.index("sudo nft -f - <<'EOF'") + 1:lines.index('EOF')])
    if trusted is None:
        return '\n'.join(line for line in rules.split('\n') if DOC_TRUSTED not in line)
    return rules.replace(DOC_TRUSTED, trusted)


def ip(*args):
    subprocess.run(['ip'] + list(args), check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


class Hosts(object):
    """Two namespaces joined by a veth pair; everything undone by close()."""

    def __init__(self):
        tag = str(os.getpid())
        self.names = {'a': 'tb3a' + tag, 'b': 'tb3b' + tag}
        self.made = []
        try:
            for host, name in self.names.items():
                ip('netns', 'add', name)
                self.made.append(name)
            link = {'a': 'tb3va' + tag, 'b': 'tb3vb' + tag}
            ip('link', 'add', link['a'], 'type', 'veth', 'peer', 'name', link['b'])
            for host in ('a', 'b'):
                ip('link', 'set', link[host], 'netns', self.names[host])
                ip('-n', self.names[host], 'addr', 'add', ADDRESS[host] + '/24', 'dev', link[host])
                ip('-n', self.names[host], 'link', 'set', link[host], 'up')
                ip('-n', self.names[host], 'link', 'set', 'lo', 'up')
        except BaseException:
            self.close()
            raise

    def argv(self, host, command, **environment):
        """`command` (a shell line) on `host`, in a bash that first exports
        `environment` (ROS_IP...) and sources setup.bash, as a user would."""
        exports = ''.join('export %s=%s; ' % item for item in sorted(environment.items()))
        return ['ip', 'netns', 'exec', self.names[host], 'env', '-u', 'ROS_HOSTNAME', '-u', 'ROS_IP',
                '-u', 'ROS_MASTER_URI', 'bash', '-c',
                '%ssource %s/setup.bash && exec %s' % (exports, REPO, command)]

    def run(self, host, command, timeout=60.0, **environment):
        return subprocess.run(self.argv(host, command, **environment), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True, timeout=timeout)

    def firewall(self, host, rules):
        """`rules` applied with nft on `host`, as doc/network.md's block does."""
        subprocess.run(['ip', 'netns', 'exec', self.names[host], 'nft', '-f', '-'], input=rules,
                       universal_newlines=True, check=True)

    def wait_for_topic(self, host, topic, timeout=90.0, **environment):
        """Until `topic` is published, as `rostopic list` run on `host` sees it."""
        def listed():
            try:
                done = self.run(host, 'rostopic list', timeout=10.0, **environment)
            except subprocess.TimeoutExpired:
                return False
            return done.returncode == 0 and topic in done.stdout.split()
        assert wait_until(listed, timeout), 'host %s sees no %s within %.0f s' % (host, topic, timeout)

    def close(self):
        for name in self.made:
            subprocess.run(['ip', 'netns', 'delete', name], stderr=subprocess.DEVNULL)
        self.made = []


@pytest.fixture
def hosts(processes):
    if os.geteuid() != 0:
        pytest.fail('this test makes network namespaces: it needs root (CAP_NET_ADMIN), as `make test` has')
    made = Hosts()
    try:
        yield made
    finally:
        processes.stop_all()  # nothing may run in a namespace that goes
        made.close()


def poses(log):
    """`rostopic echo -p` of an Odometry: (t, x, y, yaw) rows."""
    rows, header = [], None
    with open(log, errors='replace') as text:
        lines = text.read().split('\n')[:-1]
    for line in lines:
        if line.startswith('%time,'):
            header = line[1:].split(',')
        elif header and line[:1].isdigit() and line.count(',') == len(header) - 1:
            row = dict(zip(header, line.split(',')))
            value = lambda name: float(row['field.pose.pose.' + name])  # noqa: E731
            rows.append((int(row['field.header.stamp']) * 1e-9, value('position.x'), value('position.y'),
                         yaw_of_quaternion(value('orientation.x'), value('orientation.y'),
                                       value('orientation.z'), value('orientation.w'))))
    return rows


def test_a_script_on_another_host_drives_the_robot(hosts, processes):
    master = 'http://%s:%d' % (ADDRESS['a'], free_port())
    on_a = dict(ROS_IP=ADDRESS['a'], ROS_MASTER_URI=master)
    on_b = dict(ROS_IP=ADDRESS['b'], ROS_MASTER_URI=master)
    hosts.firewall('a', readme_firewall(trusted=ADDRESS['b']))
    hosts.firewall('b', readme_firewall(trusted=ADDRESS['a']))
    sim = processes.start('sim', hosts.argv('a', 'roslaunch tb3_sim_bringup tb3_empty_world.launch', **on_a))
    hosts.wait_for_topic('b', '/base_pose_ground_truth', **on_b)
    truth = processes.start('truth', hosts.argv('b', 'rostopic echo -p /base_pose_ground_truth', **on_b))
    assert wait_until(lambda: len(poses(truth.log)) > 30 or not sim.running(), 90.0), \
        'host B reads no ground truth from host A; %s\n%s' % (sim.output(), truth.output())
    script = processes.start('script', hosts.argv('b', 'rosrun tb3_sim_nav odom_out_and_back.py', **on_b))
    exit_code = script.wait(180.0)
    assert exit_code == 0, 'odom_out_and_back.py on host B: %s' % script.describe()
    end_of_script = poses(truth.log)[-1][0]
    assert wait_until(lambda: poses(truth.log)[-1][0] > end_of_script + 1.0, 30.0)
    path = poses(truth.log)
    summary = report.summarize(report.RunResult('odom_out_and_back.py', path, [], None, None, 0, None))
    start = path[0]
    farthest = max(path, key=lambda p: math.hypot(p[1] - start[1], p[2] - start[2]))
    print('MEASURED two_hosts: end %.4f m and %.2f deg from the start, farthest %.3f m, turned %.1f deg'
          % (summary.error_distance, math.degrees(summary.error_heading),
             math.hypot(farthest[1] - start[1], farthest[2] - start[2]), math.degrees(summary.turned)))
    assert math.hypot(farthest[1] - start[1], farthest[2] - start[2]) > 0.9
    assert summary.error_distance < 0.05 and abs(math.degrees(summary.error_heading)) < 5.0
    assert abs(math.degrees(summary.turned) - 360.0) < 10.0
    with open(sim.log, errors='replace') as log:  # lockstep follows local nodes only
        assert 'lockstep: no PID' not in log.read()


def listening(hosts):
    """(address, port, process name) of every TCP port listening on host A."""
    out = subprocess.run(['ip', 'netns', 'exec', hosts.names['a'], 'ss', '-ltnpH'], stdout=subprocess.PIPE,
                         universal_newlines=True, check=True).stdout
    found = []
    for line in out.splitlines():
        fields = line.split()
        address, port = fields[3].rsplit(':', 1)
        names = re.findall(r'\("([^"]+)"', line)
        found.append((address, int(port), names[0] if names else '?'))
    return found


def from_b(hosts, code, *args):
    """Python `code` run on host B (sys.argv[1:] = args); its output lines."""
    out = subprocess.run(['ip', 'netns', 'exec', hosts.names['b'], '/usr/bin/python3', '-c', code]
                         + [str(arg) for arg in args], stdout=subprocess.PIPE, universal_newlines=True,
                         check=True).stdout
    return out.split()


def reachable_from_b(hosts, ports):
    """The ports of `ports` on A's address that accept a TCP connection from host B."""
    probe = ('import socket, sys\n'
             'for port in map(int, sys.argv[2:]):\n'
             '    try:\n'
             '        socket.create_connection((sys.argv[1], port), timeout=2).close()\n'
             '        print(port)\n'
             '    except OSError:\n'
             '        pass\n')
    return set(int(port) for port in from_b(hosts, probe, ADDRESS['a'], *ports))


def ros_api_pid(hosts, port, then=''):
    """getPid of the ROS node API at A's `port`, asked from B (then `then`, e.g. shutdown)."""
    call = ('import sys, xmlrpc.client\n'
            'api = xmlrpc.client.ServerProxy("http://%s:%d/")\n'
            'print(api.getPid("/stranger")[2])\n' % (ADDRESS['a'], port))
    if then:
        call += 'api.%s("/stranger", "a stranger on the network")\n' % then
    return int(from_b(hosts, call)[0])


def test_what_a_stranger_reaches_on_a_machine_set_up_as_the_readme_says(hosts, processes):
    local = dict(ROS_MASTER_URI='http://localhost:%d' % free_port())
    processes.start('sim', hosts.argv('a', 'roslaunch tb3_sim_bringup tb3_empty_world.launch', **local))
    hosts.wait_for_topic('a', '/odom', **local)
    assert hosts.run('a', 'rostopic echo -n 1 /odom/header', timeout=60.0, **local).returncode == 0
    ports = listening(hosts)
    assert set(LOOPBACK_ONLY) | set(ROSCPP) <= set(name for _, _, name in ports), ports
    reached = reachable_from_b(hosts, [port for _, port, _ in ports])
    print('MEASURED listening on host A: %s; reached from host B: %s'
          % (sorted(ports), sorted((port, name) for _, port, name in ports if port in reached)))
    everywhere = [(port, name) for address, port, name in ports if not address.startswith('127.')]
    assert sorted(name for _, name in everywhere) == sorted(ROSCPP), \
        'what listens on every interface changed: %s: update doc/network.md' % everywhere
    assert reached == set(port for port, _ in everywhere)
    # Each is a node's XML-RPC API: it tells its PID, and obeys shutdown, to anyone.
    for port, name in everywhere:
        pid = ros_api_pid(hosts, port, then='shutdown' if name == 'robot_state_pub' else '')
        assert pid > 0
        if name == 'robot_state_pub':
            assert wait_until(lambda: not os.path.exists('/proc/%d' % pid), 10.0), \
                'robot_state_publisher did not stop when a stranger said shutdown'
    hosts.firewall('a', readme_firewall())
    still = [(address, port, name) for address, port, name in listening(hosts)]
    assert not reachable_from_b(hosts, [port for _, port, _ in still]), \
        'doc/network.md\'s firewall leaves ports open: %s' % still
    assert hosts.run('a', 'rostopic echo -n 1 /odom/header', timeout=60.0, **local).returncode == 0, \
        'with the firewall, the machine itself no longer reads the simulator'
