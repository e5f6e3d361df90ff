"""A node's config read from its private parameters, once, checked, logged (tb3_common.params's rules).

A node reads every field of its config dataclass (a tb3_common.params.Checked)
from `~name` (or `~namespace/name`, as move_base's `DWAPlannerROS/max_vel_x`),
logs the resolved set once, and on a bad value ends at start-up with the
message naming the parameter and the value, exit status 2. Parameters of
the original that the node takes but cannot honour (gmapping's particles,
say) are named in a warning at start when they are set.
"""
import dataclasses
import sys

import rospy

from ..params import ParameterError


def _prefix(namespace):
    return '~' + (namespace.strip('/') + '/' if namespace else '')


def read(config_class, namespace='', overrides=None):
    """A `config_class` from the node's private parameters `~namespace/NAME` (the field's default
    where unset; `overrides` {name: value} win over both)."""
    prefix = _prefix(namespace)
    values = {}
    for field in dataclasses.fields(config_class):
        if overrides and field.name in overrides:
            values[field.name] = overrides[field.name]
        else:
            values[field.name] = rospy.get_param(prefix + field.name, field.default)
    return config_class(**values)


def warn_unhonoured(node, unhonoured, namespace=''):
    """A warning for each parameter of `unhonoured` {name: why} that is set: the original's, taken
    here without effect (a launch file written for the original sets it)."""
    prefix = _prefix(namespace)
    for name, why in sorted(unhonoured.items()):
        if rospy.has_param(prefix + name):
            rospy.logwarn('%s: parameter %s%s = %r has no effect here: %s', node, prefix, name,
                          rospy.get_param(prefix + name), why)


def read_or_exit(node, config_class, namespace='', overrides=None, unhonoured=None):
    """read(), the resolved set logged once; a bad value ends the node (exit 2) with its message."""
    try:
        config = read(config_class, namespace, overrides)
    except (ParameterError, ValueError, TypeError) as error:
        rospy.logfatal('%s cannot start: %s', node, error)
        rospy.signal_shutdown('bad parameter')
        sys.exit(2)
    if unhonoured:
        warn_unhonoured(node, unhonoured, namespace)
    rospy.loginfo('%s parameters%s: %s', node, ' (%s)' % namespace if namespace else '',
                  ', '.join('%s=%r' % (field.name, getattr(config, field.name))
                            for field in dataclasses.fields(config)))
    return config
