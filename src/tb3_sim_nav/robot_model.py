"""A robot model read from its URDF: drive geometry, limits, casters, cameras, joints. The one source of truth.

The simulator knows a TurtleBot3 only through its URDF: the wheels' radius
and separation from the wheel joints and links, the drive's limits from the
element <drive_limits max_linear_speed=".." max_angular_speed=".."/>, the
ball casters from their link names, and its cameras from the same
<gazebo reference="LINK"><sensor type="camera"|"depth"> blocks that
ROBOTIS' Gazebo descriptions give (size, field of view, clip, rate, topics,
frame).
"""
import math
import os
import xml.etree.ElementTree as ElementTree
from collections import namedtuple

from .diff_drive import Limits
from .frames import compose, from_rpy

LEFT_WHEEL_JOINT = 'wheel_left_joint'
RIGHT_WHEEL_JOINT = 'wheel_right_joint'
CASTER_PREFIX = 'caster_'  # ball casters: links named caster_back_link, caster_back_left_link...

# pybullet reports a multibody's base pose at the base's centre of mass, and
# gives a link without <inertial> 1 kg: the root gets this tiny one at its origin.
ROOT_INERTIAL = ('<inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="0.001"/>'
                 '<inertia ixx="1e-7" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial>')

DriveGeometry = namedtuple('DriveGeometry', 'wheel_radius wheel_separation')

#: A camera as a Gazebo sensor block describes it. `depth`: a depth camera
#: (RealSense R200: colour, depth image and cloud from one sensor); topics are
#: relative to the robot's namespace (camera/rgb/image_raw...); `cutoff`: depths
#: closer than this read NaN (Gazebo's pointCloudCutoff).
CameraSpec = namedtuple('CameraSpec', 'link name depth width height horizontal_fov near far rate frame '
                                      'image_topic info_topic depth_topic depth_info_topic points_topic cutoff')

#: Everything the simulator takes from a robot's URDF (its text too; urdf_file is None for one spawned as text).
RobotModel = namedtuple('RobotModel', 'urdf_file urdf_text name geometry limits casters cameras joints')

#: Joint types whose child moves with the joint's position (robot_state_publisher reads it from joint_states).
MOVING_JOINTS = ('revolute', 'continuous', 'prismatic')


class Joint(namedtuple('Joint', 'name kind parent child origin axis')):
    """A URDF <joint>: type, parent and child links, origin (a pose) and unit axis."""

    @property
    def moving(self):
        return self.kind in MOVING_JOINTS

    @property
    def fixed(self):
        """What robot_state_publisher (1.15) puts on /tf_static: every joint that does not
        move, but a floating one (KDL cannot move a planar joint either: fixed too)."""
        return not self.moving and self.kind != 'floating'

    def pose(self, position=0.0):
        """The child link's frame in the parent's at `position` (rad; m if prismatic):
        the origin, then a turn or a shift along the axis, as KDL's segment gives it."""
        if self.kind in ('revolute', 'continuous'):
            sine = math.sin(0.5 * position)
            turn = (self.axis[0] * sine, self.axis[1] * sine, self.axis[2] * sine, math.cos(0.5 * position))
            return compose(self.origin, ((0.0, 0.0, 0.0), turn))
        if self.kind == 'prismatic':
            return compose(self.origin, (tuple(value * position for value in self.axis), (0.0, 0.0, 0.0, 1.0)))
        return self.origin


class ModelError(ValueError):
    """The URDF is missing or lacks what a differential drive needs."""


def _floats(text):
    return [float(value) for value in text.split()]


def _parse(urdf_path):
    if not os.path.isfile(urdf_path):
        raise ModelError('URDF file %r does not exist' % urdf_path)
    try:
        return ElementTree.parse(urdf_path).getroot()
    except ElementTree.ParseError as error:
        raise ModelError('URDF file %r is not valid XML: %s' % (urdf_path, error))


def root_link(robot):
    """The <link> element that is no joint's child."""
    children = {child.get('link') for child in robot.iter('child')}
    roots = [link for link in robot.iter('link') if link.get('name') not in children]
    if len(roots) != 1:
        raise ModelError('a URDF needs exactly one root link, not %d' % len(roots))
    return roots[0]


def _completed(robot):
    root = root_link(robot)
    if root.find('inertial') is None:
        root.append(ElementTree.fromstring(ROOT_INERTIAL))
    return ElementTree.tostring(robot, encoding='unicode')


def urdf_for_pybullet(urdf_path):
    """The URDF's text with a tiny <inertial> added to a root link that has none."""
    return _completed(_parse(urdf_path))


def urdf_text_for_pybullet(text):
    """The same, for a URDF's text."""
    try:
        return _completed(ElementTree.fromstring(text))
    except ElementTree.ParseError as error:
        raise ModelError('the URDF is not valid XML: %s' % error)


def _joints(robot):
    """The robot's <joint> elements (not those a <transmission> names) with their
    parent and child links; URDF's defaults: origin at the parent's, axis x."""
    joints = []
    for joint in robot.findall('joint'):
        parent, child, origin, axis = (joint.find(tag) for tag in ('parent', 'child', 'origin', 'axis'))
        if parent is None or child is None:
            continue
        xyz = _floats(origin.get('xyz', '0 0 0')) if origin is not None else [0.0] * 3
        rpy = _floats(origin.get('rpy', '0 0 0')) if origin is not None else [0.0] * 3
        direction = _floats(axis.get('xyz', '1 0 0')) if axis is not None else [1.0, 0.0, 0.0]
        length = math.sqrt(sum(value * value for value in direction)) or 1.0
        joints.append(Joint(joint.get('name'), joint.get('type'), parent.get('link'), child.get('link'),
                            (tuple(xyz), from_rpy(*rpy)), tuple(value / length for value in direction)))
    return tuple(joints)


def _drive_geometry(robot, urdf_path):
    joints = {joint.get('name'): joint for joint in robot.iter('joint')}
    links = {link.get('name'): link for link in robot.iter('link')}
    origins, radii = [], []
    for name in (LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT):
        joint = joints.get(name)
        if joint is None:
            raise ModelError('URDF file %r has no joint %r' % (urdf_path, name))
        origin = joint.find('origin')
        origins.append(_floats(origin.get('xyz', '0 0 0')) if origin is not None else [0.0] * 3)
        child = joint.find('child')
        link = links.get(child.get('link') if child is not None else None)
        if link is None:
            raise ModelError('URDF file %r: joint %r has no child link defined in the file'
                             % (urdf_path, name))
        geometry = link.find('collision/geometry')
        round_shape = None if geometry is None else (
            geometry.find('sphere') if geometry.find('sphere') is not None else geometry.find('cylinder'))
        if round_shape is None:
            raise ModelError('URDF file %r: the link of %r has no collision sphere or cylinder'
                             % (urdf_path, name))
        radii.append(float(round_shape.get('radius')))
    if abs(radii[0] - radii[1]) > 1e-9:
        raise ModelError('URDF file %r: the wheels differ in radius (%s)' % (urdf_path, radii))
    separation = abs(origins[0][1] - origins[1][1])
    if separation <= 0.0:
        raise ModelError('URDF file %r: the wheels are not apart along y' % urdf_path)
    return DriveGeometry(wheel_radius=radii[0], wheel_separation=separation)


def read_drive_geometry(urdf_path):
    """Wheel radius (m) and separation (m) of a two-wheeled URDF."""
    return _drive_geometry(_parse(urdf_path), urdf_path)


def _limits(robot, urdf_path):
    element = robot.find('drive_limits')
    if element is None:
        raise ModelError('URDF file %r has no <drive_limits max_linear_speed="..." max_angular_speed="..."/> '
                         '(m/s, rad/s): add one, as urdf/turtlebot3_burger.urdf has' % urdf_path)
    values = []
    for name in ('max_linear_speed', 'max_angular_speed'):
        try:
            value = float(element.get(name))
        except (TypeError, ValueError):
            value = None
        if value is None or not value > 0.0 or value == float('inf'):
            raise ModelError('URDF file %r: <drive_limits %s=%r> must be a number > 0 (and finite)'
                             % (urdf_path, name, element.get(name)))
        values.append(value)
    return Limits(*values)


def _camera(gazebo, sensor, urdf_path):
    """A CameraSpec of a <gazebo reference=LINK><sensor> block, or ModelError."""
    def text(element, path, default=None):
        found = element.find(path)
        if found is None or found.text is None:
            if default is None:
                raise ModelError('URDF file %r: camera %r has no <%s>' % (urdf_path, sensor.get('name'), path))
            return default
        return found.text.strip()

    def number(element, path, default=None):
        value = text(element, path, default)
        try:
            return float(value)
        except ValueError:
            raise ModelError('URDF file %r: camera %r: <%s> %r is not a number'
                             % (urdf_path, sensor.get('name'), path, value))
    plugin = sensor.find('plugin')
    if plugin is None:
        raise ModelError('URDF file %r: camera %r has no <plugin>' % (urdf_path, sensor.get('name')))
    camera = text(plugin, 'cameraName', 'camera')

    def topic(name, default):
        return camera + '/' + text(plugin, name, default)
    return CameraSpec(
        link=gazebo.get('reference'), name=sensor.get('name', 'camera'), depth=sensor.get('type') == 'depth',
        width=int(number(sensor, 'camera/image/width')), height=int(number(sensor, 'camera/image/height')),
        horizontal_fov=number(sensor, 'camera/horizontal_fov'), near=number(sensor, 'camera/clip/near'),
        far=number(sensor, 'camera/clip/far'), rate=number(plugin, 'updateRate'),
        frame=text(plugin, 'frameName'), image_topic=topic('imageTopicName', 'rgb/image_raw'),
        info_topic=topic('cameraInfoTopicName', 'rgb/camera_info'),
        depth_topic=topic('depthImageTopicName', 'depth/image_raw'),
        depth_info_topic=topic('depthImageCameraInfoTopicName', 'depth/camera_info'),
        points_topic=topic('pointCloudTopicName', 'depth/points'),
        cutoff=number(plugin, 'pointCloudCutoff', '0'))


def _cameras(robot, urdf_path):
    links = set(link.get('name') for link in robot.iter('link'))
    cameras = []
    for gazebo in robot.findall('gazebo'):
        for sensor in gazebo.findall('sensor'):
            if sensor.get('type') in ('camera', 'depth'):
                if gazebo.get('reference') not in links:
                    raise ModelError('URDF file %r: camera %r refers to no link of the file: %r'
                                     % (urdf_path, sensor.get('name'), gazebo.get('reference')))
                cameras.append(_camera(gazebo, sensor, urdf_path))
    return tuple(cameras)


def load_model(urdf_path):
    """The RobotModel of a URDF file, or ModelError naming the file and what it lacks."""
    robot = _parse(urdf_path)
    with open(urdf_path) as urdf:
        return _model(robot, urdf.read(), urdf_path, urdf_path)


def load_model_text(text, name):
    """The RobotModel of a URDF's text (a spawn request's), or ModelError."""
    where = 'the URDF of %s' % name
    try:
        robot = ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise ModelError('%s is not valid XML: %s' % (where, error))
    return _model(robot, text, where, None)


def _model(robot, text, urdf_path, urdf_file):
    casters = tuple(sorted(link.get('name') for link in robot.iter('link')
                           if link.get('name', '').startswith(CASTER_PREFIX)))
    return RobotModel(urdf_file=urdf_file, urdf_text=text, name=robot.get('name', ''),
                      geometry=_drive_geometry(robot, urdf_path), limits=_limits(robot, urdf_path),
                      casters=casters, cameras=_cameras(robot, urdf_path), joints=_joints(robot))


#: The TurtleBot3 family, as TURTLEBOT3_MODEL names it.
TURTLEBOT3_MODELS = ('burger', 'waffle', 'waffle_pi')


def _is_path(model):
    return os.sep in model or model.endswith('.urdf')


def model_problem(model):
    """Why `model` is neither a TurtleBot3 model nor the path of a URDF file; None if it is one."""
    if _is_path(model):
        return None if os.path.isfile(os.path.expanduser(model)) else 'no such URDF file'
    if model not in TURTLEBOT3_MODELS:
        return 'unknown TurtleBot3 model: the models are %s (or give the path of a URDF)' % ', '.join(TURTLEBOT3_MODELS)
    return None


def model_urdf(model, urdf_folder):
    """The URDF file of a model given by TurtleBot3 name (in `urdf_folder`) or by path."""
    problem = model_problem(model)
    if problem:
        raise ModelError('model %r: %s' % (model, problem))
    if _is_path(model):
        return os.path.abspath(os.path.expanduser(model))
    return os.path.join(urdf_folder, 'turtlebot3_%s.urdf' % model)
