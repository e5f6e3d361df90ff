"""Rays against the world's still part, in numpy: the ground and every static box, cylinder and sphere. No pybullet.

Why not pybullet's rayTestBatch for everything: it costs 0.4 us a ray even
where nothing is, and Bullet tests a ray against a box or cylinder by a
convex cast: 3.5 us a ray in turtlebot3_world (15 obstacles), 9 us with ten
robots there (2026-11-23, this VM). A scan of 360 beams cost 3.5 ms, and ten
robots' scans were half of the simulator's CPU (py-spy). Here the rays of
every lidar due in a step are tested at once, each against the shapes
within its reach, in closed form: a slab test in the shape's own frame for
a box, a circle and two caps for a cylinder, a quadratic for a sphere.

What pybullet does and this keeps (measured against rayTestBatch in
test_sensors.py): a ray that starts inside a shape does not hit that shape;
the ground (the plane z = 0) is hit from above and from below. What it does
not keep: Bullet's convex cast stops up to 6 mm short of a cylinder; here
every shape is met at its exact surface (test_rays.py works the distances
out by hand).
"""
import numpy as np

from .frames import matrix

KINDS = ('box', 'cylinder', 'sphere')


class StaticScene(object):
    """The still shapes, as arrays: centre (K x 3), world-from-shape rotation (K x 3 x 3),
    half extents (K x 3: a box's half sizes; a cylinder's radius, radius, half
    length; a sphere's radius thrice), kind index (K), bounding radius (K)."""

    def __init__(self, shapes):
        """`shapes`: (kind, size, pose) of each still shape in the world; size as
        model_files.Shape's: box (x, y, z), cylinder (radius, length), sphere (radius,)."""
        count = len(shapes)
        self.centres = np.zeros((count, 3))
        self.rotations = np.zeros((count, 3, 3))
        self.halves = np.zeros((count, 3))
        self.kinds = np.zeros(count, dtype=int)
        for index, (kind, size, (position, orientation)) in enumerate(shapes):
            self.centres[index] = position
            self.rotations[index] = matrix(orientation)
            self.kinds[index] = KINDS.index(kind)
            self.halves[index] = {'box': lambda: np.divide(size, 2.0),
                                  'cylinder': lambda: (size[0], size[0], size[1] / 2.0),
                                  'sphere': lambda: (size[0],) * 3}[kind]()
        self.radii = np.linalg.norm(self.halves, axis=1)

    def reachable(self, origins, length):
        """How many shapes each origin (L x 3) can reach within `length`."""
        gaps = np.linalg.norm(self.centres[None, :, :] - np.asarray(origins)[:, None, :], axis=2)
        return (gaps - self.radii[None, :] <= length).sum(axis=1)

    def cast(self, origins, directions, length):
        """Distance along each ray to the first still surface within `length`, inf
        where none: L x N, for L origins (L x 3; a lidar's beams share one) and the
        unit `directions` (L x N x 3) of their N rays each."""
        count, beams = directions.shape[:2]
        nearest = _ground(np.repeat(origins, beams, axis=0), directions.reshape(-1, 3))
        if len(self.kinds):
            # Which shapes each origin can reach, then which of its rays pass
            # within a shape's bounding sphere: only those are tested exactly.
            offsets = self.centres[None, :, :] - origins[:, None, :]  # L x K x 3
            near = np.linalg.norm(offsets, axis=2) - self.radii[None, :] <= length
            lidar, reached = np.nonzero(near)
            ray = (lidar[:, None] * beams + np.arange(beams)[None, :]).reshape(-1)
            shape = np.repeat(reached, beams)
            offset = np.repeat(offsets[lidar, reached], beams, axis=0)
            direction = directions.reshape(-1, 3)[ray]
            along = (offset * direction).sum(axis=1)
            radius = self.radii[shape]
            across = (offset * offset).sum(axis=1) - along * along
            passing = (across <= radius * radius) & (along >= -radius) & (along - radius <= length)
            ray, shape, direction = ray[passing], shape[passing], direction[passing]
            if len(ray):
                # Into each shape's frame: the rows of the world-from-shape rotation.
                rotations = self.rotations[shape]
                start = np.einsum('kji,kj->ki', rotations, -offset[passing])
                step = np.einsum('kji,kj->ki', rotations, direction)
                hits = np.full(len(ray), np.inf)
                kinds = self.kinds[shape]
                for index, test in enumerate((_box, _cylinder, _sphere)):
                    mine = kinds == index
                    if mine.any():
                        hits[mine] = test(start[mine], step[mine], self.halves[shape[mine]])
                np.minimum.at(nearest, ray, hits)
        return np.where(nearest <= length, nearest, np.inf).reshape(count, beams)


def _ground(origins, directions):
    """Distance to the plane z = 0 along each ray, from either side; inf if it never gets there."""
    with np.errstate(divide='ignore', invalid='ignore'):
        distance = -origins[:, 2] / directions[:, 2]
    return np.where((directions[:, 2] != 0.0) & (distance >= 0.0), distance, np.inf)


def _box(start, step, half):
    """Slab test in the box's frame; a ray from inside meets nothing."""
    with np.errstate(divide='ignore', invalid='ignore'):
        first, second = (-half - start) / step, (half - start) / step
    parallel = step == 0.0
    within = np.abs(start) <= half
    near = np.where(parallel, np.where(within, -np.inf, np.inf), np.minimum(first, second)).max(axis=1)
    far = np.where(parallel, np.where(within, np.inf, -np.inf), np.maximum(first, second)).min(axis=1)
    return np.where((near <= far) & (near >= 0.0), near, np.inf)


def _cylinder(start, step, half):
    """The side (a circle in x, y) within the length, and the two caps; a ray from inside meets nothing."""
    radius, length = half[:, 0], half[:, 2]
    a = step[:, 0] ** 2 + step[:, 1] ** 2
    b = start[:, 0] * step[:, 0] + start[:, 1] * step[:, 1]
    c = start[:, 0] ** 2 + start[:, 1] ** 2 - radius ** 2
    chord = b * b - a * c
    with np.errstate(divide='ignore', invalid='ignore'):
        side = (-b - np.sqrt(np.maximum(chord, 0.0))) / a
    z = start[:, 2] + side * step[:, 2]
    side = np.where((a > 0.0) & (chord >= 0.0) & (side >= 0.0) & (np.abs(z) <= length) & (c >= 0.0), side, np.inf)
    with np.errstate(divide='ignore', invalid='ignore'):
        cap = (np.where(start[:, 2] > 0.0, length, -length) - start[:, 2]) / step[:, 2]
        x, y = start[:, 0] + cap * step[:, 0], start[:, 1] + cap * step[:, 1]
    outside = np.abs(start[:, 2]) > length
    cap = np.where(outside & (cap >= 0.0) & (x * x + y * y <= radius * radius), cap, np.inf)
    return np.minimum(side, cap)


def _sphere(start, step, half):
    radius = half[:, 0]
    b = (start * step).sum(axis=1)
    c = (start * start).sum(axis=1) - radius ** 2
    chord = b * b - c
    entry = -b - np.sqrt(np.maximum(chord, 0.0))
    return np.where((chord >= 0.0) & (c >= 0.0) & (entry >= 0.0), entry, np.inf)
