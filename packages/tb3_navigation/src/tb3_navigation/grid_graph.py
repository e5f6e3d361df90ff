"""Shortest paths over the cells of a grid, at C speed (scipy's Dijkstra). No ROS here.

A grid of H x W cells is a graph whose edges join each cell to its 4 or 8
neighbours; stepping into cell c costs `step_costs[c]` times the step's
length (1, or sqrt(2) for a diagonal), and a cell whose step cost is inf
cannot be entered. The global planner uses it with navfn's cell costs
(8 neighbours, from the robot's cell); the controller counts steps
(4 neighbours, cells away from the plan, as base_local_planner's MapGrid)
with step_counts, a breadth-first search.

The edges' layout depends on the grid's shape only, so it is built once per
shape and kept; a graph then costs one pass of numpy over the edges (11 ms
for 400 x 260 cells, 0.83 M edges), and `reweigh` mends one in place where
some cells' costs changed (a global costmap's update changes a few hundred
of them: the same walls seen again, a frontier's new floor). scipy's Dijkstra has no A*, but A* is
Dijkstra over edges reweighted by a consistent heuristic h (w + h(target) -
h(source) >= 0), which `build` makes given h; a search over it bounded by
`limit` visits only the cells whose cost so far plus h stays within it.
"""
import functools
import math

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, dijkstra

UNREACHED = -9999  # scipy's predecessor of a source or of a cell no path reaches


@functools.lru_cache(maxsize=8)
def _edges(shape, connectivity):
    """(indptr, targets, lengths, sides, sources) of every edge of a `shape` grid,
    sorted by source: sides (2, E) are, for a diagonal edge, the two cells it
    passes between (for a straight edge, its target twice)."""
    if connectivity not in (4, 8):
        raise ValueError('connectivity must be 4 or 8, not %r' % (connectivity,))
    height, width = shape
    index = np.arange(height * width).reshape(shape)
    sources, targets, lengths, sides = [], [], [], []
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if (dx, dy) == (0, 0) or (connectivity == 4 and dx and dy):
                continue
            rows = slice(max(0, -dy), height - max(0, dy))
            columns = slice(max(0, -dx), width - max(0, dx))
            source = index[rows, columns]
            target = index[rows.start + dy:rows.stop + dy, columns.start + dx:columns.stop + dx]
            sources.append(source.ravel())
            targets.append(target.ravel())
            lengths.append(np.full(source.size, math.hypot(dx, dy)))
            # A diagonal step passes between (y + dy, x) and (y, x + dx).
            sides.append(np.stack(((source + dy * width).ravel(), (source + dx).ravel())) if dx and dy
                         else np.stack((target.ravel(), target.ravel())))
    sources = np.concatenate(sources)
    order = np.argsort(sources, kind='stable')
    indptr = np.searchsorted(sources[order], np.arange(height * width + 1)).astype(np.int32)
    return (indptr, np.concatenate(targets)[order].astype(np.int32), np.concatenate(lengths)[order],
            np.concatenate(sides, axis=1)[:, order], sources[order])


@functools.lru_cache(maxsize=8)
def _dependents(shape, connectivity):
    """(indptr, edges): the edges whose weight depends on each cell's step cost, CSR-like by cell: those
    into it and the diagonal ones passing beside it."""
    _, targets, _, sides, _ = _edges(shape, connectivity)
    edges = np.arange(len(targets), dtype=np.int32)
    diagonal = sides[0] != targets
    cells = np.concatenate((targets, sides[0][diagonal], sides[1][diagonal]))
    owners = np.concatenate((edges, edges[diagonal], edges[diagonal]))
    order = np.argsort(cells, kind='stable')
    return np.searchsorted(cells[order], np.arange(shape[0] * shape[1] + 1)), owners[order]


def _weights(flat, edges, connectivity, shape, heuristic):
    """The weights of `edges` (indices, or a slice) of a graph over cells of step costs `flat`."""
    _, targets, lengths, sides, sources = _edges(shape, connectivity)
    targets, lengths, sides = targets[edges], lengths[edges], sides[:, edges]
    weights = flat[targets] * lengths
    if heuristic is not None:
        estimate = np.asarray(heuristic, dtype=float).ravel()
        weights = np.maximum(weights + estimate[targets] - estimate[sources[edges]], 0.0)
    enterable = np.isfinite(flat)
    weights[~(enterable[sides[0]] & enterable[sides[1]])] = np.inf
    return weights


def build(step_costs, connectivity=8, heuristic=None):
    """The graph (scipy CSR, cells as nodes) of a grid whose cells cost `step_costs`
    (H, W) to step into. A diagonal step needs both cells it passes between to be
    enterable, so that no path slips through a wall drawn as a diagonal line of
    cells. With a `heuristic` (H, W), a consistent estimate of the cost left from
    each cell, the weights are A*'s: w + h(target) - h(source), rounding errors
    clipped at 0."""
    step_costs = np.asarray(step_costs, dtype=float)
    indptr, targets = _edges(step_costs.shape, connectivity)[:2]
    flat = step_costs.ravel()
    weights = _weights(flat, slice(None), connectivity, step_costs.shape, heuristic)
    graph = csr_matrix((weights, targets, indptr), shape=(flat.size, flat.size))
    graph.has_sorted_indices = True
    return graph


def reweigh(graph, step_costs, cells, connectivity=8, heuristic=None):
    """Mends in place a graph `build` made, for the step costs (H, W) it holds now, of which only
    the `cells` (flat indices) changed: the same weights as build(step_costs, connectivity, heuristic)."""
    step_costs = np.asarray(step_costs, dtype=float)
    indptr, owners = _dependents(step_costs.shape, connectivity)
    cells = np.asarray(cells, dtype=np.intp).ravel()
    starts, ends = indptr[cells], indptr[cells + 1]
    counts = ends - starts
    # Every owner between each cell's start and end, in one gather.
    positions = np.repeat(starts - np.concatenate(([0], np.cumsum(counts)[:-1])), counts) + np.arange(counts.sum())
    edges = np.unique(owners[positions])
    graph.data[edges] = _weights(step_costs.ravel(), edges, connectivity, step_costs.shape, heuristic)


def shortest_paths(graph, shape, sources, limit=np.inf):
    """(distances, predecessors), each of `shape` (H, W), of the cheapest paths over
    `graph` from the nearest of `sources` (flat indices) to every cell whose
    distance is within `limit`: inf and UNREACHED elsewhere. A source's own
    step cost never counts."""
    sources = np.atleast_1d(np.asarray(sources, dtype=np.intp))
    distances, predecessors, _ = dijkstra(graph, indices=sources, min_only=True, return_predecessors=True,
                                          limit=limit)
    return distances.reshape(shape), predecessors.reshape(shape)


def step_counts(blocked, sources):
    """The fewest 4-neighbour steps (H, W) from the nearest of `sources` (flat indices) to each
    cell, never into a `blocked` one (a blocked source is left all the same); inf where none
    reaches: shortest_paths' distances over build(where(blocked, inf, 1), 4), by a breadth-first search
    from one node more, joined to every source (60 x 60 cells: 0.55 ms, Dijkstra 1.55 ms)."""
    return step_counter(blocked)(sources)


def step_counter(blocked):
    """step_counts(blocked, sources) as a function of `sources`: the edges between open cells, half
    the work of a count on a local costmap, are found once for the counts from several sources."""
    height, width = shape = np.shape(blocked)
    cells = height * width
    indptr, targets = _edges(shape, 4)[:2]
    kept = ~np.asarray(blocked, dtype=bool).ravel()[targets]
    open_rows = np.empty(cells + 1, dtype=np.int32)
    open_rows[0] = 0
    np.cumsum(np.add.reduceat(kept, indptr[:-1], dtype=np.int32), out=open_rows[1:])
    open_targets = targets[kept]

    def counts(sources):
        sources = np.asarray(sources, dtype=np.int32).ravel()
        rows = np.append(open_rows, open_rows[-1] + len(sources)).astype(np.int32)
        columns = np.concatenate((open_targets, sources))
        graph = csr_matrix((np.ones(len(columns)), columns, rows), shape=(cells + 1, cells + 1))
        _, parents = breadth_first_order(graph, cells, directed=True, return_predecessors=True)
        # Each cell's depth in the search's tree, by pointer jumping: every round adds the depth of
        # the ancestor it points at and points twice as far up (7 rounds for 60 x 60 cells).
        reached = parents >= 0
        up = np.where(reached, parents, cells).astype(np.int32)
        up[cells] = cells
        depth = reached.astype(np.int32)
        while (up != cells).any():
            depth += depth[up]
            up = up[up]
        return np.where(reached[:cells], depth[:cells] - 1.0, np.inf).reshape(shape)
    return counts


def neighbours(graph, cell):
    """The flat indices of the cells `graph` has an edge to from `cell` (a flat index)."""
    return graph.indices[graph.indptr[cell]:graph.indptr[cell + 1]]


def path_cost(graph, cells):
    """The sum of `graph`'s weights along the path `cells` (flat indices, each a neighbour of the
    one before): inf if a step is no edge of it or is blocked."""
    cells = np.asarray(cells, dtype=np.intp)
    if len(cells) < 2:
        return 0.0
    sources, targets = cells[:-1], cells[1:]
    # A cell's edges lie side by side in the CSR arrays, at most 8 of them: look at each.
    positions = graph.indptr[sources][:, None] + np.arange(8)
    inside = positions < graph.indptr[sources + 1][:, None]
    positions = np.minimum(positions, len(graph.indices) - 1)
    match = inside & (graph.indices[positions] == targets[:, None])
    if not match.any(axis=1).all():
        return np.inf
    return float(np.sum(graph.data[positions[match]]))


def path_to(predecessors, target):
    """The flat indices of the cells from a source to `target` (both included),
    following `predecessors`; [target] alone if target is a source."""
    flat = predecessors.ravel()
    cells = [int(target)]
    while flat[cells[-1]] != UNREACHED:
        cells.append(int(flat[cells[-1]]))
        if len(cells) > flat.size:
            raise RuntimeError('the predecessors loop: no path to cell %d' % target)
    return cells[::-1]
