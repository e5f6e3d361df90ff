"""Shortest paths over the cells of a grid, compiled (numba). No ROS here.

A grid of H x W cells is a graph whose edges join each cell to its 4 or 8
neighbours; stepping into cell c costs `step_costs[c]` times the step's
length (1, or sqrt(2) for a diagonal), and a cell whose step cost is inf
cannot be entered. The global planner uses it with navfn's cell costs
(8 neighbours, from the robot's cell); the controller counts steps
(4 neighbours, cells away from the plan, as base_local_planner's MapGrid)
with step_counts.

A* is Dijkstra over edges reweighted by a consistent heuristic h (w + h(target) -
h(source) >= 0); a search bounded by `limit` visits only the cells whose cost
so far plus h stays within it.

Why compiled: scipy's Dijkstra, which this replaced, needs the grid as a
sparse matrix of its edges (0.83 M for 400 x 260 cells), to be built or
mended whenever costs change, and its heap is general; the search here reads
the step costs where they lie, and took a third to a half of its time
(doc/speed.md). The explorer spreads over its whole known window every
planner period, move_base plans five times a second.
"""
import math

import numba
import numpy as np

UNREACHED = -9999  # the predecessor of a source or of a cell no path reaches
SQRT2 = math.sqrt(2.0)
#: The neighbours' offsets (dx, dy): the 4 straight ones first.
OFFSETS = np.array([(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)], dtype=np.int64)


class GridGraph(object):
    """The graph of a grid whose cells cost `step_costs` (float (H, W), inf: blocked) to step into, over
    `connectivity` 4 or 8 neighbours. A diagonal step needs both cells it passes between to be
    enterable, so that no path slips through a wall drawn as a diagonal line of cells. With a
    `heuristic` (H, W), a consistent estimate of the cost left from each cell, the weights are A*'s:
    w + h(target) - h(source), rounding errors clipped at 0.

    The graph reads `step_costs` where it lies (a float64 array is not copied): change its cells and
    the graph has changed with them."""

    def __init__(self, step_costs, connectivity=8, heuristic=None):
        if connectivity not in (4, 8):
            raise ValueError('connectivity must be 4 or 8, not %r' % (connectivity,))
        self.steps = np.asarray(step_costs, dtype=float)
        self.shape = self.steps.shape
        self.connectivity = connectivity
        self.heuristic = (np.zeros(self.shape) if heuristic is None
                          else np.asarray(heuristic, dtype=float).reshape(self.shape))


def shortest_paths(graph, sources, limit=np.inf):
    """(distances, predecessors), each of the graph's shape (H, W), of the cheapest paths
    over `graph` from the nearest of `sources` (flat indices) to every cell whose distance
    is within `limit`: inf and UNREACHED elsewhere. A source's own step cost never counts."""
    cells = graph.steps.size
    distances = np.full(cells, np.inf)
    predecessors = np.full(cells, UNREACHED, dtype=np.int32)
    sources = np.atleast_1d(np.asarray(sources, dtype=np.int64)).ravel()
    _search(graph.steps.ravel(), graph.heuristic.ravel(), graph.shape[1], graph.connectivity, sources,
            float(limit), distances, predecessors)
    return distances.reshape(graph.shape), predecessors.reshape(graph.shape)


@numba.njit(cache=True, nogil=True)
def _weight(steps, heuristic, width, cell, dx, dy):  # pragma: no cover
    """The weight of the edge from `cell` to its neighbour (dx, dy) (GridGraph's rule): inf if that
    cell is blocked, or if the step is diagonal and a cell it passes between is."""
    target = cell + dy * width + dx
    if dx == 0 or dy == 0:
        weight = steps[target]
    elif math.isinf(steps[cell + dy * width]) or math.isinf(steps[cell + dx]):
        return math.inf
    else:
        weight = steps[target] * SQRT2
    return max(weight + heuristic[target] - heuristic[cell], 0.0)


@numba.njit(cache=True, nogil=True)
def _search(steps, heuristic, width, connectivity, sources, limit, distances, predecessors):  # pragma: no cover
    """Dijkstra over the grid's edges (GridGraph's weights), filling `distances` and `predecessors`,
    with a binary heap of (distance, cell) entries: one is pushed each time a cell's distance
    drops, and the outdated ones are skipped when they come up (at most one per edge and source)."""
    height = len(steps) // width
    capacity = len(steps) * connectivity + len(sources)
    keys = np.empty(capacity)
    cells = np.empty(capacity, dtype=np.int64)
    done = np.zeros(len(steps), dtype=np.bool_)
    size = 0
    for source in sources:
        distances[source] = 0.0
        keys[size], cells[size] = 0.0, source
        size += 1
    while size > 0:
        key, cell = keys[0], cells[0]
        size -= 1
        if size > 0:  # the last entry sifted down from the root
            last_key, last_cell, i = keys[size], cells[size], 0
            while True:
                child = 2 * i + 1
                if child >= size:
                    break
                if child + 1 < size and keys[child + 1] < keys[child]:
                    child += 1
                if keys[child] >= last_key:
                    break
                keys[i], cells[i] = keys[child], cells[child]
                i = child
            keys[i], cells[i] = last_key, last_cell
        if done[cell]:
            continue
        done[cell] = True
        y, x = cell // width, cell % width
        for k in range(connectivity):
            dx, dy = OFFSETS[k, 0], OFFSETS[k, 1]
            if x + dx < 0 or x + dx >= width or y + dy < 0 or y + dy >= height:
                continue
            target = cell + dy * width + dx
            if done[target]:
                continue
            reached = key + _weight(steps, heuristic, width, cell, dx, dy)
            if not reached <= limit or not reached < distances[target]:
                continue
            distances[target], predecessors[target] = reached, cell
            i = size  # the new entry sifted up
            size += 1
            while i > 0 and keys[(i - 1) // 2] > reached:
                keys[i], cells[i] = keys[(i - 1) // 2], cells[(i - 1) // 2]
                i = (i - 1) // 2
            keys[i], cells[i] = reached, target


def step_counts(blocked, sources):
    """The fewest 4-neighbour steps (H, W) from the nearest of `sources` (flat indices) to each
    cell, never into a `blocked` one (a blocked source is left all the same); inf where none
    reaches."""
    return step_counter(blocked)(sources)


def step_counter(blocked):
    """step_counts(blocked, sources) as a function of `sources`, for the counts from several sources
    on one grid (the controller counts from the plan, the local goal and the point ahead)."""
    graph = GridGraph(np.where(blocked, np.inf, 1.0), 4)

    def counts(sources):
        return shortest_paths(graph, sources)[0]
    return counts


def neighbours(graph, cell):
    """The flat indices of the cells `graph` has an edge to from `cell` (a flat index): those beside
    it on the grid, blocked or not."""
    height, width = graph.shape
    y, x = divmod(int(cell), width)
    offsets = OFFSETS[:graph.connectivity]
    xs, ys = x + offsets[:, 0], y + offsets[:, 1]
    inside = (xs >= 0) & (xs < width) & (ys >= 0) & (ys < height)
    return ys[inside] * width + xs[inside]


def path_cost(graph, cells):
    """The sum of `graph`'s weights along the path `cells` (flat indices, each a neighbour of the
    one before): inf if a step is no edge of it or is blocked."""
    return _path_cost(graph.steps.ravel(), graph.heuristic.ravel(), graph.shape[1], graph.connectivity,
                      np.asarray(cells, dtype=np.int64).ravel())


@numba.njit(cache=True, nogil=True)
def _path_cost(steps, heuristic, width, connectivity, cells):  # pragma: no cover
    total = 0.0
    for i in range(len(cells) - 1):
        dx = cells[i + 1] % width - cells[i] % width
        dy = cells[i + 1] // width - cells[i] // width
        if abs(dx) > 1 or abs(dy) > 1 or (dx == 0 and dy == 0) or (connectivity == 4 and dx != 0 and dy != 0):
            return math.inf
        total += _weight(steps, heuristic, width, cells[i], dx, dy)
    return total


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
