"""Shared helpers of the system tests: tests that cannot run under rostest
because they start and stop ROS masters themselves (pytest, inside
`source setup.bash`: `python3 -m pytest -q test/system`).

Every process is started by tb3_harness's Process: a process group of its
own, output to a log file, stopped by group (SIGINT, then SIGTERM, then
SIGKILL) in the fixtures' finalizers (conftest.py), also when a test fails.
Every master listens on a free loopback port, never on 11311.
"""
import os
import signal
import subprocess
import time

from tb3_harness import processes as harness

MASTER_TIMEOUT = 30.0   # wall s for a roscore to answer


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

    def start(self, name, argv, **popen):
        process = harness.Process(name, list(argv), self.log_dir, **popen)
        self.started.append(process)
        return process

    def start_master(self, name, port):
        master = self.start(name, ['roscore', '-p', str(port)])
        if not wait_until(lambda: master_pid(port) is not None or not master.running(), MASTER_TIMEOUT):
            raise AssertionError('roscore -p %d did not answer within %.0f s; %s:\n%s'
                                 % (port, MASTER_TIMEOUT, master.log, harness.tail(master.log)))
        if not master.running():
            raise AssertionError('roscore -p %d exited; %s:\n%s' % (port, master.log, harness.tail(master.log)))
        return master

    def stop_all(self):
        for process in reversed(self.started):
            process.stop(timeout=20.0)


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
