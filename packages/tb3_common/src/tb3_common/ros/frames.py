"""tf in and out in the plane: poses (x, y, yaw) of one frame in another, and transforms sent.

A missing transform is waited for with one clear warning per kind and
period, not a flood: a node started before the simulator, or a robot whose
odometry stopped, says so once every WARN_PERIOD s.
"""
import math
import time

import rospy
import tf2_ros

from .poses import plane_pose, transform_stamped

WARN_PERIOD = 10.0  # wall s between repeats of one warning
CACHE = 30.0        # s of tf history kept (tf2's default is 10)


def namespaced(frame, namespace):
    """`frame` with the node's namespace as a prefix (tb3_0/odom for a node in /tb3_0/), as
    ROBOTIS' multi-robot frames are named; unchanged in the root namespace or if it has a prefix."""
    namespace = namespace.strip('/')
    if not namespace or '/' in frame:
        return frame
    return namespace + '/' + frame


class Frames(object):
    """A tf listener and broadcaster for one node."""

    def __init__(self, node_name):
        self.node_name = node_name
        self.buffer = tf2_ros.Buffer(rospy.Duration(CACHE))
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.broadcaster = tf2_ros.TransformBroadcaster()
        self._warned = {}  # kind -> wall time of the last warning

    def warn(self, kind, text, *args):
        """A warning at most once per WARN_PERIOD s for each kind."""
        now = time.monotonic()
        if now - self._warned.get(kind, -math.inf) >= WARN_PERIOD:
            self._warned[kind] = now
            rospy.logwarn('%s: ' + text + ' (at most one such warning per %g s)', self.node_name,
                          *(args + (WARN_PERIOD,)))

    def pose(self, target, source, stamp, timeout=0.0):
        """(x, y, yaw) of frame `source` in frame `target` at `stamp` (rospy.Time(0): the
        latest), waiting up to `timeout` wall s; None (and a throttled warning) if tf has none."""
        try:
            transform = self.buffer.lookup_transform(target, source, stamp, rospy.Duration(timeout))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException) as error:
            self.warn((target, source), 'waiting for tf %s -> %s: %s', target, source, error)
            return None
        return plane_pose(transform)

    def send(self, parent, child, pose, stamp):
        self.broadcaster.sendTransform(transform_stamped(parent, child, pose, stamp))
