"""The simulator's publishers: written from the step loop, never blocked by a reader.

Each subscriber connection goes through a transport.NonBlockingConnection;
the step loop flushes the backlogs once a step. A subscriber that loses
messages is named in a warning, at most once per period per subscriber.
"""
import warnings

import rospy

from . import rospy_internals
from .transport import Backlogs, NonBlockingConnection

DROP_WARNING_PERIOD = 10.0  # wall s between warnings about the same slow subscriber


class _OnSubscribe(rospy.SubscribeListener):
    def __init__(self, callback):
        super(_OnSubscribe, self).__init__()
        self._callback = callback

    def peer_subscribe(self, topic_name, topic_publish, peer_publish):
        self._callback()


class Publishers(object):

    def __init__(self, throttle):
        self.backlogs = Backlogs()
        self._throttle = throttle
        #: (caller id, topic) of each subscriber written to since the step loop last cleared it.
        self.written = set()
        #: Caller ids of the subscribers whose messages must leave at once (the lockstep's nodes).
        self.prompt = set()

    def advertise(self, topic, message_class, latch=False, on_subscribe=None):
        """A publisher whose publish() writes to every subscriber at once and in
        order, without waiting for any. No Nagle delay for small messages."""
        listener = _OnSubscribe(on_subscribe) if on_subscribe else None
        with warnings.catch_warnings():  # rospy warns whenever queue_size is None
            warnings.simplefilter('ignore', SyntaxWarning)
            publisher = rospy.Publisher(topic, message_class, queue_size=None, tcp_nodelay=True, latch=latch,
                                        subscriber_listener=listener)
        rospy_internals.wrap_connections(
            publisher, lambda connection: NonBlockingConnection(connection, publisher.resolved_name,
                                                                self.backlogs, self._on_drop,
                                                                written=self.written, prompt=self.prompt))
        return publisher

    def flush(self):
        """Send what slow subscribers' backlogs hold, as far as their sockets take it."""
        if len(self.backlogs):
            self.backlogs.flush()

    def _on_drop(self, connection):
        if self._throttle.allow(('drop', connection.topic, connection.endpoint_id)):
            rospy.logwarn('%s: subscriber %s does not keep up: %d of its messages dropped so far, oldest '
                          'first (it gets the newest when it reads again; other subscribers and the '
                          'simulation are not affected)', connection.topic, connection.endpoint_id,
                          connection.dropped)
