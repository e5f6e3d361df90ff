"""move_base's live parameters through dynamic_reconfigure, under the real servers' names.

    rosrun dynamic_reconfigure dynparam set /move_base/DWAPlannerROS max_vel_x 0.1
    rosrun dynamic_reconfigure dynparam set /move_base/TrajectoryPlannerROS max_vel_x 0.1
    rosrun dynamic_reconfigure dynparam set /move_base/local_costmap/inflation_layer inflation_radius 0.3

Servers: `~DWAPlannerROS` (DWAPlanner.cfg's names) or `~TrajectoryPlannerROS`
(BaseLocalPlanner.cfg's), whichever local planner runs, and each costmap's
`~NAME/inflation_layer` (InflationPlugin.cfg's: noetic's costmap_2d moves
the pre-Hydro inflation_radius and cost_scaling_factor there and serves them
from there). Each serves the live fields of its config (cfg/*.cfg make the
servers' types from them: one source). A server starts from the values the
node resolved; a change is checked as a start-up value is, applied under
the node's lock (the next control cycle or costmap update uses it) and
logged; a bad one is refused with the reason, logged, and nothing changes
(dynparam get then shows the old value). No bounds in the .cfg files:
dynamic_reconfigure would clamp an out-of-range value without a word.
"""
import rospy
from dynamic_reconfigure.server import Server

from tb3_common.cfg import live_fields
from tb3_common.params import ParameterError

from .settings import qualified, trajectory_dwa


def live_names(config_class):
    """The names of a config's live fields (parameter(..., live=True))."""
    return [field.name for field in live_fields(config_class)]


class Live(object):
    """A dynamic_reconfigure server at `~namespace` of type `config_type` (a generated *Config) over
    `current()` (the config in force) and `apply(new config)` (called with the node's `lock` held)."""

    def __init__(self, node, namespace, config_type, current, apply, lock):
        self.node, self.namespace, self.current, self.apply, self.lock = node, namespace, current, apply, lock
        config = current()
        self.names = [name for name in live_names(type(config)) if name in config_type.defaults]  # as generated
        for name in self.names:
            rospy.set_param('~%s/%s' % (namespace, name), getattr(config, name))
        self.server = Server(config_type, self._on_change, namespace='~' + namespace)

    def _on_change(self, values, _level):
        config = self.current()
        changes = dict((name, values[name]) for name in self.names if values[name] != getattr(config, name))
        if changes:
            try:
                with self.lock:
                    self.apply(self.current().replace(**changes))
                rospy.loginfo('%s: dynamic_reconfigure ~%s: %s', self.node, self.namespace,
                              ', '.join('%s = %r' % change for change in sorted(changes.items())))
            except ParameterError as error:
                rospy.logwarn('%s: dynamic_reconfigure refused %s: %s; nothing changed', self.node, changes,
                              qualified(error, self.namespace))
        config = self.current()
        for name in self.names:
            values[name] = getattr(config, name)
        return values


def serve(node, resolved):
    """The servers of a running move_base.node.MoveBaseNode configured by `resolved` (its
    move_base.settings.Resolved): its local planner's, then each costmap's inflation layer's."""
    from .cfg import BaseLocalPlannerConfig, DWAPlannerConfig, InflationPluginConfig  # made by catkin from cfg/
    name, lock, controller = node.name, node.lock, node.controller
    if resolved.trajectory is None:
        servers = [Live(name, resolved.local_namespace, DWAPlannerConfig, lambda: controller.config,
                        controller.configure, lock)]
    else:
        def apply(config):
            controller.configure(trajectory_dwa(config, resolved.local_costmap.ros.resolution,
                                                resolved.dwa.controller_frequency,
                                                {'obstacle_clearance': resolved.dwa.obstacle_clearance}))
            resolved.trajectory = config
        servers = [Live(name, resolved.local_namespace, BaseLocalPlannerConfig, lambda: resolved.trajectory, apply,
                        lock)]
    for io in (node.global_io, node.local_io):
        servers.append(Live(name, io.name + '/inflation_layer', InflationPluginConfig, lambda io=io: io.config,
                            io.reconfigure, lock))
    return servers
