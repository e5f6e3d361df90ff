"""A publisher transport that never blocks the step loop. No rospy here.

rospy writes a published message to each subscriber's socket in turn, with a
blocking sendall: one subscriber that stops reading (a `rostopic echo`
suspended with Ctrl+Z, a reader on a slow link) fills its socket's buffers,
and then the simulation stops. Queued publishers hand each message to a
writer thread per subscriber instead, but faster than real time the step
loop starves those threads of the GIL and /clock reaches subscribers in
bursts.

A NonBlockingConnection keeps what writing from the step loop buys and
drops what it costs: each message is written at once, in order, without
waiting (a non-blocking socket); what the socket cannot take waits in the
connection's own backlog, sent first on its next write or on the step loop's
flush of every backlog. A backlog holds at most `max_messages` whole messages
(and `max_bytes`): past that, the oldest messages not yet begun are dropped,
for that subscriber only, as roscpp (and so Gazebo) drops them for a reader
that falls behind. A message begun is always finished, so the stream stays
whole; when the reader reads again it gets the newest messages.
"""
import socket
import threading
from collections import deque

MAX_MESSAGES = 16        # whole messages a slow subscriber's backlog keeps ...
MAX_BYTES = 16 << 20     # ... and bytes (the newest message is kept whatever its size)


class Backlogs(object):
    """The connections that have messages waiting; the step loop flushes them."""

    def __init__(self):
        self._waiting = set()

    def add(self, connection):
        self._waiting.add(connection)

    def discard(self, connection):
        self._waiting.discard(connection)

    def __len__(self):
        return len(self._waiting)

    def flush(self):
        for connection in tuple(self._waiting):  # another thread may add meanwhile
            connection.flush()


class NonBlockingConnection(object):
    """Wraps a rospy publisher connection (its `socket`, `endpoint_id`, stats,
    `close`) and behaves as one, but its write_data never waits.

    `on_drop(connection)` is called after messages were dropped; `dropped`
    counts them. `written`, a set, gets (the subscriber's caller id,
    `topic`) at each write. If the subscriber's caller id is in `prompt` (a
    set), Nagle's algorithm is turned off before the write: rospy lets a
    subscriber's tcp_nodelay choose (0, rospy's and roscpp's default, keeps
    it on), and a small message written while one before it is not yet
    acknowledged then waits in the kernel for the reader's delayed
    acknowledgement, up to 40 ms: late for a node whose reaction the
    lockstep waits for. Others keep their choice: many small messages
    (/clock, 100 a sim second) then fill fewer segments, and a slow reader's
    socket holds more of them.
    """

    def __init__(self, connection, topic, backlogs, on_drop, max_messages=MAX_MESSAGES, max_bytes=MAX_BYTES,
                 written=None, prompt=None):
        self._connection = connection
        self.topic = topic
        self._backlogs = backlogs
        self._on_drop = on_drop
        self._written = written
        self._reader = connection.endpoint_id  # rospy sets it in the handshake, before it adds the connection
        self._prompt = prompt
        self._no_delay = False
        self.max_messages, self.max_bytes = max_messages, max_bytes
        self.dropped = 0
        self._lock = threading.Lock()  # the step loop and rospy's thread that sends a latched message
        self._pending = deque()  # messages not yet wholly sent, oldest first
        self._pending_bytes = 0
        self._head_sent = 0      # bytes of the first pending message already sent
        if connection.socket is not None:
            connection.socket.setblocking(False)

    def __getattr__(self, name):
        if name.startswith('__'):
            raise AttributeError(name)
        return getattr(self._connection, name)

    @property
    def backlog(self):
        """Messages waiting (the one begun included)."""
        return len(self._pending)

    def write_data(self, data):
        """Send `data` (one serialised message) now, or keep it for later, in order.
        Raises OSError when the subscriber has gone (rospy then drops it)."""
        if self._written is not None:
            self._written.add((self._reader, self.topic))
        if self._prompt is not None and not self._no_delay and self._reader in self._prompt:
            self._no_delay = True
            try:
                self._connection.socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            except (OSError, AttributeError):  # not a TCP socket, or closed
                pass
        with self._lock:
            if not self._pending:
                sent = self._send(data)
                self._count(sent, sent == len(data))
                if sent == len(data):
                    return True
                self._head_sent = sent
            self._pending.append(data)
            self._pending_bytes += len(data)
            self._drop_oldest()
            self._send_pending()
            if self._pending:
                self._backlogs.add(self)
            else:  # the socket took the backlog: nothing left for the step loop's flush
                self._backlogs.discard(self)
        return True

    def flush(self):
        """Send what waits, as far as the socket takes it."""
        with self._lock:
            try:
                self._send_pending()
            except OSError:  # gone: closing tells rospy, which then forgets the connection
                self._clear()
                self._connection.close()
            if not self._pending:
                self._backlogs.discard(self)

    def close(self):
        with self._lock:
            self._clear()
        self._connection.close()

    def _clear(self):
        self._pending.clear()
        self._pending_bytes = self._head_sent = 0
        self._backlogs.discard(self)

    def _send(self, data):
        sock = self._connection.socket
        if sock is None:
            raise BrokenPipeError('connection to %s closed' % self._connection.endpoint_id)
        try:
            return sock.send(data)
        except (BlockingIOError, InterruptedError):
            return 0

    def _count(self, sent, finished):
        """rospy's statistics of the connection (rosnode info shows them)."""
        self._connection.stat_bytes += sent
        if finished:
            self._connection.stat_num_msg += 1

    def _send_pending(self):
        pending = self._pending
        while pending:
            head = pending[0]
            sent = self._send(memoryview(head)[self._head_sent:])
            self._head_sent += sent
            self._count(sent, self._head_sent == len(head))
            if self._head_sent < len(head):
                return
            pending.popleft()
            self._pending_bytes -= len(head)
            self._head_sent = 0

    def _drop_oldest(self):
        """Whole messages not yet begun, oldest first, beyond the backlog's limits."""
        pending = self._pending
        begun = 1 if self._head_sent else 0
        dropped = 0
        while len(pending) - begun > 1 and (len(pending) - begun > self.max_messages
                                            or self._pending_bytes > self.max_bytes):
            self._pending_bytes -= len(pending[begun])
            del pending[begun]
            dropped += 1
        if dropped:
            self.dropped += dropped
            self._on_drop(self)
