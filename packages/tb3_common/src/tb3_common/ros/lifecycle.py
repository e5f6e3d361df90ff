"""How every node of ours ends: at once, whatever moment the request lands.

A node is asked to end by a signal (Ctrl+C in its terminal or roslaunch's
SIGINT, SIGTERM, SIGHUP), by `rosnode kill` or the master ("new node
registered with same name"), both through rospy's XML-RPC thread, or by the
death of the roslaunch that started it (SIGKILL), which tells it nothing.

rospy's own signal handler runs rospy's whole shutdown (hooks, every
connection closed) inside the handler: in the main thread, between two
bytecodes of whatever that thread was doing. When that was a write holding a
lock which closing a connection takes too, the handler waits for the code it
interrupted: forever (issue 18: the simulator's publish path). So here a
signal only sets a flag. The node's loop sees it, stops publishing, and
only then shuts rospy down, from its own thread and outside any handler. A
shutdown that rospy starts in another thread first asks the loop to stop and
waits (briefly) until it has. A thread watches the parent: a node started by
roslaunch or rostest ends when they are gone instead of living on as an orphan.
"""
import atexit
import contextlib
import faulthandler
import os
import signal
import sys
import threading
import time

import rospy

from .. import wake

PARENT_POLL = 0.5  # wall s between looks at the parent process
LOOP_STOP_WAIT = 1.0  # wall s a shutdown from another thread waits for the node's loop to stop
SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
LAUNCHERS = ('roslaunch', 'rostest')  # parents whose death ends the node
# wall s after an end was asked for: a node still running then prints every
# thread's stack to stderr (faulthandler: it works even if no python thread
# can run), so that an end that hangs says where (roslaunch escalates at 15 s)
STACKS_AFTER = 5.0


def _command_line(pid):
    try:
        with open('/proc/%d/cmdline' % pid, 'rb') as stream:
            return [part.decode('utf-8', 'replace') for part in stream.read().split(b'\0') if part]
    except OSError:
        return []


def started_by_launcher(pid):
    """True if process `pid` is a roslaunch or rostest (a python running either)."""
    return any(os.path.basename(part) in LAUNCHERS for part in _command_line(pid)[:2])


class Life(object):
    """A node's request to end (a flag, its reason) and the end itself.

    `stopping` is true once an end was asked for, in any of the ways above.
    A node with a loop of its own runs `while not life.stopping:`, waits
    with `sleep` (wall time) or `sleep_sim` (ROS time), never rospy.sleep or
    rospy.Rate, and then calls `finish()`; a node driven by callbacks calls
    `spin()`.

    A Life made by init_node also keeps the node's wake.Notice: while every
    thread that acts of its own accord (those that called `sleep_sim`, or
    entered `waiting_for_data` or `spin`) waits, the simulator's lockstep
    need not wait for the node's reaction to /clock ticks before the
    earliest of their wake-ups.
    """

    def __init__(self, notice=None):
        self._stop = threading.Event()
        self._loop_done = threading.Event()
        self.reason = None
        self._notice = notice
        self._wakes = {}  # thread id -> sim ns before which it does nothing of its own accord (wake.ACTING: now)
        self._wakes_lock = threading.Lock()
        self._stores = False  # it declared topics it only stores
        self._alarm = None  # a SimAlarm once follow_clock() made one

    def request_stop(self, reason):
        """Safe in a signal handler: sets the flag (and arms the stacks' print, STACKS_AFTER)."""
        if not self._stop.is_set():
            self.reason = reason
            self._stop.set()
            faulthandler.dump_traceback_later(STACKS_AFTER)

    @property
    def stopping(self):
        return self._stop.is_set() or rospy.core.is_shutdown_requested()

    def sleep(self, seconds):
        """Waits `seconds` of wall time, less if an end is asked for; False then."""
        return not self._stop.wait(seconds) and not rospy.core.is_shutdown_requested()

    def sleep_sim(self, seconds):
        """Waits `seconds` of ROS time (sim time under /clock), less if an end is asked for or time
        jumps back; False if an end was asked for. (rospy.sleep and rospy.Rate wait for a clock that
        stopped, a simulator gone, until rospy itself shuts down: a signal here only sets the flag.)
        After follow_clock() the thread wakes at its end, not at every /clock tick."""
        alarm = self._alarm
        condition = rospy.rostime.get_rostime_cond() if alarm is None else alarm.condition
        start = rospy.get_rostime()
        end = start + rospy.Duration(seconds)
        end_ns, thread = end.to_nsec(), threading.get_ident()
        with self._waking_at(end_ns):
            try:
                if alarm is not None:
                    with condition:
                        alarm.ends[thread] = end_ns
                while not self.stopping:
                    # The time is read and the wait begun under the lock the wake-up takes after the
                    # clock moved: no tick slips in between.
                    with condition:
                        now = rospy.get_rostime()
                        if now >= end or now < start:
                            return True
                        condition.wait(0.1)
            finally:
                if alarm is not None:
                    with condition:
                        alarm.ends.pop(thread, None)
        return False

    def follow_clock(self):
        """Wake the threads in sleep_sim at their ends only (SimAlarm), from rospy's /clock subscription."""
        from rosgraph_msgs.msg import Clock
        self._alarm = SimAlarm()
        rospy.Subscriber('/clock', Clock, self._alarm.on_clock)

    def waiting_for_data(self, except_stored=False):
        """A context in which the calling thread waits for messages only (no timed wake-up); with
        `except_stored`, not for those of the topics declared with stores()."""
        return self._waking_at(wake.AWAITING if except_stored and self._stores else wake.NEVER)

    def stores(self, topics):
        """Declares, once, that this node's callbacks for `topics` (resolved names) only store what it reads
        when other data wakes it (tb3_common.wake): the simulator's lockstep then need not wait for its
        reaction to them while it waits in waiting_for_data(except_stored=True)."""
        with self._wakes_lock:
            if self._notice is not None:
                self._notice.declare_stored(topics)
            self._stores = True

    @contextlib.contextmanager
    def _waking_at(self, ns):
        """The calling thread does nothing of its own accord before sim time `ns` (an int, as sleep_sim's
        `now >= end` compares) until the context ends; from then on it may act at any tick."""
        if self._notice is None:
            yield
            return
        thread = threading.get_ident()
        self._set_wake(thread, ns)
        try:
            yield
        finally:
            self._set_wake(thread, wake.ACTING)

    def close_notice(self):
        """The notice file removed (the node ends; also at the process's exit)."""
        with self._wakes_lock:
            notice, self._notice = self._notice, None
        if notice is not None:
            notice.close()

    def _set_wake(self, thread, ns):
        with self._wakes_lock:
            self._wakes[thread] = ns
            if len(self._wakes) > 1:  # a thread that ended said ACTING last: it must not say so for ever
                alive = set(running.ident for running in threading.enumerate())
                for ended in [other for other in self._wakes if other not in alive]:
                    del self._wakes[ended]
            if self._notice is not None:
                self._notice.write(wake.combined(self._wakes.values()))

    def callback(self, function):
        """`function` as a rospy callback that ends quietly: it does not run once an end was asked for,
        and a publish it makes while rospy closes the topics under it (rospy.ROSException "publish()
        to a closed topic": amcl's tf in a scan that came as Ctrl+C did) ends it without a traceback."""
        def run(*args):
            if self.stopping:
                return None
            try:
                return function(*args)
            except rospy.ROSException:
                if not self.stopping:
                    raise
                return None
        return run

    def spin(self):
        """Until an end is asked for (callbacks run in rospy's threads meanwhile); then finish()."""
        with self.waiting_for_data():
            while self.sleep(0.1):
                pass
        self.finish()

    def finish(self):
        """The node's loop has stopped: shut rospy down from here (it closes every connection)."""
        self._loop_done.set()
        self.close_notice()
        rospy.signal_shutdown(self.reason or 'asked to end')

    # --- the ways an end comes --------------------------------------------------
    def handle_signals(self):
        """SIGINT, SIGTERM and SIGHUP only set the flag from now on (call from the main thread)."""
        for number in SIGNALS:
            signal.signal(number, self._on_signal)

    def _on_signal(self, number, _frame):
        self.request_stop('%s received' % signal.Signals(number).name)

    def _on_rospy_shutdown(self):
        """rospy's shutdown started elsewhere (rosnode kill, the master, finish()):
        let the loop stop publishing before rospy closes the connections."""
        self.request_stop(self.reason or 'rospy shut down')
        if threading.current_thread() is not threading.main_thread():
            self._loop_done.wait(LOOP_STOP_WAIT)

    def _watch_parent(self, parent):
        while not self._stop.is_set():
            if os.getppid() != parent:
                self.request_stop('the roslaunch that started this node (pid %d) is gone' % parent)
                rospy.logwarn('%s: the roslaunch that started it (pid %d) is gone: shutting down',
                              rospy.get_name(), parent)
                return
            time.sleep(PARENT_POLL)


class SimAlarm(object):
    """Wakes the threads that sleep in sim time when the earliest of their ends has come or the time
    went back, rather than at every /clock tick.

    rospy wakes every thread waiting for ROS time at each /clock message (100 Hz of sim time from the
    simulator): a loop at 10 or 20 Hz finds nothing to do nine times in ten, each time a thread
    switch and the interpreter's lock taken, which every other thread of the node then waits for (the
    SLAM's tf loop, doc/speed.md). on_clock is a second callback on rospy's own /clock subscription:
    it runs after rospy has taken the new time."""

    def __init__(self):
        self.condition = threading.Condition()
        self.ends = {}  # thread id -> sim ns it sleeps until (changed under `condition`)
        self._last = None  # the last tick's sim ns

    def on_clock(self, message):
        ns = message.clock.to_nsec()
        with self.condition:
            if self.ends and (ns >= min(self.ends.values()) or (self._last is not None and ns < self._last)):
                self.condition.notify_all()
            self._last = ns


def init_node(name, watch_clock=True, **keywords):
    """rospy.init_node(name, ...) with the ends above wired: the node's Life.

    Call from the main thread, as rospy.init_node; handlers installed before it
    registers, so that no signal finds rospy's own. `watch_clock`: the node
    follows /clock (warn_when_left_on_wall_time, Life.follow_clock); the
    simulator, which publishes it, says False."""
    try:
        notice = wake.Notice()
    except OSError as error:  # no shared memory: the simulator waits for this node at every tick
        notice = None
        sys.stderr.write('%s: no lockstep notice (%s): a simulator waits for this node at every tick\n'
                         % (name, error))
    life = Life(notice)
    atexit.register(life.close_notice)
    life.handle_signals()
    rospy.init_node(name, disable_signals=True, **keywords)
    rospy.on_shutdown(life._on_rospy_shutdown)
    parent = os.getppid()
    if started_by_launcher(parent):
        threading.Thread(target=life._watch_parent, args=(parent,), name='parent_watch', daemon=True).start()
    if watch_clock:
        warn_when_left_on_wall_time()
        if not rospy.rostime.is_wallclock():
            life.follow_clock()
    return life


def warn_when_left_on_wall_time():
    """rospy reads /use_sim_time once, in init_node: a node started before a simulator's launch set it
    keeps wall time for good, takes every transform stamped in sim time for 1.8e9 s old and, as
    move_base does then, may hold still without saying why. On wall time, the first /clock message
    (a simulator runs) makes the node say so once, with the remedy; then it stops listening."""
    if not rospy.rostime.is_wallclock():
        return
    from rosgraph_msgs.msg import Clock
    heard = threading.Event()

    def on_clock(_message):
        if heard.is_set():
            return
        heard.set()
        try:
            late = bool(rospy.get_param('/use_sim_time', False))
        except Exception:  # the master is away: the remedy is the same
            late = True
        why = ('started before /use_sim_time was set (a simulator\'s launch sets it)' if late else
               'runs on wall time: /use_sim_time is not true')
        rospy.logwarn('%s %s, while /clock gives sim time: every transform and message stamped in sim time looks '
                      'about 1.8e9 s old to it. Start it again now that the simulator runs (or set use_sim_time '
                      'to true in its launch file)', rospy.get_name(), why)
    subscriber = rospy.Subscriber('/clock', Clock, on_clock, queue_size=1)
    # Stop listening once heard (a thread, not the callback: it may run before `subscriber` is bound).
    threading.Thread(target=lambda: heard.wait() and subscriber.unregister(), name='wall_time_check',
                     daemon=True).start()
