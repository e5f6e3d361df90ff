"""The parameter trees move_base's tests resolve (no ROS): launch() fakes the parameter server with the
tree a launch file's `<rosparam>` loads and `<param>`s make (move_base.settings.Parameters over a dict);
the YAML of the ROS wiki's navigation tutorial, filled in for a Burger, and of ROS by Example's TurtleBot
files (rbx1 indigo-devel), as the WIKI and RBX1 loads; turtlebot3_files(), turtlebot3_navigation's param
files as move_base.launch loads them; and Recorder, a `read` that keeps what the node would warn about.
"""
import os

import yaml

from move_base.settings import Parameters, construct

PARAM = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'turtlebot3_navigation', 'param')

# The ROS wiki's navigation tutorial (RobotSetup), filled in for a Burger; ROS by Example's
# config/turtlebot values (rbx1 indigo-devel) in base_local_planner_params.yaml's layout.
WIKI_COMMON = """
obstacle_range: 2.5
raytrace_range: 3.0
robot_radius: 0.15
inflation_radius: 0.55
observation_sources: laser_scan_sensor
laser_scan_sensor: {sensor_frame: base_scan, data_type: LaserScan, topic: scan, marking: true, clearing: true}
"""
WIKI_GLOBAL = """
global_costmap:
  global_frame: /map
  robot_base_frame: base_footprint
  update_frequency: 5.0
  static_map: true
"""
WIKI_LOCAL = """
local_costmap:
  global_frame: odom
  robot_base_frame: base_footprint
  update_frequency: 5.0
  publish_frequency: 2.0
  static_map: false
  rolling_window: true
  width: 6.0
  height: 6.0
  resolution: 0.05
"""
WIKI_PLANNER = """
TrajectoryPlannerROS:
  max_vel_x: 0.45
  min_vel_x: 0.1
  max_vel_theta: 1.0
  min_in_place_vel_theta: 0.4
  acc_lim_theta: 3.2
  acc_lim_x: 2.5
  acc_lim_y: 2.5
  holonomic_robot: false
"""
RBX1_COMMON = """
obstacle_range: 2.5
raytrace_range: 3.0
robot_radius: 0.165
inflation_radius: 0.3
max_obstacle_height: 0.6
min_obstacle_height: 0.0
observation_sources: scan
scan: {data_type: LaserScan, topic: /scan, marking: true, clearing: true, expected_update_rate: 0}
"""
RBX1_GLOBAL = """
global_costmap:
  global_frame: /map
  robot_base_frame: /base_footprint
  update_frequency: 1.0
  publish_frequency: 0
  static_map: true
  rolling_window: false
  resolution: 0.01
  transform_tolerance: 1.0
  map_type: costmap
"""
RBX1_LOCAL = """
local_costmap:
  global_frame: /odom
  robot_base_frame: /base_footprint
  update_frequency: 3.0
  publish_frequency: 1.0
  static_map: false
  rolling_window: true
  width: 6.0
  height: 6.0
  resolution: 0.01
  transform_tolerance: 1.0
  map_type: costmap
"""
RBX1_PLANNER = """
controller_frequency: 3.0
recovery_behavior_enabled: false
clearing_rotation_allowed: false
TrajectoryPlannerROS:
  max_vel_x: 0.3
  min_vel_x: 0.05
  max_vel_y: 0.0
  min_vel_y: 0.0
  min_in_place_vel_theta: 0.5
  escape_vel: -0.1
  acc_lim_x: 2.5
  acc_lim_y: 0.0
  acc_lim_theta: 3.2
  holonomic_robot: false
  yaw_goal_tolerance: 0.1
  xy_goal_tolerance: 0.1
  latch_xy_goal_tolerance: false
  pdist_scale: 0.8
  gdist_scale: 0.6
  meter_scoring: true
  heading_lookahead: 0.325
  heading_scoring: false
  heading_scoring_timestep: 0.8
  occdist_scale: 0.1
  oscillation_reset_dist: 0.05
  publish_cost_grid_pc: false
  prune_plan: true
  sim_time: 1.0
  sim_granularity: 0.025
  angular_sim_granularity: 0.025
  vx_samples: 8
  vy_samples: 0
  vtheta_samples: 20
  dwa: true
  simple_attractor: false
"""


def merge(into, more):
    for key, value in more.items():
        if isinstance(value, dict) and isinstance(into.get(key), dict):
            merge(into[key], value)
        else:
            into[key] = value
    return into


def launch(*loads, **params):
    """The private tree of move_base after `<rosparam file=... ns=...>` for each (ns, YAML text) of
    `loads`, then `<param name=... value=...>` for each of `params` (a name with '/' in it as written)."""
    tree = {}
    for namespace, text in loads:
        loaded = yaml.safe_load(text)
        merge(tree, {namespace: loaded} if namespace else loaded)
    for name, value in params.items():
        parts = name.split('/')
        merge(tree, dict([(parts[0], value)]) if len(parts) == 1 else {parts[0]: dict([(parts[1], value)])})
    return Parameters(tree)


def turtlebot3_files():
    """move_base.launch's loads of turtlebot3_navigation's param files (the Burger)."""
    def text(name):
        with open(os.path.join(PARAM, name)) as stream:
            return stream.read()
    common = text('costmap_common_params_burger.yaml')
    return [('global_costmap', common), ('local_costmap', common), ('', text('local_costmap_params.yaml')),
            ('', text('global_costmap_params.yaml')), ('', text('move_base_params.yaml')),
            ('', text('dwa_local_planner_params_burger.yaml'))]


class Recorder(object):
    """A `read` that keeps what the node would warn about: {namespace: {name: why}}."""

    def __init__(self):
        self.unhonoured = {}

    def __call__(self, config_class, namespace, values, unhonoured):
        if unhonoured:
            self.unhonoured.setdefault(namespace, {}).update(unhonoured)
        return construct(config_class, namespace, values)


WIKI = [('global_costmap', WIKI_COMMON), ('local_costmap', WIKI_COMMON), ('', WIKI_LOCAL), ('', WIKI_GLOBAL),
        ('', WIKI_PLANNER)]
RBX1 = [('global_costmap', RBX1_COMMON), ('local_costmap', RBX1_COMMON), ('', RBX1_LOCAL), ('', RBX1_GLOBAL),
        ('', RBX1_PLANNER)]
