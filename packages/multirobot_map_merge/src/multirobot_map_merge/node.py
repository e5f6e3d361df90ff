"""The map_merge node: hrnr/m-explore's multirobot_map_merge (noetic) interface over multirobot_map_merge.merge.

    rosrun multirobot_map_merge map_merge
    roslaunch turtlebot3_gazebo multi_map_merge.launch     (ROBOTIS' e-manual)

Every 1 / discovery_rate s (sim time) it asks the master for robots' maps
(multirobot_map_merge.discovery) and subscribes to each new robot's
<robot>/map and, where Debian's python3-map-msgs is installed,
<robot>/map_updates (map_msgs/OccupancyGridUpdate); with known_init_poses a
robot without its four init_pose parameters is skipped, with a warning, and
looked for again at the next discovery. Every 1 / merging_rate s it merges
the latest maps and publishes the result, latched, on merged_map_topic, in
world_frame, stamped now.

Where each robot's map goes in world_frame: where tf puts the map's frame
there, when tf has that transform (~tf_placement, ours, default true);
else by the robot's init pose; else (known_init_poses false) as it is.
Why tf first: ROBOTIS' multi_map_merge.launch gives the robots' spawn
poses as init poses, but a map made under Gazebo (and this simulator) is
already in world coordinates: odometry starts at the spawn pose, and so
does the SLAM's map frame. The same launch file publishes map -> tb3_N/map
as the identity, which is the truth there, and what rviz draws. Placing
those maps by their init poses would move each by its spawn (the original
gets away with it by reading the pose in cells: 7 m became 7 cells).
A robot whose map frame tf does not know is placed by its init pose, as the
original documents (a robot whose map starts where it started).

The original's estimation of unknown poses (feature matching with OpenCV)
is not here: with known_init_poses false the node says so at start-up and
what to do instead.
"""
import math
import threading
import time

import rospy
import tf2_ros
from nav_msgs.msg import OccupancyGrid

from multirobot_map_merge import discovery
from multirobot_map_merge.config import MapMergeConfig
from multirobot_map_merge.merge import apply_update, merge
from tb3_common.ros import lifecycle, params
from tb3_common.ros.frames import WARN_PERIOD
from tb3_common.ros.map_messages import MapMessage, grid_of_message, occupancy_grid
from tb3_common.ros.poses import plane_pose

try:  # Debian's python3-map-msgs; without it only full maps are followed
    from map_msgs.msg import OccupancyGridUpdate
except ImportError:
    OccupancyGridUpdate = None

NODE = 'map_merge'
FIRST_TF_WAIT = 1.0  # wall s the first placement of a robot's map waits for tf (a static publisher just started)
SAME_PLACE = (0.01, 0.01)  # m, rad: an init pose this close to tf's placement agrees with it
TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)

UNKNOWN_POSES = (
    "~known_init_poses is false, but the original's estimation of the robots' poses by matching features "
    "of their maps (OpenCV; ~estimation_rate, ~estimation_confidence) is not available here. Each robot's "
    "map goes where tf puts its frame in ~world_frame (%s), or else is taken as already lying in world "
    "coordinates (true when every robot's odometry starts at its true pose in one frame, as in this "
    "simulator and in Gazebo). Otherwise give each robot its start pose in %s as the parameters "
    "<robot>/map_merge/init_pose_x, init_pose_y, init_pose_z and init_pose_yaw and set ~known_init_poses "
    "true, or publish %s -> each robot's map frame on tf.")


class Robot(object):
    """One robot: its name (its namespace), init pose, and latest map (set by its callbacks)."""

    def __init__(self, name, init_pose):
        self.name = name
        self.init_pose = init_pose  # (x, y, yaw) in the world frame, or None
        self.lock = threading.Lock()
        self.grid = self.values = self.stamp = None
        self.frame = ''
        self.placed_by = None  # how its map was placed last: 'tf', 'init_pose' or 'as_is'
        self.subscribers = []


class MapMergeNode(object):

    def __init__(self, life):
        self.life = life
        self.config = params.read_or_exit(NODE, MapMergeConfig)
        self.merged_topic = rospy.resolve_name(self.config.merged_map_topic)
        self.robot_map_topic = self.config.robot_map_topic.strip('/')
        self.robots = {}  # name -> Robot; written by the loop's thread only
        self._warned = {}  # kind -> wall time of the last warning
        self.publisher = rospy.Publisher(self.config.merged_map_topic, OccupancyGrid, queue_size=1, latch=True)
        self.buffer = None
        if self.config.tf_placement:
            self.buffer = tf2_ros.Buffer()
            self._listener = tf2_ros.TransformListener(self.buffer)
        if not self.config.known_init_poses:
            world = self.config.world_frame
            rospy.logwarn('%s: ' + UNKNOWN_POSES, NODE, world, world, world)
        if OccupancyGridUpdate is None:
            rospy.loginfo("%s: map_msgs is not installed (Debian's python3-map-msgs): the robots' %s topics are "
                          'not followed, only their full maps', NODE, self.config.robot_map_updates_topic)

    def warn(self, kind, text, *args):
        """A warning at most once per WARN_PERIOD wall s for each kind (a map arriving at 5 Hz, say)."""
        now = time.monotonic()
        if now - self._warned.get(kind, -math.inf) >= WARN_PERIOD:
            self._warned[kind] = now
            rospy.logwarn('%s: ' + text, NODE, *args)

    # --- discovery --------------------------------------------------------------------------------
    def discover(self):
        try:
            published = rospy.get_published_topics()
        except Exception as error:  # the master's XML-RPC: refused, reset, timed out
            self.warn('master', 'cannot ask the master for topics: %s', error)
            return
        found = discovery.robot_maps(published, self.robot_map_topic, self.config.robot_namespace,
                                     self.merged_topic)
        for name, topic in sorted(found.items()):
            if name in self.robots:
                continue
            init_pose = None
            if self.config.known_init_poses:
                try:
                    init_pose = discovery.init_pose(name, rospy.get_param)
                except discovery.InitPoseError as error:
                    rospy.logwarn('%s: no initial position for robot [%s] (%s): define its parameters '
                                  'map_merge/init_pose_x, _y, _z and _yaw in its namespace, or set ~known_init_poses '
                                  'false to merge without them (see the node\'s documentation)', NODE, name, error)
                    continue
            self._add(name, topic, init_pose)

    def _add(self, name, topic, init_pose):
        robot = Robot(name, init_pose)
        self.robots[name] = robot
        rospy.loginfo('%s: adding robot [%s]%s; subscribing to %s', NODE, name,
                      ' at (%.3f, %.3f, %.3f)' % init_pose if init_pose else '', topic)
        robot.subscribers.append(rospy.Subscriber(topic, MapMessage, self.life.callback(
            lambda message: self._on_map(robot, message)), queue_size=1))
        if OccupancyGridUpdate is not None:
            updates = discovery.append(name, self.config.robot_map_updates_topic)
            robot.subscribers.append(rospy.Subscriber(updates, OccupancyGridUpdate, self.life.callback(
                lambda message: self._on_update(robot, message)), queue_size=50))

    # --- the robots' maps ----------------------------------------------------------------------
    def _on_map(self, robot, message):
        try:
            grid, values, _ = grid_of_message(message)
            if not all(math.isfinite(value) for value in grid.origin):
                raise ValueError('its origin %s is not finite' % (grid.origin,))
        except ValueError as error:
            self.warn(('map', robot.name), 'ignoring a map of robot [%s]: %s', robot.name, error)
            return
        with robot.lock:
            if robot.stamp is not None and robot.stamp > message.header.stamp:
                return  # overtaken by a newer one, as the original drops it
            robot.grid, robot.values, robot.stamp = grid, values, message.header.stamp
            robot.frame = message.header.frame_id.lstrip('/')

    def _on_update(self, robot, message):
        with robot.lock:
            if robot.values is None:
                self.warn(('update', robot.name), "robot [%s]: a partial map update, but no full map to update "
                          'yet: skipped', robot.name)
                return
            if robot.stamp > message.header.stamp:
                return
            try:
                values, cut = apply_update(robot.values, message.x, message.y, message.width, message.height,
                                           message.data)
            except ValueError as error:
                self.warn(('update', robot.name), 'ignoring a map update of robot [%s]: %s', robot.name, error)
                return
            robot.values, robot.stamp = values, message.header.stamp
        if cut:
            self.warn(('cut', robot.name), "robot [%s]: a map update does not fit into its map: only its part "
                      'inside was copied', robot.name)

    # --- the merge -----------------------------------------------------------------------------
    def _tf_placement(self, robot, frame):
        if self.buffer is None or not frame:
            return None
        wait = FIRST_TF_WAIT if robot.placed_by is None else 0.0
        try:
            transform = self.buffer.lookup_transform(self.config.world_frame, frame, rospy.Time(0),
                                                     rospy.Duration(wait))
        except TF_ERRORS:
            return None
        pose = plane_pose(transform)
        return pose if all(math.isfinite(value) for value in pose) else None

    def placement(self, robot, frame):
        """Where `robot`'s map (in `frame`) lies in the world frame, (x, y, yaw), or None (see the module)."""
        pose, how = self._tf_placement(robot, frame), 'tf'
        if pose is None:
            pose, how = robot.init_pose, 'init_pose'
        if pose is None and not self.config.known_init_poses:
            pose, how = (0.0, 0.0, 0.0), 'as_is'
        if pose is not None and how != robot.placed_by:
            robot.placed_by = how
            self._tell(robot, frame, pose, how)
        return pose

    def _tell(self, robot, frame, pose, how):
        where = '(%.3f, %.3f, %.3f)' % tuple(pose)
        world = self.config.world_frame
        if how == 'tf':
            text = 'its map goes where tf puts %s in %s: %s' % (frame, world, where)
            if robot.init_pose is not None and (
                    math.hypot(pose[0] - robot.init_pose[0], pose[1] - robot.init_pose[1]) > SAME_PLACE[0]
                    or abs(math.remainder(pose[2] - robot.init_pose[2], 2 * math.pi)) > SAME_PLACE[1]):
                text += ('; its init pose (%.3f, %.3f, %.3f) is not used: tf says where its map lies (a SLAM whose '
                         'odometry starts at the true pose maps in world coordinates); ~tf_placement false places '
                         'maps by their init poses' % tuple(robot.init_pose))
        elif how == 'init_pose':
            text = 'its map (frame %s) is placed at its init pose %s in %s' % (frame or '""', where, world)
        else:
            text = 'no init pose and no tf %s -> %s: its map is taken as lying in world coordinates' % (world, frame)
        rospy.loginfo('%s: robot [%s]: %s', NODE, robot.name, text)

    def merge_and_publish(self):
        maps = []
        for name in sorted(self.robots):
            robot = self.robots[name]
            with robot.lock:
                grid, values, frame = robot.grid, robot.values, robot.frame
            if grid is None:
                continue
            placement = self.placement(robot, frame)
            if placement is not None:
                maps.append((grid, values, placement))
        if not maps:
            return
        try:
            grid, values = merge(maps)
        except ValueError as error:
            self.warn('merge', 'cannot merge the maps: %s', error)
            return
        self.publisher.publish(occupancy_grid(grid, values, self.config.world_frame, rospy.Time.now()))

    # --- the loop --------------------------------------------------------------------------------
    def run(self):
        """Discovery and merging, each at its rate of ROS time, until the node ends."""
        periods = {self.discover: 1.0 / self.config.discovery_rate,
                   self.merge_and_publish: 1.0 / self.config.merging_rate}
        due = dict((task, None) for task in periods)
        while not self.life.stopping:
            now = rospy.get_time()
            for task, period in periods.items():
                if due[task] is None or now >= due[task] or now < due[task] - period:  # (time went back)
                    task()
                    due[task] = now + period
            self.life.sleep_sim(max(0.0, min(due.values()) - rospy.get_time()))
        self.life.finish()


def main():
    life = lifecycle.init_node(NODE)
    MapMergeNode(life).run()
