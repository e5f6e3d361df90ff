"""Drive geometry read from the robot's URDF: the one source of truth."""
import os
import xml.etree.ElementTree as ElementTree
from collections import namedtuple

LEFT_WHEEL_JOINT = 'wheel_left_joint'
RIGHT_WHEEL_JOINT = 'wheel_right_joint'

# pybullet reports a multibody's base pose at the base's centre of mass, and
# gives a link without <inertial> 1 kg: the root gets this tiny one at its origin.
ROOT_INERTIAL = ('<inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="0.001"/>'
                 '<inertia ixx="1e-7" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial>')

DriveGeometry = namedtuple('DriveGeometry', 'wheel_radius wheel_separation')


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


def urdf_for_pybullet(urdf_path):
    """The URDF's text with a tiny <inertial> added to a root link that has none."""
    robot = _parse(urdf_path)
    root = root_link(robot)
    if root.find('inertial') is None:
        root.append(ElementTree.fromstring(ROOT_INERTIAL))
    return ElementTree.tostring(robot, encoding='unicode')


def read_drive_geometry(urdf_path):
    """Wheel radius (m) and separation (m) of a two-wheeled URDF."""
    robot = _parse(urdf_path)
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
