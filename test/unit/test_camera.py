"""Cameras of the Waffle and Waffle Pi, rendered by real pybullet, without ROS:
what the geometry predicts is where it appears, and depth agrees with the lidar."""
import math

import numpy as np
import pytest

from tb3_sim_nav.camera import DEFAULT_MAX_WIDTH, camera_size
from tb3_sim_nav.frames import IDENTITY
from tb3_sim_nav.params import resolve
from tb3_sim_nav.robot_model import load_model
from tb3_sim_nav.simulation import build
from tb3_sim_nav.world_file import Obstacle

RED = (1.0, 0.0, 0.0, 1.0)


def box(x, y, size=(0.1, 0.1, 0.4), color=(0.8, 0.8, 0.8, 1.0)):
    return Obstacle('box', size, (x, y, size[2] / 2), 0.0, color)


@pytest.fixture
def make(repo):
    """make(model, obstacles, **parameters): (simulation, its one robot), closed after the test."""
    made = []

    def make_robot(name, obstacles=(), **parameters):
        model = load_model(str(repo / 'urdf' / ('turtlebot3_%s.urdf' % name)))
        parameters.setdefault('model', model.urdf_file)
        parameters.setdefault('scan_noise', 0.0)
        config = resolve(lambda key, default: parameters.get(key, default))
        simulation = build(config, obstacles, [('', model, IDENTITY)])
        made.append(simulation)
        for _ in range(50):
            simulation.step()
        return simulation, simulation.robots['']
    yield make_robot
    for simulation in made:
        simulation.close()


def camera_x(robot):
    """The camera's position along the robot's x axis, from the world (robot at the origin, facing +x)."""
    return robot.body.link_pose(robot.cameras[0].spec.link)[0]


def test_sizes_follow_the_model_and_what_is_asked(repo):
    r200 = load_model(str(repo / 'urdf' / 'turtlebot3_waffle.urdf')).cameras[0]
    pi = load_model(str(repo / 'urdf' / 'turtlebot3_waffle_pi.urdf')).cameras[0]
    assert (r200.width, r200.height, pi.width, pi.height) == (1920, 1080, 640, 480)
    assert camera_size(pi) == (640, 480)
    assert camera_size(r200) == (DEFAULT_MAX_WIDTH, 360)  # scaled down, the aspect kept
    assert camera_size(r200, width=1920) == (1920, 1080)
    assert camera_size(r200, height=270) == (480, 270)
    assert camera_size(pi, 100, 100) == (100, 100)


def test_the_burger_has_no_camera_and_the_waffles_one_each(make):
    assert make('burger')[1].cameras == []
    for name in ('waffle', 'waffle_pi'):
        (camera,) = make(name)[1].cameras
        assert camera.spec.frame == 'camera_rgb_optical_frame'


@pytest.mark.parametrize('model', ['waffle', 'waffle_pi'])
@pytest.mark.parametrize('lateral', [0.0, 0.25, -0.3])
def test_a_red_box_appears_at_the_column_the_geometry_predicts(make, model, lateral):
    distance = 1.5
    simulation, robot = make(model, [box(distance, lateral, color=RED)])
    camera = robot.cameras[0]
    (cx, cy, cz) = camera_x(robot)
    rgb, _ = camera.render()
    red = (rgb[..., 0] > 150) & (rgb[..., 1] < 80) & (rgb[..., 2] < 80)
    columns = np.nonzero(red.any(axis=0))[0]
    assert len(columns), 'no red pixel in the image'
    # The box's outline is that of its four vertical edges (x, y) = (distance
    # +- 0.05, lateral +- 0.05), each at column u = cx - fx (y - y_camera) / (x - x_camera).
    edges = [camera.cx - camera.fx * (y - cy) / (x - cx)
             for x in (distance - 0.05, distance + 0.05) for y in (lateral - 0.05, lateral + 0.05)]
    assert columns.min() == pytest.approx(min(edges), abs=2.0)
    assert columns.max() == pytest.approx(max(edges), abs=2.0)


def test_the_waffles_depth_at_the_centre_is_the_lidars_range_to_the_wall(make):
    wall = 1.7  # x of the wall's near face
    simulation, robot = make('waffle', [box(wall + 0.05, 0.0, size=(0.1, 3.0, 0.5))])
    camera = robot.cameras[0]
    _, depth = camera.render()
    centre = depth[int(camera.cy), int(camera.cx)]
    lidar_x = robot.body.link_pose('base_scan')[0][0]
    lidar_range = robot.scan()[0]  # beam 0 looks straight ahead
    assert centre + camera_x(robot)[0] == pytest.approx(wall, abs=0.005)
    assert centre + camera_x(robot)[0] == pytest.approx(lidar_range + lidar_x, abs=0.02)


def test_depth_is_nan_where_nothing_is_near_enough_or_too_near(make):
    simulation, robot = make('waffle', [box(0.3, 0.0, size=(0.1, 3.0, 2.0))])  # 0.16 m ahead of the camera
    _, depth = robot.cameras[0].render()
    assert np.isnan(depth).all()  # closer than the R200's 0.4 m cutoff
    simulation, robot = make('waffle')
    camera = robot.cameras[0]
    _, depth = camera.render()
    assert np.isnan(depth[:10]).all()  # the sky: nothing within the far clip
    horizon = int(camera.cy)
    assert np.isfinite(depth[horizon + 10:horizon + 40]).all()  # the ground, 1 to 5 m ahead
    assert np.isnan(depth[-10:]).all()  # the ground, nearer than the cutoff


def test_the_cloud_puts_each_pixel_at_its_ray_and_depth(make):
    simulation, robot = make('waffle', [box(1.7, 0.0, size=(0.1, 3.0, 0.5))])
    camera = robot.cameras[0]
    _, depth = camera.render()
    points = camera.points(depth)
    row, column = int(camera.cy), 100
    x, y, z = points[row, column]
    assert z == depth[row, column]
    assert x == pytest.approx((column - camera.cx) * z / camera.fx)
    assert abs(y) < 0.01  # the centre row lies on the optical axis' plane


def test_k_agrees_with_the_field_of_view_and_size(make):
    (camera,) = make('waffle_pi', camera_width=320, camera_horizontal_fov=1.2)[1].cameras
    fx, _, cx, _, fy, cy, _, _, one = camera.intrinsics()
    assert (camera.width, camera.height) == (320, 240)
    assert 2 * math.atan(camera.width / 2.0 / fx) == pytest.approx(1.2)
    assert (fx, cx, cy, one) == (fy, 159.5, 119.5, 1.0)
