"""Lockstep: each step waits until the local nodes that publish cmd_vel have reacted.

See Lockstep's docstring; quiescence.py reads the processes' state off /proc.
"""
import math
import time
import xmlrpc.client

import rospy

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


def local_pid(connection):
    """PID of the node at the other end of a subscriber connection, asked over
    its XML-RPC API (as rosnode does); None if it runs on another machine.
    Raises LookupError when a node on this machine does not tell."""
    try:
        sock = connection.socket
        if sock.getpeername()[0] != sock.getsockname()[0]:
            return None
    except (AttributeError, OSError):  # closed meanwhile: nothing to wait for
        return None
    try:
        proxy = xmlrpc.client.ServerProxy(connection.endpoint_id, transport=_TimeoutTransport())
        code, message, pid = proxy.getPid(rospy.get_name())
    except Exception as error:  # refused, timed out, not a ROS node
        raise LookupError(str(error) or type(error).__name__)
    if code != 1:
        raise LookupError(message)
    return pid


class Lockstep(object):
    """Holds each step until the local nodes that publish cmd_vel have reacted to it.

    Otherwise a node's reaction to a tick costs it wall time in which the
    simulator runs on: its commands land late in sim time, and a rospy.Rate
    loop that falls two periods behind drops ticks, so a script's path would
    depend on the factor and the machine's load (even at real time, a python
    script's first ticks, slowed by its connections, can be dropped). A node
    that has not reacted within `timeout` (it computes, or never sleeps) is not
    waited for until it is seen waiting again: the simulator never stalls on it.
    """

    def __init__(self, timeout, poll, warnings, warn_period):
        self._subscribers = []  # the cmd_vel subscribers of every robot
        self._timeout = timeout
        self._poll = poll
        self._warnings = warnings
        self._warn_period = warn_period
        self._connections = None  # the lists of cmd_vel connections last followed
        self._connecting = False  # some of them still shaking hands
        self._ask_again_at = math.inf  # when to ask a local node that did not tell its PID
        self._watches = {}   # publisher node name -> ProcessWatch of its process
        self._behind = set()  # node names not waited for until seen waiting
        self.receive_threads = InputWaits()  # the threads that ran our cmd_vel callbacks

    def follow(self, subscriber):
        """Wait also for the publishers of `subscriber` (a robot's cmd_vel)."""
        self._subscribers.append(subscriber)
        self._connections = None

    def forget(self, subscriber):
        self._subscribers.remove(subscriber)
        self._connections = None

    def _follow_publishers(self):
        """Watch the processes of cmd_vel's publishers, anew whenever they change."""
        # rospy replaces a list whenever a connection comes or goes, and lists
        # a connection before a thread of its own has connected it: look
        # again each step until every listed one has its handshake done.
        lists = [rospy_internals.subscriber_connections(subscriber) for subscriber in self._subscribers]
        if (self._connections is not None and len(lists) == len(self._connections)
                and all(now is then for now, then in zip(lists, self._connections))
                and not self._connecting and time.monotonic() < self._ask_again_at):
            return
        self._connections = lists
        connections = [connection for listed in lists for connection in listed]
        connected = [connection for connection in connections if connection.header is not None]
        self._connecting = len(connected) < len(connections)
        names = set(connection.callerid_pub for connection in connected)
        for name in set(self._watches) - names:
            self._watches.pop(name).close()
            self._behind.discard(name)
        self.receive_threads.clear()  # ended connections' threads; live ones come back
        unknown = []
        for connection in connected:
            name = connection.callerid_pub
            if name in self._watches:
                continue
            try:
                pid = local_pid(connection)
                if pid is not None:
                    self._watches[name] = ProcessWatch(pid)
            except ProcessGone:
                pass
            except LookupError as error:
                unknown.append('%s (%s)' % (name, error))
        # Not waited for until it tells: ask again a second later.
        self._ask_again_at = time.monotonic() + PID_RETRY if unknown else math.inf
        if unknown and self._warnings.allow('lockstep pid'):
            rospy.loginfo('lockstep: no PID from %s: not waiting for it; asking again every %g s (wall)',
                          ', '.join(unknown), PID_RETRY)

    def _reacted(self, name):
        try:
            return self._watches[name].waiting()
        except ProcessGone:  # it ended: nothing more will come from it
            return True

    def wait(self):
        self._follow_publishers()
        # A node left behind and now seen waiting has reacted: no second look.
        recovered = set(name for name in self._behind if self._reacted(name))
        self._behind -= recovered
        pending = [name for name in self._watches if name not in self._behind and name not in recovered]
        deadline = time.monotonic() + self._timeout
        while True:
            pending = [name for name in pending if not self._reacted(name)]
            if not pending:
                break
            if time.monotonic() > deadline:
                self._behind.update(pending)
                # Information, not a fault: at real time nothing waits for
                # a busy node either (Gazebo never does).
                if self._warnings.allow('lockstep'):
                    rospy.loginfo('lockstep: %s did not wait for /clock within %g s (wall); stepping on '
                                  'without it until it does (at most one such message per %g s)',
                                  ', '.join(pending), self._timeout, self._warn_period)
                return
            time.sleep(self._poll)
        # The commands they sent are read: let our callback have handled them.
        while not self.receive_threads.all_waiting():
            if time.monotonic() > deadline:
                return
            time.sleep(self._poll)


