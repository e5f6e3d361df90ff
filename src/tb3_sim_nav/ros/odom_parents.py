"""Which robots' odom frames another node has given a parent (a SLAM or a localizer: map -> odom).

The simulator publishes world -> odom so that the world's obstacles, drawn
in the world frame, sit under the lidar's dots in rviz. A SLAM node or
amcl publishes map -> odom; a frame with two parents breaks every tf lookup
through it. So the simulator listens to /tf, and while another node
publishes a parent of a robot's odom frame, it publishes no world -> odom
for that robot; it hangs the world under that parent instead (map -> world,
from the other node's map -> odom and its own world -> odom), so rviz still
draws the obstacles where they truly are, seen from the map, for the first
robot so claimed (a frame has one parent: the world can hang under one map).

Listening (to /tf and /tf_static) costs little: the simulator does not
connect to its own /tf, and a message is parsed only if the bytes of an odom
frame's name are in it (map -> odom at gmapping's 20 Hz, not
robot_state_publisher's wheels).
"""
import struct
import threading

import rospy
from rospy.msg import AnyMsg
from tf2_msgs.msg import TFMessage

from ..frames import compose, inverse
from . import messages, rospy_internals


def _pose(transform):
    t, r = transform.translation, transform.rotation
    return (t.x, t.y, t.z), (r.x, r.y, r.z, r.w)


def parents_in(raw, needles):
    """{child frame: (parent frame, pose of the child in the parent)} of a serialised
    TFMessage `raw`, for the children among `needles` ({frame: its serialised name})."""
    if not any(needle in raw for needle in needles.values()):
        return {}
    message = TFMessage()
    message.deserialize(raw)
    return dict((transform.child_frame_id, (transform.header.frame_id, _pose(transform.transform)))
                for transform in message.transforms if transform.child_frame_id in needles)


def needle(frame):
    """How a frame id is serialised: its length (uint32) and its bytes."""
    name = frame.encode()
    return struct.pack('<I', len(name)) + name


class OdomParents(object):
    """Parents other nodes give the odom frames `frames`; `claims()` says which are held now."""

    def __init__(self, frames):
        self._needles = dict((frame, needle(frame)) for frame in frames)
        self._lock = threading.Lock()
        self._claims = {}  # odom frame -> (caller id, parent frame, pose of odom in parent)
        self._own = rospy.get_name()
        # tf_static too: `static_transform_publisher ... map odom` is a parent as well.
        self._subscribers = [rospy.Subscriber(topic, AnyMsg, self._on_tf, queue_size=10, tcp_nodelay=True)
                             for topic in ('tf', 'tf_static')]
        for subscriber in self._subscribers:
            rospy_internals.ignore_own_publications(subscriber)

    def add(self, frame):
        """Watch `frame` too (a robot spawned while running); a new dict, as _on_tf reads it meanwhile."""
        self._needles = dict(self._needles, **{frame: needle(frame)})

    def _on_tf(self, raw):
        caller = rospy_internals.caller_id(raw)
        if caller == self._own:  # connected to ourselves before ignore_own_publications took hold
            return
        found = parents_in(raw._buff, self._needles)
        if found:
            with self._lock:
                for child, (parent, pose) in found.items():
                    self._claims[child] = (caller, parent, pose)

    def claims(self):
        """{odom frame: (caller id, parent frame, pose)} held by nodes still connected."""
        connected = set(connection.callerid_pub for subscriber in self._subscribers
                        for connection in rospy_internals.subscriber_connections(subscriber))
        with self._lock:
            for frame in [frame for frame, claim in self._claims.items() if claim[0] not in connected]:
                del self._claims[frame]
            return dict(self._claims)


class WorldLinks(object):
    """The world's links into the robots' tf trees, anew at each odom step."""

    def __init__(self, world_frame, odom_frames):
        self.world_frame = world_frame
        self.parents = OdomParents(odom_frames)
        self._hang = messages.transform('', world_frame)
        self._claimed = {}  # odom frame -> (caller id, parent frame), as last logged

    def links(self, robots, stamp):
        """world -> odom of each RobotIO in `robots` (its world_transform filled for
        this step) whose odom has no other parent, and PARENT -> world under the first that has."""
        claims = self.parents.claims()
        self._tell(claims)
        links, hung = [], False
        for io in robots:
            claim = claims.get(io.odom_frame)
            if claim is None:
                links.append(io.world_transform)
            elif not hung:
                _, parent, odom_in_parent = claim
                odom_in_world = _pose(io.world_transform.transform)
                self._hang.header.frame_id = parent
                messages.fill_transform(self._hang, stamp, compose(odom_in_parent, inverse(odom_in_world)))
                links.append(self._hang)
                hung = True
        return links

    def _tell(self, claims):
        now = dict((frame, claim[:2]) for frame, claim in claims.items())
        for frame, (caller, parent) in now.items():
            if self._claimed.get(frame) != (caller, parent):
                rospy.loginfo('tb3_sim: %s publishes %s -> %s: no more %s -> %s from the simulator (a frame '
                              'has one parent); the world hangs under %s while it does, so rviz draws it in place',
                              caller, parent, frame, self.world_frame, frame, parent)
        for frame in set(self._claimed) - set(now):
            rospy.loginfo('tb3_sim: nobody else publishes a parent of %s now: publishing %s -> %s again',
                          frame, self.world_frame, frame)
        self._claimed = now
