"""The controller's step counts (a breadth-first search) against Dijkstra over the same grid."""
import numpy as np
import pytest

from tb3_navigation.grid_graph import build, reweigh, shortest_paths, step_counter, step_counts


@pytest.mark.parametrize('seed', range(4))
def test_step_counts_are_dijkstras_distances_over_unit_steps_that_never_enter_a_blocked_cell(seed):
    rng = np.random.default_rng(seed)
    for _ in range(50):
        shape = tuple(rng.integers(1, 40, 2))
        blocked = rng.random(shape) < rng.uniform(0.0, 0.5)
        # Sources anywhere, blocked ones and repeats included (a plan through an inflated cell).
        sources = rng.integers(0, blocked.size, rng.integers(1, 12))
        expected, _ = shortest_paths(build(np.where(blocked, np.inf, 1.0), 4), shape, sources)
        assert np.array_equal(step_counts(blocked, sources), expected)


def test_one_step_counter_counts_from_each_set_of_sources_as_a_new_one_would():
    """The controller counts from the plan, the local goal and the point ahead on one counter."""
    rng = np.random.default_rng(7)
    blocked = rng.random((30, 40)) < 0.25
    counter = step_counter(blocked)
    for count in (25, 1, 1, 3, 25):
        sources = rng.integers(0, blocked.size, count)
        expected, _ = shortest_paths(build(np.where(blocked, np.inf, 1.0), 4), blocked.shape, sources)
        assert np.array_equal(counter(sources), expected)


def test_a_wall_with_one_gap_is_walked_round_and_a_closed_room_is_unreached():
    blocked = np.zeros((5, 7), dtype=bool)
    blocked[:4, 3] = True                 # a wall down column 3, open in the bottom row
    blocked[0, 5] = blocked[1, 6] = True  # the corner cell (0, 6) shut in
    counts = step_counts(blocked, [0])
    assert counts[0, 2] == 2 and counts[0, 4] == 4 + 4 + 4   # down, across and up again
    assert counts[4, 6] == 4 + 6 and counts[0, 6] == np.inf and counts[0, 3] == np.inf


@pytest.mark.parametrize('connectivity', (4, 8))
def test_a_graph_mended_where_costs_changed_has_the_weights_of_one_built_anew(connectivity):
    rng = np.random.default_rng(connectivity)
    shape = (23, 31)
    steps = np.where(rng.random(shape) < 0.2, np.inf, rng.uniform(50, 250, shape))
    heuristic = 50 * rng.random(shape)  # any values: the weights' formula is what is compared
    for estimate in (None, heuristic):
        graph = build(steps, connectivity, estimate)
        mended = steps.copy()
        for _ in range(20):
            cells = rng.choice(steps.size, rng.integers(1, 40), replace=False)
            mended.ravel()[cells] = np.where(rng.random(len(cells)) < 0.3, np.inf,
                                             rng.uniform(50, 250, len(cells)))
            reweigh(graph, mended, cells, connectivity, estimate)
            fresh = build(mended, connectivity, estimate)
            assert np.array_equal(graph.data, fresh.data)
            assert np.array_equal(graph.indices, fresh.indices) and np.array_equal(graph.indptr, fresh.indptr)
