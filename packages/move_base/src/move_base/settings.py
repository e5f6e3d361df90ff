"""move_base's parameters, read where and as move_base and its plugins read them. No ROS here.

The node hands `resolve` its private parameters as one tree (rospy's
get_param('~'), the dict a launch file's params and rosparam files make)
and a `read(config_class, namespace, values, unhonoured)` that checks and
logs one config (tb3_common.ros.params.read_or_exit in the node, the
dataclass itself in the tests). What move_base and its plugins read, where:

- `~base_global_planner`, `~base_local_planner`, and move_base's own
  (NavigatorConfig; `~local_costmap/circumscribed_radius` too);
- each costmap under `~global_costmap/`, `~local_costmap/` (costmap_params);
- the global planner under `~NavfnROS/` or `~GlobalPlanner/`, the local one
  under `~DWAPlannerROS/` or `~TrajectoryPlannerROS/` (planners), each
  searching `controller_frequency` upwards as they do;
- rotate_recovery's limits under `~TrajectoryPlannerROS/` whichever local
  planner runs, and its sim_granularity under `~rotate_recovery/`.

A value the node cannot honour is refused, as a bad value is: ParameterError
'parameter ~NAMESPACE/NAME = VALUE: PROBLEM'.
"""
import dataclasses

from tb3_common.params import Checked, ParameterError, one_of, parameter
from tb3_navigation.dwa_config import DwaConfig
from tb3_navigation.navigator import NavigatorConfig
from tb3_navigation.planner import PlannerConfig
from tb3_navigation.recovery import RotateRecoveryConfig

from . import planners
from .costmap_params import read_costmap

#: move_base's recovery behaviour types: clear_costmap_recovery's named aggressive_reset is the aggressive one.
CLEAR, ROTATE = 'clear_costmap_recovery/ClearCostmapRecovery', 'rotate_recovery/RotateRecovery'

UNHONOURED = {
    'shutdown_costmaps': 'the costmaps keep updating while no goal is active',
    'make_plan_clear_costmap': "make_plan plans on the costmap as it is (move_base's default clears obstacles "
                               'around the start first)',
    'clearing_radius': 'make_plan does not clear the costmap here',
}
HARMLESS = {'shutdown_costmaps': False, 'make_plan_clear_costmap': False}


@dataclasses.dataclass(frozen=True)
class MoveBaseConfig(Checked):
    """move_base's choice of planners, and what its make_plan service does (the rest of move_base's own
    parameters are NavigatorConfig's)."""
    base_global_planner: str = parameter(planners.NAVFN, 'the global planner', one_of(*planners.GLOBAL_PLANNERS))
    base_local_planner: str = parameter(planners.DWA, "the local planner: TurtleBot3's DWA (move_base's own "
                                                      'default is TrajectoryPlannerROS: see resolve)',
                                        one_of(*planners.LOCAL_PLANNERS))
    make_plan_add_unreachable_goal: bool = parameter(True, 'make_plan adds the goal to a plan that ends short of it')


class Parameters(object):
    """A node's private parameters as one tree: `get('a/b')`, `has('a/b')`, `search('a/b', 'c')`."""

    def __init__(self, tree):
        self.tree = tree if isinstance(tree, dict) else {}

    def namespace(self, path):
        """The sub-tree at `path` ('' the whole tree), {} if there is none."""
        node = self.tree
        for part in [part for part in path.strip('/').split('/') if part]:
            node = node.get(part) if isinstance(node, dict) else None
        return node if isinstance(node, dict) else {}

    def has(self, path):
        namespace, _, name = path.strip('/').rpartition('/')
        return name in self.namespace(namespace)

    def get(self, path, default=None):
        namespace, _, name = path.strip('/').rpartition('/')
        return self.namespace(namespace).get(name, default)

    def search(self, namespace, name):
        """ros::NodeHandle::searchParam within the node: the path of `name` in `namespace` or the nearest
        namespace above it that has it, or None."""
        parts = [part for part in namespace.strip('/').split('/') if part]
        for depth in range(len(parts), -1, -1):
            path = '/'.join(parts[:depth] + [name])
            if self.has(path):
                return path
        return None

    def values(self, config_class, namespace='', defaults=None, renamed=None):
        """{field: value} of `config_class` under `namespace`: the value set, else the one set under its
        old name (`renamed` {name: old name}), else `defaults`' or the field's default."""
        found, defaults, renamed = self.namespace(namespace), defaults or {}, renamed or {}
        values = {}
        for field in dataclasses.fields(config_class):
            old = renamed.get(field.name)
            value = found.get(field.name, found.get(old, defaults.get(field.name, field.default)))
            values[field.name] = value
        return values

    def unhonoured(self, namespace, unhonoured, harmless=None):
        """Those of `unhonoured` {name: why} set under `namespace` to a value other than their `harmless` one."""
        found, harmless = self.namespace(namespace), harmless or {}
        return dict((name, why) for name, why in unhonoured.items()
                    if name in found and not (name in harmless and found[name] == harmless[name]))


def qualified(error, namespace):
    """A ParameterError whose parameter is named with its `namespace` (~NAMESPACE/NAME)."""
    prefix = 'parameter ~%s/' % namespace.strip('/')
    if not namespace or str(error).startswith(prefix):
        return error
    return ParameterError(str(error).replace('parameter ~', prefix, 1))


def construct(config_class, namespace, values, unhonoured=None):
    """`config_class(**values)`, a bad value refused naming ~NAMESPACE/NAME: the tests' `read`."""
    try:
        return config_class(**values)
    except ParameterError as error:
        raise qualified(error, namespace) from None


@dataclasses.dataclass
class Resolved(object):
    """Every config move_base runs with, and what the node should say about them."""
    move_base: MoveBaseConfig
    navigator: NavigatorConfig
    rotation: RotateRecoveryConfig
    global_costmap: object      # costmap_params.CostmapSettings
    local_costmap: object
    planner: PlannerConfig
    dwa: DwaConfig
    trajectory: planners.TrajectoryPlannerConfig = None  # when TrajectoryPlannerROS runs
    notes: list = dataclasses.field(default_factory=list)  # warnings beside the unhonoured ones

    @property
    def global_namespace(self):
        return planners.namespace_of(self.move_base.base_global_planner)

    @property
    def local_namespace(self):
        return planners.namespace_of(self.move_base.base_local_planner)


def local_planner_choice(params):
    """`~base_local_planner` as set; unset, TurtleBot3's DWAPlannerROS, unless only TrajectoryPlannerROS's
    parameters are given (ROS by Example's launch files count on move_base's own default then)."""
    if params.has('base_local_planner'):
        return params.get('base_local_planner'), None
    if params.namespace('TrajectoryPlannerROS') and not params.namespace('DWAPlannerROS'):
        return planners.TRAJECTORY, ('~base_local_planner unset and only ~TrajectoryPlannerROS/ parameters given: '
                                     "%s, move_base's default" % planners.TRAJECTORY)
    return planners.DWA, None


def recovery_names(params):
    """move_base's `~recovery_behaviors` list of {name, type} as NavigatorConfig names them, or the
    value as given when it is not such a list (NavigatorConfig then says what is wrong)."""
    given = params.get('recovery_behaviors')
    if not isinstance(given, list) or not all(isinstance(entry, dict) for entry in given):
        return given
    names = []
    for entry in given:
        kind, name = entry.get('type'), entry.get('name')
        if kind == ROTATE:
            names.append('rotate_recovery')
        elif kind == CLEAR:
            names.append('aggressive_reset' if name == 'aggressive_reset' else 'conservative_reset')
        else:
            names.append('%s (%s)' % (name, kind))
    return tuple(names)


def resolve(params, read=construct):
    """Every config of move_base from `params` (a Parameters), each checked through `read`."""
    notes = []
    choice, note = local_planner_choice(params)
    notes += [note] if note else []
    top = params.values(MoveBaseConfig, defaults={'base_local_planner': choice})
    move_base = read(MoveBaseConfig, '', top, params.unhonoured('', UNHONOURED, HARMLESS))
    global_costmap = read_costmap(params, 'global_costmap', read)
    local_costmap = read_costmap(params, 'local_costmap', read)
    values = params.values(NavigatorConfig)
    values.update(global_frame=global_costmap.ros.global_frame,
                  circumscribed_radius=params.get('local_costmap/circumscribed_radius', 0.46))
    if params.has('recovery_behaviors'):
        values['recovery_behaviors'] = recovery_names(params)
    navigator = read(NavigatorConfig, '', values, None)
    rotation_values = params.values(RotateRecoveryConfig, 'TrajectoryPlannerROS', renamed=dict(
        acc_lim_theta='acc_lim_th', max_vel_theta='max_rotational_vel',
        min_in_place_vel_theta='min_in_place_rotational_vel'))
    rotation_values['sim_granularity'] = construct(RotateRecoveryConfig, 'rotate_recovery', dict(
        sim_granularity=params.get('rotate_recovery/sim_granularity', 0.017))).sim_granularity
    rotation = read(RotateRecoveryConfig, 'TrajectoryPlannerROS', rotation_values, None)
    resolved = Resolved(move_base, navigator, rotation, global_costmap, local_costmap, None, None, notes=notes)
    name = resolved.global_namespace
    defaults = planners.GLOBAL_PLANNER_DEFAULTS if move_base.base_global_planner == planners.GLOBAL_PLANNER else {}
    resolved.planner = read(PlannerConfig, name, params.values(PlannerConfig, name, defaults),
                            params.unhonoured(name, planners.GLOBAL_UNHONOURED[move_base.base_global_planner],
                                              planners.GLOBAL_HARMLESS))
    name = resolved.local_namespace
    frequency = params.get(params.search(name, 'controller_frequency') or 'controller_frequency',
                           navigator.controller_frequency)
    if move_base.base_local_planner == planners.DWA:
        values = params.values(DwaConfig, name, dict(controller_frequency=frequency))
        resolved.dwa = read(DwaConfig, name, values,
                            params.unhonoured(name, planners.DWA_UNHONOURED, planners.DWA_HARMLESS))
    else:
        values = params.values(planners.TrajectoryPlannerConfig, name, renamed=planners.TRAJECTORY_RENAMED)
        resolved.trajectory = read(planners.TrajectoryPlannerConfig, name, values, params.unhonoured(
            name, planners.TRAJECTORY_UNHONOURED, planners.TRAJECTORY_HARMLESS))
        resolved.dwa = trajectory_dwa(resolved.trajectory, local_costmap.ros.resolution, frequency,
                                      params.namespace(name))
        notes += [note for note in (planners.turn_limit(resolved.trajectory)[1],) if note]
    return resolved


def trajectory_dwa(trajectory, resolution, frequency, given):
    """The DwaConfig that drives as `trajectory` (a TrajectoryPlannerConfig) asks, keeping our own
    obstacle_clearance if `given` (the namespace's values) sets it."""
    ours = {'obstacle_clearance': given['obstacle_clearance']} if 'obstacle_clearance' in given else {}
    return construct(DwaConfig, planners.namespace_of(planners.TRAJECTORY),
                     planners.dwa_of_trajectory_planner(trajectory, resolution, frequency, **ours))
