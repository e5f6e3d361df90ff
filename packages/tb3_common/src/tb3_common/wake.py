"""A node's notice to the simulator's lockstep: "nothing of my own before sim time T". No ROS here.

Faster than real time, the simulator's lockstep holds every step until the
local nodes that drive a robot have reacted to its /clock tick (tb3_sim_nav's
ros/lockstep.py). Most ticks ask nothing of a node: it waits for a scan, or
sleeps until its next control cycle, and its reaction is rospy's /clock thread
taking the new time. Waiting for that reaction was the largest part of a
step's wall time in the DQN chain (2026-11-28, doc/speed.md). A node of ours
tells the lockstep, in a file of 8 bytes that it rewrites whenever its
threads fall asleep or wake, the earliest sim time (ns) at which it will act
of its own accord: ACTING (it may act at any tick: wait for it, the default),
a time, or NEVER (only data wakes it, and the steps that send it data are
waited for anyway). The simulator reads the file between two steps (pread:
a microsecond) and skips its look at the node on the ticks before that time.

A node may also declare, once, topics whose messages it only stores (its
callbacks for them act on nothing): ROBOTIS' DQN agent keeps the odometry it
reads when a scan comes. While its notice says AWAITING (only data wakes it,
and not data on those topics), the lockstep need not wait for its reaction
to a step that sent it only such messages: five of the six steps a DQN step
that send it data. The node must then not act on stored data before all of
it up to the time it acts on is in (the agent waits for the odometry of its
scan's time, which comes in the same step: one connection keeps its order).

The file is named after the process's PID and its start time (so that a
file a killed node left behind never speaks for a later process with its
PID), in shared memory, and removed when the node ends.
"""
import os
import struct
import tempfile

ACTING = -1              # sim ns: it may act at any tick
NEVER = (1 << 63) - 1    # sim ns: only data wakes it
AWAITING = NEVER - 1     # sim ns: only data wakes it, and not data on the topics it declared stored
_FORMAT = struct.Struct('<q')
DIRECTORY = '/dev/shm' if os.path.isdir('/dev/shm') else tempfile.gettempdir()


def _start_time(pid):
    """The process's start time (clock ticks after boot, /proc/PID/stat's 22nd field); None if it is gone."""
    try:
        with open('/proc/%d/stat' % pid, 'rb') as stream:
            return int(stream.read().rsplit(b')', 1)[1].split()[19])
    except (OSError, IndexError, ValueError):
        return None


def path_of(pid, directory=DIRECTORY):
    """The notice file of process `pid`; None if the process is gone."""
    started = _start_time(pid)
    return None if started is None else os.path.join(directory, 'tb3_wake_%d_%d' % (pid, started))


def combined(wakes):
    """A process's notice from its waiting threads' (a non-empty iterable): the earliest, where AWAITING
    counts as NEVER unless every thread awaits (a thread waiting for any data is woken by stored data)."""
    wakes = list(wakes)
    if all(ns == AWAITING for ns in wakes):
        return AWAITING
    return min(NEVER if ns == AWAITING else ns for ns in wakes)


class Notice(object):
    """This process's notice, written by the node (ACTING until told otherwise)."""

    def __init__(self, directory=DIRECTORY):
        self.path = path_of(os.getpid(), directory)
        self._fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o644)
        self.value = None
        self.write(ACTING)

    def write(self, ns):
        if ns != self.value and self._fd is not None:
            os.pwrite(self._fd, _FORMAT.pack(ns), 0)
            self.value = ns

    def declare_stored(self, topics):
        """The topics (resolved names) whose messages the node only stores; once, before it first
        writes AWAITING."""
        if self._fd is not None:
            os.pwrite(self._fd, '\n'.join(topics).encode('utf-8'), _FORMAT.size)

    def close(self):
        if self._fd is not None:
            fd, self._fd = self._fd, None
            os.close(fd)
            try:
                os.unlink(self.path)
            except OSError:
                pass


class Reader(object):
    """The notice of process `pid`, read by the simulator; ACTING when the process has none."""

    def __init__(self, pid, directory=DIRECTORY):
        path = path_of(pid, directory)
        try:
            self._fd = os.open(path, os.O_RDONLY) if path else None
        except OSError:  # not a node of ours (or an older one): it is waited for at every tick
            self._fd = None
        self._stored = None

    def next_wake(self):
        if self._fd is None:
            return ACTING
        data = os.pread(self._fd, _FORMAT.size, 0)
        return _FORMAT.unpack(data)[0] if len(data) == _FORMAT.size else ACTING

    def stored(self):
        """The topics the node declared stored: read once, the first time after it said AWAITING."""
        if self._stored is None:
            data = os.pread(self._fd, 1 << 16, _FORMAT.size) if self._fd is not None else b''
            self._stored = frozenset(data.decode('utf-8', 'replace').split('\n')) - {''}
        return self._stored

    def close(self):
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
