"""Gazebo-style models without ROS: pose maths, model files of simple shapes, and the
simulation's registry (names, states in other frames, spawns, teleports, deletes)."""
import math

import pytest

from tb3_sim_nav.frames import IDENTITY, compose, from_rpy, inverse, relative, rotate
from tb3_sim_nav.model_files import ModelFileError, check_urdf, link_shapes, parse_sdf
from tb3_sim_nav.params import resolve
from tb3_sim_nav.robot_model import load_model
from tb3_sim_nav.simulation import ModelStateError, build
from tb3_sim_nav.world_file import Obstacle

QUARTER = from_rpy(0.0, 0.0, math.pi / 2)
SDF = ('<sdf version="1.6"><model name="goal"><static>%s</static><pose>0 0 0.2 0 0 0</pose>'
       '<link name="a"><pose>0.5 0 0 0 0 0</pose><collision name="c"><geometry><box><size>0.1 0.2 0.4</size>'
       '</box></geometry></collision><visual name="v"><geometry><box><size>0.1 0.2 0.4</size></box></geometry>'
       '<material><diffuse>1 0 0 1</diffuse></material></visual></link>%s</model></sdf>')
SECOND_LINK = ('<link name="b"><visual name="v"><geometry><sphere><radius>0.1</radius></sphere></geometry>'
               '</visual></link>')


# --- frames ----------------------------------------------------------------------------

def test_a_pose_composed_with_its_inverse_is_the_identity():
    pose = ((1.0, -2.0, 0.5), from_rpy(0.1, -0.2, 2.0))
    position, orientation = compose(pose, inverse(pose))
    assert position == pytest.approx((0, 0, 0), abs=1e-12)
    assert abs(orientation[3]) == pytest.approx(1.0)


def test_relative_expresses_a_pose_in_another_frame():
    frame = ((1.0, 1.0, 0.0), QUARTER)  # at (1, 1), facing +y
    position, _ = relative(frame, ((1.0, 3.0, 0.0), (0, 0, 0, 1)))
    assert position == pytest.approx((2.0, 0.0, 0.0))  # 2 m straight ahead of it
    assert rotate(QUARTER, (1.0, 0.0, 0.0)) == pytest.approx((0.0, 1.0, 0.0))


# --- model files -------------------------------------------------------------------------

def test_an_sdf_model_of_boxes_parses_with_its_poses_colours_and_static_flag():
    model = parse_sdf(SDF % ('true', ''))
    assert (model.name, model.static) == ('goal', True)
    assert model.pose[0] == (0.0, 0.0, 0.2)
    (link,) = model.links
    assert link.collisions[0].size == (0.1, 0.2, 0.4) and link.visuals[0].color == (1, 0, 0, 1)
    shapes = link_shapes(model)
    assert all(shape.pose[0] == pytest.approx((0.5, 0, 0)) for _, shape, _ in shapes)


@pytest.mark.parametrize('text, problem', [
    ('<sdf><model name="m"><link name="l"><visual name="v"><geometry><mesh><uri>x.dae</uri></mesh></geometry>'
     '</visual></link></model></sdf>', 'a <mesh> cannot be built here'),
    (SDF % ('false', SECOND_LINK), 'a dynamic model of 2 links cannot be built here'),
    ('<model name="m"/>', 'must be <sdf> with exactly one <model>'),
    ('<sdf><model name="m"/></sdf>', 'has no <link>'),
    ('<sdf><model name="m"><link name="l"><visual name="v"><geometry><box><size>1 nan 1</size></box>'
     '</geometry></visual></link></model></sdf>', 'must be 3 finite numbers'),
    ('<sdf><model', 'not valid XML'),
])
def test_a_bad_sdf_is_refused_saying_why(text, problem):
    with pytest.raises(ModelFileError, match=problem):
        parse_sdf(text)


def test_a_urdf_of_simple_shapes_passes_and_one_with_a_mesh_does_not():
    model = check_urdf('<robot name="r"><gazebo><static>true</static></gazebo><link name="l"><visual><geometry>'
                       '<cylinder radius="0.1" length="0.2"/></geometry></visual></link></robot>')
    assert (model.name, model.static, model.links) == ('r', True, ['l'])
    with pytest.raises(ModelFileError, match="link 'l': a visual of <mesh> cannot be built here"):
        check_urdf('<robot name="r"><link name="l"><visual><geometry><mesh filename="a.dae"/></geometry>'
                   '</visual></link></robot>')


# --- the registry --------------------------------------------------------------------------

@pytest.fixture
def simulation(burger_urdf):
    config = resolve(lambda name, default: dict(model=str(burger_urdf), scan_noise=0.0).get(name, default))
    pillar = Obstacle('cylinder', (0.15, 0.4), (2.0, 0.0, 0.2), 0.0, (0, 1, 0, 1), 'pillar')
    made = build(config, [pillar, Obstacle('box', (0.1, 1.0, 0.4), (-1.0, 1.0, 0.2), 0.0, (1, 1, 1, 1))],
                 [('', load_model(str(burger_urdf)), IDENTITY)])
    for _ in range(20):
        made.step()
    yield made
    made.close()


def test_models_are_named_as_gazebo_names_them(simulation):
    assert simulation.model_names() == ['ground_plane', 'pillar', 'box_2', 'turtlebot3_burger']


def test_a_model_state_in_another_models_frame(simulation):
    pose, linear, angular = simulation.model_state('pillar', 'turtlebot3_burger')
    assert pose[0][:2] == pytest.approx((2.0, 0.0), abs=1e-3)  # 2 m ahead of the robot
    simulation.set_model_state('turtlebot3_burger', ((0.0, 0.0, 0.0), QUARTER), (0, 0, 0), (0, 0, 0))
    pose, _, _ = simulation.model_state('pillar', 'turtlebot3_burger')
    assert pose[0][:2] == pytest.approx((0.0, -2.0), abs=1e-3)  # now on its right
    link_pose, _, _ = simulation.model_state('pillar', 'turtlebot3_burger::base_scan')
    assert link_pose[0][2] == pytest.approx(0.2 - 0.182, abs=2e-3)


def test_a_spawned_sdf_box_is_seen_by_the_lidar_moved_and_deleted(simulation):
    robot = simulation.robots['']
    model = parse_sdf(SDF % ('true', ''))
    shapes = [(shape, visual) for _, shape, visual in link_shapes(model)]
    simulation.spawn_object('goal', shapes, compose(((1.0, 0.0, 0.0), (0, 0, 0, 1)), model.pose), True)
    scan_x = robot.body.link_pose('base_scan')[0][0]
    assert robot.scan()[0] == pytest.approx(1.0 + 0.5 - 0.05 - scan_x, abs=0.002)
    simulation.set_model_state('goal', ((0.3, 0.0, 0.2), (0, 0, 0, 0)), (0, 0, 0), (0, 0, 0))
    assert robot.scan()[0] == pytest.approx(0.3 + 0.5 - 0.05 - scan_x, abs=0.002)
    assert simulation.model_state('goal')[0][1] == (0.0, 0.0, 0.0, 1.0)  # a zero quaternion: no rotation
    simulation.delete_model('goal')
    assert robot.scan()[0] == pytest.approx(2.0 - 0.15 - scan_x, abs=0.002)  # the pillar behind it again
    assert 'goal' not in simulation.model_names()


def test_a_spawned_urdf_object_keeps_its_model_frame_whatever_its_centre_of_mass(simulation):
    urdf = ('<robot name="crate"><link name="c"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>'
            '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
            '<box size="0.1 0.1 0.1"/></geometry></collision><visual><geometry><box size="0.1 0.1 0.1"/>'
            '</geometry></visual></link></robot>')
    simulation.spawn_object('crate', None, ((0.0, 2.0, 0.05), (0, 0, 0, 1)), True, urdf=urdf)
    assert simulation.model_state('crate')[0][0] == pytest.approx((0.0, 2.0, 0.05))
    (name, shape), = [item for item in simulation.world.visual_shapes() if item[0] == 'crate']
    assert shape.pose[0] == pytest.approx((0.0, 2.0, 0.05)) and shape.size == pytest.approx((0.1, 0.1, 0.1))


def test_bad_requests_change_nothing(simulation):
    before = simulation.model_state('turtlebot3_burger')[0]
    with pytest.raises(ModelStateError, match="no model is named 'ghost'"):
        simulation.model_state('ghost')
    with pytest.raises(ModelStateError, match="reference frame 'nowhere'"):
        simulation.model_state('pillar', 'nowhere')
    with pytest.raises(ModelStateError, match='inside obstacle 1 of the world \\(pillar\\)'):
        simulation.set_model_state('turtlebot3_burger', ((2.0, 0.0, 0.0), (0, 0, 0, 1)), (0, 0, 0), (0, 0, 0))
    with pytest.raises(ModelStateError, match='non-finite'):
        simulation.set_model_state('turtlebot3_burger', ((math.inf, 0.0, 0.0), (0, 0, 0, 1)), (0, 0, 0), (0, 0, 0))
    with pytest.raises(ModelStateError, match="already named 'pillar'"):
        simulation.spawn_object('pillar', [], ((5.0, 5.0, 0.0), (0, 0, 0, 1)), True)
    with pytest.raises(ModelStateError, match='cannot be deleted'):
        simulation.delete_model('ground_plane')
    assert simulation.model_state('turtlebot3_burger')[0][0] == pytest.approx(before[0], abs=1e-6)


def test_reset_world_puts_spawned_objects_back_too(simulation):
    box = parse_sdf(SDF % ('false', ''))
    (link,) = box.links
    simulation.spawn_object('loose', [(shape, False) for shape in link.collisions], ((0.0, -1.5, 0.3), (0, 0, 0, 1)),
                            False, link.mass)
    for _ in range(100):  # it falls to the ground
        simulation.step()
    assert simulation.model_state('loose')[0][0][2] < 0.25
    simulation.reset_world()
    assert simulation.model_state('loose')[0][0] == pytest.approx((0.0, -1.5, 0.3), abs=1e-6)


def test_a_robot_deleted_is_gone_from_the_world(simulation):
    simulation.delete_model('turtlebot3_burger')
    assert simulation.robots == {} and 'turtlebot3_burger' not in simulation.model_names()
    assert simulation.world.p.getNumBodies() == 3  # the ground and two obstacles
