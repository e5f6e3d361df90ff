"""ROBOTIS' worlds as their launches use them (real pybullet, no ROS).

For tb3_house.launch and tb3_stage_1.launch ... tb3_stage_4.launch, the
world and the spawn pose are read from the launch file's argument defaults:
the world loads and names every obstacle once; the spawn pose is free for
each TurtleBot3 model (the simulator refuses one inside an obstacle); and
the Burger's lidar there reads, beam for beam, the distance that a 2-D ray
cast of its own finds against the boxes and cylinders of the YAML file,
read here with yaml and not with world_file. Only obstacles whose height
range covers the lidar's plane (base_scan, 0.182 m above the ground on the
Burger) are in the ray cast: pieces above doors and table tops pass over
the beams, low ones under them.
"""
import math
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest
import yaml

from tb3_sim_nav.frames import planar
from tb3_sim_nav.params import resolve
from tb3_sim_nav.robot_model import TURTLEBOT3_MODELS, load_model
from tb3_sim_nav.simulation import build
from tb3_sim_nav.world_file import load_world

LAUNCHES = ['tb3_house.launch', 'tb3_stage_1.launch', 'tb3_stage_2.launch', 'tb3_stage_3.launch',
            'tb3_stage_4.launch']
# ROBOTIS' multi_turtlebot3.launch (turtlebot3_gazebo, noetic-devel): (x, y, yaw)
# of tb3_0, tb3_1 and tb3_2 in turtlebot3_house.world.
HOUSE_MULTI_POSES = {'tb3_0': (-7.0, -1.0, 1.57), 'tb3_1': (7.0, -1.0, 1.57), 'tb3_2': (0.5, 3.0, 0.0)}

SCAN_OFFSET = (-0.032, 0.182)  # Burger: base_scan's x and height above the ground, in base_footprint
AGREE = 0.01                   # m: a beam agrees with the ray cast within this
AGREEING_SHARE = 0.9           # of the beams
SEEN_SHARE = 0.25              # at least this share of the beams hits a wall within range
SETTLE = 0.5                   # sim s before the scan is read


def launch_defaults(repo, launch):
    """{argument: default} of a launch file."""
    root = ElementTree.parse(str(repo / 'launch' / launch)).getroot()
    return {arg.get('name'): arg.get('default') for arg in root.findall('arg')}  # its own, not its includes'


def spawn_of(repo, launch):
    """(world, (x, y, z)) of a launch's defaults."""
    defaults = launch_defaults(repo, launch)
    return defaults['world'], tuple(float(defaults[axis + '_pos']) for axis in 'xyz')


@pytest.fixture
def make(repo):
    """make(robots, obstacles, model=..): a Simulation of `robots` [(name, model, (x, y, z, yaw))],
    the lidar without noise; closed after the test."""
    made = []

    def make_simulation(robots, obstacles, model='burger'):
        urdf = str(repo / 'urdf' / ('turtlebot3_%s.urdf' % model))
        config = resolve(lambda name, default: {'model': urdf, 'scan_noise': 0.0}.get(name, default))
        simulation = build(config, obstacles, [(name, load_model(urdf), planar(*pose)) for name, pose in robots])
        made.append(simulation)
        return simulation
    yield make_simulation
    for simulation in made:
        simulation.close()


# --- the worlds and their spawn poses ----------------------------------------------

@pytest.mark.parametrize('launch', LAUNCHES)
def test_the_world_loads_and_names_every_obstacle_once(launch, repo, worlds_folder):
    world, _ = spawn_of(repo, launch)
    assert world == 'turtlebot3_' + launch[len('tb3_'):-len('.launch')]  # tb3_house.launch: turtlebot3_house
    obstacles = load_world(world, str(worlds_folder)).obstacles
    names = [obstacle.name for obstacle in obstacles]
    assert obstacles and all(names), names
    assert len(set(names)) == len(names), sorted(name for name in names if names.count(name) > 1)


@pytest.mark.parametrize('model', TURTLEBOT3_MODELS)
@pytest.mark.parametrize('launch', LAUNCHES)
def test_the_launch_spawn_pose_is_free_for_each_model(launch, model, repo, worlds_folder, make):
    world, (x, y, z) = spawn_of(repo, launch)
    make([('', (x, y, z, 0.0))], load_world(world, str(worlds_folder)).obstacles, model)  # no ValueError


def test_multi_tb3_launch_starts_as_robotis_multi_turtlebot3_launch(repo):
    defaults = launch_defaults(repo, 'multi_tb3.launch')
    assert defaults['world'] == 'turtlebot3_house'
    for order, name in enumerate(['first', 'second', 'third']):
        robot = 'tb3_%d' % order
        assert defaults[name + '_tb3'] == robot
        assert tuple(float(defaults['%s_tb3_%s' % (name, key)]) for key in ('x_pos', 'y_pos', 'yaw')) == \
            HOUSE_MULTI_POSES[robot]


def test_robotis_three_robot_poses_in_the_house_are_free_together(worlds_folder, make):
    simulation = make([(name, (x, y, 0.0, yaw)) for name, (x, y, yaw) in sorted(HOUSE_MULTI_POSES.items())],
                      load_world('turtlebot3_house', str(worlds_folder)).obstacles)
    assert sorted(simulation.robots) == sorted(HOUSE_MULTI_POSES)


# --- the lidar against a ray cast of the world file ----------------------------------

def _box_hit(origin, direction, shape):
    """Distance along a ray (2-D) to a box's footprint (slabs in the box's own axes), inf if none."""
    cx, cy = shape['position'][:2]
    yaw = shape.get('yaw', 0.0)
    cos, sin = math.cos(yaw), math.sin(yaw)
    dx, dy = origin[0] - cx, origin[1] - cy
    start = (cos * dx + sin * dy, -sin * dx + cos * dy)
    heading = (cos * direction[0] + sin * direction[1], -sin * direction[0] + cos * direction[1])
    near, far = -math.inf, math.inf
    for start_i, heading_i, half in zip(start, heading, (shape['size'][0] / 2, shape['size'][1] / 2)):
        if heading_i == 0.0:
            if abs(start_i) > half:
                return math.inf
            continue
        first, second = sorted(((-half - start_i) / heading_i, (half - start_i) / heading_i))
        near, far = max(near, first), min(far, second)
    return near if 0.0 <= near <= far else math.inf


def _cylinder_hit(origin, direction, shape):
    """Distance along a ray (2-D) to a cylinder's circle, inf if none."""
    dx, dy = origin[0] - shape['position'][0], origin[1] - shape['position'][1]
    half_chord = (dx * direction[0] + dy * direction[1]) ** 2 - (dx * dx + dy * dy - shape['radius'] ** 2)
    if half_chord < 0.0:
        return math.inf
    distance = -(dx * direction[0] + dy * direction[1]) - math.sqrt(half_chord)
    return distance if distance >= 0.0 else math.inf


def shapes_at_height(world_file, height):
    """(kind, fields) of the world file's obstacles whose height range covers `height`."""
    with open(world_file) as stream:
        entries = yaml.safe_load(stream)['obstacles']
    shapes = []
    # A model's shapes stand where the file puts them, as the others do.
    for entry in [shape for entry in entries for shape in entry.get('model', {}).get('shapes', [entry])]:
        ((kind, fields),) = entry.items()
        tall = fields['size'][2] if kind == 'box' else fields['height']
        position = fields.get('position', [0.0, 0.0])
        centre = position[2] if len(position) == 3 else tall / 2  # on the ground unless given
        if centre - tall / 2 <= height <= centre + tall / 2:
            shapes.append((kind, fields))
    return shapes


def ray_cast(shapes, origin, yaw, samples, range_min, range_max):
    """What a lidar at `origin` (x, y) heading `yaw` should read: the nearest
    hit per beam, -inf nearer than range_min, +inf beyond range_max (REP 117)."""
    hit = {'box': _box_hit, 'cylinder': _cylinder_hit}
    expected = []
    for beam in range(samples):
        angle = yaw + beam * 2.0 * math.pi / samples
        direction = (math.cos(angle), math.sin(angle))
        nearest = min([hit[kind](origin, direction, fields) for kind, fields in shapes] + [math.inf])
        expected.append(-math.inf if nearest < range_min else math.inf if nearest > range_max else nearest)
    return np.array(expected)


def agreement(ranges, expected):
    """Per beam: the lidar reads what the ray cast found (finite within AGREE, or the same infinity)."""
    both_finite = np.isfinite(ranges) & np.isfinite(expected)
    close = np.zeros(len(ranges), dtype=bool)
    close[both_finite] = np.abs(ranges[both_finite] - expected[both_finite]) <= AGREE
    return np.where(both_finite, close, ranges == expected)


def scan_and_ray_cast(repo, worlds_folder, make, launch, obstacles=None):
    """(lidar ranges of a Burger settled at the launch's spawn pose, ray-cast ranges).
    The simulation gets `obstacles` if given, else the world file's."""
    world, (x, y, z) = spawn_of(repo, launch)
    if obstacles is None:
        obstacles = load_world(world, str(worlds_folder)).obstacles
    simulation = make([('', (x, y, z, 0.0))], obstacles)
    for _ in range(int(round(SETTLE / (simulation.step_ns * 1e-9)))):
        simulation.step()
    robot = simulation.robots['']
    ranges = robot.scan()
    config = simulation.config
    expected = ray_cast(shapes_at_height(str(worlds_folder / (world + '.yaml')), SCAN_OFFSET[1]),
                        (x + SCAN_OFFSET[0], y), 0.0, config.scan_samples, config.scan_range_min,
                        config.scan_range_max)
    return ranges, expected


@pytest.mark.parametrize('launch', LAUNCHES)
def test_the_lidar_at_the_spawn_pose_reads_the_world_files_walls(launch, repo, worlds_folder, make):
    ranges, expected = scan_and_ray_cast(repo, worlds_folder, make, launch)
    agrees = agreement(ranges, expected)
    finite = np.isfinite(ranges) & np.isfinite(expected)
    differences = np.abs(ranges[finite] - expected[finite]) if finite.any() else np.array([math.nan])
    misses = [(beam, ranges[beam], expected[beam]) for beam in np.nonzero(~agrees)[0]]
    print('MEASURED %s: %d of %d beams agree, %d finite compared, worst difference %.4f m, misses %s'
          % (launch, agrees.sum(), len(agrees), finite.sum(), differences.max(), misses[:10]))
    assert np.isfinite(ranges).sum() >= SEEN_SHARE * len(ranges)  # it sees walls
    assert agrees.sum() >= AGREEING_SHARE * len(agrees), misses


def test_the_comparison_catches_a_wall_2_cm_from_where_the_file_puts_it(repo, worlds_folder, make):
    """Stage 1's east wall (Wall_4) moved 2 cm east in the simulation only: the
    quarter of the beams that hit it disagree, and the test above would fail."""
    obstacles = load_world('turtlebot3_stage_1', str(worlds_folder)).obstacles
    moved = [obstacle._replace(position=(obstacle.position[0] + 0.02,) + obstacle.position[1:])
             if obstacle.name == 'Wall_4' else obstacle for obstacle in obstacles]
    ranges, expected = scan_and_ray_cast(repo, worlds_folder, make, 'tb3_stage_1.launch', moved)
    agrees = agreement(ranges, expected)
    assert agrees.sum() < AGREEING_SHARE * len(agrees)
    # The beams that disagree are the ones towards the wall, east of the lidar (x = -0.032,
    # wall face at x = 1.85): within 45 degrees of heading 0.
    beams = np.nonzero(~agrees)[0]
    angles = np.remainder(beams * 2 * math.pi / len(agrees) + math.pi, 2 * math.pi) - math.pi
    assert np.all(np.abs(angles) <= math.radians(46.0))
    assert len(beams) >= 85
