"""One costmap's ROS side in move_base: its settings, its map, the scans marked into it, what it publishes.

Settings as costmap_2d reads them under move_base's `~global_costmap/` and
`~local_costmap/` (move_base.costmap_params); the layers are
tb3_navigation.costmap's. Published as costmap_2d names them:
`~NAME/costmap` (nav_msgs/OccupancyGrid, costs through costmap_2d's
translation table) and `~NAME/footprint` (the padded footprint at the robot).
The full grid of a large costmap costs tens of milliseconds to send from
python; it goes out at publish_frequency only while someone subscribes, and
never more than once a second when it holds more than LARGE cells (costmap_2d
sends the changed part on costmap_updates instead, a topic not served here).
"""
import rospy
from geometry_msgs.msg import Point32, PolygonStamped
from nav_msgs.msg import OccupancyGrid

from tb3_common.grid import Grid
from tb3_common.pose2d import compose, transform_points
from tb3_common.ros.frames import namespaced
from tb3_common.ros.map_messages import occupancy_grid
from tb3_navigation.costmap import Costmap

LARGE = 40000      # cells (a 10 x 10 m map at 0.05 m): such a grid is sent at most once a second
LARGE_PERIOD = 1.0  # s


class CostmapIO(object):
    """A costmap of `settings` (move_base.costmap_params.CostmapSettings) for a robot in `namespace`."""

    def __init__(self, settings, namespace):
        ros = self.ros = settings.ros
        self.name, self.config, self.sources = settings.name, settings.config, settings.sources
        self.frame = namespaced(ros.global_frame, namespace)
        self.base_frame = namespaced(ros.robot_base_frame, namespace)
        # {topic: frame} of the sources that name their sensor's frame, in the robot's namespace as the
        # costmap's own frames are: ROBOTIS' sensor_frame base_scan is tb3_0/base_scan for tb3_0's move_base.
        self.sensor_frames = dict((source.topic, namespaced(source.sensor_frame, namespace))
                                  for _, source in self.sources if source.sensor_frame)
        self.costmap = None
        if ros.rolling_window and not ros.static_map:
            self.costmap = Costmap.rolling(self.config, ros.width, ros.height, ros.resolution)
        elif not ros.static_map:
            grid = Grid(ros.resolution, int(round(ros.width / ros.resolution)), int(round(ros.height / ros.resolution)),
                        (ros.origin_x, ros.origin_y, 0.0))
            self.costmap = Costmap(grid, self.config)
        self._marked = {}  # source name -> the number of the last scan marked from it
        self._next_update = self._next_publish = 0.0
        self.costmap_pub = rospy.Publisher('~%s/costmap' % self.name, OccupancyGrid, queue_size=1, latch=True)
        self.footprint_pub = rospy.Publisher('~%s/footprint' % self.name, PolygonStamped, queue_size=1)

    def set_map(self, grid, values):
        """A static map arrived (a new one replaces the old, obstacles and all)."""
        self.costmap = Costmap(grid, self.config, static=values)
        self._next_publish = 0.0

    def reconfigure(self, config):
        """New layer parameters (the inflation's, from dynamic_reconfigure): costs made anew with them."""
        self.config = config
        if self.costmap is not None:
            self.costmap.reconfigure(config)

    def update(self, now, pose, scans):
        """At update_frequency: the robot at `pose` (this costmap's frame); `scans` {topic: (number,
        tb3_navigation.scan.Scan, sensor pose in the base frame)}, the newest of each topic: those
        not yet marked are marked, as their sources say."""
        frequency = self.ros.update_frequency
        if self.costmap is None or frequency <= 0 or now < self._next_update:
            return False
        self._next_update = now + 1.0 / frequency
        marked = False
        for name, source in self.sources:
            number, scan, sensor = scans.get(source.topic, (None, None, None))
            if scan is None or self._marked.get(name) == number:
                continue
            self._marked[name] = number
            self.costmap.update(pose, scan, tuple(compose(pose, sensor)), source)
            marked = True
        if not marked:
            self.costmap.update(pose)
        return True

    def publish(self, now, stamp, pose):
        if self.costmap is None or now < self._next_publish or self.ros.publish_frequency <= 0:
            return
        grid = self.costmap.grid
        period = 1.0 / self.ros.publish_frequency
        if grid.width * grid.height > LARGE:
            period = max(period, LARGE_PERIOD)
        self._next_publish = now + period
        if self.costmap_pub.get_num_connections():
            self.costmap_pub.publish(occupancy_grid(grid, self.costmap.occupancy_grid(), self.frame, stamp))
        if self.footprint_pub.get_num_connections():
            polygon = PolygonStamped()
            polygon.header.frame_id, polygon.header.stamp = self.frame, stamp
            polygon.polygon.points = [Point32(x, y, 0.0) for x, y in transform_points(pose, self.costmap.footprint)]
            self.footprint_pub.publish(polygon)
