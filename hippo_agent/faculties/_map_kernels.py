"""Compiled loops (numba) of the map and its planner (:mod:`hippo_agent.faculties.map`): ray
marches and the searches (the fit of a scan to the map is in
:mod:`hippo_agent.faculties._fit_kernel`). Grid cells are addressed ``(i, j)`` with ``i`` along
x; ``n`` is the grid's side."""

import math

import numpy as np
from numba import njit

__all__ = [
    "distance",
    "enter_scan",
    "known_with_steps",
    "lines_clear",
    "mark_disk",
    "path_to",
    "search",
    "search_disk",
    "walkable_points",
    "waypoint",
]


@njit(cache=True, inline="always")
def _grid_index(v, cell, inv_cell):  # pragma: no cover - compiled
    """``floor(v / cell)``: by multiplying with ``inv_cell`` when that is exact (``inv_cell > 0``,
    a power-of-two cell): a division is the slowest step of the ray marches' inner loops."""
    return math.floor(v * inv_cell) if inv_cell > 0.0 else math.floor(v / cell)


@njit(cache=True, inline="always")
def _forget_walkable(walk_cache, i, j, n):  # pragma: no cover - compiled
    """Forget the walkability remembered of the cells in the 3 x 3 block round ``(i, j)``."""
    for a in range(max(i - 1, 0), min(i + 2, n)):
        for b in range(max(j - 1, 0), min(j + 2, n)):
            walk_cache[a * n + b] = 0


@njit(cache=True)
def enter_scan(
    free, hits, x, y, heading, ranges, stride, max_range, extent, cell, inv_cell, free_range, hit_range, unknown_only, walk_cache
):  # pragma: no cover - compiled
    """Ray march every ``stride``-th ray: cells it passes are counted free, the cell it ends in hit
    (with ``unknown_only``, only cells neither free nor hit so far). Returns how many cells changed
    what the map says of them (known free, a wall); a count that changes neither is not counted
    (the searches and the fits read only that). The walkability remembered of the cells round each
    cell that changed is forgotten (``walk_cache``, :func:`_walk_known`): only theirs depends on it."""
    n = free.shape[0]
    changed = 0
    n_rays = ranges.size
    step = cell * 0.5
    for r in range(0, n_rays, stride):
        angle = heading + 2.0 * math.pi * r / n_rays
        c, s = math.cos(angle), math.sin(angle)
        d = float(ranges[r])
        reach = min(d - step, free_range)
        t = 0.0
        last_i, last_j = -1, -1
        while t < reach:
            i = _grid_index(x + t * c + extent, cell, inv_cell)
            j = _grid_index(y + t * s + extent, cell, inv_cell)
            if i < 0 or j < 0 or i >= n or j >= n:
                break
            if i != last_i or j != last_j:
                if free[i, j] < 65535 and not (unknown_only and (free[i, j] > 0 or hits[i, j] > 0)):
                    # a cell known free stays so; it changes if it was unknown or stops being a wall
                    if free[i, j] == 0 or (hits[i, j] > 0 and hits[i, j] == free[i, j]):
                        changed += 1
                        _forget_walkable(walk_cache, i, j, n)
                    free[i, j] += 1
                last_i, last_j = i, j
            t += step
        if d < hit_range and d < max_range * 0.999:
            i = _grid_index(x + d * c + extent, cell, inv_cell)
            j = _grid_index(y + d * s + extent, cell, inv_cell)
            if 0 <= i < n and 0 <= j < n and hits[i, j] < 65535 and not (unknown_only and (free[i, j] > 0 or hits[i, j] > 0)):
                # a hit makes a wall of a cell that was not one (hits + 1 >= free, where hits < free)
                if hits[i, j] + 1 == free[i, j] or (hits[i, j] == 0 and free[i, j] == 0):
                    changed += 1
                    _forget_walkable(walk_cache, i, j, n)
                hits[i, j] += 1
    return changed


@njit(cache=True, inline="always")
def walls_beside(free, hits, new_walls, i, j):  # pragma: no cover - compiled
    """2 if the map holds a wall not written in a run in the 3 x 3 cells round ``(i, j)``, else 1
    if it holds one written in a run there, else 0."""
    found = 0
    for a in range(i - 1, i + 2):
        for b in range(j - 1, j + 2):
            if hits[a, b] > 0 and hits[a, b] >= free[a, b]:
                if not new_walls[a, b]:
                    return 2
                found = 1
    return found


@njit(cache=True)
def walkable_points(free, hits, stride, extent, cell, out):  # pragma: no cover - compiled
    n = free.shape[0]
    flat_free, flat_hits = free.reshape(n * n), hits.reshape(n * n)
    m = 0
    for i in range(1, n - 1, stride):
        for j in range(1, n - 1, stride):
            if free[i, j] > 0 and _walkable(flat_free, flat_hits, i * n + j, n):
                out[m, 0] = (i + 0.5) * cell - extent
                out[m, 1] = (j + 0.5) * cell - extent
                m += 1
    return m


@njit(cache=True)
def mark_disk(grid, x, y, radius, extent, cell):  # pragma: no cover - compiled
    """Set the cells whose centres lie within ``radius`` of ``(x, y)``; returns how many of them were
    not set before."""
    n = grid.shape[0]
    ci = (x + extent) / cell
    cj = (y + extent) / cell
    r = radius / cell
    newly = 0
    for i in range(max(0, int(ci - r) - 1), min(n, int(ci + r) + 2)):
        for j in range(max(0, int(cj - r) - 1), min(n, int(cj + r) + 2)):
            if (i + 0.5 - ci) ** 2 + (j + 0.5 - cj) ** 2 <= r * r and not grid[i, j]:
                grid[i, j] = True
                newly += 1
    return newly


@njit(cache=True)
def mark_disks(visited, searched, x, y, visit_radius, search_radius, extent, cell):  # pragma: no cover - compiled
    """:func:`mark_disk` into ``visited`` with ``visit_radius`` and into ``searched`` with
    ``search_radius``; returns how many cells of either were not set before."""
    return mark_disk(visited, x, y, visit_radius, extent, cell) + mark_disk(searched, x, y, search_radius, extent, cell)


# The searches address cells by flat index k = i n + j (one index, no division per cell step):
# the helpers below take the grids as flat views (``free.reshape(n * n)``) and a cell on the grid.
# (The forms of their expressions are the measured fast ones: numba compiles an ``or`` of calls
# into faster code than the same test written with early returns.)


@njit(cache=True, inline="always")  # (a call passing arrays costs reference counting)
def _is_wall(free, hits, k):  # pragma: no cover - compiled
    return hits[k] > 0 and hits[k] >= free[k]


@njit(cache=True, inline="always")
def _walkable(free, hits, k, n):  # pragma: no cover - compiled
    """Known free, and no wall in the 3 x 3 block around it (off the grid's border)."""
    i = k // n
    j = k - i * n
    if i < 1 or j < 1 or i >= n - 1 or j >= n - 1:
        return False
    if free[k] == 0 or _is_wall(free, hits, k):
        return False
    for d in (-n - 1, -n, -n + 1, -1, 1, n - 1, n, n + 1):
        if _is_wall(free, hits, k + d):
            return False
    return True


@njit(cache=True, inline="always")
def _free_not_wall(free, hits, k, n):  # pragma: no cover - compiled
    i = k // n
    j = k - i * n
    return 1 <= i < n - 1 and 1 <= j < n - 1 and free[k] > 0 and not _is_wall(free, hits, k)


# Whether a cell is walkable is remembered in ``walk_cache`` as ``2 walk_id + walkable``: one id per
# state of the grids, so that searches on unchanged grids reuse what earlier ones worked out (one
# array for the id and the answer: a search reads one entry per cell, not two). A search asks in two
# steps: what is remembered (:func:`_walk_known`, :func:`_move_known`, which read the cache only)
# and, where that does not decide, the answer worked out and remembered (:func:`_walk_learnt`,
# :func:`_move_learnt`). A compiled helper that writes into an array it is passed costs reference
# counting at every call, even where the write is skipped: the breadth-first search of the open
# arena's map took 112 us with the question in one such helper, 28 us so (14 us with the question
# written out in full at each use). A search may step onto a cell that is walkable or, near its
# start (``near``), at least free and not a wall (:func:`_free_not_wall`).


@njit(cache=True, inline="always")
def _walk_known(walk_cache, k, walk_id):  # pragma: no cover - compiled
    """1 if cell ``k`` is walkable, 0 if not, -1 if not yet worked out for these grids
    (:func:`_walk_learnt`)."""
    cached = walk_cache[k]
    return cached & 1 if (cached >> 1) == walk_id else -1


@njit(cache=True, inline="always")
def _walk_learnt(free, hits, k, n, walk_cache, walk_id):  # pragma: no cover - compiled
    """Whether cell ``k`` is walkable (:func:`_walkable`), remembered for these grids."""
    walkable = _walkable(free, hits, k, n)
    walk_cache[k] = 2 * walk_id + walkable
    return int(walkable)


# the 8 neighbours of a cell, in the order the searches try them: the row and column of each step
_ROW_STEP = (-1, -1, -1, 0, 0, 1, 1, 1)
_COLUMN_STEP = (-1, 0, 1, -1, 1, -1, 0, 1)


@njit(cache=True, inline="always")
def _step_to(cur, d, n):  # pragma: no cover - compiled
    """The flat index of neighbour ``d`` of the cell ``cur``."""
    return cur + _ROW_STEP[d] * n + _COLUMN_STEP[d]


@njit(cache=True, inline="always")
def _straight(d):  # pragma: no cover - compiled
    """Whether the step to neighbour ``d`` is along a row or column (else diagonal)."""
    return d == 1 or d == 3 or d == 4 or d == 6


@njit(cache=True, inline="always")
def _beside(cur, d, n):  # pragma: no cover - compiled
    """The two cells beside the diagonal step ``d`` from ``cur``, the row's and the column's: they
    must be passable too (no corner cutting)."""
    return cur - n if d < 3 else cur + n, cur - 1 if d == 0 or d == 5 else cur + 1


@njit(cache=True, inline="always")
def _move_known(cur, d, n, near, walk_cache, walk_id):  # pragma: no cover - compiled
    """Whether a search may step from ``cur`` to its neighbour ``d``, as far as the cells' remembered
    walkability decides it: 1 if the neighbour (and for a diagonal step both cells beside it) is
    walkable, 0 if one is not and the search is not ``near`` its start; -1 otherwise
    (:func:`_move_learnt` decides)."""
    a = _walk_known(walk_cache, _step_to(cur, d, n), walk_id)
    b, c = 1, 1
    if not _straight(d):
        row, column = _beside(cur, d, n)
        b = _walk_known(walk_cache, row, walk_id)
        c = _walk_known(walk_cache, column, walk_id)
    if a == 1 and b == 1 and c == 1:
        return 1
    if not near and (a == 0 or b == 0 or c == 0):
        return 0
    return -1


@njit(cache=True)
def _move_learnt(free, hits, cur, d, n, near, walk_cache, walk_id):  # pragma: no cover - compiled
    """Whether a search may step from ``cur`` to its neighbour ``d``: the neighbour, and for a diagonal
    step both cells beside it, are walkable or (``near``: within two steps of the search's start, or
    ``squeeze``) at least free and not walls. The walkability it works out is remembered."""
    row, column = _beside(cur, d, n)
    for q in range(1 if _straight(d) else 3):
        k = _step_to(cur, d, n) if q == 0 else (row if q == 1 else column)
        walkable = _walk_known(walk_cache, k, walk_id)
        if walkable < 0:
            walkable = _walk_learnt(free, hits, k, n, walk_cache, walk_id)
        if walkable == 0 and not (near and _free_not_wall(free, hits, k, n)):
            return False
    return True


@njit(cache=True)
def search(free, hits, known, i0, j0, target, stamp, parent, queue, search_id, squeeze, walk_cache, walk_id):  # pragma: no cover - compiled
    """Breadth-first search over walkable cells (8-connected, no corner cutting) from (i0, j0) to
    ``target`` (a flat index); if ``target == -1``, to the nearest walkable cell that ``known``
    does not hold; if ``target == -2``, everywhere reachable. ``squeeze``: over every free cell
    that is not a wall. Returns the flat index of the cell found (its path back to the start
    through ``parent``), or -1 if there is none (or the robot is there), and the number of cells
    reached (``queue[:reached]``, in the order reached). ``walk_cache`` and ``walk_id``:
    each cell's walkability, worked out once per state of the grids (:func:`_walk_known`)."""
    n = free.shape[0]
    if i0 < 1 or j0 < 1 or i0 >= n - 1 or j0 >= n - 1:
        return -1, 0
    free_, hits_, known_ = free.reshape(n * n), hits.reshape(n * n), known.reshape(n * n)  # (flat views)
    start = i0 * n + j0
    stamp[start] = search_id
    parent[start] = -1
    head, tail = 0, 1
    queue[0] = start
    found = -1
    while head < tail:
        cur = queue[head]
        head += 1
        # a robot beside a wall stands on cells that are not walkable: leave them by free ones
        near = squeeze or (target != -2 and (cur == start or parent[cur] == start))
        if cur != start:
            if target >= 0:
                if cur == target:
                    found = cur
                    break
            elif target == -1 and not known_[cur]:
                walkable = _walk_known(walk_cache, cur, walk_id)
                if walkable < 0:
                    walkable = _walk_learnt(free_, hits_, cur, n, walk_cache, walk_id)
                if walkable:
                    found = cur
                    break
        for d in range(8):
            nxt = _step_to(cur, d, n)
            if stamp[nxt] == search_id:
                continue
            allowed = _move_known(cur, d, n, near, walk_cache, walk_id)
            if allowed < 0:
                allowed = _move_learnt(free_, hits_, cur, d, n, near, walk_cache, walk_id)
            if not allowed:
                continue
            stamp[nxt] = search_id
            parent[nxt] = cur
            queue[tail] = nxt
            tail += 1
    return found, tail


@njit(cache=True)
def start_free_is_walkable(free, hits, i0, j0, walk_cache, walk_id):  # pragma: no cover - compiled
    """Whether every free cell that is not a wall within two steps of ``(i0, j0)`` is walkable: then
    letting a search leave its start over such cells (:func:`search`'s ``near``) changes nothing,
    and a search to any one cell finds the path that the search everywhere reachable found."""
    n = free.shape[0]
    free_, hits_ = free.reshape(n * n), hits.reshape(n * n)
    for i in range(max(i0 - 2, 0), min(i0 + 3, n)):
        for j in range(max(j0 - 2, 0), min(j0 + 3, n)):
            k = i * n + j
            if _free_not_wall(free_, hits_, k, n):
                walkable = _walk_known(walk_cache, k, walk_id)
                if walkable < 0:
                    walkable = _walk_learnt(free_, hits_, k, n, walk_cache, walk_id)
                if walkable == 0:
                    return False
    return True


@njit(cache=True)
def search_disk(
    free, hits, known, i0, j0, dx, dy, dr, squeeze, search_id, stamp, closed, parent, steps, heap, heap_cells, walk_cache, walk_id
):  # pragma: no cover - compiled
    """A shortest path (in steps, over the same cells and moves as :func:`search`) from (i0, j0)
    to the nearest walkable cell that ``known`` does not hold and whose centre lies within ``dr``
    of ``(dx, dy)`` (grid units): an A* search, which heads for the disk instead of spreading in
    every direction as the breadth-first search does. Its lower bound on the steps left from a
    cell is the Chebyshev distance of its centre to the disk's centre less ``dr``, rounded up (a
    step moves at most one cell along each axis). Of the open cells with the least bound, the one
    farthest along is taken first, then the one nearest the disk's centre in a straight line (of
    the many paths equally short in steps, one near the straight line). Returns the flat index of
    the cell found (its path back through ``parent``), or -1 if there is none (or the robot is
    there). ``stamp`` marks the cells reached, ``closed`` those done, ``steps`` their path lengths;
    ``heap`` holds the queue's priorities (:func:`_priority`) and ``heap_cells`` their cells;
    ``walk_cache`` / ``walk_id`` as in :func:`search`."""
    n = free.shape[0]
    if i0 < 1 or j0 < 1 or i0 >= n - 1 or j0 >= n - 1:
        return -1
    free_, hits_, known_ = free.reshape(n * n), hits.reshape(n * n), known.reshape(n * n)  # (flat views)
    start = i0 * n + j0
    stamp[start] = search_id
    parent[start] = -1
    steps[start] = 0
    size = _heap_push(heap, heap_cells, 0, _priority(i0, j0, 0, dx, dy, dr), start)
    while size > 0:
        cur = heap_cells[0]
        size = _heap_pop(heap, heap_cells, size)
        if closed[cur] == search_id:
            continue  # an older entry of a cell since reached by a shorter path
        closed[cur] = search_id
        ci, cj = cur // n, cur % n
        if cur != start and not known_[cur] and (ci + 0.5 - dx) ** 2 + (cj + 0.5 - dy) ** 2 <= dr * dr:
            walkable = _walk_known(walk_cache, cur, walk_id)
            if walkable < 0:
                walkable = _walk_learnt(free_, hits_, cur, n, walk_cache, walk_id)
            if walkable:
                return cur
        near = squeeze or cur == start or parent[cur] == start
        g = steps[cur] + 1
        for d in range(8):
            nxt = _step_to(cur, d, n)
            if closed[nxt] == search_id or (stamp[nxt] == search_id and steps[nxt] <= g):
                continue
            allowed = _move_known(cur, d, n, near, walk_cache, walk_id)
            if allowed < 0:
                allowed = _move_learnt(free_, hits_, cur, d, n, near, walk_cache, walk_id)
            if not allowed:
                continue
            stamp[nxt] = search_id
            parent[nxt] = cur
            steps[nxt] = g
            if size == heap.size:
                return -1  # (cannot happen: a cell enters the queue at most once from each neighbour)
            size = _heap_push(heap, heap_cells, size, _priority(ci + _ROW_STEP[d], cj + _COLUMN_STEP[d], g, dx, dy, dr), nxt)
    return -1


# the disk search's priority, an int64 packing 21 bits each of the bound on a path's steps, the
# steps so far (complemented: more steps, a smaller priority) and the straight distance to the
# disk's centre (in 1/256 cells), so that comparing priorities orders them in that order
_BITS = 21
_MASK = (1 << _BITS) - 1


@njit(cache=True, inline="always")
def _priority(i, j, g, dx, dy, dr):  # pragma: no cover - compiled
    ex, ey = i + 0.5 - dx, j + 0.5 - dy
    bound = g + max(0, math.ceil(max(abs(ex), abs(ey)) - dr - 1e-9))  # Chebyshev distance to the disk, at least
    straight = min(_MASK, int(256.0 * math.sqrt(ex * ex + ey * ey)))
    return (bound << (2 * _BITS)) | ((_MASK - g) << _BITS) | straight


@njit(cache=True, inline="always")
def _heap_push(heap, cells, size, priority, cell):  # pragma: no cover - compiled
    """Push ``cell`` with ``priority`` onto the binary min-heap ``heap[:size]`` (``cells`` beside
    it); the new size."""
    k = size
    while k > 0:
        up = (k - 1) >> 1
        if heap[up] <= priority:
            break
        heap[k] = heap[up]
        cells[k] = cells[up]
        k = up
    heap[k] = priority
    cells[k] = cell
    return size + 1


@njit(cache=True, inline="always")
def _heap_pop(heap, cells, size):  # pragma: no cover - compiled
    """Drop the least entry of the binary min-heap ``heap[:size]`` (``cells`` beside it); the new size."""
    size -= 1
    priority, cell = heap[size], cells[size]
    k = 0
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        if child + 1 < size and heap[child + 1] < heap[child]:
            child += 1
        if heap[child] >= priority:
            break
        heap[k] = heap[child]
        cells[k] = cells[child]
        k = child
    heap[k] = priority
    cells[k] = cell
    return size


@njit(cache=True)
def _farthest_in_sight(free, hits, path, gx, gy, most, squeeze, walk_cache, walk_id):  # pragma: no cover - compiled
    """The index of the farthest cell along ``path`` (at most ``most`` cells on, at least 1) that a
    straight line from ``(gx, gy)`` (grid units) reaches over passable cells only: the planner heads
    straight for it, not along the search's 8-connected zig-zags. ``walk_cache`` / ``walk_id`` as
    in :func:`search`."""
    n = free.shape[0]
    free_, hits_ = free.reshape(n * n), hits.reshape(n * n)  # (flat views)
    best = 1
    for k in range(2, min(most, path.size - 1) + 1):
        if not _line_clear(free_, hits_, n, gx, gy, path[k] // n + 0.5, path[k] % n + 0.5, squeeze, walk_cache, walk_id):
            break
        best = k
    return best


@njit(cache=True)
def distance(tx, ty, x, y):  # pragma: no cover - compiled
    """From ``(x, y)`` to ``(tx, ty)``: the C library's ``hypot``, which NumPy's ``np.hypot`` calls
    too (Python's ``math.hypot`` rounds differently), without NumPy's cost per scalar call."""
    return math.hypot(tx - x, ty - y)


@njit(cache=True)
def lines_clear(free, hits, gx, gy, tx, ty, nx, ny, margin, walk_cache, walk_id):  # pragma: no cover - compiled
    """:func:`_line_clear` for the line from ``(gx, gy)`` to ``(tx, ty)`` shifted by ``k`` times
    ``(nx, ny)``, for every ``k`` from ``-margin`` to ``margin``."""
    n = free.shape[0]
    free_, hits_ = free.reshape(n * n), hits.reshape(n * n)  # (flat views)
    for k in range(-margin, margin + 1):
        if not _line_clear(free_, hits_, n, gx + k * nx, gy + k * ny, tx + k * nx, ty + k * ny, False, walk_cache, walk_id):
            return False
    return True


@njit(cache=True)
def _line_clear(free, hits, n, gx, gy, tx, ty, squeeze, walk_cache, walk_id):  # pragma: no cover - compiled
    """Whether the straight line from ``(gx, gy)`` to ``(tx, ty)`` (grid units), sampled every third
    of a cell, passes over walkable cells only (near the start, or with ``squeeze``, free cells that
    are not walls will do). The grids as flat views, ``n`` their side."""
    samples = int(3.0 * math.hypot(tx - gx, ty - gy)) + 1
    last_i, last_j, last_near = -1, -1, False
    for s in range(1, samples + 1):
        x = gx + (tx - gx) * s / samples
        y = gy + (ty - gy) * s / samples
        near = squeeze or (x - gx) ** 2 + (y - gy) ** 2 <= 4.0  # a robot by a wall leaves it over free cells
        i, j = int(x), int(y)
        if i == last_i and j == last_j and near == last_near:
            continue  # (the sample before was in this cell: it passed)
        if not (0 <= i < n and 0 <= j < n):
            return False
        walkable = _walk_known(walk_cache, i * n + j, walk_id)
        if walkable < 0:
            walkable = _walk_learnt(free, hits, i * n + j, n, walk_cache, walk_id)
        if walkable == 0 and not (near and _free_not_wall(free, hits, i * n + j, n)):
            return False
        last_i, last_j, last_near = i, j, near
    return True


@njit(cache=True)
def waypoint(free, hits, parent, found, gx, gy, most, squeeze, scratch, walk_cache, walk_id):  # pragma: no cover - compiled
    """The cell the planner heads for (:func:`_farthest_in_sight`) along the path from the search's
    start to ``found`` (written into ``scratch``)."""
    length = 0
    cur = found
    while parent[cur] != -1:
        length += 1
        cur = parent[cur]
    cur = found
    for k in range(length, -1, -1):
        scratch[k] = cur
        cur = parent[cur]
    return scratch[_farthest_in_sight(free, hits, scratch[: length + 1], gx, gy, most, squeeze, walk_cache, walk_id)]


@njit(cache=True)
def path_to(parent, found):  # pragma: no cover - compiled
    """The flat indices from the search's start to ``found``, in order."""
    length = 0
    cur = found
    while parent[cur] != -1:
        length += 1
        cur = parent[cur]
    path = np.empty(length + 1, dtype=np.int64)
    cur = found
    for k in range(length, -1, -1):
        path[k] = cur
        cur = parent[cur]
    return path


@njit(cache=True)
def known_with_steps(known, parent, queue, reached, depth, n):  # pragma: no cover - compiled
    """Of the cells a search reached (``queue[:reached]``, in the order reached), those ``known``
    holds, with their path lengths in steps (``depth``: scratch, one entry per cell)."""
    count = 0
    for k in range(reached):
        c = queue[k]
        depth[c] = 0 if k == 0 else depth[parent[c]] + 1
        if known[c // n, c % n]:
            count += 1
    cells = np.empty(count, dtype=np.int64)
    steps = np.empty(count, dtype=np.int64)
    m = 0
    for k in range(reached):
        c = queue[k]
        if known[c // n, c % n]:
            cells[m] = c
            steps[m] = depth[c]
            m += 1
    return cells, steps
