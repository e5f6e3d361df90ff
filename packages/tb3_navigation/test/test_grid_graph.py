"""The compiled grid search against scipy's Dijkstra over the same graph built edge by edge here."""
import math

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from tb3_navigation import grid_graph
from tb3_navigation.grid_graph import GridGraph, path_cost, path_to, shortest_paths, step_counter, step_counts

UNREACHED = grid_graph.UNREACHED


def reference_weights(steps, connectivity, heuristic):
    """{(source, target): weight} of every edge, written out one at a time from the module's rule."""
    height, width = steps.shape
    h = np.zeros(steps.shape) if heuristic is None else heuristic
    weights = {}
    for y in range(height):
        for x in range(width):
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    ty, tx = y + dy, x + dx
                    if (dx, dy) == (0, 0) or (connectivity == 4 and dx and dy):
                        continue
                    if not (0 <= ty < height and 0 <= tx < width):
                        continue
                    if not np.isfinite(steps[ty, tx]) or (dx and dy and not (np.isfinite(steps[ty, x])
                                                                             and np.isfinite(steps[y, tx]))):
                        continue
                    weight = steps[ty, tx] * math.hypot(dx, dy) + h[ty, tx] - h[y, x]
                    weights[(y * width + x, ty * width + tx)] = max(weight, 0.0)
    return weights


def reference(steps, connectivity, heuristic, sources, limit):
    """scipy's distances, and the edge weights, of the same search."""
    weights = reference_weights(steps, connectivity, heuristic)
    rows, columns = zip(*weights) if weights else ((), ())
    # scipy drops explicit zeros from a sparse matrix: a zero weight is kept as a tiny one.
    data = np.maximum(np.array(list(weights.values())), 1e-300)
    graph = csr_matrix((data, (rows, columns)), shape=(steps.size, steps.size))
    distances = dijkstra(graph, indices=sources, min_only=True, limit=limit)
    return distances.reshape(steps.shape), weights


def random_case(rng):
    shape = tuple(rng.integers(1, 25, 2))
    steps = np.where(rng.random(shape) < rng.uniform(0.0, 0.4), np.inf, rng.uniform(50, 250, shape))
    return shape, steps, rng.integers(0, steps.size, rng.integers(1, 4))


@pytest.mark.parametrize('connectivity', (4, 8))
@pytest.mark.parametrize('seed', range(3))
def test_distances_are_scipys_and_each_predecessor_is_the_step_the_cheapest_path_took(connectivity, seed):
    rng = np.random.default_rng(seed)
    for _ in range(15):
        shape, steps, sources = random_case(rng)
        # A consistent heuristic: the cheapest step times the steps left to a goal cell, as the planner's.
        goal_y, goal_x = rng.integers(0, shape[0]), rng.integers(0, shape[1])
        iy, ix = np.mgrid[0:shape[0], 0:shape[1]]
        dx, dy = np.abs(ix - goal_x), np.abs(iy - goal_y)
        octile = np.maximum(dx, dy) + (math.sqrt(2) - 1) * np.minimum(dx, dy)
        for heuristic in (None, 50.0 * (octile if connectivity == 8 else dx + dy)):
            for limit in (np.inf, float(rng.uniform(0, 2000))):
                graph = GridGraph(steps, connectivity, heuristic)
                distances, predecessors = shortest_paths(graph, sources, limit)
                expected, weights = reference(steps, connectivity, heuristic, sources, limit)
                assert np.array_equal(np.isfinite(distances), np.isfinite(expected))
                reached = np.isfinite(expected)
                assert distances[reached] == pytest.approx(expected[reached], rel=1e-12, abs=1e-9)
                flat_distances, flat_predecessors = distances.ravel(), predecessors.ravel()
                for cell in np.flatnonzero(reached):
                    before = flat_predecessors[cell]
                    if cell in sources:
                        assert before == UNREACHED and flat_distances[cell] == 0.0
                        continue
                    assert flat_distances[before] + weights[(before, cell)] == flat_distances[cell]
                    path = path_to(predecessors, cell)
                    assert path[0] in sources
                    assert flat_distances[path[0]] + path_cost(graph, path) == pytest.approx(flat_distances[cell])
                assert np.all(flat_predecessors[~reached.ravel()] == UNREACHED)


def test_a_graph_reads_its_step_costs_where_they_lie():
    """The planner mends its step costs in place: the graphs made over them see the change."""
    steps = np.full((3, 5), 50.0)
    graph = GridGraph(steps)
    assert shortest_paths(graph, [0])[0][0, 4] == 200.0
    steps[:, 2] = np.inf
    assert np.isinf(shortest_paths(graph, [0])[0][0, 4])


def test_no_diagonal_step_passes_between_two_blocked_cells():
    steps = np.array([[50.0, np.inf], [np.inf, 50.0]])
    distances, _ = shortest_paths(GridGraph(steps), [0])
    assert np.isinf(distances[1, 1])
    assert path_cost(GridGraph(steps), [0, 3]) == np.inf
    steps[0, 1] = 50.0  # one side open: round it
    assert shortest_paths(GridGraph(steps), [0])[0][1, 1] == 100.0
    steps[1, 0] = 50.0  # both: across
    assert shortest_paths(GridGraph(steps), [0])[0][1, 1] == pytest.approx(50.0 * math.sqrt(2))


def test_path_costs_are_inf_for_steps_that_are_no_edges():
    graph = GridGraph(np.full((4, 4), 50.0))
    assert path_cost(graph, [0]) == 0.0
    assert path_cost(graph, [0, 1, 6]) == pytest.approx(50.0 + 50.0 * math.sqrt(2))
    assert path_cost(graph, [3, 4]) == np.inf       # the end of one row to the start of the next
    assert path_cost(graph, [0, 2]) == np.inf       # two cells away
    assert path_cost(graph, [0, 0]) == np.inf       # no step
    assert path_cost(GridGraph(np.full((4, 4), 50.0), 4), [0, 5]) == np.inf   # a diagonal, 4 neighbours
    assert sorted(grid_graph.neighbours(graph, 0)) == [1, 4, 5]
    assert sorted(grid_graph.neighbours(graph, 5)) == [0, 1, 2, 4, 6, 8, 9, 10]
    assert sorted(grid_graph.neighbours(GridGraph(np.ones((4, 4)), 4), 5)) == [1, 4, 6, 9]


@pytest.mark.parametrize('seed', range(4))
def test_step_counts_are_breadth_first_depths_that_never_enter_a_blocked_cell(seed):
    rng = np.random.default_rng(seed)
    for _ in range(50):
        shape = tuple(rng.integers(1, 40, 2))
        blocked = rng.random(shape) < rng.uniform(0.0, 0.5)
        # Sources anywhere, blocked ones and repeats included (a plan through an inflated cell).
        sources = rng.integers(0, blocked.size, rng.integers(1, 12))
        expected, _ = reference(np.where(blocked, np.inf, 1.0), 4, None, sources, np.inf)
        assert np.array_equal(step_counts(blocked, sources), expected)


def test_one_step_counter_counts_from_each_set_of_sources_as_a_new_one_would():
    """The controller counts from the plan, the local goal and the point ahead on one counter."""
    rng = np.random.default_rng(7)
    blocked = rng.random((30, 40)) < 0.25
    counter = step_counter(blocked)
    for count in (25, 1, 1, 3, 25):
        sources = rng.integers(0, blocked.size, count)
        assert np.array_equal(counter(sources), step_counts(blocked, sources))


def test_a_wall_with_one_gap_is_walked_round_and_a_closed_room_is_unreached():
    blocked = np.zeros((5, 7), dtype=bool)
    blocked[:4, 3] = True                 # a wall down column 3, open in the bottom row
    blocked[0, 5] = blocked[1, 6] = True  # the corner cell (0, 6) shut in
    counts = step_counts(blocked, [0])
    assert counts[0, 2] == 2 and counts[0, 4] == 4 + 4 + 4   # down, across and up again
    assert counts[4, 6] == 4 + 6 and counts[0, 6] == np.inf and counts[0, 3] == np.inf
