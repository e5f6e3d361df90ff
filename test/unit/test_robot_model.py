"""The Burger URDF and what robot_model reads from it."""
import xml.etree.ElementTree as ElementTree

import pytest

from tb3_sim_nav.robot_model import (
    ModelError,
    load_model,
    model_urdf,
    read_drive_geometry,
    root_link,
    urdf_for_pybullet,
)

WHEEL_LINK = ('<link name="{0}"><collision><geometry><sphere radius="0.033"/></geometry>'
              '</collision></link>')
WHEEL_JOINT = ('<joint name="{0}" type="continuous"><parent link="base"/><child link="{1}"/>'
               '<origin xyz="0 {2} 0.023"/><axis xyz="0 0 1"/></joint>')


def write(tmp_path, body, name='robot.urdf'):
    path = tmp_path / name
    path.write_text('<?xml version="1.0"?><robot name="r">%s</robot>' % body)
    return path


def two_wheels(left_child='wheel_left_link', right_child='wheel_right_link'):
    return ('<link name="base"/>'
            + WHEEL_LINK.format('wheel_left_link') + WHEEL_LINK.format('wheel_right_link')
            + WHEEL_JOINT.format('wheel_left_joint', left_child, 0.08)
            + WHEEL_JOINT.format('wheel_right_joint', right_child, -0.08))


def shipped(burger_urdf):
    return ElementTree.parse(str(burger_urdf)).getroot()


# --- read_drive_geometry -------------------------------------------------------------

def test_read_drive_geometry_of_shipped_urdf(burger_urdf):
    geometry = read_drive_geometry(str(burger_urdf))
    assert geometry.wheel_radius == pytest.approx(0.033, abs=1e-9)
    assert geometry.wheel_separation == pytest.approx(0.160, abs=1e-9)


def test_read_drive_geometry_of_minimal_two_wheeler(tmp_path):
    geometry = read_drive_geometry(str(write(tmp_path, two_wheels())))
    assert geometry == pytest.approx((0.033, 0.16))


def test_missing_file_raises_model_error_naming_it(tmp_path):
    path = str(tmp_path / 'no_such_robot.urdf')
    with pytest.raises(ModelError, match='no_such_robot.urdf'):
        read_drive_geometry(path)
    with pytest.raises(ModelError, match='no_such_robot.urdf'):
        urdf_for_pybullet(path)


def test_invalid_xml_raises_model_error_naming_the_file(tmp_path):
    path = tmp_path / 'broken.urdf'
    path.write_text('<robot name="r"><link name="base">')
    with pytest.raises(ModelError, match='broken.urdf'):
        read_drive_geometry(str(path))
    with pytest.raises(ModelError, match='broken.urdf'):
        urdf_for_pybullet(str(path))


def test_urdf_without_wheel_joints_raises_model_error_naming_file_and_joint(tmp_path):
    path = write(tmp_path, '<link name="base"/>', name='wheelless.urdf')
    with pytest.raises(ModelError, match='wheelless.urdf') as error:
        read_drive_geometry(str(path))
    assert 'wheel_left_joint' in str(error.value)


def test_wheel_joint_to_undefined_link_raises_model_error_naming_the_file(tmp_path):
    path = write(tmp_path, two_wheels(left_child='ghost_link'), name='dangling.urdf')
    with pytest.raises(ModelError, match='dangling.urdf'):
        read_drive_geometry(str(path))


# --- urdf_for_pybullet -----------------------------------------------------------------

def test_urdf_for_pybullet_adds_tiny_inertial_to_bare_root(burger_urdf):
    robot = ElementTree.fromstring(urdf_for_pybullet(str(burger_urdf)))
    root = root_link(robot)
    assert root.get('name') == 'base_footprint'
    inertials = root.findall('inertial')
    assert len(inertials) == 1
    assert 0.0 < float(inertials[0].find('mass').get('value')) <= 0.001


def test_urdf_for_pybullet_keeps_existing_root_inertial(tmp_path):
    body = two_wheels().replace(
        '<link name="base"/>',
        '<link name="base"><inertial><mass value="2.5"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>')
    robot = ElementTree.fromstring(urdf_for_pybullet(str(write(tmp_path, body))))
    inertials = root_link(robot).findall('inertial')
    assert len(inertials) == 1
    assert inertials[0].find('mass').get('value') == '2.5'


def test_urdf_for_pybullet_leaves_other_links_alone(burger_urdf):
    before = shipped(burger_urdf)
    after = ElementTree.fromstring(urdf_for_pybullet(str(burger_urdf)))
    for link in before.iter('link'):
        if link.get('name') == 'base_footprint':
            continue
        twin = after.find("link[@name='%s']" % link.get('name'))
        assert ElementTree.tostring(twin) == ElementTree.tostring(link)


# --- the shipped URDF against DESIGN.md's facts ------------------------------------------

def test_every_non_root_link_of_shipped_urdf_has_an_inertial(burger_urdf):
    robot = shipped(burger_urdf)
    root = root_link(robot).get('name')
    lacking = [link.get('name') for link in robot.iter('link')
               if link.get('name') != root and link.find('inertial') is None]
    assert lacking == []


@pytest.mark.parametrize('joint, parent, child, xyz', [
    ('base_joint', 'base_footprint', 'base_link', (0.0, 0.0, 0.010)),
    ('wheel_left_joint', 'base_link', 'wheel_left_link', (0.0, 0.08, 0.023)),
    ('wheel_right_joint', 'base_link', 'wheel_right_link', (0.0, -0.08, 0.023)),
    ('caster_back_joint', 'base_link', 'caster_back_link', (-0.081, 0.0, -0.004)),
    ('imu_joint', 'base_link', 'imu_link', (-0.032, 0.0, 0.068)),
    ('scan_joint', 'base_link', 'base_scan', (-0.032, 0.0, 0.172)),
])
def test_shipped_joint_origins_match_design(burger_urdf, joint, parent, child, xyz):
    element = shipped(burger_urdf).find("joint[@name='%s']" % joint)
    assert element is not None, 'no joint %s' % joint
    assert element.find('parent').get('link') == parent
    assert element.find('child').get('link') == child
    got = [float(value) for value in element.find('origin').get('xyz').split()]
    assert got == pytest.approx(xyz, abs=1e-9)


def test_shipped_wheel_joints_spin_about_the_axle(burger_urdf):
    robot = shipped(burger_urdf)
    for name in ('wheel_left_joint', 'wheel_right_joint'):
        joint = robot.find("joint[@name='%s']" % name)
        assert joint.get('type') == 'continuous'
        rpy = [float(value) for value in joint.find('origin').get('rpy').split()]
        axis = [float(value) for value in joint.find('axis').get('xyz').split()]
        # The joint frame is rolled -90 deg, so its z axis is the robot's +y axis.
        assert rpy == pytest.approx([-1.5707963267948966, 0.0, 0.0])
        assert axis == [0.0, 0.0, 1.0]


def test_shipped_base_link_mass(burger_urdf):
    mass = shipped(burger_urdf).find("link[@name='base_link']/inertial/mass")
    assert float(mass.get('value')) == pytest.approx(0.83, abs=0.01)


# --- load_model: limits and casters; model_urdf ------------------------------------------

def test_the_burger_model_has_robotis_limits_and_its_caster(burger_urdf):
    model = load_model(str(burger_urdf))
    assert model.name == 'turtlebot3_burger'
    assert model.limits == (0.22, 2.84)
    assert model.geometry == pytest.approx((0.033, 0.160))
    assert model.casters == ('caster_back_link',)


def test_a_urdf_without_drive_limits_is_refused_naming_the_element(tmp_path):
    path = write(tmp_path, two_wheels(), name='limitless.urdf')
    with pytest.raises(ModelError, match='limitless.urdf.*drive_limits'):
        load_model(str(path))


@pytest.mark.parametrize('attributes', ['max_linear_speed="0.2"', 'max_linear_speed="0" max_angular_speed="1"',
                                        'max_linear_speed="fast" max_angular_speed="1"',
                                        'max_linear_speed="0.2" max_angular_speed="inf"'])
def test_bad_drive_limits_are_refused(tmp_path, attributes):
    path = write(tmp_path, two_wheels() + '<drive_limits %s/>' % attributes, name='bad_limits.urdf')
    with pytest.raises(ModelError, match="bad_limits.urdf': <drive_limits max_"):
        load_model(str(path))


def test_models_by_name_are_urdfs_of_the_folder_and_paths_are_paths(tmp_path):
    assert model_urdf('waffle_pi', '/pkg/urdf') == '/pkg/urdf/turtlebot3_waffle_pi.urdf'
    mine = write(tmp_path, two_wheels(), name='mine.urdf')
    assert model_urdf(str(mine), '/pkg/urdf') == str(mine)
    with pytest.raises(ModelError, match="model '.*/gone.urdf': no such URDF file"):
        model_urdf(str(tmp_path / 'gone.urdf'), '/pkg/urdf')


def test_an_unknown_model_is_refused_naming_the_three(tmp_path):
    with pytest.raises(ModelError, match="model 'wafle': unknown TurtleBot3 model: the models are burger, "
                                         "waffle, waffle_pi"):
        model_urdf('wafle', '/pkg/urdf')


# --- joints: what robot_state_publisher makes of them ----------------------

def _kdl_pose(joint, position):
    """The joint's child in its parent at `position` as KDL computes it for
    robot_state_publisher (kdl_parser: the joint turns or slides about its
    axis, given in the parent frame through the origin; the segment's tip is
    the origin)."""
    import PyKDL
    (x, y, z), (qx, qy, qz, qw) = joint.origin
    origin = PyKDL.Frame(PyKDL.Rotation.Quaternion(qx, qy, qz, qw), PyKDL.Vector(x, y, z))
    axis = origin.M * PyKDL.Vector(*joint.axis)
    kind = {'revolute': PyKDL.Joint.RotAxis, 'continuous': PyKDL.Joint.RotAxis,
            'prismatic': PyKDL.Joint.TransAxis}
    kdl_joint = (PyKDL.Joint(joint.name, origin.p, axis, kind[joint.kind]) if joint.kind in kind
                 else PyKDL.Joint(joint.name))
    frame = PyKDL.Segment(joint.child, kdl_joint, origin).pose(position)
    return (frame.p[0], frame.p[1], frame.p[2]), frame.M.GetQuaternion()


def _same_pose(a, b):
    (position_a, rotation_a), (position_b, rotation_b) = a, b
    sign = 1.0 if sum(u * v for u, v in zip(rotation_a, rotation_b)) >= 0.0 else -1.0
    return (max(abs(u - v) for u, v in zip(position_a, position_b)) < 1e-12
            and max(abs(u - sign * v) for u, v in zip(rotation_a, rotation_b)) < 1e-12)


@pytest.mark.parametrize('model', ['burger', 'waffle', 'waffle_pi'])
def test_every_joint_of_the_shipped_urdfs_is_where_kdl_puts_it(model):
    import os
    import random
    urdfs = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), 'urdf')
    joints = load_model(model_urdf(model, urdfs)).joints
    assert {joint.name for joint in joints if joint.moving} == {'wheel_left_joint', 'wheel_right_joint'}
    assert len([joint for joint in joints if joint.fixed]) >= 4  # base, imu, scan, casters (and cameras)
    rng = random.Random(7)
    for joint in joints:
        for position in [0.0, 1.0, -2.5] + [rng.uniform(-20.0, 20.0) for _ in range(5)]:
            assert _same_pose(joint.pose(position), _kdl_pose(joint, position)), (joint.name, position)


def test_joint_kinds_defaults_and_transmissions(tmp_path):
    """URDF's defaults (no origin: the parent's frame; no axis: x), a slanted
    axis, a prismatic joint, a floating one left out as robot_state_publisher
    leaves it, and a <transmission>'s <joint> not taken for a joint."""
    body = two_wheels() + '<drive_limits max_linear_speed="0.22" max_angular_speed="2.84"/>' + (
        '<link name="arm"/><link name="slide"/><link name="free"/><link name="flat"/>'
        '<joint name="arm_joint" type="revolute"><parent link="base"/><child link="arm"/>'
        '<origin xyz="0.1 0 0.2" rpy="0.3 -0.2 1.1"/><axis xyz="1 1 0"/></joint>'
        '<joint name="slide_joint" type="prismatic"><parent link="arm"/><child link="slide"/>'
        '<axis xyz="0 0 2"/></joint>'
        '<joint name="free_joint" type="floating"><parent link="base"/><child link="free"/></joint>'
        '<joint name="flat_joint" type="fixed"><parent link="base"/><child link="flat"/></joint>'
        '<transmission name="t"><joint name="arm_joint"><hardwareInterface>x</hardwareInterface></joint>'
        '</transmission>')
    joints = {joint.name: joint for joint in load_model(str(write(tmp_path, body))).joints}
    assert sorted(joints) == ['arm_joint', 'flat_joint', 'free_joint', 'slide_joint', 'wheel_left_joint',
                              'wheel_right_joint']
    assert [name for name, joint in sorted(joints.items()) if joint.fixed] == ['flat_joint']
    assert not joints['free_joint'].fixed and not joints['free_joint'].moving
    assert joints['flat_joint'].pose(5.0) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert joints['slide_joint'].axis == (0.0, 0.0, 1.0)
    assert _same_pose(joints['slide_joint'].pose(0.25), ((0.0, 0.0, 0.25), (0.0, 0.0, 0.0, 1.0)))
    for position in (0.0, 0.7, -3.0):
        assert _same_pose(joints['arm_joint'].pose(position), _kdl_pose(joints['arm_joint'], position))
        assert _same_pose(joints['slide_joint'].pose(position), _kdl_pose(joints['slide_joint'], position))
