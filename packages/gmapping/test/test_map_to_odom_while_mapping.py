"""map -> odom goes on being sent while a scan's update holds the SLAM core (a loop closure's redraw of the map
takes seconds): every lookup through the map frame (move_base's, rviz's) would fail meanwhile."""
import threading

import rospy

from gmapping.node import SlamNode


class Frames(object):
    def __init__(self):
        self.sent = threading.Event()

    def send(self, parent, child, pose, stamp):
        self.sent.set()


class Core(object):
    map_to_odom = (1.0, 2.0, 0.5)


def test_map_to_odom_is_sent_while_the_core_is_busy(monkeypatch):
    monkeypatch.setattr(rospy.Time, 'now', staticmethod(lambda: rospy.Time(10)))
    node = SlamNode.__new__(SlamNode)  # only what sending needs: no master here
    node.slam, node.frames, node.map_frame, node.odom_frame, node.tf_delay = Core(), Frames(), 'map', 'odom', 0.05
    node._lock = threading.Lock()
    with node._lock:  # a scan's update, mid-redraw
        threading.Thread(target=node._send_map_to_odom, daemon=True).start()
        assert node.frames.sent.wait(2.0)
