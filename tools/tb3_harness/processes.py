"""Child processes, masters and ports for the tools (demo, bench, soak) and every test tier.

A Process runs a command as a user would, in a session (and so a process
group) of its own, its output in a log file, and stops the whole group:
SIGINT as Ctrl+C would, then SIGTERM, then SIGKILL. Every master listens on
a free loopback port, never on 11311.
"""
import ctypes
import os
import signal
import socket
import subprocess
import tempfile
import time

STOP_TIMEOUT = 30.0     # wall s for a process group to end after SIGINT (roslaunch escalates after 15 s)
MASTER_TIMEOUT = 30.0   # wall s for roscore to answer
PR_SET_PDEATHSIG = 1
_T0 = time.monotonic()


class RunError(Exception):
    """Something a tool or test started did not do what it should; the message says what."""


def say(message):
    print('[%6.1fs] %s' % (time.monotonic() - _T0, message), flush=True)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def tail(filename, lines=15):
    try:
        with open(filename, errors='replace') as log:
            return ''.join(log.readlines()[-lines:]).rstrip()
    except OSError:
        return '(no log)'


def _as_from_a_terminal():
    # Runs in the child between fork and exec. SIGINT and SIGQUIT back to their
    # defaults, as a terminal's commands have them: whatever a script starts in
    # the background (`make test &`, nohup, CI runners) inherits them ignored,
    # and python then sets no KeyboardInterrupt handler (a `python -c 'while
    # True: pass'` busy core outlived each SIGINT of make test's stops by 20 s).
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGQUIT, signal.SIG_DFL)


def _as_from_a_terminal_dying_with_parent():
    _as_from_a_terminal()
    # Should the parent be killed outright (SIGKILL at rostest's time limit),
    # the kernel kills the child.
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


class Process(object):
    """`argv` in a session of its own, output to `log_dir`/`name`.log (a new
    temporary folder if None), stopped by process group. With
    `die_with_parent` the kernel kills it when the thread that started it ends."""

    def __init__(self, name, argv, log_dir=None, die_with_parent=False, **popen):
        self.name = name
        self.argv = list(argv)
        self.log = os.path.join(log_dir or tempfile.mkdtemp(prefix='tb3_'), name + '.log')
        with open(self.log, 'w') as log:
            self.popen = subprocess.Popen(self.argv, **dict(dict(
                stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                preexec_fn=_as_from_a_terminal_dying_with_parent if die_with_parent else _as_from_a_terminal),
                **popen))

    @property
    def pid(self):
        return self.popen.pid

    def running(self):
        return self.popen.poll() is None

    def wait(self, timeout):
        """Exit code, or None if still running after `timeout` wall seconds."""
        try:
            return self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def _group_alive(self):
        try:
            os.killpg(self.popen.pid, 0)
            return True
        except ProcessLookupError:
            return False
        except PermissionError:
            return True

    def signal_group(self, sig):
        try:
            os.killpg(self.popen.pid, sig)
        except ProcessLookupError:
            pass

    def _wait_group(self, timeout):
        """Wait for the leader and every other member of the group to end."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.popen.poll()
            if self.popen.returncode is not None and not self._group_alive():
                return True
            time.sleep(0.1)
        return False

    def stop(self, timeout=STOP_TIMEOUT):
        """SIGINT to the group (as Ctrl+C would), then SIGTERM, then SIGKILL; the exit code."""
        previous = None
        for sig, wait in ((signal.SIGINT, timeout), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
            if self.popen.poll() is not None and not self._group_alive():
                break
            if previous is not None:
                say('%s did not stop after %s: sending %s' % (self.name, previous, sig.name))
            self.signal_group(sig)
            self.signal_group(signal.SIGCONT)  # a stopped (Ctrl+Z) process acts on it only when continued
            if self._wait_group(wait):
                break
            previous = sig.name
        return self.popen.poll()

    def output(self, last=3000):
        """The end of what it printed: its `last` characters, all of it if None (what a test counts or
        looks for: a node's start can print more than a tail holds, as move_base's parameters do)."""
        try:
            with open(self.log, 'rb') as log:
                text = log.read().decode('utf-8', 'replace')
        except OSError:
            return ''
        return text if last is None else text[-last:]

    def describe(self):
        return '%s (exit %r), output:\n%s' % (' '.join(self.argv), self.popen.poll(), self.output())


def master_pid(uri):
    """The pid of the master at `uri`, or None if nothing answers there."""
    import rosgraph
    try:
        return rosgraph.Master('/tb3_harness_probe', master_uri=uri).getPid()
    except Exception:  # refused, reset, timed out: not there
        return None


def start_master(log_dir, port=None, name='roscore'):
    """roscore on a free loopback port (or `port`), answering, with this process's
    ROS environment pointed at it and /use_sim_time set, as every node of the
    tutorial's world has it."""
    import rosgraph
    port = port or free_port()
    uri = 'http://localhost:%d' % port
    os.environ['ROS_MASTER_URI'] = uri
    os.environ['ROS_HOSTNAME'] = 'localhost'
    os.environ.pop('ROS_IP', None)
    say('starting roscore -p %d (ROS_MASTER_URI=%s)' % (port, uri))
    master = Process(name, ['roscore', '-p', str(port)], log_dir)
    deadline = time.monotonic() + MASTER_TIMEOUT
    while master_pid(uri) is None:
        if not master.running():
            raise RunError('roscore exited (code %s); %s ends with:\n%s'
                           % (master.popen.returncode, master.log, tail(master.log)))
        if time.monotonic() > deadline:
            master.stop()
            raise RunError('roscore on port %d did not answer within %.0f s' % (port, MASTER_TIMEOUT))
        time.sleep(0.2)
    rosgraph.Master('/tb3_harness_probe', master_uri=uri).setParam('/use_sim_time', True)
    return master


def wait_until(predicate, timeout, what, poll=0.01, watch=()):
    """Poll `predicate` until true; RunError naming `what` after `timeout` wall
    seconds, or at once if a Process of `watch` exits."""
    deadline = time.monotonic() + timeout
    while not predicate():
        for process in watch:
            if not process.running():
                raise RunError('%s exited (code %s) before %s; %s ends with:\n%s'
                               % (process.name, process.popen.returncode, what, process.log, tail(process.log)))
        if time.monotonic() > deadline:
            raise RunError('no %s within %.0f s' % (what, timeout))
        time.sleep(poll)
