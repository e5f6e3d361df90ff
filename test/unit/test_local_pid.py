"""lockstep.local_pid: which cmd_vel publishers lockstep can wait for. No
master: a bare XML-RPC server on loopback stands in for a node's API."""
import os
import socket
import threading
from xmlrpc.server import SimpleXMLRPCServer

import pytest

from tb3_sim_nav.ros.lockstep import local_pid as _local_pid


class Connection(object):
    """The two attributes of a rospy subscriber connection that _local_pid reads."""

    def __init__(self, sock, endpoint_id):
        self.socket = sock
        self.endpoint_id = endpoint_id


class FarSocket(object):
    def getsockname(self):
        return ('192.0.2.1', 40000)

    def getpeername(self):
        return ('192.0.2.2', 50000)


@pytest.fixture
def loopback():
    """A connected TCP socket on 127.0.0.1, as a local node's connection is."""
    listener = socket.socket()
    listener.bind(('127.0.0.1', 0))
    listener.listen(1)
    ours = socket.create_connection(listener.getsockname())
    theirs, _ = listener.accept()
    yield ours
    for sock in (ours, theirs, listener):
        sock.close()


def node_api(answer):
    """An XML-RPC server whose getPid returns `answer`; (its URI, a stop function)."""
    server = SimpleXMLRPCServer(('127.0.0.1', 0), logRequests=False)
    server.register_function(lambda caller_id: answer, 'getPid')
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()

    def stop():
        server.shutdown()
        server.server_close()
        thread.join()
    return 'http://127.0.0.1:%d/' % server.server_address[1], stop


def test_a_local_node_tells_its_pid(loopback):
    uri, stop = node_api([1, 'pid', os.getpid()])
    try:
        assert _local_pid(Connection(loopback, uri)) == os.getpid()
    finally:
        stop()


def test_a_local_node_that_refuses_is_a_lookup_error(loopback):
    uri, stop = node_api([-1, 'no such thing here', 0])
    try:
        with pytest.raises(LookupError, match='no such thing here'):
            _local_pid(Connection(loopback, uri))
    finally:
        stop()


def test_a_local_node_that_does_not_answer_is_a_lookup_error(loopback):
    uri, stop = node_api([1, 'pid', 1])
    stop()  # nobody listens there any more
    with pytest.raises(LookupError):
        _local_pid(Connection(loopback, uri))


def test_a_node_on_another_machine_or_a_closed_connection_is_not_waited_for(loopback):
    assert _local_pid(Connection(FarSocket(), 'http://192.0.2.2:1/')) is None
    loopback.close()
    assert _local_pid(Connection(loopback, 'http://127.0.0.1:1/')) is None
