"""Scan-to-map matching: a correlative search on a likelihood field, then point-to-line Gauss-Newton. No ROS here.

The map's occupied cells become a likelihood field, exp(-d^2 / 2 sigma^2) of
each cell's distance d to the nearest occupied cell (scipy's exact Euclidean
distance transform), read between cell centres by bilinear interpolation. A
scan's end points, put at a pose, score the sum of the field under them:
each beam adds at most 1, so a score counts about how many beams land on
the map's walls, the scale on which gmapping's minimumScore (50 on
TurtleBot3) is set. With sigma 0.05 m (gmapping's sigma on TurtleBot3) a
beam half a cell off a wall still adds 0.88, one two cells off 0.14.

Matching first scores every pose of a small grid around the prior (steps
lstep and astep, as gmapping names its first search steps), then refines
the best one by Gauss-Newton on point-to-line distances, as ICP does: each
end point is paired, through the distance transform's nearest-cell index,
with the occupied cell nearest to it, and measured against the line
through that cell's mean end point (where in the cell its wall lies) along
the wall's direction there (from the mean points of the occupied cells
within 2 cells), unless that wall was seen from the other side only (see
ONE_SIDED). Why not Gauss-Newton on the field itself, as Hector SLAM
does: the field is known at cell centres only, so its optimum snaps to
them; with turtlebot3_world's drive and a map made at the true poses, the
field's optimum was 7 mm and 0.15 degree (rms) off the truth for scans
taken while not turning, the point-to-line optimum is 2.3 mm and 0.08 degree. Why the search
first: the refinement alone follows the nearest walls and can settle on
wrong ones; on maps of turtlebot3_house made at the true poses, from 150
priors each up to 0.1 m and 0.1 rad off (0.2, 0.3), it ended more than 2 cm
or 0.6 degree off 14 (49, 80) times, after a search of +-0.1 m and rad 2
(20, 44) times, after one of +-0.3 m and rad 3 (6, 5) times.
"""
import math

import numpy as np
from scipy import ndimage

from tb3_common.pose2d import normalize_angle

from .wall_shapes import SHAPE_RADIUS, WallShapes

#: A point pairs only with a wall seen from the point's side, when the wall's cell was seen from one side:
#: the mean of the unit vectors from its hits back to the sensor reaches at least this far along the
#: wall's normal (a post seen all round has no side). The two faces of the house's inner walls lie 0.12 m
#: apart, within the pairing's reach, and a robot that came round such a wall was pulled onto the face
#: it had seen from the other side (by 16 cm on an exploration). The scanner is taken to be at the base
#: (3 cm off on a Burger).
ONE_SIDED = 0.3
class WallField(object):
    """The map as the matcher reads it, from `shapes` (a WallShapes): the likelihood field of the
    occupied cells for `sigma` (m), and the walls to pair points with, over the grid's cells in `box`
    (row0, row1, col0, col1; None: around every occupied cell).

    Unlike amcl's field (tb3_navigation.likelihood: made once per map, over
    the whole grid), the SLAM's is made anew as the map grows, a few times a
    second: so it is only computed over the box where the scans can land
    (see slam.Slam), widened by 4 sigma (and one more cell), where the field
    is below exp(-8) and taken as 0, which a ring of zeros around the box
    gives; and it keeps each cell's nearest occupied cell, to pair points with.
    """

    def __init__(self, shapes, sigma, box=None):
        self.grid, self.sigma, self._shapes = shapes.grid, float(sigma), shapes
        grid, r = shapes.grid, SHAPE_RADIUS
        pad = int(math.ceil(4.0 * sigma / grid.resolution)) + 1
        if box is None:
            rows, cols = np.nonzero(~np.isnan(shapes.points[r:-r, r:-r, 0]))
            box = (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1) if rows.size else (0, 0, 0, 0)
        self.box = box
        self.row0, self.col0 = max(0, box[0] - pad), max(0, box[2] - pad)
        row1, col1 = min(grid.height, box[1] + pad), min(grid.width, box[3] + pad)
        window = ~np.isnan(shapes.points[self.row0 + r:row1 + r, self.col0 + r:col1 + r, 0])
        self.empty = row1 <= self.row0 or col1 <= self.col0 or not window.any()
        self._rings = {}  # the field framed by rings of zeros of each width asked for (coarse_scores)
        if self.empty:
            self.row0 = self.col0 = 0
            self._padded = np.zeros((3, 3))
            return
        distance, nearest = ndimage.distance_transform_edt(~window, return_indices=True)
        self._padded = np.pad(np.exp(-0.5 * (distance * grid.resolution / sigma) ** 2), 1)
        # Each window cell's nearest occupied cell, as a flat index into the shapes' (framed) arrays.
        self._nearest = (nearest[0] + self.row0 + r) * (grid.width + 2 * r) + nearest[1] + self.col0 + r

    @classmethod
    def of_map(cls, grid, occupied, sigma, means=None, views=None):
        """The field of a whole map: `occupied` (bool, the grid's shape), `means` and `views` as WallShapes.of_map's."""
        return cls(WallShapes.of_map(grid, occupied, means, views), sigma)

    def covers(self, box):
        """Whether the field was made over the whole of `box` (row0, row1, col0, col1)."""
        return (self.box[0] <= box[0] and box[1] <= self.box[1] and self.box[2] <= box[2]
                and box[3] <= self.box[3])

    @property
    def values(self):
        """The field over its window (rows from row0, columns from col0)."""
        return self._padded[1:-1, 1:-1]

    def _interpolate(self, points):
        """Samples (v00, v10, v01, v11) around points (..., 2) and the points' fractions (fx, fy) between them."""
        cells = self.grid.to_cells_float(points) - 0.5  # cell centres at whole numbers
        cells[..., 0] += 1 - self.col0  # + 1: the ring of zeros
        cells[..., 1] += 1 - self.row0
        height, width = self._padded.shape
        # Points off the window land on the ring: 0 there, a flat field with no pull.
        cells[..., 0] = np.clip(cells[..., 0], 0, width - 1.5)
        cells[..., 1] = np.clip(cells[..., 1], 0, height - 1.5)
        corner = np.floor(cells)
        fraction = cells - corner
        col, row = corner[..., 0].astype(np.intp), corner[..., 1].astype(np.intp)
        padded = self._padded
        samples = padded[row, col], padded[row, col + 1], padded[row + 1, col], padded[row + 1, col + 1]
        return samples, fraction[..., 0], fraction[..., 1]

    def value(self, points):
        """The field (...) at points (..., 2) of the grid's frame."""
        (v00, v10, v01, v11), fx, fy = self._interpolate(points)
        return (v00 * (1 - fx) + v10 * fx) * (1 - fy) + (v01 * (1 - fx) + v11 * fx) * fy

    def walls(self, points):
        """For points (n, 2): the wall point (n, 2) each is paired with, the pairing matrix (n, 2, 2)
        that turns the offset from it into the residual (the wall's normal in its first row, and
        nothing more along a wall; a weighted identity at a corner), the side (n, 2) the wall was
        seen from (WallShapes.views), and whether it has one (n,)."""
        if self.empty:
            return (np.zeros_like(points), np.zeros((len(points), 2, 2)), np.full_like(points, np.nan),
                    np.zeros(len(points), dtype=bool))
        cells = self.grid.to_cells(points) - (self.col0, self.row0)
        height, width = self._nearest.shape
        inside = (cells[:, 0] >= 0) & (cells[:, 0] < width) & (cells[:, 1] >= 0) & (cells[:, 1] < height)
        index = self._nearest[np.clip(cells[:, 1], 0, height - 1), np.clip(cells[:, 0], 0, width - 1)]
        shapes = self._shapes
        return (shapes.points.reshape(-1, 2)[index], shapes.pairing.reshape(-1, 2, 2)[index],
                shapes.views.reshape(-1, 2)[index], inside)

    def score(self, points):
        """Sum of the field under points (..., n, 2): about how many of them lie on the map's walls."""
        return self.value(points).sum(axis=-1)

    def coarse_scores(self, points, shifts):
        """score() of points (..., n, 2) moved by each of `shifts` (s, 2) m, with each point read at
        its cell's centre, not between centres: (..., s). For the correlative search, whose steps are
        a cell long anyway. Shifts of whole cells move the points' flat indices, not the points, on
        the field framed by a ring of zeros twice as wide as the longest shift (a point off the
        window, clipped onto the ring's inner half, stays on the ring however it is shifted): half
        the time of placing each shifted point anew (doc/speed.md)."""
        moves = self.grid.to_cells_float(shifts) - self.grid.to_cells_float(np.zeros(2))  # (s, 2) in cells
        whole = np.rint(moves)
        if not np.all(np.abs(moves - whole) < 1e-9):  # steps that are not whole cells: one point at a time
            return self._score_cells(np.floor(self.grid.to_cells_float(points)[..., None, :, :] + moves[:, None, :]))
        reach = int(np.abs(whole).max()) if len(whole) else 0
        ring = 2 * reach + 1
        framed = self._rings.get(ring)
        if framed is None:
            framed = self._rings[ring] = np.pad(self.values, ring)
        height, width = framed.shape
        cells = np.floor(self.grid.to_cells_float(points)).astype(np.intp)
        col = np.clip(cells[..., 0] + ring - self.col0, reach, width - 1 - reach)
        row = np.clip(cells[..., 1] + ring - self.row0, reach, height - 1 - reach)
        offsets = (whole[:, 1] * width + whole[:, 0]).astype(np.intp)
        return framed.ravel()[(row * width + col)[..., None, :] + offsets[:, None]].sum(axis=-1)

    def _score_cells(self, cells):
        """The field summed over the last axis at the centres of cells (..., n, 2) (ix, iy, whole numbers)."""
        height, width = self._padded.shape
        col = np.clip(cells[..., 0].astype(np.intp) + 1 - self.col0, 0, width - 1)
        row = np.clip(cells[..., 1].astype(np.intp) + 1 - self.row0, 0, height - 1)
        return self._padded.ravel()[row * width + col].sum(axis=-1)


def place(pose, points):
    """Points (n, 2) of the base's frame put at `pose` (x, y, yaw): (n, 2) in the map's frame."""
    cos, sin = math.cos(pose[2]), math.sin(pose[2])
    return np.stack((pose[0] + cos * points[:, 0] - sin * points[:, 1],
                     pose[1] + sin * points[:, 0] + cos * points[:, 1]), axis=-1)


def search(field, points, prior, linear, angular, lstep, astep):
    """The best pose (x, y, yaw) and its score among the poses within `linear` m and
    `angular` rad of `prior`, every `lstep` m and `astep` rad: a correlative search."""
    steps_xy = int(math.floor(linear / lstep + 1e-9)) if lstep > 0 else 0
    steps_yaw = int(math.floor(angular / astep + 1e-9)) if astep > 0 else 0
    offsets = lstep * np.arange(-steps_xy, steps_xy + 1)
    yaws = prior[2] + astep * np.arange(-steps_yaw, steps_yaw + 1)
    cos, sin = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    # (yaws, n, 2): the points turned by each yaw, at the prior's position.
    turned = np.stack((cos * points[:, 0] - sin * points[:, 1] + prior[0],
                       sin * points[:, 0] + cos * points[:, 1] + prior[1]), axis=-1)
    shifts = np.stack(np.meshgrid(offsets, offsets, indexing='ij'), axis=-1).reshape(-1, 2)
    scores = field.coarse_scores(turned, shifts)  # (yaws, shifts)
    # Ties (as on an empty map) go to the pose nearest the prior, not to the first one listed.
    nearness = (np.abs(yaws - prior[2])[:, None] / max(astep, 1e-9)
                + np.abs(shifts).sum(axis=1)[None, :] / max(lstep, 1e-9))
    best = np.lexsort((nearness.ravel(), -scores.ravel()))[0]
    yaw_index, shift_index = np.unravel_index(best, scores.shape)
    pose = (prior[0] + shifts[shift_index, 0], prior[1] + shifts[shift_index, 1], yaws[yaw_index])
    return pose, float(scores[yaw_index, shift_index])


def refine(field, points, pose, iterations, prior=None, prior_weight=0.0, reach=None, first=None):
    """Gauss-Newton from `pose` on the distances of the points (base frame) to the walls they are
    paired with, each iteration pairing them anew (ICP, point to line): at most `iterations`
    steps. Points farther than `reach` (default 3 sigma) from their wall point are left out
    (a wall the map does not have yet), and far ones count less (Cauchy weights, scale
    sigma). `prior` (x, y, yaw), if given, pulls as much as `prior_weight` points would (its
    heading with a lever of 1 m): it holds the pose where no wall does, as along a corridor,
    and barely moves it where a few hundred points agree. `prior_weight` may also be a (3, 3)
    information matrix on (x, y, yaw) in the same units (points' worth), to pull more in some
    directions than in others. `first`: normal_equations at `pose`, if the caller has them. Returns
    the pose and its score."""
    pose = np.array(pose, dtype=float)
    information = None
    if prior is not None:
        weight = np.asarray(prior_weight, dtype=float)
        information = max(float(weight), 0.0) * np.eye(3) if weight.ndim == 0 else weight
        if not information.any():
            information = None
    for iteration in range(iterations):
        equations = first if iteration == 0 and first is not None else normal_equations(field, points, pose, reach)
        if equations is None:
            break
        hessian, gradient = equations
        if information is not None:
            towards = np.array((prior[0] - pose[0], prior[1] - pose[1], normalize_angle(prior[2] - pose[2])))
            hessian, gradient = hessian + information, gradient + information.dot(towards)
        step = np.linalg.lstsq(hessian, gradient, rcond=1e-12)[0]
        # One pairing is only good nearby: no step longer than a cell or a twentieth of a radian.
        step /= max(1.0, math.hypot(step[0], step[1]) / field.grid.resolution, abs(step[2]) / 0.05)
        pose += step
        if math.hypot(step[0], step[1]) < 1e-4 and abs(step[2]) < 1e-5:
            break
    pose[2] = normalize_angle(pose[2])
    return tuple(pose), float(field.score(place(pose, points)))


def normal_equations(field, points, pose, reach=None):
    """The Gauss-Newton normal equations (hessian (3, 3), gradient (3,): a step solves hessian . step =
    gradient) of the points (base frame) at `pose` against the walls they pair with, as refine weighs
    them (its `reach`); None if fewer than 3 points pair. The hessian is what the scan tells of the
    pose, in points' worth (a point on a line, one along its normal; the heading with a lever of 1 m).

    Summed from the residuals' two rows by hand: a least-squares solver on the stacked (2n + 3, 3)
    rows took 4 times as long."""
    reach = 3.0 * field.sigma if reach is None else reach
    px, py = points[:, 0], points[:, 1]
    cos, sin = math.cos(pose[2]), math.sin(pose[2])
    tx, ty = cos * px - sin * py, sin * px + cos * py  # the points turned, not moved
    world = np.stack((tx + pose[0], ty + pose[1]), axis=-1)
    wall, pairing, seen_from, paired = field.walls(world)
    offset = world - wall
    # Not with a wall seen from its other side only: along its normal (a line's; a corner's is not
    # known), the side it was seen from (NaN: not known) and the base's now have opposite signs.
    normal = pairing[:, 0]
    seen = normal[:, 0] * seen_from[:, 0] + normal[:, 1] * seen_from[:, 1]
    far_side = (np.abs(seen) >= ONE_SIDED) & (seen * (normal[:, 0] * tx + normal[:, 1] * ty) > 0)
    far_side &= ~pairing[:, 1].any(axis=-1)
    use = paired & ~far_side & (np.einsum('ni,ni->n', offset, offset) < reach * reach)
    if use.sum() < 3:
        return None
    (a, b), (c, d) = pairing[use, 0].T, pairing[use, 1].T
    ox, oy, tx, ty = offset[use, 0], offset[use, 1], tx[use], ty[use]
    # The residual's two rows (pairing . offset) and their derivatives by (x, y, yaw): d(point) =
    # [[1, 0, -ty], [0, 1, tx]].
    rows = np.stack((a, b, b * tx - a * ty, a * ox + b * oy, c, d, d * tx - c * ty, c * ox + d * oy))
    # Cauchy weights on the squared residual: w = 1 / (1 + r^2 / sigma^2).
    w = 1.0 / (1.0 + (rows[3] ** 2 + rows[7] ** 2) / field.sigma ** 2)
    first, second = rows[:4] * np.sqrt(w), rows[4:] * np.sqrt(w)
    normal = first.dot(first.T) + second.dot(second.T)  # (4, 4): [J^T W J, J^T W r; ., .]
    return normal[:3, :3], -normal[:3, 3]
