"""Shared helpers of the system tests: tests that cannot run under rostest
because they start and stop ROS masters themselves (pytest, inside
`source setup.bash`: `python3 -m pytest -q test/system`).

Every process is started by tb3_harness's Process: a process group of its
own, output to a log file, stopped by group (SIGINT, then SIGTERM, then
SIGKILL) in the fixtures' finalizers (conftest.py), also when a test fails.
Every master listens on a free loopback port, never on 11311.
"""
import math
import os
import signal
import subprocess
import threading
import time

from tb3_harness import processes as harness

MASTER_TIMEOUT = 30.0   # wall s for a roscore to answer
#: The three robots of multi_tb3.launch and ROBOTIS' multi_turtlebot3.launch in turtlebot3_house, at their spawns.
ROBOTS = {'tb3_0': (-7.0, -1.0), 'tb3_1': (7.0, -1.0), 'tb3_2': (0.5, 3.0)}


def master_uri(port):
    return 'http://localhost:%d' % port


def master_pid(port):
    """The master's pid, or None if nothing answers on `port`."""
    return harness.master_pid(master_uri(port))


def alive(pid):
    """True while process `pid` runs (a zombie, ended but not yet reaped, does not)."""
    try:
        with open('/proc/%d/stat' % pid) as stream:
            return stream.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except OSError:
        return False


def registered(master, node):
    """True once `node` is registered with `master` (a rosgraph.Master)."""
    try:
        master.lookupNode(node)
        return True
    except Exception:  # rosgraph.MasterError: not (yet) registered
        return False


def wait_until(predicate, timeout, poll=0.2):
    """Poll until `predicate()` is true or `timeout` wall s pass; its last value."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value or time.monotonic() >= deadline:
            return value
        time.sleep(poll)


class Processes(object):
    """Processes of one test, all stopped by process group at its end."""

    def __init__(self, log_dir):
        self.log_dir = str(log_dir)
        self.started = []
        self.servers = []   # what the others need until they have ended: masters, X servers

    def add(self, process, server=False):
        """A process started elsewhere (Xvfb, a pty's), stopped with the others."""
        self.started.append(process)
        if server:
            self.servers.append(process)
        return process

    def start(self, name, argv, **popen):
        process = harness.Process(name, list(argv), self.log_dir, **popen)
        self.started.append(process)
        return process

    def start_master(self, name, port):
        master = self.start(name, ['roscore', '-p', str(port)])
        self.servers.append(master)
        if not wait_until(lambda: master_pid(port) is not None or not master.running(), MASTER_TIMEOUT):
            raise AssertionError('roscore -p %d did not answer within %.0f s; %s:\n%s'
                                 % (port, MASTER_TIMEOUT, master.log, harness.tail(master.log)))
        if not master.running():
            raise AssertionError('roscore -p %d exited; %s:\n%s' % (port, master.log, harness.tail(master.log)))
        return master

    def stop_all(self):
        """Every process at once (SIGINT to each group, each escalated on its own),
        then the servers: one after another, a test's readers and nodes each took
        1-3 wall s to end on a busy machine (measured), and a node whose master is
        gone waits for it on its way out."""
        servers = [process for process in self.started if process in self.servers]
        others = [process for process in self.started if process not in self.servers]
        for group in (others, servers):
            stoppers = [threading.Thread(target=process.stop, kwargs={'timeout': 20.0}) for process in group]
            for stopper in stoppers:
                stopper.start()
            for stopper in stoppers:
                stopper.join()


def run(argv, timeout):
    """A short command (rostopic, rosparam...): CompletedProcess with text output, or
    a CompletedProcess with returncode None if it did not end within `timeout` s."""
    process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True, start_new_session=True)
    try:
        output, _ = process.communicate(timeout=timeout)
        return subprocess.CompletedProcess(argv, process.returncode, output)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        return subprocess.CompletedProcess(argv, None, output)


class Echo(object):
    """`rostopic echo -p TOPIC` to a log file, read back as rows of CSV. One
    reader for a whole test, through restarts of the publisher: a `rostopic
    echo -n 1` for each look costs 1.5-2.5 wall s of python start-up on a busy
    machine (measured), this one start-up."""

    def __init__(self, processes, topic):
        self.process = processes.start('echo' + topic.replace('/', '_'), ['rostopic', 'echo', '-p', topic],
                                       env=dict(os.environ, PYTHONUNBUFFERED='1'))
        self._header, self._rows, self._offset = None, [], 0

    def rows(self):
        """Every complete line so far as a dict of column name -> text (read on from where the last call ended)."""
        with open(self.process.log, 'rb') as log:
            log.seek(self._offset)
            text = log.read()
        whole = text[:text.rfind(b'\n') + 1]   # the last line may be half written
        self._offset += len(whole)
        for line in whole.decode('utf-8', 'replace').split('\n')[:-1]:
            if line.startswith('%time,'):
                self._header = line[1:].split(',')
            elif self._header and line[:1].isdigit() and line.count(',') == len(self._header) - 1:
                self._rows.append(dict(zip(self._header, line.split(','))))
        return list(self._rows)

    def count(self):
        """How many rows have come: a mark for `after`."""
        return len(self.rows())

    def after(self, mark, timeout=60.0, where=lambda row: True):
        """The first row after `mark` rows for which where(row) is true, once it
        has come (within `timeout` wall s), or None."""
        def found():
            return next((row for row in self.rows()[mark:] if where(row)), None)
        return wait_until(found, timeout, 0.02) or None


def poses(echo, rows=None):
    """Odometry rows (all of `echo`'s, or `rows`) as dicts: t (sim s), x, y, yaw, speed (m/s), turn (rad/s)."""
    result = []
    for row in echo.rows() if rows is None else rows:
        f = {name: float(value) for name, value in row.items() if name.startswith('field.') and
             ('position' in name or 'orientation' in name or 'twist.twist' in name)}
        qx, qy, qz, qw = (f['field.pose.pose.orientation.' + axis] for axis in 'xyzw')
        result.append({
            't': int(row['field.header.stamp']) * 1e-9,
            'x': f['field.pose.pose.position.x'],
            'y': f['field.pose.pose.position.y'],
            'yaw': math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)),
            'speed': math.hypot(f['field.twist.twist.linear.x'], f['field.twist.twist.linear.y']),
            'turn': f['field.twist.twist.angular.z'],
        })
    return result
