"""transport.NonBlockingConnection on real loopback TCP sockets, without ROS: a
subscriber that stops reading loses whole messages, oldest first, its own
only; one that keeps up loses nothing; the writer never waits."""
import socket
import struct
import threading
import time

import pytest

from tb3_sim_nav.ros.transport import Backlogs, NonBlockingConnection

FRAME = struct.Struct('<II')  # TCPROS-like: length of the rest, then a sequence number


def message(seq, size=1000):
    """A framed message of `size` bytes whose body starts with `seq`."""
    return FRAME.pack(size - 4, seq) + b'x' * (size - FRAME.size)


class Connection(object):
    """What NonBlockingConnection uses of a rospy publisher connection."""

    def __init__(self, sock, endpoint_id):
        self.socket = sock
        self.endpoint_id = endpoint_id
        self.stat_bytes = self.stat_num_msg = 0
        self.closed = False

    def close(self):
        self.closed = True
        if self.socket is not None:
            self.socket.close()
        self.socket = None


class Reader(object):
    """The subscriber's end: reads what has arrived and splits it into messages."""

    def __init__(self, sock):
        self.sock = sock
        self.sock.setblocking(False)
        self._buffer = b''
        self.seqs = []

    def read(self):
        """Everything that has arrived; the sequence numbers of the whole messages."""
        while True:
            try:
                chunk = self.sock.recv(1 << 20)
            except BlockingIOError:
                break
            if not chunk:
                break
            self._buffer += chunk
        while len(self._buffer) >= 4:
            (length,) = struct.unpack_from('<I', self._buffer)
            if len(self._buffer) < 4 + length:
                break
            frame, self._buffer = self._buffer[:4 + length], self._buffer[4 + length:]
            assert len(frame) == 4 + length
            self.seqs.append(FRAME.unpack_from(frame)[1])
        return self.seqs


@pytest.fixture
def pairs():
    """make(): a (NonBlockingConnection, Reader) over loopback TCP, and the Backlogs and drops
    they share; every socket closed after the test."""
    listener = socket.socket()
    listener.bind(('127.0.0.1', 0))
    listener.listen(8)
    sockets = [listener]
    backlogs = Backlogs()
    drops = []

    def make(name='/reader', **limits):
        writer = socket.create_connection(listener.getsockname())
        reader, _ = listener.accept()
        sockets.extend([writer, reader])
        connection = NonBlockingConnection(Connection(writer, name), '/topic', backlogs, drops.append, **limits)
        return connection, Reader(reader)
    make.backlogs, make.drops = backlogs, drops
    yield make
    for sock in sockets:
        sock.close()


def never_blocks(work, timeout=30.0):
    """Run `work()` in a thread; its result, or a failure if it is still running
    after `timeout` s (a blocking send on a reader that does not read never returns)."""
    result = []
    thread = threading.Thread(target=lambda: result.append(work()), daemon=True)
    thread.start()
    thread.join(timeout)
    assert not thread.is_alive(), 'write_data blocked on a reader that does not read'
    return result[0]


def write_until_backlogged(connection, start=0):
    """Write messages until the socket takes no more and one waits; the next seq."""
    def fill():
        seq = start
        while connection.backlog == 0:
            connection.write_data(message(seq))
            seq += 1
            assert seq < 1000000, 'the socket never filled'
        return seq
    return never_blocks(fill)


def test_a_reader_that_keeps_up_gets_every_message_in_order(pairs):
    connection, reader = pairs()
    for seq in range(2000):
        connection.write_data(message(seq))
        if seq % 50 == 0:
            reader.read()
    deadline = time.monotonic() + 5.0
    while len(reader.read()) < 2000 and time.monotonic() < deadline:
        pairs.backlogs.flush()
    assert reader.seqs == list(range(2000))
    assert connection.dropped == 0 and not pairs.drops
    assert connection.stat_num_msg == 2000 and connection.stat_bytes == 2000 * 1000


def test_a_stopped_reader_never_blocks_the_writer(pairs):
    connection, _reader = pairs(max_messages=16)
    seq = write_until_backlogged(connection)
    waiting, sent = connection.backlog, connection.stat_num_msg
    # Far past the socket's buffers and the backlog.
    never_blocks(lambda: [connection.write_data(message(seq + extra)) for extra in range(5000)])
    assert connection.backlog <= 16 + 1  # whole messages, and the one begun
    # Each message was sent, dropped or waits; the kernel may take a few hundred
    # more as its buffers grow (4689 dropped on a busy machine), no more.
    assert (connection.stat_num_msg - sent) + connection.dropped + connection.backlog == waiting + 5000
    assert connection.dropped >= 5000 // 2


def test_a_stopped_reader_loses_whole_messages_oldest_first_and_then_gets_the_newest(pairs):
    connection, reader = pairs(max_messages=4)
    seq = write_until_backlogged(connection)
    # Until messages are dropped: the kernel may take more meanwhile (its buffers grow, and on a busy
    # machine it moves what waits in the writer's buffer to the reader's late: 100 writes once took it all).
    last = seq
    while not pairs.drops or last < seq + 100:
        connection.write_data(message(last))
        last += 1
        assert last < seq + 100000, 'nothing dropped'
    assert pairs.drops[-1] is connection
    # The reader reads again; the backlog drains into it as the step loop flushes.
    deadline = time.monotonic() + 5.0
    while (not reader.read() or reader.seqs[-1] != last - 1) and time.monotonic() < deadline:
        pairs.backlogs.flush()
    seqs = reader.seqs
    assert seqs[-1] == last - 1, 'the newest message never arrived'
    assert seqs == sorted(seqs) and len(set(seqs)) == len(seqs)  # in order, none twice, all whole
    lost = set(range(last)) - set(seqs)
    assert lost and min(lost) >= seq - 1  # what was lost is what came after the socket filled ...
    assert list(range(last - 4, last)) == seqs[-4:]  # ... and the newest four were kept
    assert len(pairs.backlogs) == 0


def test_one_stopped_reader_costs_another_nothing(pairs):
    slow, _slow_reader = pairs('/slow', max_messages=4)
    fast, fast_reader = pairs('/fast', max_messages=4)
    for seq in range(20000):
        slow.write_data(message(seq))
        fast.write_data(message(seq))
        if seq % 20 == 0:
            fast_reader.read()
    fast_reader.read()
    assert slow.dropped > 0
    assert fast.dropped == 0 and fast_reader.seqs == list(range(20000))
    assert set(connection.endpoint_id for connection in pairs.drops) == {'/slow'}


def test_the_newest_message_is_kept_even_if_larger_than_the_byte_limit(pairs):
    connection, reader = pairs(max_bytes=1500)
    seq = write_until_backlogged(connection)
    connection.write_data(message(seq, size=100000))
    connection.write_data(message(seq + 1, size=200000))
    assert connection.backlog <= 2
    deadline = time.monotonic() + 5.0
    while (not reader.read() or reader.seqs[-1] != seq + 1) and time.monotonic() < deadline:
        pairs.backlogs.flush()
    assert reader.seqs[-1] == seq + 1


def test_a_reader_that_went_away_is_an_error_for_rospy_to_drop(pairs):
    connection, reader = pairs()
    connection.write_data(message(0))
    reader.sock.close()
    with pytest.raises(OSError):
        for seq in range(1, 1000):  # the first writes after a close may still succeed
            connection.write_data(message(seq))
            time.sleep(0.001)


def test_flushing_a_connection_whose_reader_went_away_closes_it(pairs):
    connection, reader = pairs()
    write_until_backlogged(connection)
    reader.sock.close()
    deadline = time.monotonic() + 5.0
    while len(pairs.backlogs) and time.monotonic() < deadline:
        pairs.backlogs.flush()
    assert len(pairs.backlogs) == 0 and connection.closed


def test_nagle_is_off_for_the_lockstep_s_nodes_and_each_write_names_its_reader_and_topic(pairs):
    """Lockstep counts a message as sent when it is written: Nagle's algorithm, which rospy leaves on
    for subscribers that do not ask for tcp_nodelay, held odometry up to 40 ms in the kernel (the
    DQN agent's, 2026-11-28). And it waits only for the nodes a step's data may wake, by topic."""
    written, prompt = set(), set()
    connection, reader = pairs('/agent', written=written, prompt=prompt)
    writer = connection.socket
    connection.write_data(message(1))
    assert writer.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) == 0   # the subscriber's choice
    assert written == {('/agent', '/topic')}
    prompt.add('/agent')   # the lockstep follows it now
    connection.write_data(message(2))
    assert writer.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) != 0
    assert reader.read() == [1, 2]
