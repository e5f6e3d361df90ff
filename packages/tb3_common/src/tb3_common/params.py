"""One parameter layer: typed, checked, documented configs under the ROS originals' names. No ROS here.

A node's parameters are a frozen dataclass whose field names are the
original's (amcl's `laser_max_beams`, gmapping's `maxUrange`, DWA's
`max_vel_x`, the simulator's own), whose defaults are TurtleBot3's values,
and whose fields are made with `parameter(default, doc, check, unit)`.
Subclassing `Checked` makes the dataclass type and check every field when it
is made, by one set of rules:

- a number field takes an int or a float, never a bool; an int field takes
  a float only if it is whole (5.0 from a launch file is the 5 meant);
  a tuple field takes a list; NaN and inf are no numbers;
- a field whose check fails raises ParameterError
  'parameter ~NAME = VALUE: PROBLEM', the message a node ends with;
- a frame id may start with "/" (ROS 1 launch files write "/map"): the
  slash is dropped, as tf's listener and the navigation stack's nodes drop
  it, since tf2 refuses such ids;
- relations between fields go in the dataclass's `check_together()`,
  which raises ParameterError the same way (see `fail`).

tb3_common.ros.params reads such a dataclass from the parameter server.
"""
import dataclasses
import math
import numbers
import typing


class ParameterError(ValueError):
    """A parameter a node cannot take: its message names the parameter and the value."""


def fail(name, value, problem):
    """Raise the ParameterError of parameter `name` with `value`: `problem` says what it must be."""
    raise ParameterError('parameter ~%s = %r: %s' % (name, value, problem))


def parameter(default, doc='', check=None, unit='', **metadata):
    """A field of a Checked dataclass: its default, what it means, its check (value -> None, or the
    problem), its unit; further metadata (say `live=True`) for the node that reads it."""
    return dataclasses.field(default=default, metadata=dict(metadata, doc=doc, check=check, unit=unit))


# -- checks: each takes the typed value and returns None, or what the value must be ---------------------------------

def number(low=-math.inf, high=math.inf, low_open=False, high_open=False):
    def check(value):
        too_low = value < low or (low_open and value == low)
        too_high = value > high or (high_open and value == high)
        if not (too_low or too_high):
            return None
        if low > -math.inf and high < math.inf and not (low_open or high_open):
            return 'must be between %s and %s' % (_number_text(low), _number_text(high))
        parts = []
        if low > -math.inf:
            parts.append('%s %s' % ('>' if low_open else '>=', _number_text(low)))
        if high < math.inf:
            parts.append('%s %s' % ('<' if high_open else '<=', _number_text(high)))
        return 'must be ' + ' and '.join(parts)
    return check


def _number_text(value):
    return '%d' % value if float(value).is_integer() else '%g' % value


positive = number(0.0, low_open=True)
non_negative = number(0.0)


def one_of(*choices):
    def check(value):
        return None if value in choices else 'must be one of: %s' % ', '.join(str(choice) for choice in choices)
    return check


def frame_id(value):
    """A tf frame id: a name without spaces (a leading "/" is dropped before this check)."""
    if not value:
        return 'must be a frame id, not empty'
    if any(character.isspace() for character in value):
        return 'must be a frame id (a name without spaces)'
    return None


def optional_frame_id(value):
    """A frame id, or empty for none."""
    return frame_id(value) if value else None


def points(at_least):
    """A list of at least `at_least` [x, y] points (a footprint, a polygon)."""
    def check(value):
        good = len(value) >= at_least and all(
            isinstance(point, (list, tuple)) and len(point) == 2
            and all(_is_number(coordinate) and math.isfinite(coordinate) for coordinate in point)
            for point in value)
        return None if good else 'must be a list of at least %d [x, y] points of finite numbers' % at_least
    return check


#: Checks whose values are normalised first: a frame id loses a leading "/".
NORMALIZE = {frame_id: lambda value: value.lstrip('/') if isinstance(value, str) else value,
             optional_frame_id: lambda value: value.lstrip('/') if isinstance(value, str) else value}


# -- typing and checking -------------------------------------------------------------------------------------------

def _is_number(value):
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def kind_of(field):
    """The field's python type (float, int, bool, str, tuple), and whether it may be None (Optional)."""
    kind = field.type
    arguments = [argument for argument in getattr(kind, '__args__', ()) if argument is not type(None)]
    if getattr(kind, '__origin__', None) is typing.Union and len(arguments) == 1:
        return arguments[0], True
    return kind, False


def typed(name, kind, value, optional=False):
    """`value` as `kind`, or ParameterError naming parameter `name`."""
    if value is None and optional:
        return None
    if kind is float and _is_number(value):
        if math.isfinite(value):
            return float(value)
        fail(name, value, 'must be a finite number')
    if kind is int and _is_number(value) and math.isfinite(value) and float(value).is_integer():
        return int(value)
    if kind is tuple and isinstance(value, (list, tuple)):
        return tuple(tuple(item) if isinstance(item, list) else item for item in value)
    if kind in (bool, str) and isinstance(value, kind):
        return value
    article = {int: 'a whole number', float: 'a number', bool: 'true or false', str: 'a string', tuple: 'a list'}
    fail(name, value, 'must be %s' % article.get(kind, getattr(kind, '__name__', str(kind))))


def checked(field, value):
    """`value` typed, normalised and checked for the dataclass field, or ParameterError."""
    kind, optional = kind_of(field)
    check = field.metadata.get('check')
    given = value
    value = typed(field.name, kind, NORMALIZE.get(check, lambda same: same)(value), optional)
    problem = check(value) if check is not None and value is not None else None
    if problem:
        fail(field.name, given, problem)
    return value


class Checked(object):
    """A frozen dataclass mixin: every field typed and checked (see the module), then
    check_together() for the relations between fields."""

    def __post_init__(self):
        for field in dataclasses.fields(self):
            object.__setattr__(self, field.name, checked(field, getattr(self, field.name)))
        self.check_together()

    def check_together(self):
        """Relations between fields: call fail() for the first that does not hold."""

    def replace(self, **changes):
        """A copy with `changes`, checked."""
        return dataclasses.replace(self, **changes)


def fields_of(config_class):
    """[(name, default, kind, doc, unit)] of a Checked dataclass, for tables and messages."""
    return [(field.name, field.default, kind_of(field)[0], field.metadata.get('doc', ''),
             field.metadata.get('unit', ''))
            for field in dataclasses.fields(config_class)]
