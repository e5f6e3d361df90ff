"""The map's walls as the scan matcher pairs points with them: each occupied cell's wall point and line. No ROS here.

A cell's wall point is the mean of the scan end points that fell in it (where
in the cell its wall lies), else its centre; its line runs through the wall
points of the occupied cells within SHAPE_RADIUS cells, unless they lie on
none (a corner, clutter), where the cell pairs as a point. matcher.WallField
reads these arrays, which WallShapes keeps up to date as the map grows.
"""
import numpy as np

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


class WallShapes(object):
    """Each occupied cell's wall point (the mean of its hits, else its centre), pairing matrix (see
    _pairing) and the side it was seen from (OccupancyGrid.hit_views; NaN: not known) over a whole
    `grid`, kept up to date cell by cell: a scan added to a map changes a few thousand cells of the
    grid's 160 000 and the matrices of a few hundred, and remaking all of them at each map update was a
    third of the SLAM's CPU on the house (doc/speed.md)."""

    def __init__(self, grid):
        self.grid = grid
        r = SHAPE_RADIUS
        # Framed by SHAPE_RADIUS cells of NaN: a cell's neighbourhood is then at hand even at the grid's edge.
        self.points = np.full((grid.height + 2 * r, grid.width + 2 * r, 2), np.nan)
        self.pairing = np.zeros((grid.height + 2 * r, grid.width + 2 * r, 2, 2))
        self.views = np.full((grid.height + 2 * r, grid.width + 2 * r, 2), np.nan)

    @classmethod
    def of_map(cls, grid, occupied, means=None, views=None):
        """The shapes of a whole map: `occupied` (bool, the grid's shape), `means` (height, width, 2; NaN
        where a cell has none) or None (the cells' centres), `views` likewise (None: no side known)."""
        shapes = cls(grid)
        shapes.update(np.arange(grid.width * grid.height), np.ravel(occupied),
                      None if means is None else np.reshape(means, (-1, 2)),
                      None if views is None else np.reshape(views, (-1, 2)))
        return shapes

    def _framed(self, cells):
        r, width = SHAPE_RADIUS, self.grid.width
        return (cells // width + r) * (width + 2 * r) + cells % width + r

    def update(self, cells, occupied, means=None, views=None):
        """Take the state of the grid's `cells` (flat indices into its shape, each once): whether each
        is `occupied`, the mean (k, 2) of the hits in it (NaN: none; None: the centres) and the side
        (k, 2) it was seen from (NaN or None: not known)."""
        cells = np.asarray(cells, dtype=np.intp)
        width = self.grid.width
        points = self.grid.centres(np.stack((cells % width, cells // width), axis=-1))
        if means is not None:
            points = np.where(np.isnan(means), points, means)
        points[~np.asarray(occupied, dtype=bool)] = np.nan
        framed = self._framed(cells)
        self.views.reshape(-1, 2)[framed] = np.nan if views is None else views
        flat = self.points.reshape(-1, 2)
        old = flat[framed]
        changed = np.any((points != old) & ~(np.isnan(points) & np.isnan(old)), axis=-1)
        if not changed.any():
            return
        flat[framed[changed]] = points[changed]
        # The cells whose neighbourhood holds a changed cell: their lines are fitted anew.
        r, stride = SHAPE_RADIUS, width + 2 * SHAPE_RADIUS
        offsets = (np.arange(-r, r + 1)[:, None] * stride + np.arange(-r, r + 1)[None, :]).ravel()
        near = np.unique((framed[changed][:, None] + offsets[None, :]).ravel())  # inside: the frame holds them
        pairing = self.pairing.reshape(-1, 2, 2)
        pairing[near] = 0.0
        near = near[~np.isnan(flat[near, 0])]
        pairing[near] = _pairing(self.points, near // stride, near % stride)

    def has_point(self, cells):
        """Whether each of the grid's `cells` (flat indices) has a wall point (was occupied at the last update)."""
        return ~np.isnan(self.points.reshape(-1, 2)[self._framed(np.asarray(cells, dtype=np.intp)), 0])


def _pairing(points, rows, cols):
    """The pairing matrices (cells, 2, 2) of the cells (`rows`, `cols`) of `points` (a WallShapes'
    framed array of wall points, NaN where none): [[nx, ny], [0, 0]] with n the normal of the line
    the wall points within SHAPE_RADIUS cells lie on, or CORNER_WEIGHT times the identity where
    they do not lie on one."""
    r = SHAPE_RADIUS
    around = np.stack([points[rows + dy, cols + dx] for dy in range(-r, r + 1) for dx in range(-r, r + 1)],
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
    return cell
