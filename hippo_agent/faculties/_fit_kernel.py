"""The compiled fit of a scan to the map (numba): the beam model's ray marches of
:meth:`hippo_agent.faculties.map.ExplorationMap.scan_agreement`, on one grid of each cell's kind of
wall (:func:`wall_kinds`). Grid cells are addressed ``(i, j)`` with ``i`` along x, as in
:mod:`hippo_agent.faculties._map_kernels`."""

import math

import numpy as np
from numba import njit

from hippo_agent.faculties._map_kernels import _grid_index

__all__ = ["scan_agreement", "wall_kinds"]


@njit(cache=True)
def scan_agreement(
    free,
    hits,
    walls,
    ox,
    oy,
    with_origin,
    points,
    heading,
    ranges,
    stride,
    max_range,
    extent,
    cell,
    inv_cell,
    hit_range,
    short_weight,
    judged_only,
    out,
    judged,
    new_wall_weight,
):  # pragma: no cover - compiled
    """:meth:`ExplorationMap.scan_agreement` from ``(ox, oy)`` plus each of ``points``, after
    ``(ox, oy)`` itself ``with_origin``; ``walls`` is :func:`wall_kinds` of the grids; a short
    reading weighs ``short_weight``; a ray may cross a wall written in a run, and one ending by
    such a wall only weighs ``new_wall_weight``. ``judged_only``: a ray ending where the map knows
    nothing is left out, and a place where no ray is judged fits 1. If ``judged`` has room, the
    first place's fit with short readings and unknown ends left out (``short_weight`` 0,
    ``judged_only``) goes there too, from the same ray march; if it has room for three, the share of
    the first place's rays that were short readings, and how many of its rays crossed a wall
    through its middle (:func:`_through_the_middle`), go after it."""
    also = judged.size > 0
    shorts = 0  # the first place's short readings
    middles = 0  # the first place's rays through a wall's middle
    n = free.shape[0]
    n_rays = ranges.size
    m = (n_rays + stride - 1) // stride
    cos_, sin_, dist = np.empty(m), np.empty(m), np.empty(m)
    for q in range(m):
        angle = heading + 2.0 * math.pi * (q * stride) / n_rays
        cos_[q], sin_[q], dist[q] = math.cos(angle), math.sin(angle), ranges[q * stride]
    for p in range(out.size):
        k = p - 1 if with_origin else p
        x = (ox if k < 0 else ox + points[k, 0]) + extent
        y = (oy if k < 0 else oy + points[k, 1]) + extent
        total = 0.0
        counted = 0.0
        counted_judged = 0.0  # the fit for judged (short readings and unknown ends left out)
        total_judged = 0.0
        for q in range(m):
            d = dist[q]
            far = not (d < hit_range and d < max_range * 0.999)
            c, s = cos_[q], sin_[q]
            through = False  # the ray passed through a wall the map holds
            t = 0.5
            while t < d - 0.5:
                a = _grid_index(x + t * c, cell, inv_cell)
                b = _grid_index(y + t * s, cell, inv_cell)
                if 0 <= a < n and 0 <= b < n and walls[a, b] == OLD_WALL:
                    through = True
                    break
                t += 0.5
            if through:
                if p == 0 and judged.size > 2 and _through_the_middle(free, hits, a, b, x, y, c, s, cell):
                    middles += 1
                counted += 1.0
                total -= 1.0
                counted_judged += 1.0
                total_judged -= 1.0
                continue
            if far:  # a long ray's end is too far to place on the map; only its free stretch counts
                continue
            i = _grid_index(x + d * c, cell, inv_cell)
            j = _grid_index(y + d * s, cell, inv_cell)
            if i < 1 or j < 1 or i >= n - 1 or j >= n - 1:
                counted += 1.0
                counted_judged += 1.0
                continue
            beside = _wall_kind_beside(walls, i, j)
            if beside == OLD_WALL:
                counted += 1.0
                total += 1.0
                counted_judged += 1.0
                total_judged += 1.0
            elif beside == 1:  # a wall written in a run only
                counted += new_wall_weight
                total += new_wall_weight
                counted_judged += new_wall_weight
                total_judged += new_wall_weight
            elif free[i, j] > 0:  # a short reading: a boundary where the map knows free ground
                if p == 0:
                    shorts += 1
                counted += short_weight
                total -= short_weight
            elif not judged_only:
                counted += 1.0
        out[p] = total / counted if counted else (1.0 if judged_only else 0.0)
        if also and p == 0:
            judged[0] = total_judged / counted_judged if counted_judged else 1.0
            if judged.size > 2:
                judged[1] = shorts / m
                judged[2] = middles


@njit(cache=True)
def _through_the_middle(free, hits, a, b, x, y, c, s, cell):  # pragma: no cover - compiled
    """Whether a ray from ``(x, y)`` (grid-extent metres) along ``(c, s)`` that met the wall cell
    ``(a, b)`` passed through the wall's middle: the map holds wall cells on both sides of the
    ray's line within two cells of ``(a, b)``. A ray clipping a wall's end (a door's jamb, a thin
    wall's corner at a small error in the estimate) has wall on one side only."""
    n = free.shape[0]
    if a < 2 or b < 2 or a >= n - 2 or b >= n - 2:
        return False
    left = False
    right = False
    for i in range(a - 2, a + 3):
        for j in range(b - 2, b + 3):
            if hits[i, j] > 0 and hits[i, j] >= free[i, j]:
                side = ((i + 0.5) * cell - x) * s - ((j + 0.5) * cell - y) * c
                if side > 0.2:
                    left = True
                elif side < -0.2:
                    right = True
    return left and right


#: :func:`wall_kinds`' values: no wall, a wall written in a run, a wall from the dry run.
NO_WALL, NEW_WALL, OLD_WALL = 0, 1, 2


@njit(cache=True)
def wall_kinds(free, hits, new_walls, out):  # pragma: no cover - compiled
    """Each cell's kind of wall into ``out`` (uint8): ``OLD_WALL`` where the map holds a wall not
    written in a run, ``NEW_WALL`` where it holds one written in a run, else ``NO_WALL``. The fit
    of a scan reads one grid, not three, at every step of its ray marches."""
    n = free.shape[0]
    for i in range(n):
        for j in range(n):
            if hits[i, j] > 0 and hits[i, j] >= free[i, j]:
                out[i, j] = NEW_WALL if new_walls[i, j] else OLD_WALL
            else:
                out[i, j] = NO_WALL


@njit(cache=True, inline="always")
def _wall_kind_beside(walls, i, j):  # pragma: no cover - compiled
    """:func:`walls_beside` read from :func:`wall_kinds`' grid: the strongest kind in the 3 x 3 cells round ``(i, j)``."""
    found = NO_WALL
    for a in range(i - 1, i + 2):
        for b in range(j - 1, j + 2):
            kind = walls[a, b]
            if kind == OLD_WALL:
                return OLD_WALL
            if kind == NEW_WALL:
                found = NEW_WALL
    return found
