"""Registers the simulator again with a ROS master that was restarted."""
import threading
import time

import rosgraph
import rospy

from . import rospy_internals


class MasterWatch(threading.Thread):
    """Registers this node again with a master that was restarted.

    Peer-to-peer connections survive a master's restart, but a new master
    knows no node: without this, nodes started afterwards would never find
    the simulator. `parameters` (a dict the node may add to, e.g. a spawned
    robot's robot_description) are set again too.
    """
    PERIOD = 1.0  # wall s between looks at the master

    def __init__(self, parameters):
        super(MasterWatch, self).__init__(name='master_watch', daemon=True)
        self.master = rosgraph.Master(rospy.get_name())
        self.parameters = parameters
        self.master_pid = self.master.getPid()

    def run(self):
        reachable = True
        while not rospy.is_shutdown():
            time.sleep(self.PERIOD)
            try:
                pid = self.master.getPid()
            except Exception:  # refused, reset, timed out: all mean "not there now"
                if reachable:
                    rospy.logwarn('the ROS master at %s is gone: simulating on; nodes already connected '
                                  'keep their topics; waiting for a master to come back',
                                  self.master.master_uri)
                reachable = False
                continue
            if pid != self.master_pid:
                rospy_internals.register_again(self.master, self.parameters)
                self.master_pid = pid
                rospy.logwarn('a new ROS master is up at %s: registered %s\'s topics and services '
                              'with it again', self.master.master_uri, rospy.get_name())
            reachable = True
