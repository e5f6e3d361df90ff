"""World files: static boxes and cylinders on the ground plane, in YAML.

    # worlds/example.yaml
    obstacles:
      - box: {size: [4.0, 0.1, 0.4], position: [0.0, 2.0], yaw: 0.0}
      - cylinder: {radius: 0.15, height: 0.4, position: [1.1, 1.1]}

Units are metres and radians. `position` is [x, y] of the shape's centre
(or [x, y, z]; z defaults to half the height, so the shape stands on the
ground); `yaw` (default 0) turns it about z; `color` is an optional
[r, g, b, a] in 0..1. A world named without a path ("empty",
"turtlebot3_world") is a file of that name in the package's worlds/ folder.
"""
import math
import os
from collections import namedtuple

import yaml

DEFAULT_COLOR = (0.75, 0.75, 0.72, 1.0)

#: kind is 'box' (size = (x, y, z) edge lengths) or 'cylinder' (size = (radius, height)).
Obstacle = namedtuple('Obstacle', 'kind size position yaw color')

_SHAPE_KEYS = {'box': {'size'}, 'cylinder': {'radius', 'height'}}
_OPTIONAL_KEYS = {'position', 'yaw', 'color'}


class WorldError(ValueError):
    """A world file is missing or malformed; the message names the file."""


def world_path(world, worlds_folder):
    """The file of a world given by name ("empty", in `worlds_folder`) or by path."""
    if os.sep in world or world.endswith(('.yaml', '.yml')):
        return os.path.abspath(os.path.expanduser(world))
    return os.path.join(worlds_folder, world + '.yaml')


def _numbers(where, value, count):
    if (not isinstance(value, (list, tuple)) or len(value) not in count
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                       for v in value)):
        raise ValueError('%s must be a list of %s finite numbers, not %r'
                         % (where, ' or '.join(map(str, count)), value))
    return tuple(float(v) for v in value)


def _positive(where, value):
    (number,) = _numbers(where, [value], (1,))
    if number <= 0.0:
        raise ValueError('%s must be > 0, not %r' % (where, value))
    return number


def _obstacle(entry):
    if not isinstance(entry, dict) or len(entry) != 1:
        raise ValueError('must be a mapping with one key, box or cylinder, not %r' % (entry,))
    kind, fields = next(iter(entry.items()))
    if kind not in _SHAPE_KEYS:
        raise ValueError('unknown shape %r (box or cylinder)' % (kind,))
    if not isinstance(fields, dict):
        raise ValueError('%s needs a mapping of its fields, not %r' % (kind, fields))
    missing = _SHAPE_KEYS[kind] - set(fields)
    unknown = set(fields) - _SHAPE_KEYS[kind] - _OPTIONAL_KEYS
    if missing or unknown:
        raise ValueError('%s: missing %s, unknown %s' % (kind, sorted(missing) or 'nothing',
                                                         sorted(unknown) or 'nothing'))
    if kind == 'box':
        size = _numbers('box size', fields['size'], (3,))
        if min(size) <= 0.0:
            raise ValueError('box size must be > 0, not %r' % (fields['size'],))
        height = size[2]
    else:
        size = (_positive('cylinder radius', fields['radius']),
                _positive('cylinder height', fields['height']))
        height = size[1]
    position = _numbers('position', fields.get('position', [0.0, 0.0]), (2, 3))
    if len(position) == 2:
        position += (height / 2.0,)
    (yaw,) = _numbers('yaw', [fields.get('yaw', 0.0)], (1,))
    color = _numbers('color', fields.get('color', DEFAULT_COLOR), (4,))
    return Obstacle(kind, size, position, yaw, color)


def load_world(world, worlds_folder):
    """The obstacles of a world given by name or path, or WorldError."""
    path = world_path(world, worlds_folder)
    if not os.path.isfile(path):
        raise WorldError('world %r: file %s does not exist' % (world, path))
    try:
        with open(path) as stream:
            document = yaml.safe_load(stream)
    except yaml.YAMLError as error:
        raise WorldError('world file %s is not valid YAML: %s' % (path, error))
    if document is None:
        document = {}
    if not isinstance(document, dict) or set(document) - {'obstacles'}:
        raise WorldError('world file %s: the top level must be a mapping with the one key '
                         '"obstacles", not %r' % (path, sorted(document) if isinstance(document, dict)
                                                  else document))
    entries = document.get('obstacles', [])
    if entries is None:  # "obstacles:" with nothing after it
        entries = []
    if not isinstance(entries, list):
        raise WorldError('world file %s: "obstacles" must be a list' % path)
    obstacles = []
    for index, entry in enumerate(entries):
        try:
            obstacles.append(_obstacle(entry))
        except ValueError as error:
            raise WorldError('world file %s, obstacle %d: %s' % (path, index + 1, error))
    return obstacles
