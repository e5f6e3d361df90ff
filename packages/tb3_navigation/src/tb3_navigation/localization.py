"""Where the robot is on a known map: amcl's particle filter, for a node with amcl's interface. numpy, scipy; no ROS.

Amcl(config, grid, values) holds the particles in the map's frame. The node
hands it every scan with the odometry pose (odom -> base) at the scan's time;
as amcl, the filter works only when odometry moved more than update_min_d or
turned more than update_min_a since its last update (or after
request_nomotion_update, an initial pose or global_localization): it moves
the particles by the odometry's motion with noise, weighs them by the scan on
the likelihood field (tb3_navigation.likelihood), and resamples every
resample_interval updates, as few particles as KLD-sampling asks for
(tb3_navigation.particles). Its estimate is amcl's: the weighted mean of the
heaviest cluster; map -> odom follows from it and the odometry pose of the
update.

Where this differs from amcl, and why:
- update_min_d is a distance (m); amcl tests |dx| and |dy| in the odom frame
  apart, so a diagonal drive waited up to 0.28 m for 0.2.
- The motion model is TurtleBot3's "diff" by default, noise and all (amcl's
  diff uses a variance as a standard deviation: 4 mm per 0.2 m with alphas
  0.1); "diff-corrected" (63 mm) is there too. On the realistic Burger, diff
  holds the pose within 5 cm (the 95th percentile of diff-corrected's error
  reached 6.1 cm in 10 seeds) but its cloud cannot explore: global
  localization in turtlebot3_house found the robot in 3 of 8 seeds with
  diff, 8 of 8 with diff-corrected.
- Resampling is low-variance (see particles.resample), with KLD's count.
- The recovery averages use the mean likelihood of the particles (their
  weights summed to one), where amcl divides once more by the particle
  count, which KLD changes from one update to the next.
- The estimate's covariance is the whole set's, as amcl publishes it in
  amcl_pose; the heaviest cluster's is there too.
- The estimate's pose is the heaviest cluster's mean matched to the map by
  the update's scan (tb3_navigation.matcher: point-to-line Gauss-Newton to
  lines fitted through the map's occupied cells), pulled towards the mean as
  much as the cluster's own spread says it knows (its covariance's inverse,
  in beams of REFINE_SIGMA), when the match keeps half the beams on walls
  and moves the mean less than 0.1 m and 0.1 rad; else the mean itself
  (refine_estimate false: always). With TurtleBot3's flat beam model
  (sigma_hit 0.2, z_rand 0.5) the cloud is a few cm wide and its mean
  wanders in it: on the loop round turtlebot3_world's pillars (shipped map,
  after its first quarter) the mean was median 3.5, p95 5.0, worst 5.7 cm
  off the truth, and a robot stopping on it ended up to 6.5 cm from its
  goal (tolerance 0.05 m). Matched, 0.3, 0.8, 0.9 cm (doc/design.md).
  After each update the heaviest cluster is moved, rigidly, a fifth of the
  way from its mean to the matched pose (REFINE_FOLLOW), so that the cloud
  cannot drift away from what the scans say while odometry turns wrong.
"""
import math
from collections import namedtuple

import numpy as np
from scipy import ndimage

from tb3_common.pose2d import compose, inverse, normalize_angle
from tb3_navigation import matcher
from tb3_navigation import particles as pf
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.likelihood import LikelihoodField, LikelihoodFieldModel
from tb3_navigation.scan import endpoints

#: rviz's 2D Pose Estimate and amcl's initial_cov_*: 0.5 m and 15 degrees of standard deviation.
RVIZ_COVARIANCE = np.diag([0.25, 0.25, (math.pi / 12.0) ** 2])

#: m: the walls' field of the refinement (gmapping's sigma on TurtleBot3), and a beam's standard deviation
#: in it when the cluster's spread is weighed against the beams. A fixed pull of 20 beams towards the mean
#: kept 40 % of the mean's error (p95 3.3 cm on the loop); the spread's pull keeps what the walls leave
#: open (along a corridor) and little else.
REFINE_SIGMA = 0.05
REFINE_ITERATIONS = 5    # Gauss-Newton steps
REFINE_FLOOR = 1e-6      # m^2, rad^2 added to the cluster's covariance: a collapsed cluster pulls hard, finitely
REFINE_LIMIT = (0.1, 0.1)  # m, rad: a match moving the mean further is not taken
REFINE_SHARE = 0.5       # of the beams that must score on walls
#: Share of the way from the cluster's mean to the matched pose that the cluster is moved after each update.
#: TurtleBot3's "diff" noise (4 mm and 0.004 rad per 0.2 m or rad) lets the cloud fall behind odometry
#: that turns wrong (the realistic Burger's caster): on test_navigation's drives its mean drifted 11 cm and
#: 0.12 rad, past what the match may move it, and amcl published the mean. Moved fully, the cloud follows
#: the match's error along walls it cannot see well (thick walls: p95 2.9 -> 5.4 cm); 0.2 kept both small.
REFINE_FOLLOW = 0.2


#: amcl's estimate: `pose` (x, y, yaw) the weighted mean of the heaviest cluster; `covariance` (3, 3) of
#: the whole set (what amcl publishes in amcl_pose); `cluster_covariance` the heaviest cluster's;
#: `weight` its share of the weight; `clusters` how many there are.
Estimate = namedtuple('Estimate', 'pose covariance cluster_covariance weight clusters')


def covariance_6x6(covariance):
    """A 3x3 (x, y, yaw) covariance as the 36 numbers of a PoseWithCovariance (x y z roll pitch yaw)."""
    full = np.zeros((6, 6))
    index = [0, 1, 5]
    full[np.ix_(index, index)] = np.asarray(covariance, dtype=float).reshape(3, 3)
    return full.ravel().tolist()


def covariance_3x3(covariance36):
    """The (x, y, yaw) part (3, 3) of a PoseWithCovariance's 36 numbers (amcl reads xx, xy, yx, yy and yaw-yaw)."""
    full = np.asarray(covariance36, dtype=float).reshape(6, 6)
    covariance = np.zeros((3, 3))
    covariance[:2, :2] = full[:2, :2]
    covariance[2, 2] = full[5, 5]
    return covariance


class Amcl(object):
    """amcl's filter on the map (`grid`, int8 `values` as OccupancyGrid's) with `config` (None: AmclConfig()),
    started at the config's initial pose; `seed` makes it repeatable. A new map means a new filter, as
    amcl makes one."""

    def __init__(self, config, grid, values, seed=None):
        self.config = config = config if config is not None else AmclConfig()
        self.grid = grid
        self.field = LikelihoodField(grid, values, config.laser_likelihood_max_dist)
        self.model = LikelihoodFieldModel(self.field, config.laser_z_hit, config.laser_z_rand, config.laser_sigma_hit)
        occupied = np.asarray(values).reshape(grid.shape) == 100
        self._walls = (matcher.WallField.of_map(grid, occupied, REFINE_SIGMA, line_means(grid, occupied))
                       if config.refine_estimate and occupied.any() else None)
        self._points = None  # the last update's beam end points (base frame), for the refinement
        free = np.argwhere(np.asarray(values).reshape(grid.shape) == 0)  # amcl samples free cells only, not unknown
        self._free_cells = free[:, ::-1]  # (ix, iy)
        self._rng = np.random.default_rng(seed)
        self.updates = 0  # sensor updates since the filter was (re)initialised
        self.resampled = False  # whether the last update resampled (amcl publishes amcl_pose then)
        self.initialise(config.initial_pose, config.initial_covariance)

    # -- the set of particles --------------------------------------------------------------------------------

    @property
    def particles(self):
        """The poses (n, 3) (x, y, yaw) in the map's frame: the particle cloud."""
        return self._poses

    @property
    def weights(self):
        return self._weights

    def _reset(self, poses):
        self._points = None  # a scan from before is no evidence for the new cloud
        self._poses = poses
        self._weights = np.full(len(poses), 1.0 / len(poses))
        self._odom = None  # the next scan updates the filter, moved or not (amcl's pf_init_ false)
        self._force = False
        self._w_slow = self._w_fast = 0.0
        self.updates = 0
        self.resampled = False
        self._estimate = self._compute_estimate()

    def initialise(self, pose, covariance=RVIZ_COVARIANCE):
        """max_particles drawn from a Gaussian at `pose` (x, y, yaw, map) with `covariance` (3, 3), as
        amcl does on an initialpose message."""
        pose = np.asarray(pose, dtype=float).reshape(3)
        covariance = np.asarray(covariance, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(pose)) or not np.all(np.isfinite(covariance)):
            raise ValueError('an initial pose must be finite, not %r with covariance %r' % (pose, covariance))
        if not np.allclose(covariance, covariance.T) or np.linalg.eigvalsh(covariance).min() < -1e-12:
            raise ValueError('an initial covariance must be symmetric and positive semi-definite, not %r'
                             % (covariance.tolist(),))
        poses = self._rng.multivariate_normal(pose, covariance, size=self.config.max_particles, method='eigh')
        poses[:, 2] = normalize_angle(poses[:, 2])
        self._reset(poses)

    def uniform_poses(self, count):
        """`count` poses spread evenly over the map's free cells, any heading."""
        if not len(self._free_cells):
            raise ValueError('the map has no free cell (value 0) to spread particles over')
        cells = self._free_cells[self._rng.integers(len(self._free_cells), size=count)]
        corners = self.grid.centres(cells - 0.5 + self._rng.random((count, 2)))  # anywhere in the cell
        return np.column_stack((corners, self._rng.uniform(-math.pi, math.pi, count)))

    def global_localization(self):
        """max_particles spread evenly over the free cells (amcl's global_localization service)."""
        self._reset(self.uniform_poses(self.config.max_particles))

    def request_nomotion_update(self):
        """Make the next scan update the filter even if the robot has not moved (amcl's service)."""
        self._force = True

    # -- updates ------------------------------------------------------------------------------------------------

    def update(self, odom_pose, scan, sensor_pose=(0.0, 0.0, 0.0)):
        """Take a scan (a tb3_navigation.scan.Scan) taken at `odom_pose` (x, y, yaw of base in odom),
        from a laser at `sensor_pose` in the base frame. True if the filter updated."""
        odom_pose = tuple(float(value) for value in odom_pose)
        if not all(math.isfinite(value) for value in odom_pose):
            raise ValueError('an odometry pose must be finite, not %r' % (odom_pose,))
        config = self.config
        if self._odom is not None:
            moved = math.hypot(odom_pose[0] - self._odom[0], odom_pose[1] - self._odom[1])
            turned = abs(normalize_angle(odom_pose[2] - self._odom[2]))
            if not (moved > config.update_min_d or turned > config.update_min_a or self._force):
                return False
            self._poses = pf.sample_diff_motion(self._poses, self._odom, odom_pose, config.odom_alphas,
                                                config.odom_model_type == 'diff-corrected', self._rng)
        self._force = False
        self._odom = odom_pose
        self._weigh(scan, sensor_pose)
        self.updates += 1
        self.resampled = self.updates % config.resample_interval == 0
        if self.resampled:
            self._resample()
        self._estimate = self._compute_estimate(follow_match=True)
        return True

    def _beams(self, scan, sensor_pose):
        """(end points (B, 2) in the base frame, range_max) of the beams amcl uses: laser_max_beams spread
        evenly, each skipped unless finite and within (range_min, range_max)."""
        config = self.config
        range_max = min(scan.range_max, config.laser_max_range) if config.laser_max_range > 0 else scan.range_max
        range_min = max(scan.range_min, config.laser_min_range) if config.laser_min_range > 0 else scan.range_min
        beams = scan.subsample(config.laser_max_beams)
        ranges = scan.ranges[beams]
        with np.errstate(invalid='ignore'):
            use = scan.hits[beams] & (ranges > range_min) & (ranges < range_max)
        return endpoints(sensor_pose, scan.angles[beams][use], ranges[use]), range_max

    def _weigh(self, scan, sensor_pose):
        points, range_max = self._beams(scan, sensor_pose)
        self._points = points
        weights = self._weights * self.model.weights(self._poses, points, range_max)
        total = float(weights.sum())
        self._weights = weights / total
        # The running averages of the likelihood for recovery (Probabilistic Robotics, table 8.3). The
        # weights summed to 1, so `total` is the mean likelihood (amcl divides once more by the count,
        # which KLD changes between updates).
        alpha_slow, alpha_fast = self.config.recovery_alpha_slow, self.config.recovery_alpha_fast
        self._w_slow = total if self._w_slow == 0.0 else self._w_slow + alpha_slow * (total - self._w_slow)
        self._w_fast = total if self._w_fast == 0.0 else self._w_fast + alpha_fast * (total - self._w_fast)

    def _resample(self):
        config = self.config
        random_share = max(0.0, 1.0 - self._w_fast / self._w_slow) if self._w_slow > 0 else 0.0
        self._poses, self._weights = pf.resample(
            self._poses, self._weights, config.min_particles, config.max_particles, config.kld_err, config.kld_z,
            self._rng, random_share, self.uniform_poses if len(self._free_cells) else None)
        if random_share > 0.0:
            self._w_slow = self._w_fast = 0.0  # as amcl: not to spiral off into complete randomness

    # -- what comes out -----------------------------------------------------------------------------------------

    def _compute_estimate(self, follow_match=False):
        """The Estimate; with `follow_match` (after an update), a heaviest cluster whose mean the scan matched
        elsewhere is moved there, rigidly (see the module)."""
        labels, count = pf.clusters(self._poses)
        cluster_weights = np.bincount(labels, weights=self._weights, minlength=count)
        heaviest = int(np.argmax(cluster_weights))
        members = labels == heaviest
        cluster = pf.stats(self._poses[members], self._weights[members])
        mean = tuple(float(value) for value in cluster.mean)
        pose = self._refined(mean, cluster.covariance)
        if follow_match and pose != mean and REFINE_FOLLOW > 0:
            target = (mean[0] + REFINE_FOLLOW * (pose[0] - mean[0]), mean[1] + REFINE_FOLLOW * (pose[1] - mean[1]),
                      mean[2] + REFINE_FOLLOW * normalize_angle(pose[2] - mean[2]))
            self._poses = self._poses.copy()
            self._poses[members] = compose(target, compose(inverse(mean), self._poses[members]))
            cluster = pf.stats(self._poses[members], self._weights[members])
        whole = pf.stats(self._poses, self._weights)
        return Estimate(pose, whole.covariance, cluster.covariance, float(cluster.weight), int(count))

    def _refined(self, mean, covariance):
        """The mean matched to the map by the last update's scan, pulled towards the mean as the cluster's
        `covariance` (3, 3) says, if the match holds (see the module)."""
        points = self._points
        if self._walls is None or points is None or len(points) < 10:
            return mean
        information = REFINE_SIGMA ** 2 * np.linalg.inv(np.asarray(covariance) + REFINE_FLOOR * np.eye(3))
        pose, score = matcher.refine(self._walls, points, mean, REFINE_ITERATIONS, prior=mean,
                                     prior_weight=information)
        if score < REFINE_SHARE * len(points) or math.hypot(pose[0] - mean[0], pose[1] - mean[1]) > REFINE_LIMIT[0] \
                or abs(normalize_angle(pose[2] - mean[2])) > REFINE_LIMIT[1]:
            return mean
        return tuple(float(value) for value in pose)

    def estimate(self):
        """amcl's Estimate of the current set."""
        return self._estimate

    @property
    def odom_pose(self):
        """The odometry pose of the last update (None before the first after an initialisation)."""
        return self._odom

    def map_to_odom(self):
        """The pose (x, y, yaw) of odom in map that puts base at the estimate (None before the first
        update): amcl's tf map -> odom."""
        if self._odom is None:
            return None
        return tuple(float(value) for value in compose(self._estimate.pose, inverse(self._odom)))


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
