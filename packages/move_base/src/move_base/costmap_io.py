"""One costmap's ROS side in move_base: its settings, its map, the scans marked into it, what it publishes.

Settings as costmap_2d reads them under move_base's `~global_costmap/` and
`~local_costmap/` (TurtleBot3's param files load them there); the layers
are tb3_navigation.costmap's. Published as costmap_2d names them:
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

from tb3_navigation.costmap import Costmap, CostmapConfig
from tb3_common.pose2d import compose, transform_points
from tb3_common.ros import params
from tb3_common.ros.frames import namespaced
from tb3_common.ros.map_messages import occupancy_grid

LARGE = 40000      # cells (a 10 x 10 m map at 0.05 m): such a grid is sent at most once a second
LARGE_PERIOD = 1.0  # s


class CostmapIO(object):

    def __init__(self, node, name, defaults):
        """`defaults`: tb3_navigation.costmap.GLOBAL_COSTMAP or LOCAL_COSTMAP (TurtleBot3's)."""
        namespace = rospy.get_namespace()
        self.name = name
        self.settings = dict((key, rospy.get_param('~%s/%s' % (name, key), value)) for key, value in defaults.items())
        for key in ('global_frame', 'robot_base_frame'):
            self.settings[key] = namespaced(str(self.settings[key]).lstrip('/'), namespace)
        self.frame, self.base_frame = self.settings['global_frame'], self.settings['robot_base_frame']
        self.config = params.read_or_exit(node, CostmapConfig, name)
        self.costmap = None
        if self.settings.get('rolling_window'):
            self.costmap = Costmap.rolling(self.config, float(self.settings['width']), float(self.settings['height']),
                                           float(self.settings['resolution']))
        self._next_update = self._next_publish = 0.0
        self.costmap_pub = rospy.Publisher('~%s/costmap' % name, OccupancyGrid, queue_size=1, latch=True)
        self.footprint_pub = rospy.Publisher('~%s/footprint' % name, PolygonStamped, queue_size=1)

    def set_map(self, grid, values):
        """A static map arrived (a new one replaces the old, obstacles and all)."""
        self.costmap = Costmap(grid, self.config, static=values)
        self._next_publish = 0.0

    def update(self, now, pose, scan=None, sensor_pose=None):
        """At update_frequency: the robot at `pose` (this costmap's frame); `scan`
        (tb3_navigation.scan.Scan, new since the last update) from `sensor_pose` in the base frame."""
        if self.costmap is None or now < self._next_update:
            return False
        self._next_update = now + 1.0 / max(float(self.settings['update_frequency']), 1e-3)
        if scan is not None:
            self.costmap.update(pose, scan, tuple(compose(pose, sensor_pose)))
        else:
            self.costmap.update(pose)
        return True

    def publish(self, now, stamp, pose):
        if self.costmap is None or now < self._next_publish:
            return
        rate = float(self.settings['publish_frequency'])
        if rate <= 0:
            return
        grid = self.costmap.grid
        period = 1.0 / rate
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
