"""Has a process finished reacting? Read off Linux's /proc, without ROS.

Faster than real time, the simulator holds each step until the nodes that
drive the robot have done what the last tick asked of them (see
ros/lockstep.py). A process has done so when every thread of it sleeps and none ran
between two looks: Linux marks a thread runnable the moment data, a lock or a
signal wakes it, so a process whose threads all sleep, none having run
since a look a moment before, waits for something new from outside.
"""
import os
import platform
import time

#: Thread states of /proc/.../stat that will not act before something new
#: arrives: asleep, stopped (Ctrl+Z), traced, dead. 'D' (disk) and 'R' will.
WAITING_STATES = frozenset(b'STtZXI')

#: Syscalls, by number per machine, in which a thread waits for data on a
#: socket: poll/ppoll (python's sockets with a timeout), recvfrom and read.
_IO_WAIT_SYSCALLS = {'x86_64': frozenset((7, 271, 45, 0)),
                     'aarch64': frozenset((73, 207, 63))}
IO_WAIT_SYSCALLS = _IO_WAIT_SYSCALLS.get(platform.machine())


class ProcessGone(Exception):
    """The process ended (or was never there)."""


def _read(fd, size=512):
    return os.pread(fd, size, 0)


class ProcessWatch(object):
    """Watches the threads of one process; keeps their /proc files open, as
    reading an open file costs a fifth of opening it anew."""

    def __init__(self, pid, proc='/proc', exclude=()):
        """`exclude`: ids of threads not to look at (a process watching its own other threads)."""
        self.pid = pid
        self._task_dir = os.path.join(proc, str(pid), 'task')
        if not os.path.isdir(self._task_dir):
            raise ProcessGone(pid)
        self._exclude = set(str(tid) for tid in exclude)
        self._files = {}  # tid -> (stat fd, schedstat fd or None)
        self._busy = None  # the thread last seen running or runnable
        self._counted = os.path.exists(os.path.join(self._task_dir, str(pid), 'schedstat'))
        self._last = None  # the run counters when last seen waiting
        self._quiet = None  # the run counters when last seen quiet (quiet())
        #: After waiting(): whether it ran since it was last seen waiting (True when it is not waiting).
        self.ran = True

    def close(self):
        for tid in list(self._files):
            self._forget(tid)

    def _forget(self, tid):
        for fd in self._files.pop(tid):
            if fd is not None:
                os.close(fd)

    def _open(self, tid):
        stat = os.open(os.path.join(self._task_dir, tid, 'stat'), os.O_RDONLY)
        try:
            schedstat = os.open(os.path.join(self._task_dir, tid, 'schedstat'), os.O_RDONLY)
        except OSError:  # a kernel without scheduler statistics: states only
            schedstat = None
        return stat, schedstat

    def _threads(self):
        try:
            tids = [tid for tid in os.listdir(self._task_dir) if tid not in self._exclude]
        except OSError:
            raise ProcessGone(self.pid)
        for tid in set(self._files) - set(tids):
            self._forget(tid)
        for tid in tids:
            if tid not in self._files:
                try:
                    self._files[tid] = self._open(tid)
                except OSError:  # the thread ended between listing and opening
                    pass
        return list(self._files.items())

    def _sleeps(self, stat):
        line = _read(stat)
        # The state follows the command name, which may hold spaces and ')'.
        return line[line.rindex(b')') + 2] in WAITING_STATES

    def _look(self, threads, states):
        """Each thread's run counters; None if `states` and a thread runs or is runnable."""
        counters = []
        for tid, (stat, schedstat) in threads:
            try:
                if states and not self._sleeps(stat):
                    self._busy = tid
                    return None
                counters.append((tid, _read(schedstat) if schedstat is not None else b''))
            except (OSError, ValueError, IndexError):  # the thread just ended
                continue
        return counters

    def snapshot(self):
        """Each thread's run counters now, or None when a thread runs or is runnable."""
        return self._look(self._threads(), states=True)

    def waiting(self):
        """True when every thread sleeps and none ran between two looks.

        The first look needs only the run counters: a thread asleep at the
        second that did not run in between was asleep all along (it can stop
        running or being runnable only by running). The thread last seen busy
        is asked first, as the likeliest to be busy still.
        """
        threads = self._threads()  # one listing: a thread started in between means one ran
        busy = self._files.get(self._busy)
        self.ran = True
        try:
            if busy is not None and not self._sleeps(busy[0]):
                return False
        except (OSError, ValueError, IndexError):
            pass
        first = self._look(threads, states=not self._counted)
        if first is None or self._look(threads, states=True) != first:
            return False
        self.ran, self._last = first != self._last, first
        return True

    def quiet(self, pause, sleep=time.sleep):
        """True when every thread sleeps at two looks `pause` s apart and none ran in between: for a
        process looking at its own other threads, which need the interpreter's lock to run and get it
        in the pause."""
        threads = self._threads()
        first = self._look(threads, states=True)
        if first is None:
            return False
        if self._counted and first == self._quiet:
            # None ran since they were last seen quiet: a thread that received since would have run (a
            # thread woken but not yet run is runnable, not asleep). Most steps end here: the pause cost
            # a step 0.1 ms and more (a sleep's wake-up on a loaded machine).
            return True
        sleep(pause)
        second = self._look(self._threads(), states=True)
        if second != first:
            return False
        self._quiet = second
        return True


class InputWaits(object):
    """Threads of this process that receive from sockets (rospy has one per
    connection), with their /proc syscall files kept open: all_waiting() says
    when each is blocked waiting for socket data, having handled all it read."""

    def __init__(self, proc='/proc/self'):
        self._task_dir = os.path.join(proc, 'task')
        self._files = {}  # tid -> fd of its syscall file

    def add(self, tid):
        """Follow thread `tid` (a callback calls this from its own thread)."""
        if tid not in self._files and IO_WAIT_SYSCALLS is not None:
            try:
                self._files[tid] = os.open(os.path.join(self._task_dir, str(tid), 'syscall'), os.O_RDONLY)
            except OSError:  # it ended already
                pass

    def clear(self):
        files, self._files = self._files, {}
        for fd in files.values():
            os.close(fd)

    def all_waiting(self):
        """On an unknown machine the syscall numbers are unknown: True, and
        lockstep relies on the looks at the other nodes alone."""
        return all(self._waits(fd) for fd in tuple(self._files.values()))

    @staticmethod
    def _waits(fd):
        try:
            fields = _read(fd, 128).split()
        except OSError:  # the thread ended: its connection closed
            return True
        return bool(fields) and fields[0].isdigit() and int(fields[0]) in IO_WAIT_SYSCALLS
