"""Prints doc/reference.md's tables of parameters: the simulator's (params.py), or with
--navigation those of the SLAM, amcl and move_base nodes (their cores' config dataclasses:
each field's doc, else the comment on its line)."""
import dataclasses
import inspect
import re
import sys

from tb3_sim_nav.params import FROM_MODEL, FROM_PROFILE, PARAMETERS, PROFILES

#: (node, parameter namespace, config class) of the navigation nodes, in doc/reference.md's order.
NAVIGATION = [('slam_gmapping', '', 'tb3_navigation.slam_config.SlamConfig'),
              ('slam_gmapping', '', 'gmapping.config.NodeConfig'),
              ('amcl', '', 'tb3_navigation.amcl_config.AmclConfig'),
              ('amcl', '', 'amcl.config.AmclNodeConfig'),
              ('move_base', '', 'move_base.settings.MoveBaseConfig'),
              ('move_base', '', 'tb3_navigation.navigator.NavigatorConfig'),
              ('move_base', 'global_costmap/, local_costmap/', 'move_base.costmap_params.CostmapROSConfig'),
              ('move_base', 'global_costmap/, local_costmap/', 'tb3_navigation.costmap.CostmapConfig'),
              ('move_base', 'global_costmap/SOURCE/, local_costmap/SOURCE/',
               'move_base.costmap_params.ObservationSource'),
              ('move_base', 'NavfnROS/, GlobalPlanner/', 'tb3_navigation.planner.PlannerConfig'),
              ('move_base', 'DWAPlannerROS/', 'tb3_navigation.dwa_config.DwaConfig'),
              ('move_base', 'TrajectoryPlannerROS/', 'move_base.planners.TrajectoryPlannerConfig')]


def shown(value):
    if isinstance(value, bool):
        return 'true' if value else 'false'
    return '`%s`' % value if isinstance(value, str) else repr(value)


def _comments(cls):
    """{field: the comment on its line} of a dataclass's source."""
    found = {}
    for line in inspect.getsource(cls).split('\n'):
        match = re.match(r'\s+(\w+):[^#]*#\s*(.*)$', line)
        if match:
            found[match.group(1)] = match.group(2).strip()
    return found


def navigation():
    import importlib
    for node, namespace, path in NAVIGATION:
        module, name = path.rsplit('.', 1)
        cls = getattr(importlib.import_module(module), name)
        comments = _comments(cls)
        print('`%s`%s (`%s`):' % (node, ', under `~%s`' % namespace if namespace else '', name))
        print('')
        print('| parameter | default | meaning |')
        print('|---|---|---|')
        for field in dataclasses.fields(cls):
            if dataclasses.is_dataclass(field.type) or field.default is dataclasses.MISSING:
                continue
            doc = field.metadata.get('doc') or comments.get(field.name, '')
            print('| `%s` | %s | %s |' % (field.name, shown(field.default), doc.replace('|', '/')))
        print('')


def main():
    if sys.argv[1:] == ['--navigation']:
        return navigation()
    print('| parameter | default | unit | meaning |')
    print('|---|---|---|---|')
    for parameter in PARAMETERS:
        meta = parameter.metadata
        if meta['origin'] == FROM_MODEL:
            default = "the model's"
        elif meta['origin'] == FROM_PROFILE:
            default = ', '.join('%s: %s' % (profile, shown(PROFILES[profile][parameter.name]))
                                for profile in sorted(PROFILES))
        elif parameter.default == ():
            default = '(none)'
        else:
            default = shown(parameter.default)
        live = ' (live: `dynparam set`)' if meta['live'] else ''
        print('| `~%s` | %s | %s | %s%s |' % (parameter.name, default, meta['unit'], meta['doc'], live))


if __name__ == '__main__':
    main()
