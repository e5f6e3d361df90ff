"""The three TurtleBot3 URDFs against ROBOTIS' facts (DESIGN.md): drive
geometry and limits, casters, where the sensors sit, and the Waffles' cameras."""
import math
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

from tb3_sim_nav.robot_model import read_drive_geometry

BASE_HEIGHT = 0.010  # base_joint: base_link above base_footprint

# model: wheel separation, (max linear, max angular) speed,
#        sensor positions in base_link as ROBOTIS gives them.
MODELS = {
    'burger': (0.160, (0.22, 2.84),
               {'imu_link': (-0.032, 0, 0.068), 'base_scan': (-0.032, 0, 0.172)}),
    'waffle': (0.288, (0.26, 1.82),
               {'imu_link': (0, 0, 0.068), 'base_scan': (-0.064, 0, 0.122),
                'camera_link': (0.064, -0.065, 0.094)}),
    'waffle_pi': (0.288, (0.26, 1.82),
                  {'imu_link': (0, 0, 0.068), 'base_scan': (-0.064, 0, 0.122),
                   'camera_link': (0.073, -0.011, 0.084)}),
}

# model: sensor type, width, height, horizontal FOV (rad), and the topics its plugin names
CAMERAS = {
    'waffle': ('depth', 1920, 1080, 1.3439,
               {'imageTopicName': 'rgb/image_raw', 'cameraInfoTopicName': 'rgb/camera_info',
                'depthImageTopicName': 'depth/image_raw', 'pointCloudTopicName': 'depth/points',
                'depthImageCameraInfoTopicName': 'depth/camera_info'}),
    'waffle_pi': ('camera', 640, 480, 1.085595,
                  {'imageTopicName': 'rgb/image_raw', 'cameraInfoTopicName': 'rgb/camera_info'}),
}

# The simulator takes a link whose name starts with caster_ for a frictionless caster.
CASTERS = {'burger': ['caster_back_link'],
           'waffle': ['caster_back_left_link', 'caster_back_right_link'],
           'waffle_pi': ['caster_back_left_link', 'caster_back_right_link']}

OPTICAL_FRAMES = {'burger': [],
                  'waffle': ['camera_depth_optical_frame', 'camera_rgb_optical_frame'],
                  'waffle_pi': ['camera_rgb_optical_frame']}


@pytest.fixture(params=sorted(MODELS))
def model(request, repo):
    """(name, path, parsed <robot>) of each shipped URDF."""
    path = repo / 'urdf' / ('turtlebot3_%s.urdf' % request.param)
    return request.param, str(path), ElementTree.parse(str(path)).getroot()


def origin(element, key):
    """The three numbers of an element's <origin key="...">, zeros if it has none."""
    tag = element.find('origin')
    return [float(value) for value in (tag.get(key, '0 0 0') if tag is not None else '0 0 0').split()]


def origin_matrix(joint):
    """The 4 x 4 transform of a joint's <origin> (URDF: rotate about x, y, then z)."""
    roll, pitch, yaw = origin(joint, 'rpy')
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch),
                              math.sin(pitch), math.cos(yaw), math.sin(yaw))
    matrix = np.identity(4)
    matrix[:3, :3] = (np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
                      .dot([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
                      .dot([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]))
    matrix[:3, 3] = origin(joint, 'xyz')
    return matrix


def in_footprint(robot, link):
    """The pose of `link` in base_footprint, composed up the joint chain."""
    joint_to = {joint.find('child').get('link'): joint for joint in robot.iter('joint')}
    pose = np.identity(4)
    while link != 'base_footprint':
        joint = joint_to[link]
        pose = origin_matrix(joint).dot(pose)
        link = joint.find('parent').get('link')
    return pose


def test_drive_geometry(model):
    name, path, _robot = model
    geometry = read_drive_geometry(path)
    assert geometry.wheel_radius == pytest.approx(0.033, abs=1e-9)
    assert geometry.wheel_separation == pytest.approx(MODELS[name][0], abs=1e-9)


def test_drive_limits(model):
    name, _path, robot = model
    limits = robot.findall('drive_limits')
    assert len(limits) == 1
    assert (float(limits[0].get('max_linear_speed')),
            float(limits[0].get('max_angular_speed'))) == MODELS[name][1]


def test_every_link_but_the_root_has_an_inertial(model):
    _name, _path, robot = model
    lacking = [link.get('name') for link in robot.iter('link') if link.find('inertial') is None]
    assert lacking == ['base_footprint']


def test_casters_are_spheres_touching_the_ground(model):
    name, _path, robot = model
    casters = sorted(link.get('name') for link in robot.iter('link')
                     if link.get('name').startswith('caster_'))
    assert casters == CASTERS[name]
    for link in casters:
        collision = robot.find("link[@name='%s']/collision" % link)
        centre = in_footprint(robot, link).dot(np.append(origin(collision, 'xyz'), 1.0))
        radius = float(collision.find('geometry/sphere').get('radius'))
        assert centre[2] - radius == pytest.approx(0.0, abs=1e-9), link


def test_sensor_positions_in_base_footprint(model):
    name, _path, robot = model
    for link, (x, y, z) in MODELS[name][2].items():
        position = in_footprint(robot, link)[:3, 3]
        assert position == pytest.approx([x, y, z + BASE_HEIGHT], abs=1e-9), link


def test_optical_frames_look_forward_right_down(model):
    """REP 103: an optical frame's z is the robot's forward, x its right, y down."""
    name, _path, robot = model
    optical = sorted(link.get('name') for link in robot.iter('link')
                     if link.get('name').endswith('_optical_frame'))
    assert optical == OPTICAL_FRAMES[name]
    # Columns: the optical frame's x, y and z axes in base_footprint.
    right_down_forward = np.array([[0, 0, 1], [-1, 0, 0], [0, -1, 0]])
    for link in optical:
        assert np.allclose(in_footprint(robot, link)[:3, :3], right_down_forward, atol=1e-12), link


def test_camera_sensor_as_robotis_gazebo(model):
    name, _path, robot = model
    blocks = robot.findall("gazebo[@reference='camera_rgb_frame']")
    if name not in CAMERAS:
        assert blocks == []
        return
    kind, width, height, fov, topics = CAMERAS[name]
    assert len(blocks) == 1
    sensor = blocks[0].find('sensor')
    assert sensor.get('type') == kind
    camera = sensor.find('camera')
    assert int(camera.find('image/width').text) == width
    assert int(camera.find('image/height').text) == height
    assert camera.find('image/format').text == 'R8G8B8'
    assert float(camera.find('horizontal_fov').text) == fov
    assert (float(camera.find('clip/near').text), float(camera.find('clip/far').text)) == (0.03, 100)
    plugin = sensor.find('plugin')
    assert float(plugin.find('updateRate').text) == 30.0
    assert plugin.find('cameraName').text == 'camera'
    assert plugin.find('frameName').text == 'camera_rgb_optical_frame'
    assert {key: plugin.find(key).text for key in topics} == topics
    assert robot.find("link[@name='camera_rgb_optical_frame']") is not None
