"""Processes a tool or a test tier started and left running: found, named, ended.

A run (make demo, bench, soak, each part of make test) marks its
environment with a tag of its own (TB3_RUN=<pid>.<time>); every process it
starts inherits it, down to the nodes roslaunch and rostest start. When the run ends, any process
still carrying the tag, other than the checker and its ancestors, was left
behind: a bug (a node that survived Ctrl+C, an orphan whose roslaunch died),
and the run fails after ending it.

    python3 -m tb3_harness.leftovers check   # the tag from the environment; exit 1 if any was left
"""
import os
import signal
import sys
import time

from .processes import say

TAG = 'TB3_RUN'
GRACE = 5.0   # wall s a process has to end by itself once the run is over


PF_KTHREAD = 0x00200000
SETTLE = 1.0   # wall s a process caught in the middle of exec has to show its environment


def _read(pid, name):
    try:
        with open('/proc/%d/%s' % (pid, name), 'rb') as stream:
            return stream.read()
    except OSError:  # gone, or not ours to read
        return b''


def _in_exec(pid):
    """True for a process between exec's new memory and its arguments: for that
    moment (after the parent's fork returned) it shows neither environment nor
    command line. Kernel threads and zombies show neither for good."""
    if _read(pid, 'environ') or _read(pid, 'cmdline'):
        return False
    fields = _read(pid, 'stat').rsplit(b')', 1)[-1].split()
    return len(fields) > 6 and fields[0] != b'Z' and not int(fields[6]) & PF_KTHREAD


def _environ(pid):
    deadline = time.monotonic() + SETTLE
    while _in_exec(pid) and time.monotonic() < deadline:
        time.sleep(0.01)
    return _read(pid, 'environ').split(b'\0')


def _command_line(pid):
    return _read(pid, 'cmdline').replace(b'\0', b' ').decode('utf-8', 'replace').strip() or '?'


def _ancestors():
    pids, pid = {os.getpid()}, os.getpid()
    while pid > 1:
        try:
            with open('/proc/%d/stat' % pid) as stream:
                pid = int(stream.read().rsplit(')', 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            break
        pids.add(pid)
    return pids


def tagged(value):
    """[(pid, command line)] of the processes carrying TB3_RUN=`value`, but this one and its ancestors."""
    marker = ('%s=%s' % (TAG, value)).encode()
    mine = _ancestors()
    found = []
    for entry in os.listdir('/proc'):
        if entry.isdigit() and int(entry) not in mine and marker in _environ(int(entry)):
            found.append((int(entry), _command_line(int(entry))))
    return found


def check(value, what, grace=GRACE):
    """The processes of run `value` still there after `grace` s, each named and then killed."""
    deadline = time.monotonic() + grace
    left = tagged(value)
    while left and time.monotonic() < deadline:
        time.sleep(0.2)
        left = tagged(value)
    for pid, command in left:
        say('LEFT RUNNING after %s: pid %d: %s' % (what, pid, command))
        try:
            os.kill(pid, signal.SIGCONT)
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return left


class Guard(object):
    """`with Guard('make demo') as guard:` tags what the block starts; on
    leaving, `guard.left` lists what it left running (each named and ended)."""

    def __init__(self, what, grace=GRACE):
        self.what, self.grace = what, grace
        self.value = '%d.%d' % (os.getpid(), time.monotonic_ns())
        self.left = []

    def __enter__(self):
        self._before = os.environ.get(TAG)
        os.environ[TAG] = self.value
        return self

    def __exit__(self, kind, error, trace):
        if self._before is None:
            os.environ.pop(TAG, None)
        else:
            os.environ[TAG] = self._before
        self.left = check(self.value, self.what, self.grace)
        return False


def run(what, main, grace=GRACE):
    """main()'s exit status, 1 if it left a process running."""
    with Guard(what, grace) as guard:
        status = main()
    if guard.left:
        say('%s FAILED: it left %d process(es) running (named above, now ended)' % (what, len(guard.left)))
        return 1
    return status


def main(argv):
    if argv[1:2] != ['check'] or TAG not in os.environ:
        sys.stderr.write('usage: %s=<tag> python3 -m tb3_harness.leftovers check [WHAT]\n' % TAG)
        return 2
    left = check(os.environ[TAG], ' '.join(argv[2:]) or 'the run')
    return 1 if left else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
