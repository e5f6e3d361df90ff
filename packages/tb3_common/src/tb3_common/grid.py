"""A 2-D grid laid on a frame, as nav_msgs/OccupancyGrid lays one. No ROS here.

Cell (ix, iy) is column ix, row iy of a numpy array indexed [iy, ix]; row 0
is the lowest y, as OccupancyGrid's data (row-major from the origin) and
unlike an image's. `origin` is the pose (x, y, yaw) in the frame of cell
(0, 0)'s outer corner, as map_server's YAML gives it and MapMetaData.origin
carries it. Cell values in ROS's convention are FREE 0, OCCUPIED 100 and
UNKNOWN -1 (int8); probabilities in between (0..100) are allowed.
"""
import math

import numpy as np

FREE, OCCUPIED, UNKNOWN = 0, 100, -1


class Grid(object):
    """The geometry of a grid: `width` x `height` cells of `resolution` m at `origin` (x, y, yaw)."""

    def __init__(self, resolution, width, height, origin=(0.0, 0.0, 0.0)):
        if not resolution > 0 or not math.isfinite(resolution):
            raise ValueError('resolution must be a finite number > 0, not %r' % (resolution,))
        if width < 1 or height < 1:
            raise ValueError('a grid needs at least one cell, not %d x %d' % (width, height))
        self.resolution = float(resolution)
        self.width, self.height = int(width), int(height)
        self.origin = tuple(float(value) for value in origin)
        self._cos, self._sin = math.cos(self.origin[2]), math.sin(self.origin[2])

    def __eq__(self, other):
        return (isinstance(other, Grid) and self.resolution == other.resolution and self.width == other.width
                and self.height == other.height and self.origin == other.origin)

    def __repr__(self):
        return 'Grid(%g, %d, %d, origin=%r)' % (self.resolution, self.width, self.height, self.origin)

    @property
    def shape(self):
        """(rows, columns): the numpy shape of the grid's values."""
        return self.height, self.width

    @classmethod
    def around(cls, resolution, xmin, ymin, xmax, ymax):
        """The grid covering the box [xmin, xmax] x [ymin, ymax] (as gmapping's xmin..ymax)."""
        width = max(1, int(math.ceil((xmax - xmin) / resolution - 1e-9)))
        height = max(1, int(math.ceil((ymax - ymin) / resolution - 1e-9)))
        return cls(resolution, width, height, (xmin, ymin, 0.0))

    def to_grid_frame(self, xy):
        """Points (..., 2) of the frame in metres from cell (0, 0)'s corner, along the grid's axes."""
        xy = np.asarray(xy, dtype=float)
        dx, dy = xy[..., 0] - self.origin[0], xy[..., 1] - self.origin[1]
        return np.stack((self._cos * dx + self._sin * dy, -self._sin * dx + self._cos * dy), axis=-1)

    def to_cells_float(self, xy):
        """Points (..., 2) of the frame in cell units: cell (i, j) spans [i, i + 1) x [j, j + 1)."""
        return self.to_grid_frame(xy) / self.resolution

    def to_cells(self, xy):
        """The cells (..., 2) (ix, iy) holding points (..., 2); they may lie outside (see inside)."""
        return np.floor(self.to_cells_float(xy)).astype(np.intp)

    def centres(self, cells):
        """The frame's coordinates (..., 2) of the centres of cells (..., 2) (ix, iy)."""
        cells = np.asarray(cells, dtype=float) + 0.5
        gx, gy = cells[..., 0] * self.resolution, cells[..., 1] * self.resolution
        return np.stack((self.origin[0] + self._cos * gx - self._sin * gy,
                         self.origin[1] + self._sin * gx + self._cos * gy), axis=-1)

    def inside(self, cells):
        """True where cells (..., 2) lie on the grid."""
        cells = np.asarray(cells)
        return ((cells[..., 0] >= 0) & (cells[..., 0] < self.width)
                & (cells[..., 1] >= 0) & (cells[..., 1] < self.height))

    def all_centres(self):
        """Every cell's centre, an array (height, width, 2)."""
        iy, ix = np.mgrid[0:self.height, 0:self.width]
        return self.centres(np.stack((ix, iy), axis=-1))
