"""The SLAM node: gmapping's interface over tb3_navigation.slam.

    roslaunch turtlebot3_slam turtlebot3_slam.launch    # ROBOTIS' (node turtlebot3_slam_gmapping)
    roslaunch tb3_sim_bringup tb3_slam.launch           # ours (node tb3_slam)
    rosrun gmapping slam_gmapping                       # node slam_gmapping, as gmapping names itself

Subscribes `scan` and tf odom -> base_footprint; publishes latched `map` and
`map_metadata` (every map_update_interval of scan time, as gmapping), tf
map -> odom (every transform_publish_period, stamped that far ahead so that
lookups at a scan's time succeed, as gmapping's); serves `dynamic_map`.
Each scan is handled in its own callback, start to end, so a simulator in
lockstep waits for it (and the map does not depend on the speed).

It takes every parameter gmapping takes (gmapping.config): those of its
particle filter are named in a warning at start, with why they mean nothing
here. In a namespace (`ROS_NAMESPACE=tb3_0`), frames not given are the
namespace's (tb3_0/odom, tb3_0/base_footprint, tb3_0/map), as ROBOTIS'
multi-robot SLAM sets them; topics are the namespace's (/tb3_0/scan, /tb3_0/map).
"""
import threading

import rospy
from nav_msgs.msg import MapMetaData, OccupancyGrid
from nav_msgs.srv import GetMap, GetMapResponse
from sensor_msgs.msg import LaserScan

from gmapping.config import UNHONOURED, NodeConfig
from tb3_common.ros import lifecycle, params
from tb3_common.ros.frames import Frames, namespaced
from tb3_common.ros.map_messages import occupancy_grid
from tb3_navigation.scan import Scan
from tb3_navigation.slam import Slam
from tb3_navigation.slam_config import SlamConfig

NODE = 'slam_gmapping'  # gmapping's own name for it; a launch file gives another (tb3_slam, turtlebot3_slam_gmapping)


class SlamNode(object):

    def __init__(self, life):
        self.life = life
        self.name = rospy.get_name().rsplit('/', 1)[-1]
        node = params.read_or_exit(self.name, NodeConfig, unhonoured=UNHONOURED)
        namespace = rospy.get_namespace()
        self.base_frame = node.base_frame or namespaced('base_footprint', namespace)
        self.odom_frame = node.odom_frame or namespaced('odom', namespace)
        self.map_frame = node.map_frame or namespaced('map', namespace)
        self.transform_publish_period, self.tf_delay = node.transform_publish_period, node.stamp_ahead
        self.throttle_scans = node.throttle_scans
        if node.slam_methods != 'tb3':
            rospy.loginfo('%s: slam_methods %s asked for; Debian has none of those: running tb3_navigation\'s '
                          'SLAM (scan-to-map matching) with gmapping\'s interface and TurtleBot3\'s values',
                          self.name, node.slam_methods)
        self.config = params.read_or_exit(self.name, SlamConfig)
        rospy.loginfo('%s: frames %s -> %s -> %s, transform_publish_period %g s', self.name, self.map_frame,
                      self.odom_frame, self.base_frame, self.transform_publish_period)
        self.slam = Slam(self.config)
        self.frames = Frames(self.name)
        self._lock = threading.Lock()  # the core, between the scan callback and the map service
        self._sensors = {}  # scan frame -> its pose in the base frame (static: asked once)
        self._scans = 0  # scans heard, for throttle_scans
        self._last_stamp = None
        self._published_updates = -1
        self._last_map_stamp = None
        self._map = None
        self.map_pub = rospy.Publisher('map', OccupancyGrid, queue_size=1, latch=True)
        self.metadata_pub = rospy.Publisher('map_metadata', MapMetaData, queue_size=1, latch=True)
        rospy.Service('dynamic_map', GetMap, self._on_dynamic_map)
        self.scan_sub = rospy.Subscriber('scan', LaserScan, self._on_scan, queue_size=1)
        if self.transform_publish_period > 0:
            threading.Thread(target=self._tf_loop, name='map_to_odom', daemon=True).start()

    def _sensor_pose(self, frame, stamp):
        if frame not in self._sensors:
            pose = self.frames.pose(self.base_frame, frame, rospy.Time(0), timeout=1.0)
            if pose is None:
                return None
            self._sensors[frame] = pose
        return self._sensors[frame]

    def _on_scan(self, message):
        self._scans += 1
        if self._scans % self.throttle_scans:
            return  # gmapping's throttle_scans: the n-th, 2n-th... scans are used
        stamp = message.header.stamp
        sensor = self._sensor_pose(message.header.frame_id, stamp)
        odom = self.frames.pose(self.odom_frame, self.base_frame, stamp, timeout=0.5) if sensor else None
        if odom is None:
            return
        with self._lock:
            if self._last_stamp is not None and stamp < self._last_stamp:
                rospy.logwarn('%s: time went back (%.2f s -> %.2f s: a simulation reset or a new simulator): '
                              'starting a new map', self.name, self._last_stamp.to_sec(), stamp.to_sec())
                self.slam.reset()
                self._last_map_stamp, self._published_updates = None, -1
            self._last_stamp = stamp
            closures = self.slam.loops.closures
            self.slam.update(stamp.to_sec(), odom, Scan.from_message(message), sensor)
            if self.slam.loops.closures != closures:
                rospy.loginfo('%s: a loop closed at %.2f s: the graph of %d scans moved a pose by %.2f m or rad at '
                              'most; the map is drawn anew', self.name, stamp.to_sec(), len(self.slam.loops.graph),
                              self.slam.loops.moved)
            if self.slam.jumped:
                rospy.loginfo('%s: the odometry jumped (a reset or a teleport) at %.2f s; the pose in %s is '
                              '(%.2f, %.2f, %.2f), matched: %s', self.name, stamp.to_sec(), self.map_frame,
                              *(tuple(self.slam.pose) + (self.slam.matched,)))
            due = (self._last_map_stamp is None
                   or (stamp - self._last_map_stamp).to_sec() > self.config.map_update_interval)
            if due and self.slam.map_updates != self._published_updates:
                self._map = occupancy_grid(self.slam.grid, self.slam.map_values(), self.map_frame, stamp)
                self._published_updates, self._last_map_stamp = self.slam.map_updates, stamp
                self.map_pub.publish(self._map)
                self.metadata_pub.publish(self._map.info)
        if self.transform_publish_period <= 0:
            self._send_map_to_odom()

    def _send_map_to_odom(self):
        # Not under the lock: the core replaces map_to_odom whole (one tuple), and a scan's update holds the
        # lock for as long as it takes (a loop closure's redraw of the map: seconds), in which map -> odom
        # must go on being sent, or every lookup through the map frame fails meanwhile.
        correction = self.slam.map_to_odom
        self.frames.send(self.map_frame, self.odom_frame, correction,
                         rospy.Time.now() + rospy.Duration(self.tf_delay))

    def _tf_loop(self):
        """map -> odom every transform_publish_period of sim time (rospy.Timer's thread would end
        at the first jump back in time, and wait on a stopped clock)."""
        while not self.life.stopping:
            self._send_map_to_odom()
            self.life.sleep_sim(self.transform_publish_period)

    def _on_dynamic_map(self, _request):
        with self._lock:
            if self._map is None:
                self._map = occupancy_grid(self.slam.grid, self.slam.map_values(), self.map_frame,
                                             rospy.Time.now())
            return GetMapResponse(map=self._map)


def main():
    life = lifecycle.init_node(NODE)
    SlamNode(life)
    life.spin()
