"""World files: boxes and cylinders on the ground plane, and robots, in YAML.

    # worlds/example.yaml
    obstacles:
      - box: {size: [4.0, 0.1, 0.4], position: [0.0, 2.0], yaw: 0.0, name: north_wall}
      - cylinder: {radius: 0.15, height: 0.4, position: [1.1, 1.1]}
      - cylinder: {radius: 0.12, height: 0.25, position: [2.0, 2.0], name: ball, mass: 1.0}
      - model:
          name: spinner
          mass: 1.0
          inertia: [1.0, 1.0, 1.0]
          shapes:
            - cylinder: {radius: 0.15, height: 0.5, position: [-0.6, 0.0]}
            - cylinder: {radius: 0.15, height: 0.5, position: [0.6, 0.0]}
    robots:
      - {name: tb3_3, model: burger, position: [-1.0, 0.5], yaw: 1.57}

Units are metres and radians. `position` is [x, y] of the shape's centre
(or [x, y, z]; z defaults to half the height, so the shape stands on the
ground); `yaw` (default 0) turns it about z; `color` is an optional
[r, g, b, a] in 0..1; `name` is optional and unique. An obstacle is a
static model of its own, unless it has a `mass` (kg): then it is a dynamic
one, which a twist given through Gazebo's set_model_state moves and which
the robots can push, as a Gazebo model that is not <static>. A `model`
makes one model of several shapes (given where they stand in the world):
static, or dynamic with its `mass`; its centre of mass is the shapes'
centroid. `inertia` [ixx, iyy, izz] (kg m^2, about the centre of mass) is
optional: pybullet's estimate from the shapes otherwise, and Gazebo's
default [1, 1, 1] for a model whose SDF has no <inertial>. A robot's `position`
is that of its base_footprint (z defaults to 0), its `name` its namespace
and tf prefix, its `model` burger, waffle, waffle_pi or the path of a URDF.
A world named without a path ("empty", "turtlebot3_world") is a file of
that name in the package's worlds/ folder.

A map_server map (a YAML with an `image` key, as map_saver writes them) is a
world too, as Stage makes worlds of bitmaps: its occupied cells (100) become
walls `wall_height` tall, merged into few boxes; free and unknown cells are
floor. So ROS by Example's test_map and a learner's own saved map are worlds
to drive in.
"""
import math
import os
import re
from collections import namedtuple

import numpy as np
import yaml

DEFAULT_COLOR = (0.75, 0.75, 0.72, 1.0)

#: kind is 'box' (size = (x, y, z) edge lengths) or 'cylinder' (size = (radius, height)).
#: `model`: the model it is part of ('' for a model of its own, named `name`); `mass`: its
#: model's (kg), 0 for a static model; `inertia`: its model's (ixx, iyy, izz), None for pybullet's.
Obstacle = namedtuple('Obstacle', 'kind size position yaw color name model mass inertia',
                      defaults=('', '', 0.0, None))

#: A robot to spawn: `name` ('' for the tutorial's robot without a namespace),
#: `model` (burger, waffle, waffle_pi or a URDF path), `position` (x, y, z), `yaw`.
RobotSpec = namedtuple('RobotSpec', 'name model position yaw')

#: A world: its obstacles and its robots; `map` the tb3_common.map_files.LoadedMap it was built of, if any.
WorldSpec = namedtuple('WorldSpec', 'obstacles robots map', defaults=(None,))
MAP_WALL_HEIGHT = 0.5  # m: above every TurtleBot3's lidar (0.182 m on the Burger), low enough to see over in rviz
MAP_WALL_COLOR = (0.55, 0.6, 0.65, 1.0)

_SHAPE_KEYS = {'box': {'size'}, 'cylinder': {'radius', 'height'}}
_OPTIONAL_KEYS = {'position', 'yaw', 'color', 'name', 'mass', 'inertia'}
_MODEL_KEYS = {'name', 'shapes', 'mass', 'inertia'}
_ROBOT_KEYS = {'name', 'model', 'position', 'yaw'}
ROBOT_NAME = re.compile(r'[A-Za-z][A-Za-z0-9_]*$')  # a ROS graph name without slashes


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
    name = fields.get('name', '')
    if not isinstance(name, str):
        raise ValueError('name must be a string, not %r' % (name,))
    return Obstacle(kind, size, position, yaw, color, name, '', *_dynamics(fields))


def _dynamics(fields):
    """(mass, inertia) of an obstacle's or a model's fields: 0 and None for a static one."""
    mass = _positive('mass', fields['mass']) if 'mass' in fields else 0.0
    inertia = fields.get('inertia')
    if inertia is not None:
        if not mass:
            raise ValueError('inertia needs a mass: a static model has none')
        inertia = _numbers('inertia', inertia, (3,))
        if min(inertia) <= 0.0:
            raise ValueError('inertia must be > 0, not %r' % (fields['inertia'],))
    return mass, inertia


def _obstacles(entry):
    """The Obstacles of one entry: a shape, or a `model` of several, each of them carrying the model's
    name, mass and inertia."""
    if not (isinstance(entry, dict) and list(entry) == ['model']):
        return [_obstacle(entry)]
    fields = entry['model']
    if not isinstance(fields, dict) or not {'name', 'shapes'} <= set(fields) or set(fields) - _MODEL_KEYS:
        raise ValueError('model needs a mapping of name and shapes (and optionally mass and inertia), not %r'
                         % (fields,))
    name, shapes = fields['name'], fields['shapes']
    if not isinstance(name, str) or not name:
        raise ValueError('a model needs a name, not %r' % (name,))
    if not isinstance(shapes, list) or not shapes:
        raise ValueError('model %s: shapes must be a list of boxes and cylinders, not %r' % (name, shapes))
    parts = []
    for index, shape in enumerate(shapes):
        try:
            part = _obstacle(shape)
        except ValueError as error:
            raise ValueError('model %s, shape %d: %s' % (name, index + 1, error))
        if part.mass or part.inertia:
            raise ValueError('model %s, shape %d: mass and inertia belong to the model' % (name, index + 1))
        parts.append(part._replace(model=name))
    mass, inertia = _dynamics(fields)
    return [part._replace(mass=mass, inertia=inertia) for part in parts]


def _robot(entry):
    if not isinstance(entry, dict):
        raise ValueError('must be a mapping of name, model, position and yaw, not %r' % (entry,))
    missing = {'name', 'model', 'position'} - set(entry)
    unknown = set(entry) - _ROBOT_KEYS
    if missing or unknown:
        raise ValueError('missing %s, unknown %s' % (sorted(missing) or 'nothing', sorted(unknown) or 'nothing'))
    name, model = entry['name'], entry['model']
    if not isinstance(name, str) or not ROBOT_NAME.match(name):
        raise ValueError('name %r must be a ROS name: a letter, then letters, digits or _' % (name,))
    if not isinstance(model, str) or not model:
        raise ValueError('robot %s: model must be burger, waffle, waffle_pi or a URDF path, not %r'
                         % (name, model))
    position = _numbers('robot %s: position' % name, entry['position'], (2, 3))
    (yaw,) = _numbers('robot %s: yaw' % name, [entry.get('yaw', 0.0)], (1,))
    return RobotSpec(name, model, position + (0.0,) * (3 - len(position)), yaw)


def _parse_list(entries, parse, what, where):
    """The items parse(entry) gives for each entry of a YAML list (one item, or a list of them),
    each name used once, or WorldError naming `where`, the entry's number and the problem."""
    if entries is None:  # "robots:" with nothing after it
        entries = []
    if not isinstance(entries, (list, tuple)):
        raise WorldError('%s: "%ss" must be a list, not %r' % (where, what, entries))
    items, names = [], []
    for index, entry in enumerate(entries):
        try:
            parsed = parse(entry)
        except ValueError as error:
            raise WorldError('%s, %s %d: %s' % (where, what, index + 1, error))
        if isinstance(parsed, list):  # a model's shapes, or an obstacle alone
            items.extend(parsed)
            names.append(parsed[0].model or parsed[0].name)
        else:
            items.append(parsed)
            names.append(parsed.name)
    for name in names:
        if name and names.count(name) > 1:
            raise WorldError('%s: two %ss are named %r' % (where, what, name))
    return items


def parse_robots(entries, where='~robots'):
    """RobotSpecs of a list of robot mappings, or WorldError saying which entry is wrong."""
    return _parse_list(entries, _robot, 'robot', where)


def models_of(obstacles):
    """(index of its first obstacle, name, its obstacles) of each model of a world file's obstacles, in
    order: an obstacle is a model of its own (named by its name, else KIND_N) unless it names one."""
    models = {}
    for index, obstacle in enumerate(obstacles):
        name = obstacle.model or obstacle.name or '%s_%d' % (obstacle.kind, index + 1)
        if name in models and not (obstacle.model and models[name][2][0].model == obstacle.model):
            raise ValueError('obstacle %d: two obstacles are named %r' % (index + 1, name))
        models.setdefault(name, (index, name, []))[2].append(obstacle)
    return list(models.values())


def rectangles(mask):
    """Boxes (ix, iy, columns, rows) that tile the True cells of `mask` [iy, ix]
    exactly: each row's runs, a run merged with the same run of the rows below.
    Whichever of rows or columns gives fewer boxes (ROS by Example's test_map:
    2536 cells: 689 boxes by rows, 670 by columns)."""
    def by_rows(cells):
        growing, done = {}, []
        for iy, row in enumerate(cells):
            edges = np.flatnonzero(np.diff(np.concatenate(([0], row.view(np.int8), [0]))))
            runs = set(zip(edges[::2].tolist(), edges[1::2].tolist()))
            for run in [run for run in growing if run not in runs]:
                done.append(tuple(growing.pop(run)))
            for start, stop in runs:
                if (start, stop) in growing:
                    growing[(start, stop)][3] += 1
                else:
                    growing[(start, stop)] = [start, iy, stop - start, 1]
        return sorted(done + [tuple(box) for box in growing.values()], key=lambda box: (box[1], box[0]))
    mask = np.ascontiguousarray(mask, dtype=bool)
    rows = by_rows(mask)
    columns = [(iy, ix, height, width) for ix, iy, width, height in by_rows(np.ascontiguousarray(mask.T))]
    return rows if len(rows) <= len(columns) else sorted(columns, key=lambda box: (box[1], box[0]))


def map_obstacles(grid, occupied, wall_height=MAP_WALL_HEIGHT):
    """Box obstacles `wall_height` tall standing on the True cells of `occupied` [iy, ix] of a grid.Grid."""
    obstacles = []
    for index, (ix, iy, columns, rows) in enumerate(rectangles(occupied)):
        x, y = grid.centres((ix + (columns - 1) / 2.0, iy + (rows - 1) / 2.0))
        obstacles.append(Obstacle('box', (columns * grid.resolution, rows * grid.resolution, wall_height),
                                  (float(x), float(y), wall_height / 2.0), grid.origin[2], MAP_WALL_COLOR,
                                  'wall_%d' % (index + 1)))
    return obstacles


def _map_world(path, wall_height):
    from tb3_common.grid import OCCUPIED
    from tb3_common.map_files import MapFileError, load_map
    try:
        loaded = load_map(path)
    except MapFileError as error:
        raise WorldError('world file %s is a map, and %s' % (path, error))
    return WorldSpec(map_obstacles(loaded.grid, loaded.values == OCCUPIED, wall_height), [], loaded)


def load_world(world, worlds_folder, map_wall_height=MAP_WALL_HEIGHT):
    """The WorldSpec of a world given by name or path (a world file or a map YAML), or WorldError."""
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
    if isinstance(document, dict) and 'image' in document:
        return _map_world(path, map_wall_height)
    if not isinstance(document, dict) or set(document) - {'obstacles', 'robots'}:
        raise WorldError('world file %s: the top level must be a mapping with the keys '
                         '"obstacles" and "robots", not %r' % (path, sorted(document) if isinstance(document, dict)
                                                              else document))
    where = 'world file %s' % path
    return WorldSpec(_parse_list(document.get('obstacles'), _obstacles, 'obstacle', where),
                     _parse_list(document.get('robots'), _robot, 'robot', where))
