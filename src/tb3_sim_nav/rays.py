"""Rays against boxes, cylinders, spheres and the ground, in numpy: the world's still shapes and its robots'.
No pybullet.

Why not pybullet's rayTestBatch for everything: it costs 0.4 us a ray even
where nothing is, and Bullet tests a ray against a box or cylinder by a
convex cast: 3.5 us a ray in turtlebot3_world (15 obstacles), 9 us with ten
robots there (2026-11-23, this VM). A scan of 360 beams cost 3.5 ms, and ten
robots' scans were half of the simulator's CPU (py-spy). Here the rays of
every lidar due in a step are tested at once, each against the shapes
within its reach, in closed form: a slab test in the shape's own frame for
a box, a circle and two caps for a cylinder, a quadratic for a sphere.

A ray is tested only against the shapes whose shadow on the ground it
crosses: each origin's rays sorted by heading once, the span of headings of
a shape's shadow seen from the origin is one searchsorted. Testing each ray
against each shape's bounding sphere cost L x K x N rows of temporaries
(10 lidars, 15 obstacles, 360 beams: 54000) and 21 % of the simulator's CPU
with ten robots (py-spy, 2026-11-24): 7.8 ms for the ten lidars of
tools/bench_rays.py, 1.1-1.3 ms now, the same distances (2026-11-24).

The robots are met here too: a Scene of each robot's URDF shapes in their
links' frames is `placed` where the links are at each cast, and a shape's
owner's rays pass through it (a lidar never sees its own robot). pybullet
cast the rays that passed near another robot: 15.8 % of the simulator's CPU
with ten robots close together (py-spy); with both, tools/bench_rays.py
reads ten lidars at 218-225 us a scan, 1977-2068 us before (2026-11-24).

What pybullet does and this keeps (measured against rayTestBatch in
test_world_rays.py): a ray that starts inside a shape does not hit that shape;
the ground (the plane z = 0) is hit from above and from below. What it does
not keep: Bullet's convex cast stops up to 6 mm short of a cylinder;
loadURDF makes a URDF's cylinder a convex hull with a margin, up to 2 mm
out of the cylinder (a lidar housing met 1 mm early face on, 4.5 mm at a
slant); a ray that cuts a box's edge by 0.06 or 0.24 mm passed it there. So
a ray that grazes a shape may meet it in one and not the other. Here every
shape is met at its exact surface (test_rays.py works the distances out by
hand).
"""
import numpy as np

from .frames import matrix

KINDS = ('box', 'cylinder', 'sphere')
NOBODY = -1       # the owner of a shape that is nobody's (an obstacle)
TURN = 2.0 * np.pi
MARGIN = 1e-9     # rad added to each side of a shape's span of headings: rounding, never a miss
CORNERS = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]


def halves(kind, size):
    """A shape's half extents as Scene keeps them: a box's half sizes; a cylinder's
    radius, radius, half length; a sphere's radius thrice."""
    return {'box': lambda: tuple(np.divide(size, 2.0)), 'cylinder': lambda: (size[0], size[0], size[1] / 2.0),
            'sphere': lambda: (size[0],) * 3}[kind]()


def rotations(orientations):
    """K x 3 x 3 rotation matrices of K quaternions (x, y, z, w)."""
    return np.moveaxis(matrix(np.reshape(orientations, (-1, 4)).T), 2, 0)


class Scene(object):
    """Shapes as arrays: kind index (K), half extents (K x 3, `halves`), centre
    (K x 3), world-from-shape rotation (K x 3 x 3), owner (K), and their bounds (`_bound`)."""

    def __init__(self, shapes=(), owners=None):
        """`shapes`: (kind, size, pose) of each shape; size as model_files.Shape's:
        box (x, y, z), cylinder (radius, length), sphere (radius,). `owners`: each
        one's owner (an int), else NOBODY's."""
        shapes = list(shapes)
        self.kinds = np.array([KINDS.index(kind) for kind, _, _ in shapes], dtype=int)
        self.halves = np.array([halves(kind, size) for kind, size, _ in shapes], dtype=float).reshape(-1, 3)
        self.centres = np.array([position for _, _, (position, _) in shapes], dtype=float).reshape(-1, 3)
        self.rotations = rotations([turn for _, _, (_, turn) in shapes])
        self.owners = np.full(len(shapes), NOBODY) if owners is None else np.asarray(owners, dtype=int)
        self._bound()

    @classmethod
    def _of(cls, **arrays):
        """A Scene of its arrays (kinds, halves, centres, rotations, owners), its bounds made anew."""
        scene = cls.__new__(cls)
        scene.__dict__.update(arrays)
        scene._bound()
        return scene

    def _bound(self):
        """The bounds of the shapes: a sphere about the centre (`radii`); on the
        ground, a circle about the centre's shadow that holds a cylinder's or a
        sphere's (`flat_radii`) and the shadows of a box's corners (`corners`, K x 8 x 2)."""
        box, cylinder = self.kinds == 0, self.kinds == 1
        radius, axis = self.halves[:, 0], self.rotations[:, :, 2]
        self.radii = np.where(box, np.linalg.norm(self.halves, axis=1),
                              np.where(cylinder, np.hypot(radius, self.halves[:, 2]), radius))
        self.flat_radii = np.where(cylinder, np.minimum(radius + self.halves[:, 2] * np.hypot(axis[:, 0], axis[:, 1]),
                                                        self.radii), radius)
        edges = (self.rotations * self.halves[:, None, :])[:, :2, :]  # the half edges' shadows, K x 2 x 3
        self.corners = self.centres[:, None, :2] + np.einsum('kij,cj->kci', edges, CORNERS)

    def placed(self, positions, orientations):
        """This scene's shapes, each given in a frame of its own (K positions, K
        quaternions), in the frames' frame: a body's shapes at its links' poses."""
        turns = rotations(orientations)
        centres = np.reshape(positions, (-1, 3)) + np.einsum('kij,kj->ki', turns, self.centres)
        return Scene._of(kinds=self.kinds, halves=self.halves, centres=centres,
                         rotations=np.matmul(turns, self.rotations), owners=self.owners)

    def __add__(self, other):
        """The shapes of both."""
        scene = Scene.__new__(Scene)
        for name in ('kinds', 'halves', 'centres', 'rotations', 'owners', 'radii', 'flat_radii', 'corners'):
            setattr(scene, name, np.concatenate((getattr(self, name), getattr(other, name))))
        return scene

    def reachable(self, origins, length):
        """How many shapes each origin (L x 3) can reach within `length`."""
        gaps = np.linalg.norm(self.centres[None, :, :] - np.asarray(origins)[:, None, :], axis=2)
        return (gaps - self.radii[None, :] <= length).sum(axis=1)

    def cast(self, origins, directions, length, ignore=None):
        """Distance along each ray to the first surface within `length`, inf where
        none: L x N, for L origins (L x 3; a lidar's beams share one) and the unit
        `directions` (L x N x 3) of their N rays each. Origin l's rays pass through
        the shapes of owner ignore[l] (`ignore`: L ints; None: through none)."""
        count, beams = directions.shape[:2]
        rays = directions.reshape(-1, 3)
        nearest = _ground(np.repeat(origins, beams, axis=0), rays)
        origin, shape, first, counts, order = self._spans(origins, directions, length, ignore)
        # Into each shape's frame: the rows of its world-from-shape rotation. An
        # origin once a shape; its rays one by one, each kind's together. Arrays
        # are 3 x rays: numpy reduces K x 3 along its rows at 45 ns a row.
        starts = np.einsum('pji,pj->ip', self.rotations[shape], origins[origin] - self.centres[shape])
        met = []  # (ray, distance) of each kind's hits within reach
        for index, test in enumerate((_box, _cylinder, _sphere)):
            mine = np.flatnonzero(self.kinds[shape] == index)
            run, place = _runs(counts[mine])
            if len(run):
                pair = mine[run]
                ray = origin[pair] * beams + order[origin[pair], (first[pair] + place) % beams]
                step = np.einsum('kji,kj->ik', self.rotations[shape[pair]], rays[ray], order='C')
                hits = test(starts[:, pair], step, self.halves[shape[pair]].T)
                within = hits <= length
                met.append((ray[within], hits[within]))
        if met:
            _lower(nearest, *(np.concatenate(part) for part in zip(*met)))
        return np.where(nearest <= length, nearest, np.inf).reshape(count, beams)

    def _spans(self, origins, directions, length, ignore):
        """The rays that cross the shadow on the ground of a shape within their
        origin's reach, as runs of each origin's rays sorted by heading: (origin,
        shape, first place in the run, count) of each such pair, and the order
        (L x N) that sorts each origin's rays.

        A ray that meets a shape crosses its shadow: a ray that passes over it
        (or starts within it, or runs straight up or down from there) too.
        Seen from the origin's shadow, the shadow circle (radius r, centre d
        away) spans the headings within asin(r / d) of the centre's; from
        within it (d <= r) every heading."""
        count, beams = directions.shape[:2]
        offsets = self.centres[None, :, :] - origins[:, None, :]  # L x K x 3
        near = np.linalg.norm(offsets, axis=2) - self.radii[None, :] <= length
        if ignore is not None:
            near &= self.owners[None, :] != np.asarray(ignore)[:, None]
        origin, shape = np.nonzero(near)
        offset = offsets[origin, shape]
        # Each origin's headings sorted, thrice a turn apart (a span may wrap
        # past +-pi), the origins' rows 4 turns apart: one searchsorted for all.
        headings = np.arctan2(directions[:, :, 1], directions[:, :, 0])
        order = np.argsort(headings, axis=1, kind='stable')  # timsort: a lidar's beams are one turned run
        sorted_ = np.take_along_axis(headings, order, axis=1)
        rows = 4.0 * TURN * np.arange(count)
        keys = (np.concatenate((sorted_ - TURN, sorted_, sorted_ + TURN), axis=1) + rows[:, None]).reshape(-1)
        centre = np.arctan2(offset[:, 1], offset[:, 0])
        gap, radius = np.hypot(offset[:, 0], offset[:, 1]), self.flat_radii[shape]
        with np.errstate(divide='ignore', invalid='ignore'):
            most = np.where(gap > radius, np.arcsin(radius / gap), np.pi)  # about the centre's heading
        least = -most
        # A box's shadow is the hull of its corners': seen from outside it (less
        # than half a turn), their headings span it. The walls of turtlebot3_world
        # are 3 m long: their circles held most of ten robots' beams.
        box = np.flatnonzero(self.kinds[shape] == 0)
        corners = self.corners[shape[box]] - origins[origin[box], None, :2]
        turns = (np.arctan2(corners[:, :, 1], corners[:, :, 0]) - centre[box, None] + np.pi) % TURN - np.pi
        low, high = turns.min(axis=1), turns.max(axis=1)
        outside = high - low < np.pi
        least[box], most[box] = np.where(outside, low, -np.pi), np.where(outside, high, np.pi)
        centre += rows[origin]
        first = np.searchsorted(keys, centre + least - MARGIN, 'left')
        counts = np.minimum(np.searchsorted(keys, centre + most + MARGIN, 'right') - first, beams)
        return origin, shape, first - 3 * beams * origin, counts, order


def _runs(counts):
    """For runs of `counts` items one after another: each item's run and its place in the run."""
    run = np.repeat(np.arange(len(counts)), counts)
    return run, np.arange(len(run)) - np.repeat(np.cumsum(counts) - counts, counts)


def _lower(nearest, ray, distances):
    """nearest[ray] = min(nearest[ray], distances), where a ray may come more than once: by
    sorting (4500 hits: 86 us; np.minimum.at of numpy 1.24, 246 us)."""
    if len(ray):
        order = np.argsort(ray, kind='stable')
        ray, distances = ray[order], distances[order]
        firsts = np.flatnonzero(np.concatenate(([True], ray[1:] != ray[:-1])))
        ray = ray[firsts]
        nearest[ray] = np.minimum(nearest[ray], np.minimum.reduceat(distances, firsts))


def _ground(origins, directions):
    """Distance to the plane z = 0 along each ray, from either side; inf if it never gets there."""
    with np.errstate(divide='ignore', invalid='ignore'):
        distance = -origins[:, 2] / directions[:, 2]
    return np.where((directions[:, 2] != 0.0) & (distance >= 0.0), distance, np.inf)


# The exact tests: start, step (the ray's direction) and half extents in the
# shape's frame, each 3 x rays; the distance to the surface, inf where none.

def _box(start, step, half):
    """Slab test; a ray from inside meets nothing."""
    with np.errstate(divide='ignore', invalid='ignore'):
        first, second = (-half - start) / step, (half - start) / step
    parallel = step == 0.0
    within = np.abs(start) <= half
    near = np.where(parallel, np.where(within, -np.inf, np.inf), np.minimum(first, second)).max(axis=0)
    far = np.where(parallel, np.where(within, np.inf, -np.inf), np.maximum(first, second)).min(axis=0)
    return np.where((near <= far) & (near >= 0.0), near, np.inf)


def _cylinder(start, step, half):
    """The side (a circle in x, y) within the length, and the two caps; a ray from inside meets nothing."""
    radius, length = half[0], half[2]
    a = step[0] ** 2 + step[1] ** 2
    b = start[0] * step[0] + start[1] * step[1]
    c = start[0] ** 2 + start[1] ** 2 - radius ** 2
    chord = b * b - a * c
    with np.errstate(divide='ignore', invalid='ignore'):
        side = (-b - np.sqrt(np.maximum(chord, 0.0))) / a
    z = start[2] + side * step[2]
    side = np.where((a > 0.0) & (chord >= 0.0) & (side >= 0.0) & (np.abs(z) <= length) & (c >= 0.0), side, np.inf)
    with np.errstate(divide='ignore', invalid='ignore'):
        cap = (np.where(start[2] > 0.0, length, -length) - start[2]) / step[2]
        x, y = start[0] + cap * step[0], start[1] + cap * step[1]
    outside = np.abs(start[2]) > length
    cap = np.where(outside & (cap >= 0.0) & (x * x + y * y <= radius * radius), cap, np.inf)
    return np.minimum(side, cap)


def _sphere(start, step, half):
    radius = half[0]
    b = (start * step).sum(axis=0)
    c = (start * start).sum(axis=0) - radius ** 2
    chord = b * b - c
    entry = -b - np.sqrt(np.maximum(chord, 0.0))
    return np.where((chord >= 0.0) & (c >= 0.0) & (entry >= 0.0), entry, np.inf)
