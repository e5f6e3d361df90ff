"""The likelihood field and amcl's likelihood_field beam model, against plain loops over amcl's formulas."""
import math

import numpy as np
import pytest

from tb3_common.grid import Grid
from tb3_navigation.likelihood import LikelihoodField, LikelihoodFieldModel


def random_map(seed, grid):
    """A map with walls, some unknown cells and a few cells of in-between values."""
    rng = np.random.default_rng(seed)
    values = np.zeros(grid.shape, dtype=np.int8)
    values[rng.random(grid.shape) < 0.04] = 100
    values[rng.random(grid.shape) < 0.05] = -1
    values[rng.random(grid.shape) < 0.02] = 70  # not 100: amcl does not count it as occupied
    return values


def brute_distance(grid, values, max_dist):
    """Each cell's distance to the nearest cell of value 100, centre to centre, capped."""
    centres = grid.all_centres()
    occupied = centres[values == 100]
    distance = np.full(grid.shape, max_dist)
    for iy in range(grid.height):
        for ix in range(grid.width):
            if len(occupied):
                nearest = np.min(np.hypot(*(occupied - centres[iy, ix]).T))
                distance[iy, ix] = min(max_dist, nearest)
    return distance


@pytest.mark.parametrize('origin', [(0.0, 0.0, 0.0), (-1.3, 0.7, 0.4)])
def test_field_is_the_capped_distance_to_the_nearest_occupied_cell(origin):
    grid = Grid(0.1, 23, 17, origin)
    values = random_map(1, grid)
    field = LikelihoodField(grid, values, max_dist=0.35)
    assert np.allclose(field.distance, brute_distance(grid, values, 0.35))
    assert field.distance.max() == pytest.approx(0.35)  # the cap is reached: the test covers it


def test_distance_at_points_reads_their_cell_and_max_dist_off_the_map():
    grid = Grid(0.1, 20, 10, (-1.0, -0.5, 0.3))
    values = random_map(2, grid)
    field = LikelihoodField(grid, values, max_dist=2.0)
    rng = np.random.default_rng(3)
    cells = np.column_stack((rng.integers(0, 20, 50), rng.integers(0, 10, 50)))
    inside = grid.centres(cells + rng.uniform(-0.45, 0.45, (50, 2)))
    assert np.allclose(field.distance_at(inside), field.distance[cells[:, 1], cells[:, 0]])
    outside = grid.centres(np.array([[-1, 3], [20, 3], [4, -1], [4, 10], [-30, 40]]))
    assert np.all(field.distance_at(outside) == 2.0)


def test_a_map_without_obstacles_is_max_dist_everywhere():
    grid = Grid(0.05, 8, 8)
    field = LikelihoodField(grid, np.zeros(grid.shape, dtype=np.int8), max_dist=2.0)
    assert np.all(field.distance == 2.0)


def test_flat_occupancy_grid_data_is_accepted_and_a_wrong_size_is_not():
    grid = Grid(0.1, 6, 4)
    values = random_map(4, grid)
    flat = LikelihoodField(grid, values.ravel().tolist())
    assert np.array_equal(flat.distance, LikelihoodField(grid, values).distance)
    with pytest.raises(ValueError, match='24 values'):
        LikelihoodField(grid, np.zeros(23))
    with pytest.raises(ValueError, match='laser_likelihood_max_dist'):
        LikelihoodField(grid, values, max_dist=0.0)


def amcl_weight(field, pose, points, z_hit, z_rand, sigma_hit, range_max):
    """AMCLLaser::LikelihoodFieldModel for one pose, beam by beam."""
    p = 1.0
    cos, sin = math.cos(pose[2]), math.sin(pose[2])
    for ex, ey in points:
        hit = (pose[0] + cos * ex - sin * ey, pose[1] + sin * ex + cos * ey)
        z = float(field.distance_at(np.array(hit)))
        pz = z_hit * math.exp(-z * z / (2 * sigma_hit * sigma_hit)) + z_rand / range_max
        p += pz ** 3
    return p


@pytest.mark.parametrize('origin', [(0.0, 0.0, 0.0), (-2.0, -1.0, -0.6)])
def test_vectorised_weights_equal_amcls_beam_by_beam_sum_of_cubes(origin):
    grid = Grid(0.05, 60, 50, origin)
    values = random_map(5, grid)
    field = LikelihoodField(grid, values, max_dist=2.0)
    model = LikelihoodFieldModel(field, z_hit=0.5, z_rand=0.5, sigma_hit=0.2)
    rng = np.random.default_rng(6)
    centre = grid.centres(np.array([30, 25]))
    poses = np.column_stack((centre + rng.normal(0, 1.0, (40, 2)), rng.uniform(-math.pi, math.pi, 40)))
    angles = rng.uniform(-math.pi, math.pi, 30)
    ranges = rng.uniform(0.2, 3.4, 30)  # some end off the map
    points = np.column_stack((ranges * np.cos(angles) - 0.032, ranges * np.sin(angles)))
    expected = [amcl_weight(field, pose, points, 0.5, 0.5, 0.2, 3.5) for pose in poses]
    assert np.allclose(model.weights(poses, points, 3.5, chunk=100), expected, rtol=1e-12)
    assert np.allclose(model.weights(poses, points, 3.5), expected, rtol=1e-12)


def test_the_pose_that_explains_a_scan_weighs_most_and_no_beam_weighs_one():
    # A square room 4 x 4 m of walls; a scan taken at (1.5, 2.0, 0.3) by ray casting against it.
    grid = Grid(0.05, 80, 80)
    values = np.zeros(grid.shape, dtype=np.int8)
    values[0, :] = values[-1, :] = values[:, 0] = values[:, -1] = 100
    field = LikelihoodField(grid, values)
    model = LikelihoodFieldModel(field)
    truth = (1.5, 2.0, 0.3)
    angles = np.linspace(-math.pi, math.pi, 90, endpoint=False)
    heading = truth[2] + angles
    # Distance to the walls' inner faces at 0.05 and 3.95 m along each heading.
    with np.errstate(divide='ignore'):
        tx = np.where(np.cos(heading) > 0, (3.95 - truth[0]) / np.cos(heading), (0.05 - truth[0]) / np.cos(heading))
        ty = np.where(np.sin(heading) > 0, (3.95 - truth[1]) / np.sin(heading), (0.05 - truth[1]) / np.sin(heading))
    ranges = np.minimum(np.abs(tx), np.abs(ty))
    points = np.column_stack((ranges * np.cos(angles), ranges * np.sin(angles)))
    offsets = [(0, 0, 0), (0.1, 0, 0), (0, -0.1, 0), (0, 0, 0.05), (0.3, 0.3, 0.2)]
    weights = model.weights(np.array(truth) + np.array(offsets), points, 3.5)
    assert np.argmax(weights) == 0
    assert np.all(np.diff(weights[[0, 1, 4]]) < 0)
    assert np.array_equal(model.weights(np.array([truth]), np.zeros((0, 2)), 3.5), [1.0])
