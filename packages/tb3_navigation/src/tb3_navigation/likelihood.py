"""amcl's likelihood field: how well a scan fits a map from many poses at once. numpy and scipy; no ROS.

The field holds, for every cell, the distance to the nearest occupied cell,
capped at `max_dist` (amcl's laser_likelihood_max_dist, 2.0 m): beyond it a
beam end counts as far from everything. As amcl's map conversion, only cells
of value 100 are occupied; unknown (-1) and anything in between are not, so
the field runs through them. A beam ending off the map counts as `max_dist`
away, as amcl penalises it.

The beam model is amcl's "likelihood_field" (AMCLLaser::LikelihoodFieldModel):
each beam's pz = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max,
where d is the field at the beam's end; beams at or beyond range_max (and
NaN) are skipped. amcl combines the beams by the ad-hoc sum p = 1 + sum pz^3
rather than the product: one beam on a chair that the map lacks then costs a
particle a little, not everything. With TurtleBot3's z_hit 0.5, z_rand 0.5,
range 3.5 m a beam adds 0.262 on a wall and 0.003 at 2 m from one, so 180
beams give a pose at most ~48 times the weight of the worst one: the filter
sharpens over several updates, not in one.

Since pz depends on the cell only, the field keeps pz^3 per cell (for one
range_max at a time) and a scan's weight for P poses x B beams is one gather
and one sum. The table is framed by one cell holding the off-map value, so
an end point off the map needs a clip, not a test.
"""
import math

import numpy as np
from scipy.ndimage import distance_transform_edt

from tb3_common.grid import OCCUPIED


class LikelihoodField(object):
    """The distance field of a map: `grid` (a Grid) and its `values` (int8, [iy, ix], ROS's convention)."""

    def __init__(self, grid, values, max_dist=2.0):
        if not max_dist > 0 or not math.isfinite(max_dist):
            raise ValueError('laser_likelihood_max_dist must be a finite number > 0, not %r' % (max_dist,))
        values = np.asarray(values)
        if values.shape != grid.shape and values.size == grid.width * grid.height:
            values = values.reshape(grid.shape)  # OccupancyGrid's flat data
        if values.shape != grid.shape:
            raise ValueError('a %d x %d grid needs %d values, not an array of shape %r'
                             % (grid.width, grid.height, grid.width * grid.height, values.shape))
        self.grid, self.max_dist = grid, float(max_dist)
        occupied = values == OCCUPIED
        if occupied.any():
            # The exact Euclidean distance between cell centres, in cells.
            distance = distance_transform_edt(~occupied) * grid.resolution
            self.distance = np.minimum(distance, self.max_dist)
        else:
            self.distance = np.full(grid.shape, self.max_dist)
        self._tables = {}

    def distance_at(self, points):
        """The field (...,) at points (..., 2) of the map's frame: max_dist off the map."""
        cells = self.grid.to_cells(points)
        inside = self.grid.inside(cells)
        ix = np.where(inside, cells[..., 0], 0)
        iy = np.where(inside, cells[..., 1], 0)
        return np.where(inside, self.distance[iy, ix], self.max_dist)

    def beam_table(self, z_hit, z_rand, sigma_hit, range_max):
        """pz^3 of a beam ending in each cell, framed by one cell of the off-map value:
        an array (height + 2, width + 2). Cached per parameter set."""
        key = (float(z_hit), float(z_rand), float(sigma_hit), float(range_max))
        table = self._tables.get(key)
        if table is None:
            distance = np.pad(self.distance, 1, mode='constant', constant_values=self.max_dist)
            pz = z_hit * np.exp(-distance ** 2 / (2.0 * sigma_hit ** 2)) + z_rand / range_max
            table = self._tables[key] = pz ** 3
            if len(self._tables) > 4:  # range_max changes only with the laser: keep a few
                self._tables.pop(next(iter(self._tables)))
        return table


class LikelihoodFieldModel(object):
    """amcl's likelihood_field beam model on `field`, with laser_z_hit, laser_z_rand, laser_sigma_hit."""

    def __init__(self, field, z_hit=0.5, z_rand=0.5, sigma_hit=0.2):
        self.field = field
        self.z_hit, self.z_rand, self.sigma_hit = float(z_hit), float(z_rand), float(sigma_hit)

    def weights(self, poses, points, range_max, chunk=16384):
        """p = 1 + sum over beams of pz^3 (P,), for the base poses (P, 3) in the map's
        frame and the beams' end points (B, 2) in the base frame, all closer than
        `range_max` (the caller drops the others, as amcl skips them).

        Poses go `chunk` // B at a time, so that temporaries of 16384 numbers (128 kB)
        stay in the cache: 3000 poses x 163 beams took 5.3 ms so and 17 ms in one pass.
        """
        poses = np.asarray(poses, dtype=float).reshape(-1, 3)
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        weights = np.ones(len(poses))
        if not len(points) or not len(poses):
            return weights
        grid = self.field.grid
        table = self.field.beam_table(self.z_hit, self.z_rand, self.sigma_hit, range_max).ravel()
        columns = grid.width + 2
        scale = 1.0 / grid.resolution
        # The poses in the grid's own frame, in cells, shifted by the table's frame of one cell: a beam
        # end's column is then its coordinate truncated, once clipped into [0, width + 1].
        corner = grid.to_grid_frame(poses[:, :2]) * scale + 1.0
        yaw = poses[:, 2] - grid.origin[2]
        cos, sin = np.cos(yaw)[:, None] * scale, np.sin(yaw)[:, None] * scale
        ex, ey = points[:, 0][None, :], points[:, 1][None, :]
        step = max(1, chunk // len(points))
        for start in range(0, len(poses), step):
            part = slice(start, start + step)
            gx = corner[part, 0:1] + cos[part] * ex - sin[part] * ey
            gy = corner[part, 1:2] + sin[part] * ex + cos[part] * ey
            ix = np.clip(gx, 0.0, columns - 1.0).astype(np.intp)
            iy = np.clip(gy, 0.0, grid.height + 1.0).astype(np.intp)
            iy *= columns
            iy += ix
            weights[part] += table[iy].sum(axis=1)
        return weights
