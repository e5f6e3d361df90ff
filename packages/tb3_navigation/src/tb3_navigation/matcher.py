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
within 2 cells). Why not Gauss-Newton on the field itself, as Hector SLAM
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

#: Half the side, in cells, of the square of occupied cells whose mean points give a wall's direction.
SHAPE_RADIUS = 2
#: A cell's neighbourhood is taken as a line when its spread across is below this share of its spread along
#: (turtlebot3_world's map: the walls' cells median 0.009, 95 % below 0.05; its pillars' of radius
#: 0.15 m median 0.08, 14 % below 0.05).
LINE_SPREAD = 0.05
#: A cell whose neighbourhood is no line (a corner, clutter) pairs as a point, at this weight of a line's:
#: its mean point mixes hits on two faces and lies up to half a cell off either. Along a corridor, where
#: only such cells tell the position along it, weight 1 drifted the pose 4 cm; on the recorded house
#: tour the worst error was 6.1 cm at weight 1, 2.7 cm at 0 and 2.4 cm at 0.3, and from far priors
#: (0.1 to 0.3 m and rad) 0.3 converged most often of the three.
CORNER_WEIGHT = 0.3


class WallField(object):
    """The map as the matcher reads it: the likelihood field of `occupied` (bool, the grid's shape) on
    `grid` for `sigma` (m), and the walls to pair points with: each occupied cell's point `means`
    (height, width, 2) in the frame (NaN, or None for all: the cell's centre) and the wall's
    direction there.

    Unlike amcl's field (tb3_navigation.likelihood: made once per map, over
    the whole grid), this one is made anew as the map grows, a few times a
    second: so it is only computed over the box around the occupied cells
    widened by 4 sigma (and one more cell), where the field is below exp(-8)
    and taken as 0, which a ring of zeros around the box gives; and it keeps
    each cell's nearest occupied cell, to pair points with.
    """

    def __init__(self, grid, occupied, sigma, means=None):
        self.grid, self.sigma = grid, float(sigma)
        rows, cols = np.nonzero(occupied)
        self.empty = rows.size == 0
        if self.empty:
            self.row0 = self.col0 = 0
            self._padded = np.zeros((3, 3))
            return
        pad = int(math.ceil(4.0 * sigma / grid.resolution)) + 1
        self.row0, self.col0 = max(0, rows.min() - pad), max(0, cols.min() - pad)
        row1, col1 = min(grid.height, rows.max() + pad + 1), min(grid.width, cols.max() + pad + 1)
        window = occupied[self.row0:row1, self.col0:col1]
        distance, nearest = ndimage.distance_transform_edt(~window, return_indices=True)
        self._padded = np.pad(np.exp(-0.5 * (distance * grid.resolution / sigma) ** 2), 1)
        # The wall point and the pairing matrix of every window cell's nearest occupied cell.
        rows, cols = np.mgrid[self.row0:row1, self.col0:col1]
        points = grid.centres(np.stack((cols, rows), axis=-1))
        if means is not None:
            own = means[self.row0:row1, self.col0:col1]
            points = np.where(np.isnan(own), points, own)
        points = np.where(window[..., None], points, np.nan)
        pairing = _pairing(points)
        self._wall = points[nearest[0], nearest[1]]
        self._pairing = pairing[nearest[0], nearest[1]]

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
        nothing more along a wall; a weighted identity at a corner), and whether it has one (n,)."""
        cells = self.grid.to_cells(points) - (self.col0, self.row0)
        height, width = self._padded.shape[0] - 2, self._padded.shape[1] - 2
        inside = (cells[:, 0] >= 0) & (cells[:, 0] < width) & (cells[:, 1] >= 0) & (cells[:, 1] < height)
        if self.empty or not inside.any():
            return np.zeros_like(points), np.zeros((len(points), 2, 2)), np.zeros(len(points), dtype=bool)
        col, row = np.clip(cells[:, 0], 0, width - 1), np.clip(cells[:, 1], 0, height - 1)
        return self._wall[row, col], self._pairing[row, col], inside

    def score(self, points):
        """Sum of the field under points (..., n, 2): about how many of them lie on the map's walls."""
        return self.value(points).sum(axis=-1)

    def coarse_score(self, points):
        """score() with each point read at its cell's centre, not between centres: a quarter of
        the work, for the correlative search, whose steps are a cell long anyway."""
        cells = np.floor(self.grid.to_cells_float(points)).astype(np.intp)
        height, width = self._padded.shape
        col = np.clip(cells[..., 0] + 1 - self.col0, 0, width - 1)
        row = np.clip(cells[..., 1] + 1 - self.row0, 0, height - 1)
        return self._padded[row, col].sum(axis=-1)


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
    # (yaws, shifts, n, 2) -> scores (yaws, shifts)
    scores = field.coarse_score(turned[:, None, :, :] + shifts[None, :, None, :])
    # Ties (as on an empty map) go to the pose nearest the prior, not to the first one listed.
    nearness = (np.abs(yaws - prior[2])[:, None] / max(astep, 1e-9)
                + np.abs(shifts).sum(axis=1)[None, :] / max(lstep, 1e-9))
    best = np.lexsort((nearness.ravel(), -scores.ravel()))[0]
    yaw_index, shift_index = np.unravel_index(best, scores.shape)
    pose = (prior[0] + shifts[shift_index, 0], prior[1] + shifts[shift_index, 1], yaws[yaw_index])
    return pose, float(scores[yaw_index, shift_index])


def refine(field, points, pose, iterations, prior=None, prior_weight=0.0, reach=None):
    """Gauss-Newton from `pose` on the distances of the points (base frame) to the walls they are
    paired with, each iteration pairing them anew (ICP, point to line): at most `iterations`
    steps. Points farther than `reach` (default 3 sigma) from their wall point are left out
    (a wall the map does not have yet), and far ones count less (Cauchy weights, scale
    sigma). `prior` (x, y, yaw), if given, pulls as much as `prior_weight` points would (its
    heading with a lever of 1 m): it holds the pose where no wall does, as along a corridor,
    and barely moves it where a few hundred points agree. `prior_weight` may also be a (3, 3)
    information matrix on (x, y, yaw) in the same units (points' worth), to pull more in some
    directions than in others. Returns the pose and its score."""
    reach = 3.0 * field.sigma if reach is None else reach
    pose = np.array(pose, dtype=float)
    root = None
    if prior is not None:
        weight = np.asarray(prior_weight, dtype=float)
        root = (math.sqrt(max(float(weight), 0.0)) * np.eye(3) if weight.ndim == 0
                else np.linalg.cholesky(weight).T)  # root.T @ root == the information
        if not root.any():
            root = None
    for _ in range(iterations):
        cos, sin = math.cos(pose[2]), math.sin(pose[2])
        turned = np.stack((cos * points[:, 0] - sin * points[:, 1], sin * points[:, 0] + cos * points[:, 1]), axis=-1)
        world = turned + pose[:2]
        wall, pairing, paired = field.walls(world)
        offset = world - wall
        use = paired & (np.hypot(offset[:, 0], offset[:, 1]) < reach)
        if use.sum() < 3:
            break
        pairing, offset, turned = pairing[use], offset[use], turned[use]
        residual = np.einsum('nij,nj->ni', pairing, offset)
        # d(point)/d(x, y, yaw) = [[1, 0, -y], [0, 1, x]] with (x, y) the point turned, not moved.
        moving = np.zeros((len(turned), 2, 3))
        moving[:, 0, 0] = moving[:, 1, 1] = 1.0
        moving[:, 0, 2], moving[:, 1, 2] = -turned[:, 1], turned[:, 0]
        jacobian = np.einsum('nij,njk->nik', pairing, moving)
        weight = np.sqrt(1.0 / (1.0 + np.sum(residual ** 2, axis=1) / field.sigma ** 2))[:, None]
        rows, values = (jacobian * weight[:, :, None]).reshape(-1, 3), -(residual * weight).ravel()
        if root is not None:
            towards = np.array((prior[0] - pose[0], prior[1] - pose[1], normalize_angle(prior[2] - pose[2])))
            rows = np.vstack((rows, root))
            values = np.concatenate((values, root.dot(towards)))
        step = np.linalg.lstsq(rows, values, rcond=1e-6)[0]
        # One pairing is only good nearby: no step longer than a cell or a twentieth of a radian.
        step /= max(1.0, math.hypot(step[0], step[1]) / field.grid.resolution, abs(step[2]) / 0.05)
        pose += step
        if math.hypot(step[0], step[1]) < 1e-4 and abs(step[2]) < 1e-5:
            break
    pose[2] = normalize_angle(pose[2])
    return tuple(pose), float(field.score(place(pose, points)))


def _pairing(points):
    """The pairing matrix (height, width, 2, 2) of each cell with a wall point in `points`
    (height, width, 2; NaN elsewhere): [[nx, ny], [0, 0]] with n the normal of the line the
    wall points within SHAPE_RADIUS cells lie on, or CORNER_WEIGHT times the identity where
    they do not lie on one."""
    height, width = points.shape[:2]
    pairing = np.zeros((height, width, 2, 2))
    rows, cols = np.nonzero(~np.isnan(points[..., 0]))
    r = SHAPE_RADIUS
    padded = np.pad(points, ((r, r), (r, r), (0, 0)), constant_values=np.nan)
    around = np.stack([padded[rows + r + dy, cols + r + dx] for dy in range(-r, r + 1) for dx in range(-r, r + 1)],
                      axis=1)  # (cells, (2r+1)^2, 2)
    valid = ~np.isnan(around[..., 0])
    count = valid.sum(axis=1)
    around = np.where(valid[..., None], around, 0.0)
    centre = around.sum(axis=1) / count[:, None]
    spread = np.where(valid[..., None], around - centre[:, None, :], 0.0)
    xx, yy = np.sum(spread[..., 0] ** 2, axis=1), np.sum(spread[..., 1] ** 2, axis=1)
    xy = np.sum(spread[..., 0] * spread[..., 1], axis=1)
    along = 0.5 * np.arctan2(2.0 * xy, xx - yy)  # the direction of the largest spread
    half_sum, half_diff = (xx + yy) / 2.0, np.hypot((xx - yy) / 2.0, xy)
    line = (count >= 3) & (half_sum - half_diff <= LINE_SPREAD * (half_sum + half_diff))
    cell = np.zeros((len(rows), 2, 2))
    cell[:, 0, 0], cell[:, 0, 1] = -np.sin(along), np.cos(along)
    cell[~line] = CORNER_WEIGHT * np.eye(2)
    pairing[rows, cols] = cell
    return pairing


def line_means(grid, occupied, radius=3, flatness=0.1):
    """Wall points for a map that keeps no hits (one loaded from a file): each occupied cell's
    centre put on the line fitted (principal axis) through the occupied cells' centres within
    `radius` cells of it, where those lie along a line (spread across below `flatness` of the
    spread along); else the centre. Centres alone are up to half a cell off the surface each, and
    a scan matched to them was 2 cm off the truth (median; a map made from the simulated lidar,
    saved as map_saver saves it); to the fitted lines 0.9 cm (radius 3, 2026-11-23)."""
    size = np.arange(-radius, radius + 1)
    kernel = (np.hypot(*np.meshgrid(size, size)) <= radius).astype(float)
    centres = grid.all_centres()
    weight = occupied.astype(float)

    def local(values):
        return ndimage.convolve(weight * values, kernel, mode='constant')
    count = np.maximum(local(np.ones(grid.shape)), 1.0)
    x, y = centres[..., 0], centres[..., 1]
    mean_x, mean_y = local(x) / count, local(y) / count
    sxx, syy = local(x * x) / count - mean_x ** 2, local(y * y) / count - mean_y ** 2
    sxy = local(x * y) / count - mean_x * mean_y
    angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)
    half_sum, root = 0.5 * (sxx + syy), np.sqrt(0.25 * (sxx - syy) ** 2 + sxy ** 2)
    along_x, along_y = np.cos(angle), np.sin(angle)
    reach = (x - mean_x) * along_x + (y - mean_y) * along_y
    on_line = np.stack((mean_x + reach * along_x, mean_y + reach * along_y), axis=-1)
    line = occupied & (half_sum - root < flatness * (half_sum + root))
    means = np.full(grid.shape + (2,), np.nan)
    means[occupied] = centres[occupied]
    means[line] = on_line[line]
    return means
