"""An occupancy grid built from laser scans, counting hits and visits per cell as gmapping does. No ROS here.

Each cell keeps how many scans saw it (`visits`) and how many of those ended
a beam in it (`hits`); its occupancy is hits / visits, unknown while it was
never seen. Counts rather than log-odds, because gmapping's map rule is
stated on them: a cell is occupied when more than `occ_thresh` (0.25 on
TurtleBot3) of the scans that saw it ended a beam there, so a wall cell
that one scan in three hits (and the others see through, grazing it) stays
a wall; one in four does not. Log-odds would need a prior, a hit and a miss
weight and clamps to mean the same, and would still not say 0.25.

Counting differs from gmapping in one place, on purpose: gmapping counts a
visit per beam, so a cell near the sensor that 30 beams of one scan cross
gets 30 visits from that scan while the wall cell a single beam hits gets
one hit; here every scan counts once per cell (tb3_navigation.raytrace lists
each cell once), and a cell that any beam of the scan ends in counts as a
hit of that scan even if another beam grazed it. Otherwise the beams that
brush a wall at a shallow angle would erase the wall cells that the beams
square to it hit.
"""
import math

import numpy as np

from tb3_common.grid import FREE, OCCUPIED, UNKNOWN, Grid

from . import raytrace

OCC_THRESH = 0.25  # gmapping's occ_thresh


class OccupancyGrid(object):
    """Hit and visit counts on `grid` (a tb3_common.grid.Grid)."""

    def __init__(self, grid):
        self.grid = grid
        self.hits = np.zeros(grid.shape, dtype=np.int32)
        self.visits = np.zeros(grid.shape, dtype=np.int32)
        # Every end point that fell in a cell, summed (and counted): where in the cell its
        # wall lies, finer than the cell, as gmapping's cells keep it for its matcher.
        self._point_sum = np.zeros(grid.shape + (2,))
        self._point_count = np.zeros(grid.shape)
        self._means = np.full(grid.shape + (2,), np.nan)
        # And the way back to the sensor from each (a unit vector), summed: the side of its wall a cell was
        # seen from, for the matcher (a wall's two faces lie its thickness apart: matcher.refine).
        self._view_sum = np.zeros(grid.shape + (2,))
        self._views = np.full(grid.shape + (2,), np.nan)
        # The cells whose counts changed since take_touched(), marked: listing them costs a pass over the
        # grid, where sorting the cells of every scan since took 0.3 s after the 860 scans of a redraw.
        self._touched = np.zeros(grid.shape, dtype=bool)
        self.scans = 0  # how many scans were added

    @classmethod
    def around(cls, delta, xmin, ymin, xmax, ymax):
        """The grid over [xmin, xmax] x [ymin, ymax] at `delta` m, origin (xmin, ymin) as gmapping's map."""
        return cls(Grid.around(delta, xmin, ymin, xmax, ymax))

    def clear(self):
        self.hits[:] = 0
        self.visits[:] = 0
        self._point_sum[:] = 0.0
        self._point_count[:] = 0.0
        self._means[:] = np.nan
        self._view_sum[:] = 0.0
        self._views[:] = np.nan
        self._touched[:] = True
        self.scans = 0

    def add_scan(self, sensor_pose, scan, max_urange, max_range=math.inf):
        """Count `scan` (a tb3_navigation.scan.Scan) taken from `sensor_pose` (x, y, yaw), the
        sensor's pose in the grid's frame: a hit closer than `max_urange` counts its end cell
        as hit and the cells before it as seen free; a longer hit, or a beam that saw nothing
        within the sensor's range, counts the cells up to `max_urange` as seen free (its last
        cell left alone, as gmapping leaves it); a hit longer than `max_range` is dropped
        (gmapping's maxUrange and maxRange). Returns how many beams were used."""
        ends, hit = scan.within(max_range).rays(sensor_pose, max_urange)
        if not len(ends):
            return 0
        occupied = raytrace.end_cells(self.grid, ends[hit])
        seen = np.union1d(raytrace.crossed_cells(self.grid, sensor_pose[:2], ends), occupied)
        self.visits.flat[seen] += 1
        self._touched.flat[seen] = True
        self.hits.flat[occupied] += 1
        points = ends[hit]
        cells = self.grid.to_cells(points)
        inside = self.grid.inside(cells)
        rows, cols, points = cells[inside, 1], cells[inside, 0], points[inside]
        back = np.asarray(sensor_pose[:2], dtype=float) - points
        back /= np.maximum(np.hypot(back[:, 0], back[:, 1]), 1e-12)[:, None]
        np.add.at(self._point_sum, (rows, cols), points)
        np.add.at(self._view_sum, (rows, cols), back)
        np.add.at(self._point_count, (rows, cols), 1.0)
        count = self._point_count[rows, cols, None]
        self._means[rows, cols] = self._point_sum[rows, cols] / count
        self._views[rows, cols] = self._view_sum[rows, cols] / count
        self.scans += 1
        return len(ends)

    def occupancy(self):
        """hits / visits per cell (float), NaN where no scan saw the cell."""
        with np.errstate(invalid='ignore', divide='ignore'):
            return np.where(self.visits > 0, self.hits / np.maximum(self.visits, 1), np.nan)

    def occupied(self, occ_thresh=OCC_THRESH):
        """True where more than `occ_thresh` of the scans that saw a cell hit it."""
        return self.hits > occ_thresh * self.visits

    def take_touched(self):
        """The cells (flat indices, each once) whose counts changed since the last call (after clear():
        all), and forget them: where the map's state may differ now."""
        touched = np.flatnonzero(self._touched)
        self._touched[:] = False
        return touched

    def hit_means(self):
        """The mean (height, width, 2) of the end points that fell in each cell, NaN in a cell none
        fell in: kept up to date scan by scan, so this is the grid's own array (read it only)."""
        return self._means

    def hit_views(self):
        """The mean (height, width, 2) of the unit vectors from the end points that fell in each cell back
        to the sensor, NaN in a cell none fell in: the side its wall was seen from (length near 1: one side
        only; near 0: both, as a post seen all round). The grid's own array, as hit_means'."""
        return self._views

    def walls(self, occ_thresh=OCC_THRESH, cells=None):
        """What the scan matcher takes of the map (wall_shapes.WallShapes), flat: whether each cell is
        occupied (k,), the mean of its hits (k, 2) and the side it was seen from (k, 2), over the
        whole grid or at `cells` (flat indices)."""
        cells = slice(None) if cells is None else cells
        return (np.ravel(self.hits)[cells] > occ_thresh * np.ravel(self.visits)[cells],
                self._means.reshape(-1, 2)[cells], self._views.reshape(-1, 2)[cells])

    def known(self):
        return self.visits > 0

    def values(self, occ_thresh=OCC_THRESH):
        """The cells as nav_msgs/OccupancyGrid data in gmapping's rule, int8 (rows = y, from
        the lowest): UNKNOWN -1 never seen, OCCUPIED 100 above `occ_thresh`, else FREE 0."""
        values = np.full(self.grid.shape, UNKNOWN, dtype=np.int8)
        known = self.known()
        values[known] = FREE
        values[known & self.occupied(occ_thresh)] = OCCUPIED
        return values

