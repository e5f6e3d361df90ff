"""WorldRays.cast on a real pybullet world (DIRECT) against pybullet's own rayTestBatch: the obstacles, other
robots (standing, tilted, thrown, teleported), spawned models and a robot with a mesh, and hand-worked
distances to a Burger's shapes."""
import math

import numpy as np
import pytest
from test_sensors import FRONT, RIGHT, ROOM, SCAN_X, STEP, pillar

from tb3_sim_nav.bodies import int32

GRAZE_AGREE = 0.007  # m: pybullet's ray cast against the exact surfaces, where its convex cast stops short


def every_ray_cast(robot, origin, directions, length):
    """What WorldRays.cast must give: pybullet's own answer for every ray, `robot` transparent to them."""
    ends = origin + directions * length
    hits = robot.p.rayTestBatch(np.broadcast_to(origin, ends.shape), ends, numThreads=1,
                                collisionFilterMask=int32(0xFFFFFFFF & ~robot.group))
    return np.array([hit[2] * length if hit[0] >= 0 else math.inf for hit in hits])


@pytest.mark.parametrize('seed', range(5))
def test_the_worlds_rays_meet_what_pybullets_meet(world_factory, worlds_folder, burger_urdf, seed):
    """Numpy for every shape and the ground, the other robot's and a moving
    ball's too: what pybullet finds casting every ray, but where Bullet's convex
    cast of a cylinder, which carries a margin, stops short of its surface (up
    to 6 mm at a grazing angle, measured here) or grazes a cylinder the exact
    ray passes within 1 mm of (1 ray in 100 here; the lidar's noise is 10 mm);
    81-92 % of the hits agree to 0.01 mm (81-93 % with the robot and the ball
    cast by pybullet, before 2026-11-24)."""
    from tb3_sim_nav.frames import planar
    from tb3_sim_nav.model_files import Shape
    from tb3_sim_nav.robot_model import load_model
    from tb3_sim_nav.world_file import load_world
    # Where tb3_world.launch spawns it, beside a pillar of its own, another
    # robot, a tilted static box and a ball that moves.
    robot = world_factory(STEP, 0.0, (-2.0, -0.5, 0.0, 0.0),
                          load_world('turtlebot3_world', str(worlds_folder)).obstacles + [pillar(-1.7, -0.5)])
    world = robot.world
    other = world.add_robot(load_model(str(burger_urdf)).urdf_text, planar(-2.0, 0.3, 0.0, 1.0), 'other')
    tilted = ((-1.6, 0.5, 0.2), (0.2, 0.1, 0.3, 0.927))
    world.add_object('tilted', [(Shape('box', (0.3, 0.2, 0.2), ((0.0, 0.0, 0.0), (0, 0, 0, 1)), None), False)],
                     (tilted[0], tuple(np.divide(tilted[1], np.linalg.norm(tilted[1])))), static=True)
    world.add_object('ball', [(Shape('sphere', (0.1,), ((0.0, 0.0, 0.0), (0, 0, 0, 1)), None), False)],
                     planar(-1.5, -0.9, 0.3), static=False)
    rng = np.random.default_rng(seed)
    hits, close, agree, rays = 0, 0, 0, 0
    for _ in range(20):
        # Origins in and far around the world, some inside obstacles, some
        # below ground; rays of 0.1 to 4 m, some downwards, some along an axis.
        origin = np.append(rng.uniform(-3.0, 3.0, 2), rng.uniform(-0.05, 0.4))
        directions = rng.normal(size=(100, 3)) * (1.0, 1.0, rng.uniform(0.0, 0.3))
        directions[:10, 1:] = 0.0
        directions /= np.linalg.norm(directions, axis=1)[:, None]
        length = rng.uniform(0.1, 4.0)
        expected = every_ray_cast(robot, origin, directions, length)
        got = world.rays.cast([origin], directions[None], length, [robot])[0]
        hits += np.isfinite(expected).sum()
        rays += len(expected)
        agree += agreeing(got, expected).sum()
        close += (np.isfinite(expected) & (np.abs(np.where(np.isfinite(got), got, 1e9) - expected) < 1e-5)).sum()
    assert hits > 300
    assert agree >= 0.98 * rays
    assert close >= 0.75 * hits
    assert other.radius > 0.1


def test_rays_in_a_world_of_shapes_and_robots_are_not_cast_by_pybullet(world_factory, burger_urdf, monkeypatch):
    import pybullet

    from tb3_sim_nav.frames import planar
    from tb3_sim_nav.robot_model import load_model
    robot = world_factory(STEP, 0.5, obstacles=ROOM)
    robot.world.add_robot(load_model(str(burger_urdf)).urdf_text, planar(SCAN_X, 1.0), 'other')
    monkeypatch.setattr(pybullet, 'rayTestBatch', lambda *args, **kwargs: pytest.fail('cast'))
    directions = np.array([[[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.6, -0.8]], [[0.0, 1.0, 0.0]] * 3])
    distances = robot.world.rays.cast([(SCAN_X, 0.0, 0.2), (SCAN_X, 0.0, 0.1)], directions, 3.5, [robot] * 2)
    assert distances[0] == pytest.approx([FRONT, RIGHT, 0.25])
    assert distances[1] == pytest.approx([1.0 - 0.070] * 3)  # the other robot's side: its box, 70 mm off its axis


def test_another_robot_is_met_at_its_urdf_shapes_where_its_links_are(world_factory, burger_urdf):
    """Worked by hand from urdf/turtlebot3_burger.urdf: base_link 10 mm up, its box
    0.140 x 0.140 x 0.143 centred 32 mm behind and 70 mm above it; base_scan's
    cylinder (r 55 mm, 31.5 mm long) centred 17 mm behind the base and 175.5 mm
    up; wheel spheres (r 33 mm) 80 mm to each side, 33 mm up."""
    from tb3_sim_nav.frames import from_rpy, planar
    from tb3_sim_nav.robot_model import load_model
    robot = world_factory(STEP, 0.0, (-3.0, 0.0, 0.0, 0.0))
    world, urdf = robot.world, load_model(str(burger_urdf)).urdf_text
    standing = world.add_robot(urdf, planar(1.0, 0.0), 'standing')
    world.p.resetJointState(standing.id, standing.wheels[0], 1.0)  # a wheel turned: a sphere, met where it was
    world.add_robot(urdf, ((0.0, 2.0, 0.5), from_rpy(math.pi / 2, 0.0, 0.0)), 'lying')  # on its side, in the air
    origins = [(0.0, 0.0, 0.1), (0.0, 0.03, 0.175), (0.0, 0.08, 0.033), (-0.032, 0.0, 0.5), (-0.09, 0.0, 0.5)]
    directions = [[(1.0, 0.0, 0.0)]] * 3 + [[(0.0, 1.0, 0.0)]] * 2
    got = world.rays.cast(origins, directions, 3.5, [robot] * 5)[:, 0]
    assert got == pytest.approx([1.0 - 0.032 - 0.070,                                     # the box's back
                                 1.0 - 0.032 + 0.015 - math.sqrt(0.055 ** 2 - 0.03 ** 2),  # the lidar housing
                                 1.0 - 0.033,                                             # beside the box: a wheel
                                 # The lying robot, its top towards the origins: the housing's cap, then
                                 # (past the housing's side) the box's top.
                                 2.0 - 0.182 + 0.0065 - 0.03150 / 2, 2.0 - 0.010 - 0.070 - 0.0715], abs=1e-6)


def rays_at_robots(rng, targets, count=20, rays=100):
    """(origin, directions) pairs: origins around random `targets` (bodies), rays aimed at
    random points within their bounding spheres, a few passing by."""
    for _ in range(count):
        target = targets[rng.integers(len(targets))]
        centre = np.array(target.centre())
        origin = centre + np.append(rng.uniform(-1.2, 1.2, 2), 0.0)
        origin[2] = rng.uniform(0.0, 0.5)
        aims = centre + rng.normal(size=(rays, 3)) * target.radius * 0.6
        directions = aims - origin
        yield origin, directions / np.linalg.norm(directions, axis=1)[:, None]


def agreeing(got, expected):
    """Per ray, whether two casts meet the same within GRAZE_AGREE, or both nothing."""
    return (got == expected) | (np.abs(np.where(np.isfinite(got), got, 1e9) - expected) < GRAZE_AGREE)


def aside(direction, distance, count=8):
    """`count` offsets of length `distance` square to `direction`, around it."""
    across = np.cross(direction, (0.0, 0.0, 1.0) if abs(direction[2]) < 0.9 else (1.0, 0.0, 0.0))
    across /= np.linalg.norm(across)
    angles = np.arange(count) * 2 * math.pi / count
    return distance * (np.cos(angles)[:, None] * across + np.sin(angles)[:, None] * np.cross(direction, across))


def cast_at(robot, targets, rng, count=20):
    """(hits, rays within GRAZE_AGREE of pybullet's, rays) of rays_at_robots cast by
    WorldRays.cast and by pybullet, `robot`'s own body passed through; where the two
    differ, pybullet's answer must be WorldRays.cast's for the ray moved 2 mm aside."""
    hits, agree, rays = 0, 0, 0
    for origin, directions in rays_at_robots(rng, targets, count):
        expected = every_ray_cast(robot, origin, directions, 3.5)
        got = robot.world.rays.cast([origin], directions[None], 3.5, [robot])[0]
        hits += np.isfinite(expected).sum()
        rays += len(expected)
        same = agreeing(got, expected)
        agree += same.sum()
        for index in np.flatnonzero(~same):
            moved = origin + aside(directions[index], 0.002)
            found = robot.world.rays.cast(moved, np.broadcast_to(directions[index], (len(moved), 1, 3)), 3.5,
                                     [robot] * len(moved))[:, 0]
            assert agreeing(found, expected[index]).any()
    return hits, agree, rays


@pytest.mark.parametrize('seed', range(4))
def test_other_robots_are_met_where_pybullet_meets_them(world_factory, repo, seed):
    """Burgers and a Waffle standing, turned, tilted and in the air, their wheels
    turned, one thrown and one just teleported, met in numpy: what pybullet
    finds casting every ray at them, to 7 mm (its convex cast stops short of a
    cylinder, and loadURDF makes a URDF's cylinder a convex hull with a
    margin), but for a ray that grazes a shape (4 to 6 rays in 1000 here):
    pybullet's shapes, up to 2 mm larger, catch it, or it cuts a box's edge
    that pybullet passes. pybullet's answer is then the exact one for the ray
    moved 2 mm aside (1 mm is not enough)."""
    from tb3_sim_nav.frames import from_rpy
    from tb3_sim_nav.robot_model import load_model
    rng = np.random.default_rng(seed)
    robot = world_factory(STEP, 0.0, (0.0, 0.0, 0.0, 0.0))
    world = robot.world
    others = []
    for index, model in enumerate(['burger'] * 4 + ['waffle']):
        urdf = load_model(str(repo / 'urdf' / ('turtlebot3_%s.urdf' % model))).urdf_text
        tilt = rng.uniform(-0.6, 0.6, 2) if index % 2 else (0.0, 0.0)
        pose = ((math.cos(index * 1.3) * 1.5, math.sin(index * 1.3) * 1.5, 0.3 * (index % 2)),
                from_rpy(tilt[0], tilt[1], rng.uniform(-math.pi, math.pi)))
        others.append(world.add_robot(urdf, pose, 'other%d' % index))
        for wheel in others[-1].wheels:
            world.p.resetJointState(others[-1].id, wheel, rng.uniform(-math.pi, math.pi))
    world.p.resetBaseVelocity(others[1].id, (3.0, 0.0, 0.0), (0.0, 5.0, 20.0))  # thrown, spinning
    for _ in range(3):  # a few steps: the ones in the air fall, turning
        world.step()
    # One put elsewhere since the last step, as set_model_state does: its links must follow.
    others[0].teleport(((0.5, -1.6, 0.2), from_rpy(0.3, 0.0, 1.0)))
    hits, agree, rays = cast_at(robot, others, rng)
    assert hits > 0.6 * rays
    assert agree >= 0.99 * rays


def test_a_robot_with_a_mesh_is_met_by_pybullet(world_factory, burger_urdf, tmp_path):
    """A shape without a closed form (here the lidar housing as a mesh, a box of
    its size) leaves the rays near that robot to pybullet, which meets the mesh."""
    from tb3_sim_nav.frames import planar
    cylinder = '<geometry><cylinder length="0.0315" radius="0.055"/></geometry>\n    </collision>'
    text = burger_urdf.read_text()
    assert text.count(cylinder) == 1
    mesh = tmp_path / 'housing.obj'
    mesh.write_text(''.join('v %g %g %g\n' % (x * 0.055, y * 0.055, z * 0.01575)
                            for x in (-1, 1) for y in (-1, 1) for z in (-1, 1))
                    + 'f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n')
    robot = world_factory(STEP, 0.0, (-3.0, 0.0, 0.0, 0.0))
    meshed = robot.world.add_robot(text.replace(cylinder, '<geometry><mesh filename="%s"/></geometry>\n    </collision>'
                                                % mesh), planar(1.0, 0.0), 'meshed')
    assert meshed.collisions is None
    # 54 mm beside the housing's axis: the box's face 55 mm ahead of it, where a cylinder would be 10 mm.
    got = robot.world.rays.cast([(0.0, 0.054, 0.1755), (0.0, 0.0, 0.1)], [[(1.0, 0.0, 0.0)]] * 2, 3.5, [robot] * 2)
    assert got[:, 0] == pytest.approx([1.0 - 0.032 + 0.015 - 0.055, 1.0 - 0.032 - 0.070], abs=0.002)
    rng = np.random.default_rng(5)
    for origin, directions in rays_at_robots(rng, [meshed], count=5):
        expected = every_ray_cast(robot, origin, directions, 3.5)
        assert agreeing(robot.world.rays.cast([origin], directions[None], 3.5, [robot])[0], expected).all()


#: A spawned URDF model: its root's inertial frame off and turned (pybullet's base is there), a box and a
#: lying cylinder on the root, a sphere on a turned arm.
CART = '''<robot name="cart"><gazebo><static>%s</static></gazebo>
<link name="body"><inertial><origin xyz="0.05 0.02 0.1" rpy="0.3 0.2 0.1"/><mass value="2"/>
<inertia ixx="0.01" ixy="0.002" ixz="0.001" iyy="0.02" iyz="0.003" izz="0.03"/></inertial>
<collision><origin xyz="0 0 0.15" rpy="0 0 0.3"/><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
<collision><origin xyz="0.3 0 0.1" rpy="1.5708 0 0"/><geometry><cylinder radius="0.08" length="0.3"/></geometry>
</collision></link>
<joint name="hinge" type="revolute"><parent link="body"/><child link="arm"/><origin xyz="-0.2 0 0.3" rpy="0 0.4 0"/>
<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<link name="arm"><inertial><origin xyz="0 0 0.1"/><mass value="0.5"/>
<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
<collision><origin xyz="0 0 0.15"/><geometry><sphere radius="0.07"/></geometry></collision></link></robot>'''


@pytest.mark.parametrize('static', [True, False])
def test_a_spawned_urdf_model_is_met_where_pybullet_meets_it(world_factory, static):
    from tb3_sim_nav.frames import from_rpy
    robot = world_factory(STEP, 0.0, (-2.0, 0.0, 0.0, 0.0))
    cart = robot.world.add_urdf('cart', CART % str(static).lower(), ((0.5, 0.3, 0.0), from_rpy(0.0, 0.0, 0.7)), static)
    robot.p.resetJointState(cart.id, cart.joints['hinge'], 0.6)
    assert len(cart.collisions) == 3
    hits, agree, rays = cast_at(robot, [cart], np.random.default_rng(1), count=10)
    assert hits > 0.6 * rays
    assert agree >= 0.99 * rays
