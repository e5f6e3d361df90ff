"""A core's typed config read from a node's private parameters, once, checked, logged.

Each core keeps its parameters in a frozen dataclass whose field names are
the ROS original's parameter names (gmapping's `maxUrange`, amcl's
`laser_max_beams`...) and whose defaults are TurtleBot3's values; the
dataclass checks its own values (ValueError naming the parameter). A node
reads every field from `~name` (or `~namespace/name`, as move_base's
`DWAPlannerROS/max_vel_x`), logs the resolved set once, and on a bad value
ends at start-up with that message and exit status 2.
"""
import dataclasses
import sys

import rospy


def _typed(field, value):
    """`value` as the field's type: ints are fine where floats go, never bools."""
    kind = field.type if isinstance(field.type, type) else type(field.default)
    if isinstance(value, bool) and kind is not bool:
        raise ValueError('parameter ~%s = %r: must be a %s, not a bool' % (field.name, value, kind.__name__))
    if kind is float and isinstance(value, int):
        return float(value)
    if kind is tuple and isinstance(value, list):
        return tuple(tuple(item) if isinstance(item, list) else item for item in value)
    if kind in (float, int, bool, str, tuple) and not isinstance(value, kind):
        raise ValueError('parameter ~%s = %r: must be a %s' % (field.name, value, kind.__name__))
    return value


def read(config_class, namespace='', overrides=None):
    """A `config_class` from the node's private parameters `~namespace/NAME`
    (the field's default where unset; `overrides` {name: value} win over both)."""
    prefix = '~' + (namespace.rstrip('/') + '/' if namespace else '')
    values = {}
    for field in dataclasses.fields(config_class):
        if overrides and field.name in overrides:
            values[field.name] = overrides[field.name]
        else:
            values[field.name] = _typed(field, rospy.get_param(prefix + field.name, field.default))
    return config_class(**values)


def read_or_exit(node, config_class, namespace='', overrides=None):
    """read(), the resolved set logged once; a bad value ends the node (exit 2) with its message."""
    try:
        config = read(config_class, namespace, overrides)
    except (ValueError, TypeError) as error:
        rospy.logfatal('%s cannot start: %s', node, error)
        rospy.signal_shutdown('bad parameter')
        sys.exit(2)
    rospy.loginfo('%s parameters%s: %s', node, ' (%s)' % namespace if namespace else '',
                  ', '.join('%s=%r' % (field.name, getattr(config, field.name))
                            for field in dataclasses.fields(config)))
    return config
