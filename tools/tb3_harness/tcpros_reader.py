"""A subscriber that costs its process almost nothing, for the benchmark.

A rospy subscriber handles every message in python, thousands a second at the
simulator's top speed, on the same two cores as the simulator. So that the
simulator's own speed is measured (the bench reports a rospy reader too),
TcprosReader speaks just enough TCPROS to be sent a topic, reads the bytes in
large chunks and never decodes them, but for /clock, whose newest time it
keeps (a Clock message is always 8 bytes after its 4-byte length).
"""
import io
import socket
import struct
import threading
import time
import xmlrpc.client

import rosgraph.network

CALLER_ID = '/tb3_bench_reader'
CHUNK = 1 << 16
CLOCK_RECORD = struct.Struct('<III')  # length (8), secs, nsecs
LENGTH = struct.Struct('<I')


class ReaderError(Exception):
    pass


def _request_topic(node_uri, topic):
    """(host, port) to connect to for `topic`, or the reason there is none yet."""
    if node_uri is None:
        return None, 'the node is not registered'
    try:
        code, message, protocol = xmlrpc.client.ServerProxy(node_uri).requestTopic(
            CALLER_ID, topic, [['TCPROS']])
    except OSError as error:  # registered, but its API not up (or gone)
        return None, str(error)
    return (tuple(protocol[1:3]), None) if code == 1 else (None, message)


class TcprosReader(object):
    """Subscribes to `topic` of the node whose XML-RPC URI `lookup()` gives
    (None while unknown); retries until it publishes or `timeout` wall s pass.
    With `keep`, each whole message's serialised body goes to keep(body), in
    the reader's thread (tests use it to see that none is lost)."""

    def __init__(self, lookup, topic, timeout=60.0, keep=None, caller_id=CALLER_ID):
        self.topic = topic
        self.clock = None  # newest /clock time (s), if topic is /clock
        self._keep = keep
        deadline = time.monotonic() + timeout
        while True:
            address, why_not = _request_topic(lookup(), topic)
            if address is not None:
                break
            if time.monotonic() > deadline:
                raise ReaderError('no %s within %g s: %s' % (topic, timeout, why_not))
            time.sleep(0.1)
        host, port = address
        self._sock = socket.create_connection((host, port), timeout=timeout)
        # md5sum '*' accepts any type; no tcp_nodelay, as a default rospy subscriber asks.
        self._sock.sendall(rosgraph.network.encode_ros_handshake_header(
            {'callerid': caller_id, 'topic': topic, 'md5sum': '*', 'tcp_nodelay': '0'}))
        buffer = io.BytesIO()
        reply = rosgraph.network.read_ros_handshake_header(self._sock, buffer, CHUNK)
        if 'error' in reply:
            raise ReaderError('%s refused: %s' % (topic, reply['error']))
        self._sock.settimeout(None)
        self._thread = threading.Thread(target=self._read, args=(buffer.getvalue(),), name='read ' + topic,
                                        daemon=True)
        self._thread.start()

    def _read(self, tail):
        """`tail`: what came after the handshake header in its last read."""
        while True:
            try:
                chunk = self._sock.recv(CHUNK)
            except OSError:
                return
            if not chunk:
                return
            if self._keep is not None:
                tail = self._split(tail + chunk)
            elif self.topic == '/clock':
                data = tail + chunk
                whole = len(data) - len(data) % CLOCK_RECORD.size
                if whole:
                    _, secs, nsecs = CLOCK_RECORD.unpack_from(data, whole - CLOCK_RECORD.size)
                    self.clock = secs + nsecs * 1e-9
                tail = data[whole:]

    def _split(self, data):
        """Hands each whole message of `data` to keep(); what remains of a message begun."""
        start = 0
        while len(data) - start >= LENGTH.size:
            (length,) = LENGTH.unpack_from(data, start)
            end = start + LENGTH.size + length
            if end > len(data):
                break
            self._keep(data[start + LENGTH.size:end])
            start = end
        return data[start:]

    def close(self):
        try:
            self._sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._sock.close()
        self._thread.join(5.0)
