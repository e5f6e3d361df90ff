"""The localization node: amcl's interface over tb3_navigation.localization.

    rosrun amcl amcl        (tb3_navigation.launch starts it with TurtleBot3's values)

The map comes from the `static_map` service (or the `map` topic with
~use_map_topic); `scan` and tf odom -> base_footprint drive the filter;
`initialpose` (rviz's 2D Pose Estimate, in the map frame) restarts it around
a pose; services `global_localization` and `request_nomotion_update`.
Out: latched `amcl_pose` and `particlecloud`, tf map -> odom post-dated by
transform_tolerance (re-sent with each scan, as amcl does). The pose is
saved to ~initial_pose_* every 1 / save_pose_rate s, so a restarted node
resumes there, as amcl's does. Each scan is handled in its callback, start to
end, so a simulator in lockstep waits for it.

Parameters as amcl reads them (amcl.config); AMCL.cfg's that this node
honours are live at `/amcl` through dynamic_reconfigure: a change reaches
the filter at its next update; one of the laser model's makes the filter
anew around its estimate, as amcl makes it anew on any change (here the
particles stay otherwise). A bad value is refused with the reason, logged,
and nothing changes.
"""
import math
import threading

import numpy as np
import rospy
from dynamic_reconfigure.server import Server
from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
from nav_msgs.srv import GetMap, SetMap, SetMapResponse
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty, EmptyResponse

from tb3_common.params import ParameterError
from tb3_common.ros import lifecycle, params
from tb3_common.ros.frames import Frames, namespaced
from tb3_common.ros.map_messages import MapMessage, grid_of_message
from tb3_common.ros.poses import plane_pose, pose_message
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import Amcl, covariance_3x3, covariance_6x6
from tb3_navigation.scan import Scan

from .config import AmclNodeConfig, amcl_values, changed, live_fields, node_values, reconfigured, unhonoured

NODE = 'amcl'
FRAMES = {'odom_frame_id': 'odom', 'base_frame_id': 'base_footprint', 'global_frame_id': 'map'}


class AmclNode(object):

    def __init__(self, life):
        namespace = rospy.get_namespace()
        tree = rospy.get_param('~', {})
        frames = dict((name, namespaced(frame, namespace)) for name, frame in FRAMES.items())
        self.config = params.read_or_exit(NODE, AmclConfig, overrides=amcl_values(tree, frames),
                                          unhonoured=unhonoured(tree))
        self.node_config = params.read_or_exit(NODE, AmclNodeConfig, overrides=node_values(tree))
        self.seed = None if self.node_config.seed < 0 else self.node_config.seed
        self.frames = Frames(NODE)
        self._lock = threading.Lock()  # the filter, between the scan callback, initialpose and the services
        self.filter = None
        self._map = None  # (grid, values) of the filter's map
        self._sensors = {}
        self._transform = None  # map -> odom of the last update
        self._last_cloud = self._last_save = None
        self.pose_pub = rospy.Publisher('amcl_pose', PoseWithCovarianceStamped, queue_size=2, latch=True)
        self.cloud_pub = rospy.Publisher('particlecloud', PoseArray, queue_size=2, latch=True)
        rospy.Service('global_localization', Empty, self._on_global_localization)
        rospy.Service('request_nomotion_update', Empty, self._on_nomotion_update)
        rospy.Service('set_map', SetMap, self._on_set_map)
        rospy.Subscriber('initialpose', PoseWithCovarianceStamped, life.callback(self._on_initial_pose), queue_size=2)
        if self.node_config.use_map_topic:
            rospy.Subscriber('map', MapMessage, life.callback(self._on_map_topic), queue_size=1)
        else:
            threading.Thread(target=self._request_map, name='static_map', daemon=True).start()
        rospy.Subscriber('scan', LaserScan, life.callback(self._on_scan), queue_size=1)
        self._live_server = self._serve()

    # --- live parameters (dynamic_reconfigure at /amcl) -----------------------------------------
    def _serve(self):
        from .cfg import AMCLConfig  # made by catkin from cfg/AMCL.cfg
        for config_class, field in live_fields():
            config = self.config if config_class is AmclConfig else self.node_config
            rospy.set_param('~' + field.name, getattr(config, field.name))
        return Server(AMCLConfig, self._on_reconfigure)

    def _on_reconfigure(self, values, _level):
        try:
            with self._lock:
                config, node_config, changes, model = changed(self.config, self.node_config, values)
                self._reconfigure(config, node_config, model)
            if changes:
                rospy.loginfo('%s: dynamic_reconfigure: %s%s', NODE, ', '.join(
                    '%s = %r' % change for change in sorted(changes.items())),
                    ' (the filter made anew around its estimate)' if model else '')
        except ParameterError as error:
            rospy.logwarn('%s: dynamic_reconfigure refused: %s; nothing changed', NODE, error)
        for config_class, field in live_fields():
            values[field.name] = getattr(self.config if config_class is AmclConfig else self.node_config, field.name)
        return values

    def _reconfigure(self, config, node_config, model):
        """Takes new configs (the lock held): see amcl.config.reconfigured."""
        if self.filter is not None:
            self.filter = reconfigured(self.filter, config, model, self._map[0], self._map[1], self.seed)
        self.config, self.node_config = config, node_config

    # --- the map ------------------------------------------------------------------
    def _request_map(self):
        rospy.loginfo('%s: requesting the map from static_map...', NODE)
        while not rospy.core.is_shutdown_requested():
            try:
                rospy.wait_for_service('static_map', timeout=5.0)
                self._on_map(rospy.ServiceProxy('static_map', GetMap)().map)
                return
            except (rospy.ROSException, rospy.ServiceException) as error:
                self.frames.warn('static_map', 'no map yet from static_map (%s): start map_server', error)

    def _on_map_topic(self, message):
        if self.node_config.first_map_only and self._map is not None:
            rospy.loginfo('%s: a new map on %s ignored (first_map_only)', NODE, rospy.resolve_name('map'))
            return
        self._on_map(message)

    def _on_map(self, message, pose=None, covariance=None):
        grid, values, _ = grid_of_message(message)
        with self._lock:
            self._map = (grid, values)
            self.filter = Amcl(self.config, grid, values, self.seed)
            if pose is not None:
                self.filter.initialise(pose, covariance)
                if self.node_config.force_update_after_set_map:
                    self.filter.request_nomotion_update()
            self._transform = None
        rospy.loginfo('%s: map of %d x %d cells at %.3f m/cell; particles around (%.2f, %.2f, %.2f)', NODE,
                      grid.width, grid.height, grid.resolution, *self.filter.estimate().pose)

    # --- requests -----------------------------------------------------------------------
    def _on_initial_pose(self, message):
        values = plane_pose(message)
        frame = message.header.frame_id.lstrip('/')
        if frame != self.config.global_frame_id:
            rospy.logwarn('%s: ignoring an initial pose in frame "%s": initial poses must be in the global frame, '
                          '"%s"', NODE, frame, self.config.global_frame_id)
            return
        covariance = covariance_3x3(message.pose.covariance)
        if not all(math.isfinite(value) for value in values) or not np.all(np.isfinite(covariance)):
            rospy.logwarn('%s: ignoring an initial pose with NaN or inf in it: %s', NODE, values)
            return
        with self._lock:
            if self.filter is None:
                rospy.logwarn('%s: no map yet: the initial pose waits for one', NODE)
                self.config = self.config.replace(initial_pose_x=values[0], initial_pose_y=values[1],
                                                  initial_pose_a=values[2])
                return
            try:
                self.filter.initialise(values, covariance)
            except ValueError as error:
                rospy.logwarn('%s: ignoring an initial pose: %s', NODE, error)
                return
            if self.node_config.force_update_after_initialpose:
                self.filter.request_nomotion_update()
        rospy.loginfo('%s: initial pose (%.3f, %.3f, %.3f) with standard deviations %.2f m, %.2f m, %.2f rad', NODE,
                      values[0], values[1], values[2], *np.sqrt(np.maximum(np.diag(covariance), 0.0)))

    def _on_global_localization(self, _request):
        with self._lock:
            if self.filter is not None:
                self.filter.global_localization()
        rospy.loginfo('%s: global localization: particles spread over the free space', NODE)
        return EmptyResponse()

    def _on_nomotion_update(self, _request):
        with self._lock:
            if self.filter is not None:
                self.filter.request_nomotion_update()
        return EmptyResponse()

    def _on_set_map(self, request):
        initial = request.initial_pose
        self._on_map(request.map, plane_pose(initial), covariance_3x3(initial.pose.covariance))
        return SetMapResponse(success=True)

    # --- scans -------------------------------------------------------------------------------
    def _sensor_pose(self, frame):
        if frame not in self._sensors:
            pose = self.frames.pose(self.config.base_frame_id, frame, rospy.Time(0), timeout=1.0)
            if pose is None:
                return None
            self._sensors[frame] = pose
        return self._sensors[frame]

    def _on_scan(self, message):
        stamp = message.header.stamp
        sensor = self._sensor_pose(message.header.frame_id)
        odom = (self.frames.pose(self.config.odom_frame_id, self.config.base_frame_id, stamp, timeout=0.5)
                if sensor else None)
        if odom is None:
            return
        with self._lock:
            if self.filter is None:
                return
            updated = self.filter.update(odom, Scan.from_message(message), sensor)
            if updated:
                self._transform = self.filter.map_to_odom()
                estimate = self.filter.estimate()
                if self.filter.resampled:
                    self._publish_pose(estimate, stamp)
                self._publish_cloud(self.filter.particles, stamp)
            transform = self._transform
        if transform is not None and self.config.tf_broadcast:
            self.frames.send(self.config.global_frame_id, self.config.odom_frame_id, transform,
                             stamp + rospy.Duration(self.config.transform_tolerance))
        if updated:
            self._save_pose(estimate, stamp)

    def _publish_pose(self, estimate, stamp):
        message = PoseWithCovarianceStamped()
        message.header.frame_id, message.header.stamp = self.config.global_frame_id, stamp
        message.pose.pose = pose_message(estimate.pose)
        message.pose.covariance = covariance_6x6(estimate.covariance)
        self.pose_pub.publish(message)

    def _publish_cloud(self, particles, stamp):
        rate = self.config.gui_publish_rate
        if rate > 0 and self._last_cloud is not None and (stamp - self._last_cloud).to_sec() < 1.0 / rate:
            return
        self._last_cloud = stamp
        message = PoseArray()
        message.header.frame_id, message.header.stamp = self.config.global_frame_id, stamp
        message.poses = [pose_message(pose) for pose in particles]
        self.cloud_pub.publish(message)

    def _save_pose(self, estimate, stamp):
        """amcl's save_pose_rate: the pose on the parameter server, where a restarted node starts."""
        rate = self.node_config.save_pose_rate
        if rate <= 0 or (self._last_save is not None and (stamp - self._last_save).to_sec() < 1.0 / rate):
            return
        self._last_save = stamp
        x, y, yaw = estimate.pose
        covariance = estimate.covariance
        for name, value in (('initial_pose_x', x), ('initial_pose_y', y), ('initial_pose_a', yaw),
                            ('initial_cov_xx', covariance[0][0]), ('initial_cov_yy', covariance[1][1]),
                            ('initial_cov_aa', covariance[2][2])):
            rospy.set_param('~' + name, float(value))


def main():
    life = lifecycle.init_node(NODE)
    AmclNode(life)
    life.spin()
