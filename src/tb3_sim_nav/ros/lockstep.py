"""Lockstep: each step waits until the local nodes that drive the robots or place them on a map have reacted.

See Lockstep's docstring; quiescence.py reads the processes' state off /proc.
"""
import math
import os
import threading
import time
import xmlrpc.client

import rosgraph
import rospy

from tb3_common import wake

from ..quiescence import InputWaits, ProcessGone, ProcessWatch
from . import rospy_internals

PID_RETRY = 1.0      # wall s between asks of a local node that did not tell its PID
LOCKSTEP_POLL = 0.0001  # wall s between looks at a node the step waits for, at least ...
LOCKSTEP_POLL_SHARE = 0.05  # ... and this share of a step's wall time when paced


class _TimeoutTransport(xmlrpc.client.Transport):
    def make_connection(self, host):
        connection = super(_TimeoutTransport, self).make_connection(host)
        connection.timeout = 1.0  # s: a node that hangs must not hang the simulator
        return connection


def _remote(connection):
    """True if the node at the other end of a connection runs on another machine (or it closed)."""
    try:
        sock = connection.socket
        return sock.getpeername()[0] != sock.getsockname()[0]
    except (AttributeError, OSError):  # closed meanwhile: nothing to wait for
        return True


def local_pid(connection, uri=None):
    """PID of the node at the other end of a connection, asked over its XML-RPC
    API (as rosnode does) at `uri` (a subscriber connection's endpoint_id if
    None); None if it runs on another machine. Raises LookupError when a node
    on this machine does not tell."""
    if _remote(connection):
        return None
    try:
        proxy = xmlrpc.client.ServerProxy(uri or connection.endpoint_id, transport=_TimeoutTransport())
        code, message, pid = proxy.getPid(rospy.get_name())
    except Exception as error:  # refused, timed out, not a ROS node
        raise LookupError(str(error) or type(error).__name__)
    if code != 1:
        raise LookupError(message)
    return pid


class Lockstep(object):
    """Holds each step until the local nodes that publish cmd_vel, and those that
    read a robot's scan and publish tf (a SLAM or a localizer: gmapping, amcl,
    ours), have reacted to it.

    Otherwise a node's reaction to a tick costs it wall time in which the
    simulator runs on: its commands land late in sim time, and a rospy.Rate
    loop that falls two periods behind drops ticks, so a script's path would
    depend on the factor and the machine's load (even at real time, a python
    script's first ticks, slowed by its connections, can be dropped). A node
    that has not reacted within `timeout` (it computes, or never sleeps) is not
    waited for until it is seen waiting again: the simulator never stalls on it.
    """

    def __init__(self, timeout, poll, warnings, warn_period, prompt=None):
        """`prompt`: a set this keeps to the names of the nodes it waits for (Publishers.prompt)."""
        self._subscribers = []  # the cmd_vel subscribers of every robot
        self._readers = []  # the scan publishers of every robot
        self._timeout = timeout
        self._poll = poll
        self._warnings = warnings
        self._warn_period = warn_period
        self._connections = None  # the lists of cmd_vel connections last followed
        self._connecting = False  # some of them still shaking hands
        self._ask_again_at = math.inf  # when to ask a local node that did not tell its PID
        self._watches = {}   # publisher node name -> ProcessWatch of its process
        self._wakes = {}     # publisher node name -> wake.Reader of its notice
        self._clock_ns = None  # the /clock tick the last wait followed
        self._behind = set()  # node names not waited for until seen waiting
        self.receive_threads = InputWaits()  # the threads that ran our cmd_vel callbacks
        self._ran = set()  # nodes seen running since this process's other threads were last seen asleep
        self._own = None  # ProcessWatch of this process's threads but the step loop's
        self._prompt = set() if prompt is None else prompt

    def follow(self, subscriber):
        """Wait also for the publishers of `subscriber` (a robot's cmd_vel)."""
        self._subscribers.append(subscriber)
        self._connections = None

    def forget(self, subscriber):
        self._subscribers.remove(subscriber)
        self._connections = None

    def follow_readers(self, publisher):
        """Wait also for the local subscribers of `publisher` (a robot's scan) that publish tf."""
        self._readers.append(publisher)
        self._connections = None

    def forget_readers(self, publisher):
        self._readers.remove(publisher)
        self._connections = None

    @staticmethod
    def _tf_publishers():
        """Caller ids of the nodes that publish /tf, and the master, to look up a node's URI."""
        master = rosgraph.Master(rospy.get_name())
        publishers = dict(master.getSystemState()[0])
        return set(publishers.get(rospy.resolve_name('tf'), ())), master

    def _follow_publishers(self):
        """Watch the processes of cmd_vel's publishers and of the scan's local readers
        that publish tf, anew whenever they change (and each second while a local
        reader does not publish tf: a node may subscribe before it advertises)."""
        # rospy replaces a list whenever a connection comes or goes, and lists
        # a connection before a thread of its own has connected it: look
        # again each step until every listed one has its handshake done.
        lists = ([rospy_internals.subscriber_connections(subscriber) for subscriber in self._subscribers]
                 + [rospy_internals.publisher_connections(publisher) for publisher in self._readers])
        if (self._connections is not None and len(lists) == len(self._connections)
                and all(now is then for now, then in zip(lists, self._connections))
                and not self._connecting and time.monotonic() < self._ask_again_at):
            return
        self._connections = lists
        drivers = [connection for listed in lists[:len(self._subscribers)] for connection in listed]
        connected = [(connection.callerid_pub, connection, None) for connection in drivers
                     if connection.header is not None]
        self._connecting = len(connected) < len(drivers)
        readers = [connection for listed in lists[len(self._subscribers):] for connection in listed
                   if not _remote(connection)]
        undecided = False
        if readers:
            try:
                tf_publishers, master = self._tf_publishers()
            except Exception as error:  # the master is away: look again in a second
                tf_publishers, master, undecided = (), None, True
                if self._warnings.allow('lockstep master'):
                    rospy.loginfo('lockstep: cannot ask the master which scan readers publish tf (%s)', error)
            for connection in readers:
                if connection.endpoint_id in tf_publishers:
                    connected.append((connection.endpoint_id, connection, master))
                else:
                    undecided = True
        names = set(name for name, _, _ in connected)
        for name in set(self._watches) - names:
            self._watches.pop(name).close()
            self._prompt.discard(name)
            self._wakes.pop(name).close()
            self._behind.discard(name)
        self.receive_threads.clear()  # ended connections' threads; live ones come back
        unknown = []
        for name, connection, master in connected:
            if name in self._watches:
                continue
            try:
                try:
                    uri = master.lookupNode(name) if master else None
                except Exception as error:  # gone, or the master is away
                    raise LookupError('the master does not know it: %s' % error)
                pid = local_pid(connection, uri)
                if pid is not None:
                    self._watches[name] = ProcessWatch(pid)
                    self._prompt.add(name)
                    self._wakes[name] = wake.Reader(pid)
            except ProcessGone:
                pass
            except LookupError as error:
                unknown.append('%s (%s)' % (name, error))
        # Not waited for until it tells: ask again a second later.
        self._ask_again_at = time.monotonic() + PID_RETRY if unknown or undecided else math.inf
        if unknown and self._warnings.allow('lockstep pid'):
            rospy.loginfo('lockstep: no PID from %s: not waiting for it; asking again every %g s (wall)',
                          ', '.join(unknown), PID_RETRY)

    def _reacted(self, name):
        try:
            watch = self._watches[name]
            waiting = watch.waiting()
        except ProcessGone:  # it ended: nothing more will come from it
            return True
        if watch.ran:
            self._ran.add(name)
        return waiting

    def _settle(self, pending, deadline):
        """Waits until the nodes `pending` have reacted; False (they are left behind) at `deadline`."""
        while True:
            pending = [name for name in pending if not self._reacted(name)]
            if not pending:
                return True
            if time.monotonic() > deadline:
                self._behind.update(pending)
                # Not a fault (Gazebo never waits for a node), but from here on
                # that node's commands may land later in sim time than on a
                # quiet machine: say so where the user looks, with the remedy.
                if self._warnings.allow('lockstep'):
                    rospy.logwarn('lockstep: %s did not react to /clock within %g s (wall): stepping on without it '
                                  'until it waits again, so what it sends may land later in sim time than on a '
                                  'quiet machine, and a script may overshoot. For the same result every time: fewer '
                                  'programs beside it, a lower real_time_factor, or a longer ~lockstep_timeout (at '
                                  'most one such message per %g s)',
                                  ', '.join(pending), self._timeout, self._warn_period)
                return False
            time.sleep(self._poll)

    def _own_threads_settled(self, deadline):
        """Waits until this process's threads but the step loop's sleep (what a node asked of Gazebo's
        services or topic has reached the request queue; answers are written); False at `deadline`."""
        if self._own is None:
            self._own = ProcessWatch(os.getpid(), exclude=(threading.get_native_id(),))
        while not self._own.quiet(self._poll):
            if time.monotonic() > deadline:
                if self._warnings.allow('lockstep requests'):
                    rospy.logwarn('lockstep: a request to Gazebo\'s services did not reach the step loop within %g s '
                                  '(wall): it is served a step or more later than on a quiet machine (at most one '
                                  'such message per %g s)', self._timeout, self._warn_period)
                return False
            time.sleep(self._poll)  # a thread that is not asleep may need the interpreter's lock
        return True

    def wait(self, requests=None, clock_ns=None):
        """Waits until the nodes followed have reacted to the last step; with `requests` (loop.Requests),
        also serves what they asked for meanwhile, and waits for their reaction to the answers.

        `clock_ns`: the step's only news was this /clock tick (its data were waited for before it went
        out): a node whose notice (tb3_common.wake) says it does nothing before a later time is not
        looked at. Not after time went back (a reset): every node wakes then."""
        self._follow_publishers()
        # A node left behind and now seen waiting has reacted: no second look.
        recovered = set(name for name in self._behind if self._reacted(name))
        self._behind -= recovered
        pending = [name for name in self._watches if name not in self._behind and name not in recovered]
        if clock_ns is not None:
            went_back, self._clock_ns = self._clock_ns is not None and clock_ns < self._clock_ns, clock_ns
            if not went_back:
                pending = [name for name in pending if self._wakes[name].next_wake() <= clock_ns]
        deadline = time.monotonic() + self._timeout
        if not self._settle(pending, deadline):
            return
        # The commands they sent are read: let our callback have handled them.
        while not self.receive_threads.all_waiting():
            if time.monotonic() > deadline:
                return
            time.sleep(self._poll)
        if requests is not None:
            self._serve(requests, deadline)

    def wait_for_readers(self, written):
        """After a step that sent data: waits as wait() does if the data may have woken a node followed
        (`written`: (caller id, topic) of each subscriber written to). Otherwise every node followed
        sleeps on as the wait before the step left it: no look is needed. Unwoken are the nodes that got
        nothing (a step of the IMU alone, 100 Hz, reaches neither ROBOTIS' DQN agent nor a SLAM, amcl or
        move_base), and those that await other data than what they got (tb3_common.wake: the DQN agent
        stores the odometry, 30 Hz, and acts on each scan, 5 Hz)."""
        self._follow_publishers()
        if any(self._woken(name, topic) for name, topic in tuple(written)):  # rospy threads may add
            self.wait()

    def _woken(self, name, topic):
        notice = self._wakes.get(name)
        if notice is None:  # not followed
            return False
        return notice.next_wake() != wake.AWAITING or topic not in notice.stored()

    def _serve(self, requests, deadline):
        """A node that calls Gazebo's services waits for the answer, asleep: lockstep sees it waiting
        while its request may still be on its way through this process's threads (or its answer on
        the way back). So, when such a node ran since this process's threads were last seen asleep,
        they must sleep (the request is queued) before the queue is served, and after each request
        served (the answer is written), and the node must then have reacted again: its requests land
        between the same two steps at any factor, as its commands do."""
        while True:
            callers = [name for name in self._watches if name in requests.callers and name not in self._behind]
            if self._ran.intersection(callers):
                if not self._own_threads_settled(deadline):
                    return
                self._ran.clear()
                # Our threads' writes (a handshake's reply, an answer) may have woken one; if none of them
                # ran since last seen quiet, they wrote nothing (a DQN step: 5 of its 6 looks here).
                if not self._settle(callers, deadline):
                    return
                if self._ran.intersection(callers):
                    continue
            if not requests.serve():
                return
            self._ran.update(callers)  # answers on their way: they will react
            deadline = time.monotonic() + self._timeout  # each reaction to an answer has its own time


