"""Models to spawn at run time, as Gazebo's spawn services take them: URDF or SDF text. No ROS here.

What pybullet can build here is boxes, cylinders and spheres: a URDF whose
links are made of them (any joints), or an SDF model of links made of them
(static with any number of links, as ROBOTIS' goal box; dynamic with one).
Anything else is refused with a ModelFileError that says what and where.
A URDF model is static with <gazebo><static>true</static></gazebo>, as Gazebo
reads it; an SDF model with <static>true</static>.
"""
import math
import xml.etree.ElementTree as ElementTree
from collections import namedtuple

from .frames import IDENTITY, compose, from_rpy

#: A shape of a link: kind box (size x, y, z), cylinder (radius, length) or
#: sphere (radius,); pose in the link's frame; color (r, g, b, a) or None.
Shape = namedtuple('Shape', 'kind size pose color')
#: An SDF link: pose in the model's frame, mass (kg), collision and visual Shapes.
Link = namedtuple('Link', 'name pose mass collisions visuals')
SdfModel = namedtuple('SdfModel', 'name static pose links')
UrdfModel = namedtuple('UrdfModel', 'name static links')

#: A few of Gazebo's material scripts, by their colour (gazebo.material).
GAZEBO_MATERIALS = {'Gazebo/Red': (1.0, 0.0, 0.0, 1.0), 'Gazebo/Green': (0.0, 1.0, 0.0, 1.0),
                    'Gazebo/Blue': (0.0, 0.0, 1.0, 1.0), 'Gazebo/White': (1.0, 1.0, 1.0, 1.0),
                    'Gazebo/Black': (0.0, 0.0, 0.0, 1.0), 'Gazebo/Grey': (0.7, 0.7, 0.7, 1.0),
                    'Gazebo/Yellow': (1.0, 1.0, 0.0, 1.0), 'Gazebo/Orange': (1.0, 0.5, 0.0, 1.0),
                    'Gazebo/Purple': (1.0, 0.0, 1.0, 1.0), 'Gazebo/Wood': (0.6, 0.45, 0.3, 1.0)}
TRUE = ('true', '1')
#: The attributes of a URDF shape that make its Shape's size.
URDF_SIZES = {'box': ('size',), 'cylinder': ('radius', 'length'), 'sphere': ('radius',)}


class ModelFileError(ValueError):
    """A model's text is malformed or asks for what cannot be built here."""


def _root(text, kind):
    try:
        return ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise ModelFileError('the %s is not valid XML: %s' % (kind, error))


def _numbers(text, count, where):
    try:
        values = [float(part) for part in (text or '').split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(value) for value in values):
        raise ModelFileError('%s: %r must be %d finite numbers' % (where, text, count))
    return values


def _pose(element, where):
    """The <pose> child of an SDF element (x y z roll pitch yaw), or the identity."""
    pose = element.find('pose')
    if pose is None:
        return IDENTITY
    x, y, z, roll, pitch, yaw = _numbers(pose.text, 6, where + ' pose')
    return ((x, y, z), from_rpy(roll, pitch, yaw))


def _color(visual):
    material = visual.find('material')
    if material is None:
        return None
    for tag in ('diffuse', 'ambient'):
        if material.find(tag) is not None:
            return tuple(_numbers(material.find(tag).text, 4, 'material ' + tag))
    script = material.find('script/name')
    return GAZEBO_MATERIALS.get(script.text.strip()) if script is not None and script.text else None


def _sdf_shape(element, where):
    geometry = element.find('geometry')
    if geometry is None or len(geometry) != 1:
        raise ModelFileError('%s: needs a <geometry> of one box, cylinder or sphere' % where)
    shape = geometry[0]
    if shape.tag == 'box':
        size = _numbers(shape.findtext('size'), 3, where + ' box size')
    elif shape.tag == 'cylinder':
        size = [_numbers(shape.findtext('radius'), 1, where + ' cylinder radius')[0],
                _numbers(shape.findtext('length'), 1, where + ' cylinder length')[0]]
    elif shape.tag == 'sphere':
        size = _numbers(shape.findtext('radius'), 1, where + ' sphere radius')
    else:
        raise ModelFileError('%s: a <%s> cannot be built here: only box, cylinder and sphere' % (where, shape.tag))
    if min(size) <= 0.0:
        raise ModelFileError('%s: %s size %s must be > 0' % (where, shape.tag, size))
    return Shape(shape.tag, tuple(size), _pose(element, where), _color(element) if element.tag == 'visual' else None)


def parse_sdf(text):
    """The SdfModel of an SDF document holding one model, or ModelFileError."""
    root = _root(text, 'SDF')
    models = root.findall('model') if root.tag == 'sdf' else []
    if root.tag != 'sdf' or len(models) != 1:
        raise ModelFileError('the SDF must be <sdf> with exactly one <model> (found <%s> with %d)'
                             % (root.tag, len(models)))
    model = models[0]
    name = model.get('name', '')
    if model.find('model') is not None or model.find('include') is not None:
        raise ModelFileError('model %r: nested models and includes cannot be built here' % name)
    static = (model.findtext('static') or 'false').strip().lower() in TRUE
    links = []
    for link in model.findall('link'):
        where = 'model %r, link %r' % (name, link.get('name'))
        mass = link.find('inertial/mass')
        links.append(Link(link.get('name', ''), _pose(link, where),
                          _numbers(mass.text, 1, where + ' mass')[0] if mass is not None else 1.0,
                          [_sdf_shape(collision, where + ' collision') for collision in link.findall('collision')],
                          [_sdf_shape(visual, where + ' visual') for visual in link.findall('visual')]))
    if not links:
        raise ModelFileError('model %r has no <link>' % name)
    if not static and len(links) > 1:
        raise ModelFileError('model %r: a dynamic model of %d links cannot be built here (one link, or '
                             '<static>true</static>)' % (name, len(links)))
    return SdfModel(name, static, _pose(model, 'model %r' % name), links)


def check_urdf(text):
    """The UrdfModel of a URDF made only of boxes, cylinders and spheres, or ModelFileError."""
    robot = _root(text, 'URDF')
    if robot.tag != 'robot':
        raise ModelFileError('a URDF is a <robot>, not <%s>' % robot.tag)
    links = [link.get('name', '') for link in robot.findall('link')]
    if not links:
        raise ModelFileError('robot %r has no <link>' % robot.get('name'))
    for link in robot.findall('link'):
        for part in link.findall('visual') + link.findall('collision'):
            if _urdf_primitive(part) is None:
                raise ModelFileError('robot %r, link %r: a %s of %s cannot be built here: only box, cylinder and sphere'
                                     % (robot.get('name'), link.get('name'), part.tag,
                                        ', '.join('<%s>' % shape.tag for shape in part.findall('geometry/*'))
                                        or 'no geometry'))
        for origin in link.iter('origin'):
            _numbers(origin.get('xyz', '0 0 0'), 3, 'link %r origin xyz' % link.get('name'))
            _numbers(origin.get('rpy', '0 0 0'), 3, 'link %r origin rpy' % link.get('name'))
    static = any((element.text or '').strip().lower() in TRUE for element in robot.findall('gazebo/static'))
    return UrdfModel(robot.get('name', ''), static, links)


def _urdf_primitive(part):
    """The one <box>, <cylinder> or <sphere> of a URDF <visual> or <collision>, else None."""
    geometry = part.find('geometry')
    shapes = list(geometry) if geometry is not None else []
    return shapes[0] if len(shapes) == 1 and shapes[0].tag in URDF_SIZES else None


def urdf_collisions(text):
    """{link name: [Shape of each <collision>, its pose in the link's frame]} of a
    URDF's text; None if a collision is not a box, cylinder or sphere (a mesh)."""
    collisions = {}
    for link in _root(text, 'URDF').findall('link'):
        for collision in link.findall('collision'):
            shape = _urdf_primitive(collision)
            if shape is None:
                return None
            where = 'link %r collision' % link.get('name')
            size = [value for name in URDF_SIZES[shape.tag]
                    for value in _numbers(shape.get(name), 3 if name == 'size' else 1, where + ' ' + name)]
            origin = collision.find('origin')
            origin = origin if origin is not None else {}
            pose = (tuple(_numbers(origin.get('xyz', '0 0 0'), 3, where + ' origin xyz')),
                    from_rpy(*_numbers(origin.get('rpy', '0 0 0'), 3, where + ' origin rpy')))
            collisions.setdefault(link.get('name'), []).append(Shape(shape.tag, tuple(size), pose, None))
    return collisions


def link_shapes(model):
    """Every shape of an SdfModel with its pose in the model's frame: (link, Shape, is_visual)."""
    return [(link, shape._replace(pose=compose(link.pose, shape.pose)), visual)
            for link in model.links
            for shapes, visual in ((link.collisions, False), (link.visuals, True)) for shape in shapes]
