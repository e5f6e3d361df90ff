"""Several robots in one Simulation (real pybullet, no ROS): they see each other and
never themselves, collide, move alone, reset to their own spawn poses, and bad
spawns are refused by name."""
import math

import pybullet
import pytest

from tb3_sim_nav.frames import planar
from tb3_sim_nav.params import resolve
from tb3_sim_nav.robot_model import load_model
from tb3_sim_nav.simulation import build
from tb3_sim_nav.world import MAX_ROBOTS

SCAN_X = -0.032           # base_scan in base_footprint (Burger)
HOUSING = (0.015, 0.055)  # the lidar housing cylinder: x in base_scan, radius
FRONT_EXTENT = 0.038      # base_footprint to the Burger's front face
PENETRATION = 0.005


@pytest.fixture
def make(burger_urdf):
    """make([(name, (x, y, yaw)), ...], **parameters): a Simulation of Burgers, closed after the test."""
    model = load_model(str(burger_urdf))
    made = []

    def make_simulation(robots, **parameters):
        parameters.setdefault('model', str(burger_urdf))
        parameters.setdefault('scan_noise', 0.0)
        config = resolve(lambda name, default: parameters.get(name, default))
        simulation = build(config, (), [(name, model, planar(x, y, 0.0, yaw)) for name, (x, y, yaw) in robots])
        made.append(simulation)
        return simulation
    yield make_simulation
    for simulation in made:
        simulation.close()


def settle(simulation, seconds=0.5):
    for _ in range(int(round(seconds / (simulation.step_ns * 1e-9)))):
        simulation.step()


def xy_yaw(robot):
    (x, y, _z), orientation = robot.truth()[0]
    return x, y, pybullet.getEulerFromQuaternion(orientation)[2]


def housing_centre(robot):
    x, y, yaw = xy_yaw(robot)
    offset = SCAN_X + HOUSING[0]
    return x + offset * math.cos(yaw), y + offset * math.sin(yaw)


def test_each_lidar_sees_the_other_robot_at_its_distance(make):
    simulation = make([('a', (0.0, 0.0, 0.0)), ('b', (0.0, 1.0, math.pi))])
    settle(simulation)
    a, b = simulation.robots['a'], simulation.robots['b']
    for observer, target in ((a, b), (b, a)):
        x, y, yaw = xy_yaw(observer)
        origin = (x + SCAN_X * math.cos(yaw), y + SCAN_X * math.sin(yaw))
        centre = housing_centre(target)
        bearing = math.atan2(centre[1] - origin[1], centre[0] - origin[0]) - yaw
        beam = int(round(bearing / observer.lidar.angle_increment)) % observer.lidar.samples
        ranges = observer.scan()
        assert ranges[beam] == pytest.approx(math.dist(origin, centre) - HOUSING[1], abs=0.005)
        # Nothing else in the world: every other beam reads nothing, the robot never sees itself.
        others = [r for index, r in enumerate(ranges) if abs(index - beam) > 10]
        assert all(r == math.inf for r in others)


def test_robots_get_collision_groups_of_their_own_up_to_the_limit(make):
    simulation = make([('r%d' % index, (index * 0.5 - 7.5, 0.0, 0.0)) for index in range(MAX_ROBOTS)])
    groups = [robot.body.group for robot in simulation.robots.values()]
    assert len(set(groups)) == MAX_ROBOTS
    with pytest.raises(ValueError, match='robot one_too_many: a world holds at most %d robots' % MAX_ROBOTS):
        simulation.add_robot('one_too_many', simulation.robots['r0'].model, planar(0.0, 5.0))


def test_a_robot_driven_alone_moves_alone(make):
    simulation = make([('a', (0.0, 0.0, 0.0)), ('b', (0.0, 0.5, 0.0))])
    settle(simulation)
    before = xy_yaw(simulation.robots['b'])
    simulation.robots['a'].command(0.2, 0.0, simulation.now_ns)
    settle(simulation, 2.0)
    assert xy_yaw(simulation.robots['a'])[0] > 0.3
    assert math.dist(xy_yaw(simulation.robots['b'])[:2], before[:2]) < 1e-4


@pytest.mark.parametrize('standing', [0.5, 3.0])  # 3 s: b sleeps (Bullet's 2 s at rest), as parked robots do
def test_a_robot_driven_into_a_standing_one_pushes_it_without_going_into_it(make, standing):
    simulation = make([('a', (0.0, 0.0, 0.0)), ('b', (0.6, 0.0, math.pi))])
    settle(simulation, standing)
    simulation.robots['a'].command(0.2, 0.0, simulation.now_ns)
    gaps = []
    for _ in range(400):  # 4 s: 0.8 m asked for, 0.6 m between them
        simulation.step()
        gaps.append(xy_yaw(simulation.robots['b'])[0] - xy_yaw(simulation.robots['a'])[0])
    assert min(gaps) >= 2 * FRONT_EXTENT - PENETRATION
    assert gaps[-1] < 2 * FRONT_EXTENT + 0.02  # it did reach b, and pushes it (b's caster does not grip)


def test_a_parked_robot_sleeps_and_wakes_when_commanded_and_a_slow_one_never_sleeps(make):
    """A robot whose motors stopped sleeps after 2 s at rest (bodies.py): its
    velocity is then exactly zero. A command wakes it; wheels turning however
    slowly keep it awake."""
    simulation = make([('a', (0.0, 0.0, 0.0)), ('b', (0.0, 1.0, 0.0))])
    settle(simulation, 3.0)
    for robot in simulation.robots.values():
        linear, angular = robot.body.base_velocity()
        assert tuple(linear) + tuple(angular) == (0.0,) * 6, robot.name
    a, b = simulation.robots['a'], simulation.robots['b']
    for _ in range(100):  # 10 s at `rostopic pub -r 10`: a at 0.2 m/s, b at 0.01 m/s
        a.command(0.2, 0.0, simulation.now_ns)
        b.command(0.01, 0.0, simulation.now_ns)
        settle(simulation, 0.1)
    assert xy_yaw(a)[0] == pytest.approx(2.0, abs=0.1)
    assert xy_yaw(b)[0] == pytest.approx(0.1, abs=0.01)


def test_reset_world_puts_each_robot_back_at_its_own_spawn_pose(make):
    spawns = {'a': (0.0, 0.0, 0.0), 'b': (1.0, 1.0, 1.0)}
    simulation = make(sorted(spawns.items()))
    for robot in simulation.robots.values():
        robot.command(0.2, 0.5, simulation.now_ns)
    settle(simulation, 1.0)
    simulation.reset_world()
    for name, robot in simulation.robots.items():
        assert xy_yaw(robot) == pytest.approx(spawns[name], abs=1e-3)


def test_a_robot_spawned_inside_another_is_refused_naming_both(make):
    simulation = make([('a', (0.0, 0.0, 0.0))])
    with pytest.raises(ValueError, match=r"robot b: the spawn pose \(0.05, 0.00\) puts it inside robot a"):
        simulation.add_robot('b', simulation.robots['a'].model, planar(0.05, 0.0))
    assert list(simulation.robots) == ['a']
    simulation.add_robot('b', simulation.robots['a'].model, planar(1.0, 0.0))  # the world goes on


def test_two_robots_with_one_name_are_refused(make):
    simulation = make([('a', (0.0, 0.0, 0.0))])
    with pytest.raises(ValueError, match="two robots are named 'a'"):
        simulation.add_robot('a', simulation.robots['a'].model, planar(1.0, 0.0))


def connected_clients():
    return sum(bool(pybullet.isConnected(client)) for client in range(64))


def test_a_refused_robot_at_start_up_leaves_no_pybullet_client_open(make):
    before = connected_clients()
    with pytest.raises(ValueError, match='inside robot a'):
        make([('a', (0.0, 0.0, 0.0)), ('b', (0.0, 0.0, 0.0))])
    assert connected_clients() == before
