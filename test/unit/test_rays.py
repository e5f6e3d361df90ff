"""rays.Scene against distances worked out by hand: boxes, cylinders, spheres and the ground, a body's shapes placed
at its links' frames, rays that pass through their owner's shapes; its culling against every ray tested against
every shape. No pybullet.

The lidar's ranges come from here for every box, cylinder and sphere (world_rays.WorldRays.cast),
so they must be the exact surfaces: pybullet's convex cast stopped up to 6 mm
short of a cylinder, a bias this must not copy. test_world_rays.py checks the
same casts against pybullet's, where the two agree.
"""
import math

import numpy as np
import pytest

from tb3_sim_nav.frames import from_rpy, planar, quaternion_multiply, rotate
from tb3_sim_nav.rays import Scene

LENGTH = 3.5  # the LDS-01's range_max


def cast(shapes, origin, directions, length=LENGTH):
    directions = np.asarray(directions, dtype=float)
    directions = directions / np.linalg.norm(directions, axis=-1, keepdims=True)
    return Scene(shapes).cast(np.array([origin], dtype=float), directions[None], length)[0]


def horizontal(angles):
    return np.column_stack([np.cos(angles), np.sin(angles), np.zeros(len(angles))])


def circle_distances(origin, angles, centre, radius):
    """Along each horizontal ray from `origin` (x, y), the distance to a circle's
    near side: along - sqrt(r^2 - across^2), inf where the line misses it."""
    offset = np.subtract(centre, origin)
    along = np.cos(angles) * offset[0] + np.sin(angles) * offset[1]
    across = np.cos(angles) * offset[1] - np.sin(angles) * offset[0]
    chord = radius ** 2 - across ** 2
    with np.errstate(invalid='ignore'):
        return np.where((chord >= 0.0) & (along > 0.0), along - np.sqrt(chord), np.inf)


def test_a_pillar_is_met_at_its_surface_for_every_beam_that_reaches_it():
    # turtlebot3_world's pillars: radius 0.15 m, 0.5 m tall; the lidar 0.18 m up, 1.2 m away.
    radius, centre = 0.15, (1.2, 0.4)
    angles = np.linspace(0.0, 0.7, 2001)  # many beams, some grazing the edge
    got = cast([('cylinder', (radius, 0.5), planar(*centre, z=0.25))], (0.0, 0.0, 0.18), horizontal(angles))
    expected = circle_distances((0.0, 0.0), angles, centre, radius)
    hits = np.isfinite(expected)
    assert 300 < hits.sum() < 2000  # beams both hit and pass it
    assert np.array_equal(np.isfinite(got), hits)
    assert np.abs(got[hits] - expected[hits]).max() < 1e-9


def test_a_cylinder_lying_down_is_met_on_its_round_side_and_its_flat_caps():
    # Axis along y (rolled 90 degrees), radius 0.2, 1 m long, centred at (2, 0, 0.3).
    shape = ('cylinder', (0.2, 1.0), ((2.0, 0.0, 0.3), from_rpy(math.pi / 2, 0.0, 0.0)))
    heights = np.arange(0.0525, 0.55, 0.005)  # none at a tangent (z = 0.1, 0.5), where sqrt amplifies rounding
    for z in heights:  # rays along +x at each height: the round side, seen edge-on
        got = cast([shape], (0.0, 0.1, z), [(1.0, 0.0, 0.0)])[0]
        chord = 0.2 ** 2 - (z - 0.3) ** 2
        assert got == (pytest.approx(2.0 - math.sqrt(chord), abs=1e-9) if chord >= 0 else math.inf)
    # Along the axis onto a cap, from either end; past its end nothing.
    assert cast([shape], (2.05, -3.0, 0.32), [(0.0, 1.0, 0.0)])[0] == pytest.approx(2.5, abs=1e-9)
    assert cast([shape], (1.9, 2.0, 0.25), [(0.0, -1.0, 0.0)])[0] == pytest.approx(1.5, abs=1e-9)
    assert cast([shape], (2.25, -3.0, 0.3), [(0.0, 1.0, 0.0)])[0] == math.inf


def test_a_box_turned_45_degrees_is_met_at_its_corner_and_sides():
    half = 0.25  # a 0.5 m cube centred at (2, 0), turned 45 degrees: its corner points at the origin
    shape = ('box', (0.5, 0.5, 0.5), planar(2.0, 0.0, 0.25, yaw=math.pi / 4))
    corner = 2.0 - half * math.sqrt(2.0)
    for offset in np.linspace(-0.3, 0.3, 61):  # rays along +x, shifted sideways
        got = cast([shape], (0.0, offset, 0.18), [(1.0, 0.0, 0.0)])[0]
        expected = corner + abs(offset) if abs(offset) <= half * math.sqrt(2.0) else math.inf
        assert got == pytest.approx(expected, abs=1e-9)
    # Straight down onto its top face (0.5 m up) from 1 m up.
    assert cast([shape], (2.1, 0.05, 1.0), [(0.0, 0.0, -1.0)])[0] == pytest.approx(0.5, abs=1e-9)


def test_a_sphere_is_met_where_the_line_enters_it():
    angles = np.linspace(-0.3, 0.3, 601)
    got = cast([('sphere', (0.3,), planar(1.5, 0.0, 0.18))], (0.0, 0.0, 0.18), horizontal(angles))
    expected = circle_distances((0.0, 0.0), angles, (1.5, 0.0), 0.3)  # its equator, in the rays' plane
    hits = np.isfinite(expected)
    assert np.array_equal(np.isfinite(got), hits) and hits.sum() > 100
    assert np.abs(got[hits] - expected[hits]).max() < 1e-9


def test_the_nearest_of_several_shapes_and_the_ground_counts():
    shapes = [('box', (0.2, 2.0, 0.4), planar(1.0, 0.0, 0.2)),           # face at x = 0.9
              ('cylinder', (0.1, 0.4), planar(0.5, 0.0, 0.2))]           # surface at x = 0.4
    got = cast(shapes, (0.0, 0.0, 0.18), [(1.0, 0.0, 0.0), (1.0, 0.3, 0.0), (1.0, 0.0, -0.5), (-1.0, 0.0, 0.0)])
    assert got[0] == pytest.approx(0.4, abs=1e-9)
    assert got[1] == pytest.approx(0.9 * math.hypot(1.0, 0.3), abs=1e-9)  # past the pillar: the box
    assert got[2] == pytest.approx(0.18 * math.hypot(1.0, 0.5) / 0.5, abs=1e-9)  # the floor, before either
    assert got[3] == math.inf


def test_rays_that_start_inside_a_shape_or_end_short_of_it_meet_nothing():
    # As pybullet: a ray from inside a shape does not hit that shape.
    for shape in (('box', (1.0, 1.0, 1.0), planar(0.0, 0.0, 0.5)), ('cylinder', (0.5, 1.0), planar(0.0, 0.0, 0.5)),
                  ('sphere', (0.5,), planar(0.0, 0.0, 0.5))):
        assert cast([shape], (0.1, 0.0, 0.5), [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]).tolist() == [math.inf] * 2
    wall = ('box', (0.1, 2.0, 0.4), planar(2.05, 0.0, 0.2))
    assert cast([wall], (0.0, 0.0, 0.18), [(1.0, 0.0, 0.0)], length=1.99)[0] == math.inf
    assert cast([wall], (0.0, 0.0, 0.18), [(1.0, 0.0, 0.0)], length=2.01)[0] == pytest.approx(2.0, abs=1e-9)


@pytest.mark.parametrize('seed', range(3))
def test_distances_do_not_change_when_shapes_and_rays_turn_together(seed):
    """Each shape is met in its own frame: a rotation of the whole scene leaves every
    distance as it was. The scene floats 100 m up, so that the ground (which does
    not turn) is out of reach."""
    rng = np.random.default_rng(seed)
    centre = np.array((0.0, 0.0, 100.0))
    shapes = [('box', (0.4, 0.3, 0.5), planar(1.0, 0.5, 100.3, yaw=0.4)),
              ('cylinder', (0.15, 0.5), planar(-0.8, 1.0, 100.25)),
              ('sphere', (0.2,), planar(0.2, -1.2, 100.3))]
    directions = rng.normal(size=(500, 3)) * (1.0, 1.0, 0.2)
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    origin = centre + (0.0, 0.0, 0.3)
    plain = Scene(shapes).cast(np.array([origin]), directions[None], LENGTH)[0]
    turn = from_rpy(*rng.uniform(-math.pi, math.pi, 3))

    def turned(point):
        return centre + rotate(turn, np.subtract(point, centre))
    scene = Scene([(kind, size, (turned(position), quaternion_multiply(turn, orientation)))
                   for kind, size, (position, orientation) in shapes])
    got = scene.cast(np.array([turned(origin)]), np.array([[rotate(turn, d) for d in directions]]), LENGTH)[0]
    assert np.isfinite(plain).sum() > 40
    assert np.array_equal(np.isfinite(got), np.isfinite(plain))
    hits = np.isfinite(plain)
    assert np.abs(got[hits] - plain[hits]).max() < 1e-9


def test_an_empty_scene_meets_only_the_ground():
    got = cast([], (0.0, 0.0, 0.5), [(1.0, 0.0, 0.0), (0.0, 0.6, -0.8)])
    assert got[0] == math.inf and got[1] == pytest.approx(0.625, abs=1e-12)


def brute_force(shapes, origin, directions, length=LENGTH):
    """The same casts with every ray tested against every shape (no culling), by rays' own exact tests."""
    from tb3_sim_nav import rays
    from tb3_sim_nav.frames import matrix
    nearest = rays._ground(np.broadcast_to(origin, directions.shape), directions)
    for kind, size, (position, orientation) in shapes:
        turn = matrix(orientation)
        start = np.broadcast_to(turn.T.dot(np.subtract(origin, position))[:, None], directions.T.shape)
        test = {'box': rays._box, 'cylinder': rays._cylinder, 'sphere': rays._sphere}[kind]
        half = np.broadcast_to(np.array(rays.halves(kind, size))[:, None], directions.T.shape)
        nearest = np.minimum(nearest, test(start, turn.T.dot(directions.T), half))
    return np.where(nearest <= length, nearest, np.inf)


@pytest.mark.parametrize('seed', range(4))
def test_culling_by_heading_keeps_every_ray_that_meets_a_shape(seed):
    """Rays are tested only against the shapes whose shadow on the ground they
    cross (a box's corners', a cylinder's or sphere's circle): every ray, of
    every heading and slope, straight up and down too, from origins beside,
    above and inside the shapes, finds what testing it against every shape finds."""
    rng = np.random.default_rng(seed)
    shapes = []
    for _ in range(12):
        kind = ('box', 'cylinder', 'sphere')[rng.integers(3)]
        size = {'box': tuple(rng.uniform(0.05, 2.0, 3)), 'cylinder': tuple(rng.uniform(0.05, 1.0, 2)),
                'sphere': (rng.uniform(0.05, 0.5),)}[kind]
        shapes.append((kind, size, (tuple(rng.uniform(-1.5, 1.5, 2)) + (rng.uniform(0.0, 1.0),),
                                    from_rpy(*rng.uniform(-math.pi, math.pi, 3)))))
    directions = rng.normal(size=(720, 3)) * (1.0, 1.0, rng.uniform(0.0, 2.0))
    directions[:100] = horizontal(np.sort(rng.uniform(-math.pi, math.pi, 100)))  # a lidar's: sorted, wrapping
    directions[100:104] = [(0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (-0.0, 0.0, 1.0), (1e-12, 0.0, -1.0)]
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    scene = Scene(shapes)
    origins = np.array([np.append(rng.uniform(-2.0, 2.0, 2), rng.uniform(0.0, 1.5)) for _ in range(5)]
                       + [shapes[0][2][0], shapes[1][2][0] + np.array((0.0, 0.0, 3.0))])  # inside, above a shape
    got = scene.cast(origins, np.broadcast_to(directions, (len(origins),) + directions.shape).copy(), LENGTH)
    hits = 0
    for origin, found in zip(origins, got):
        expected = brute_force(shapes, origin, directions)
        hit = np.isfinite(expected)
        assert np.array_equal(np.isfinite(found), hit)
        assert np.abs(found[hit] - expected[hit]).max() < 1e-9
        hits += hit.sum()
    assert hits > 2000


def test_an_origins_rays_pass_through_its_owners_shapes_and_no_one_elses():
    shapes = [('box', (0.2, 0.2, 0.2), planar(1.0, 0.0, 0.18)), ('sphere', (0.1,), planar(2.0, 0.0, 0.18))]
    scene = Scene(shapes, owners=[3, 4])
    origins, beams = np.array([(0.0, 0.0, 0.18)] * 3), np.array([[(1.0, 0.0, 0.0)]] * 3)
    assert scene.cast(origins, beams, LENGTH, [3, 4, -5])[:, 0] == pytest.approx([1.9, 0.9, 0.9])


def test_placed_shapes_are_where_their_frames_put_them():
    """A body's shapes, each in its link's frame: a box 0.1 m ahead of a frame at
    (1, 0, 0.2) turned 90 degrees (the box then 0.1 m to its left, along y) and a
    sphere at the origin of a frame at (0, 2, 0.2)."""
    local = Scene([('box', (0.2, 0.4, 0.2), ((0.1, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))),
                   ('sphere', (0.1,), ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))])
    placed = local.placed([(1.0, 0.0, 0.2), (0.0, 2.0, 0.2)], [planar(0, 0, yaw=math.pi / 2)[1], (0.0, 0.0, 0.0, 1.0)])
    assert placed.centres == pytest.approx(np.array([(1.0, 0.1, 0.2), (0.0, 2.0, 0.2)]))
    got = placed.cast(np.array([(0.0, 0.1, 0.2)]), np.array([[(1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]]), LENGTH)[0]
    # The box turned: 0.4 m along x (0.8 to 1.2), 0.2 m along y; the sphere's near side at y = 1.9.
    assert got == pytest.approx([0.8, 1.8], abs=1e-9)
    both = Scene([('cylinder', (0.1, 0.2), planar(3.0, 0.1, 0.2))]) + placed
    assert both.cast(np.array([(0.0, 0.1, 0.2)]), np.array([[(1.0, 0.0, 0.0)]]), LENGTH)[0, 0] == pytest.approx(0.8)
    assert both.cast(np.array([(5.0, 0.1, 0.2)]), np.array([[(-1.0, 0.0, 0.0)]]), LENGTH)[0, 0] == pytest.approx(1.9)
