"""SLAM for a node with gmapping's interface: scan-to-map matching on an occupancy grid. No ROS here.

Feed `Slam.update` each scan with the odometry pose of the base at the
scan's time; it matches the scan against the map built so far, from the
odometry's prediction, and keeps the base's pose in the map and the
map -> odom correction; now and then (gmapping's linearUpdate,
angularUpdate, temporalUpdate rule) it adds the scan to the map at that
pose. At start map -> odom is the identity: the map's coordinates are the
odometry's at start.

Why one pose and no particle filter: with 100 particles gmapping matches
each scan 100 times; here one match costs a few ms of numpy, so one
hypothesis keeps the CPU per scan far below the 200 ms between the
Burger's scans, and the result depends on nothing but the input (no
random numbers). A 3 m usable range in rooms of at most 5 m keeps walls
already mapped in view nearly all the time, so the pose does not wander
(see the tests' figures for turtlebot3_world and the house). Where no
wall is in range (the house's yard) the pose drifts with the odometry;
the scans added to the map are then the nodes of a pose graph, and a
scan that comes back near old ones closes the loop: the poses since are
corrected and the map drawn anew (tb3_navigation.loop_closure).

Every scan is matched, not only those added to the map: odometry then only
has to bridge 0.2 s, and the pose the node publishes is corrected at 5 Hz.

Bad input, and what it does:
- NaN, inf, -inf and out-of-range ranges are skipped beam by beam
  (tb3_navigation.scan.Scan); a scan whose beams cannot score minimumScore
  (fewer valid beams than that, or beams that fit nothing) does not move
  the correction: the pose follows the odometry.
- An odometry jump (more than jump_distance or jump_angle between two
  scans, which the Burger cannot drive in 0.2 s): either the robot was
  moved and the odometry saw it (a teleport), or the odometry was reset
  while the robot stood still. Both poses are matched against the map and
  the better one wins; if neither scores minimumScore the odometry is
  believed. map -> odom is then recomputed, so the pose in the map never
  jumps because of a reset.
- An odometry pose with NaN or inf: the scan is ignored.
- Stamps that go back: the temporalUpdate clock restarts; the node may
  call reset() (a new map, map -> odom the identity), as it should when
  the simulation is reset.
"""
import math

import numpy as np

from tb3_common.pose2d import IDENTITY, compose, inverse, relative

from . import matcher
from .loop_closure import LoopCloser, Node
from .occupancy import OccupancyGrid
from .slam_config import SlamConfig
from .wall_shapes import WallShapes

#: After an odometry jump the prediction is only as good as the odometry's drift since the map last
#: corrected it (turtlebot3_world's loop: 14 cm and 2.7 degrees after 55 s): search 3 times as far.
JUMP_SEARCH = 3
#: m the likelihood field reaches beyond where a scan can land: the robot may drive that far before it
#: is made anew (at 0.22 m/s, 2 s of driving when the map does not change).
FIELD_SLACK = 0.5
#: Points' worth of information a match has in every direction at least (x, y, and the heading with a
#: lever of 1 m): where the scan tells less (along a hallway, past a doorway: a few door frames and
#: corners against hundreds of points on two walls), the odometry's prediction makes up the rest.
#: With odom_weight's 20 alone, those few points slid the pose along hallways the map had drawn a
#: little off, and the map followed: 20 cm off in 50 s on perfect odometry (doc/speed.md).
SURE = 150.0
#: Share of a scan's points that must land on walls for a pose found at any heading (Slam._relocate): a
#: scan matched where it belongs scores 0.8 of its points in the house, one 10 degrees off 0.43.
RELOCATE_SHARE = 0.75
#: ... and at least this share more than the pose the prediction matched: along a hallway a slide of
#: 0.36 m scored a little more than the truth and would have been taken.
RELOCATE_GAIN = 0.2
#: After a loop closure the map is drawn anew from every scan of the graph, this many at each scan that
#: comes in: all at once, a redraw on the drive round the outside of the house took 2 s of CPU in one
#: scan's update, and a simulator in lockstep waits 0.5 s at most (doc/speed.md). Meanwhile the pose
#: follows the odometry (the old map's walls lie where the drift drew them): 13 or 14 scans a closure there.
REDRAW_PER_SCAN = 50


class Slam(object):
    """The map, the base's pose in it, and map -> odom, from scans and odometry."""

    def __init__(self, config=None):
        self.config = config or SlamConfig()
        c = self.config
        self.map = OccupancyGrid.around(c.delta, c.xmin, c.ymin, c.xmax, c.ymax)
        self.reset()

    @property
    def grid(self):
        """The map's geometry (tb3_common.grid.Grid): origin (xmin, ymin), delta, size."""
        return self.map.grid

    def reset(self):
        """Forget the map and the pose: the next scan starts a new map, map -> odom the identity."""
        self.map.clear()
        self.map_to_odom = IDENTITY
        self.pose = None  # the base's pose in the map after the last scan
        self.score = 0.0  # the last match's score (0: no match)
        self.matched = False  # whether the last scan's match was used
        self.jumped = False  # whether the odometry jumped before the last scan
        self._astray = False  # whether the odometry jumped or went astray since the last scan added to the map
        self._followed = np.zeros(2)  # m and rad the pose followed the odometry unmatched since then
        self.map_updates = 0  # changes whenever the map does: a scan added, the map drawn anew
        self._redraw = None  # after a loop closure: [the map being drawn anew, how many scans it holds]
        self._odom = None
        self._last_added = None
        self._moved = self._turned = 0.0
        self.map.take_touched()  # a new map: nothing to carry over into the new shapes
        self._shapes, self._shapes_version = WallShapes(self.map.grid), 0
        self._touched = np.zeros(0, dtype=np.intp)  # the map's cells changed since the shapes took them
        self._field = None
        self.loops = LoopCloser(self.config, self.map.grid)

    def update(self, stamp, odom_pose, scan, sensor_pose=IDENTITY):
        """Take one scan (a tb3_navigation.scan.Scan) at `stamp` (s), with `odom_pose` (x, y, yaw)
        of the base in odom at that time and `sensor_pose` (x, y, yaw) of the scanner in the
        base frame. Returns the base's pose (x, y, yaw) in the map."""
        c = self.config
        odom = tuple(float(value) for value in odom_pose)
        if not all(math.isfinite(value) for value in odom):
            return self.pose  # an odometry pose with NaN says nothing: keep what we had
        points = scan.within(c.maxRange or scan.range_max).hit_points(
            sensor_pose, max_range=c.maxUrange, beams=np.arange(0, len(scan), c.lskip + 1))
        predicted = tuple(compose(self.map_to_odom, odom))
        pose, self.matched, self.jumped, self.score = predicted, False, False, 0.0
        if self.pose is not None:
            motion = relative(self._odom, odom)
            self.jumped = bool(math.hypot(motion[0], motion[1]) > c.jump_distance or abs(motion[2]) > c.jump_angle)
            self._astray |= self.jumped
            if self._redraw is not None and self.jumped:
                self._go_on_drawing(everything=True)  # a jump's two hypotheses are told apart by the map
            if self._redraw is None:
                # After a jump, the pose before it is the other hypothesis: the odometry was reset in place.
                priors = [predicted, self.pose] if self.jumped else [predicted]
                pose = self._match(points, priors, widen=JUMP_SEARCH if self.jumped else 1)
                if pose is None or self.score < RELOCATE_SHARE * len(points):
                    found = self._relocate(points, self.pose, self.score)
                    self._astray |= found is not None
                    pose = found or pose
                pose = pose or predicted
            step = relative(self.pose, pose)
            self._moved += math.hypot(step[0], step[1])
            self._turned += abs(step[2])
            if not self.matched:
                self._followed += (math.hypot(motion[0], motion[1]), abs(motion[2]))
        if self.matched:
            self.map_to_odom = tuple(compose(pose, inverse(odom)))
        self.pose, self._odom = pose, odom
        max_range = c.maxRange or scan.range_max
        if self._due(stamp) and self.map.add_scan(tuple(compose(pose, sensor_pose)), scan, c.maxUrange, max_range):
            # A scan with no usable beam is not counted: the next one is due as well.
            self.map_updates += 1
            self._last_added, self._moved, self._turned = stamp, 0.0, 0.0
            closed = self.loops.add(pose, points, Node(scan, sensor_pose, max_range, odom),
                                    lambda: self.map.occupied(c.occ_thresh), self._astray, search=self._redraw is None,
                                    followed=tuple(self._followed))
            self._astray, self._followed = False, np.zeros(2)
            if closed is not None:
                self._closed(closed)
                return self.pose
        if self._redraw is not None:
            self._go_on_drawing()
        return self.pose

    def _closed(self, pose):
        """A loop closed: the pose is `pose`; the map is drawn anew from every scan at its corrected pose,
        starting now (see REDRAW_PER_SCAN)."""
        self.pose = pose
        self.map_to_odom = tuple(compose(pose, inverse(self._odom)))
        self._redraw = [OccupancyGrid(self.map.grid), 0]
        self._go_on_drawing()

    def _go_on_drawing(self, everything=False):
        """Draws the next REDRAW_PER_SCAN scans of the graph (or all the rest) into the new map; the last
        of them puts it in the old one's place."""
        grid, drawn = self._redraw
        end = len(self.loops.graph) if everything else min(drawn + REDRAW_PER_SCAN, len(self.loops.graph))
        self.loops.draw(grid, range(drawn, end))
        self._redraw[1] = end
        if end < len(self.loops.graph):
            return
        self.map, self._redraw = grid, None
        self.map.take_touched()
        self._shapes = WallShapes.of_map(self.map.grid, *self.map.walls(self.config.occ_thresh))
        self._touched, self._field = np.zeros(0, dtype=np.intp), None
        self.map_updates += 1
        self._shapes_version = self.map_updates

    def _match(self, points, priors, widen=1):
        """The best match of `points` (base frame) from any of `priors`, or None if none scores
        minimumScore. `widen` > 1 (after a jump): the search reaches that much farther, the
        refinement takes that many more steps, and the odometry does not pull."""
        c = self.config
        if len(points) < max(1, c.minimumScore):
            return None  # cannot score enough: do not even try
        field = self._likelihood(priors, widen)
        if field.empty:
            return None
        best, best_score = None, -1.0
        for prior in priors:
            start, _ = matcher.search(field, points, prior, widen * c.search_linear, widen * c.search_angular,
                                      c.lstep, c.astep)
            equations = matcher.normal_equations(field, points, start) if widen == 1 else None
            pose, score = matcher.refine(field, points, start, widen * c.iterations, prior,
                                         self._prior_information(equations) if widen == 1 else 0.0,
                                         first=equations)
            if score > best_score:
                best, best_score = pose, score
        self.score = best_score
        if best_score < c.minimumScore:
            return None
        self.matched = True
        return best

    def _prior_information(self, equations):
        """The odometry prior's information for a match whose scan tells `equations` (matcher.normal_equations
        at the search's pose; None: nothing): odom_weight in every direction, and in a direction the scan
        tells less of than SURE points' worth (along a corridor), the rest."""
        told, directions = np.linalg.eigh(equations[0] if equations is not None else np.zeros((3, 3)))
        return (directions * np.maximum(self.config.odom_weight, SURE - told)).dot(directions.T)

    def _relocate(self, points, around, score):
        """The pose when the prediction matched nothing, or put less than RELOCATE_SHARE of the points on
        walls, though the scan has plenty to match (the wheels turned on a robot held still, and the
        odometry with them): searched at any heading within the
        jump's reach of `around`, and taken only where RELOCATE_SHARE of the points land on walls, and
        RELOCATE_GAIN of them more than the `score` of the prediction's match. The odometry's steps since
        are then no measure for the loop closer's chain."""
        c = self.config
        if len(points) < 2 * c.minimumScore:
            return None
        field = self._likelihood([around], JUMP_SEARCH)
        if field.empty:
            return None
        start, _ = matcher.search(field, points, around, JUMP_SEARCH * c.search_linear, math.pi, c.lstep, c.astep)
        pose, found = matcher.refine(field, points, start, JUMP_SEARCH * c.iterations)
        if found < max(RELOCATE_SHARE, score / len(points) + RELOCATE_GAIN) * len(points):
            return None
        self.score, self.matched = found, True
        return pose

    def _likelihood(self, priors, widen):
        """The likelihood field of the map around `priors`, made anew only when the set of occupied cells
        changed (a robot standing still adds scans that change none) or when the scan could land
        off it: it covers the cells within maxUrange, the search's reach and FIELD_SLACK of the
        priors it was made for, so that the next few scans use it too, for a tenth of the cost
        of one over the whole house (doc/speed.md)."""
        c = self.config
        if self._shapes_version != self.map_updates:
            # The cells changed since the shapes last took them are taken when the set of occupied cells
            # changes, not at every added scan: wall points that follow each scan pulled the poses along
            # with them (the house round: median error 1.6 -> 3.2 cm).
            self._touched = np.union1d(self._touched, self.map.take_touched())
            occupied, means, views = self.map.walls(c.occ_thresh, self._touched)
            if np.any(occupied != self._shapes.has_point(self._touched)):
                self._shapes.update(self._touched, occupied, means, views)
                self._touched, self._field = self._touched[:0], None
            self._shapes_version = self.map_updates
        needed = self._box(priors, c.maxUrange + widen * c.search_linear + c.delta)
        if self._field is None or not self._field.covers(needed):
            self._field = matcher.WallField(self._shapes, c.sigma,
                                            self._box(priors, c.maxUrange + widen * c.search_linear + FIELD_SLACK))
        return self._field

    def _box(self, priors, reach):
        """The cells (row0, row1, col0, col1) within `reach` m of the priors' positions, on the grid."""
        grid = self.map.grid
        xy = np.array([prior[:2] for prior in priors])
        corners = grid.to_cells_float(np.concatenate((xy - reach, xy + reach)))  # the grid is not turned
        low, high = np.floor(corners.min(axis=0)).astype(int), np.floor(corners.max(axis=0)).astype(int) + 1
        return (max(0, low[1]), min(grid.height, high[1]), max(0, low[0]), min(grid.width, high[0]))

    def _due(self, stamp):
        """gmapping's rule: add the first scan, then one after linearUpdate m or angularUpdate rad
        of motion, or temporalUpdate s (if >= 0) after the last added one."""
        c = self.config
        if self._last_added is None:
            return True  # the first scan with a usable beam
        if stamp < self._last_added:
            self._last_added = stamp  # time went back: count temporalUpdate from now
        return (self._moved >= c.linearUpdate or self._turned >= c.angularUpdate
                or (c.temporalUpdate >= 0 and stamp - self._last_added > c.temporalUpdate))

    def map_values(self):
        """The map as nav_msgs/OccupancyGrid data (int8, rows from the lowest y): -1, 0, 100 as gmapping's."""
        return self.map.values(self.config.occ_thresh)
