"""The compiled ray march (numba) that revises the map from a run's scan
(:meth:`hippo_agent.faculties.map.ExplorationMap.revise`): a world that changes. Grid cells are
addressed ``(i, j)`` with ``i`` along x, as in :mod:`hippo_agent.faculties._map_kernels`."""

import math

import numpy as np
from numba import njit

from hippo_agent.faculties._map_kernels import _grid_index, walls_beside

__all__ = ["revise_scan"]


@njit(cache=True)
def revise_scan(
    free,
    hits,
    new_walls,
    change,
    vantage,
    stamp,
    hit_stamp,
    scan_id,
    x,
    y,
    heading,
    ranges,
    stride,
    max_range,
    extent,
    cell,
    inv_cell,
    free_range,
    gone_range,
    hit_range,
    new_evidence,
    gone_evidence,
    write_new,
    paired,
    enter_unknown,
):  # pragma: no cover - compiled
    """Ray march every ``stride``-th ray against what the map holds (:meth:`ExplorationMap.revise`):
    cells unknown so far are entered as :func:`enter_scan` enters them; a wall the ray crosses
    through its middle (two samples in the cell, the ray ending at least a cell beyond, and no ray
    of the scan ending within a cell of it: a thin wall's cell is partly free, and rays graze it)
    and a boundary where the map knows free ground with no wall beside it each add one to the
    cell's ``change`` count, at most once per scan (``stamp``) and once per cell the robot stands
    in (``vantage``, the flat index of the robot's cell at the last count: a robot standing still
    sees the same crossing again, which is no new evidence); at ``gone_evidence`` the wall is
    cleared (at ``new_evidence`` a wall written in a run, ``new_walls``), at ``new_evidence`` the
    boundary is made a wall, marked in ``new_walls`` (0 or not ``write_new``: never). A reading that agrees with
    a cell resets its count. Rays enter cells up to ``free_range`` and cross walls up to
    ``gone_range``. With ``paired``, a crossing counts only if a ray beside it crossed a wall
    near it too (:func:`_seen_through`). Without ``enter_unknown``, cells unknown so far stay so.
    Returns how many cells changed."""
    n = free.shape[0]
    changed = 0
    here = _grid_index(x + extent, cell, inv_cell) * n + _grid_index(y + extent, cell, inv_cell)
    n_rays = ranges.size
    step = cell * 0.5
    m = (n_rays + stride - 1) // stride
    cos_, sin_ = np.empty(m), np.empty(m)  # each ray's direction, worked out once for both passes
    for q in range(m):
        angle = heading + 2.0 * math.pi * (q * stride) / n_rays
        cos_[q], sin_[q] = math.cos(angle), math.sin(angle)
    for r in range(0, n_rays, stride):  # where this scan's rays end
        d = float(ranges[r])
        if d < hit_range and d < max_range * 0.999:
            q = r // stride
            i = _grid_index(x + d * cos_[q] + extent, cell, inv_cell)
            j = _grid_index(y + d * sin_[q] + extent, cell, inv_cell)
            if 0 <= i < n and 0 <= j < n:
                hit_stamp[i, j] = scan_id
    crossed = np.full(m if paired else 0, -2, dtype=np.int64)  # each ray's first crossing, worked out when asked (-2)
    for r in range(0, n_rays, stride):
        q = r // stride
        c, s = cos_[q], sin_[q]
        d = float(ranges[r])
        reach = min(d - step, max(free_range, gone_range))
        t = 0.0
        i, j, inside = -1, -1, 0
        while t < reach:
            i, j, inside = _sample(x, y, t, c, s, extent, cell, inv_cell, n, i, j, inside)
            if inside == 0:
                break
            if inside == 1:  # a cell entered
                if t >= free_range:
                    pass  # beyond the range that enters cells: only a wall crossed counts
                elif free[i, j] == 0 and hits[i, j] == 0:
                    if enter_unknown:
                        free[i, j] = 1
                        changed += 1
                elif not (hits[i, j] > 0 and hits[i, j] >= free[i, j]) and stamp[i, j] != scan_id:
                    change[i, j] = 0  # free, as the map holds
            # a wall crossed through its middle (the cheap tests first: most samples are not a cell's second)
            if inside == 2 and t + cell < d and t < gone_range and stamp[i, j] != scan_id and hits[i, j] > 0 and hits[i, j] >= free[i, j]:
                gone = new_evidence if new_walls[i, j] else gone_evidence
                if gone > 0 and (
                    not paired
                    or _seen_through(crossed, q, i, j, free, hits, x, y, heading, ranges, stride, extent, cell, inv_cell, gone_range)
                ):
                    stamp[i, j] = scan_id
                    if _hit_near(hit_stamp, i, j, scan_id):
                        change[i, j] = 0  # a ray ended by it: the wall is there
                    elif vantage[i, j] != here:  # (crossed from this cell before: no new evidence)
                        vantage[i, j] = here
                        change[i, j] += 1
                        if change[i, j] >= gone:  # the wall is gone
                            hits[i, j] = 0
                            new_walls[i, j] = False
                            free[i, j] = max(free[i, j], 1)
                            change[i, j] = 0
                            changed += 1
            t += step
        if not (d < hit_range and d < max_range * 0.999):
            continue
        i = _grid_index(x + d * c + extent, cell, inv_cell)
        j = _grid_index(y + d * s + extent, cell, inv_cell)
        if i < 1 or j < 1 or i >= n - 1 or j >= n - 1:
            continue
        if free[i, j] == 0 and hits[i, j] == 0:
            if enter_unknown:
                hits[i, j] = 1
                changed += 1
            continue
        if walls_beside(free, hits, new_walls, i, j):
            if stamp[i, j] != scan_id:
                change[i, j] = 0  # a boundary where the map holds one
        elif new_evidence > 0 and write_new and stamp[i, j] != scan_id:
            stamp[i, j] = scan_id
            change[i, j] += 1
            if change[i, j] >= new_evidence:  # a new wall
                hits[i, j] = min(int(free[i, j]) + 1, 65535)
                new_walls[i, j] = True
                change[i, j] = 0
                changed += 1
    return changed


@njit(cache=True, inline="always")
def _hit_near(hit_stamp, i, j, scan_id):  # pragma: no cover - compiled
    """Whether a ray of scan ``scan_id`` ended within one cell of ``(i, j)``."""
    n = hit_stamp.shape[0]
    for a in range(max(i - 1, 0), min(i + 2, n)):
        for b in range(max(j - 1, 0), min(j + 2, n)):
            if hit_stamp[a, b] == scan_id:
                return True
    return False


@njit(cache=True)
def _first_crossing(free, hits, x, y, heading, ranges, stride, q, extent, cell, inv_cell, gone_range):  # pragma: no cover - compiled
    """The flat index of the first wall cell ray ``q`` (every ``stride``-th ray) crosses through its
    middle (two samples in the cell, ending at least a cell beyond), up to ``gone_range``; -1 if none."""
    n = free.shape[0]
    step = cell * 0.5
    angle = heading + 2.0 * math.pi * (q * stride) / ranges.size
    c, s = math.cos(angle), math.sin(angle)
    d = float(ranges[q * stride])
    t = 0.0
    i, j, inside = -1, -1, 0
    while t < gone_range and t + cell < d:
        i, j, inside = _sample(x, y, t, c, s, extent, cell, inv_cell, n, i, j, inside)
        if inside == 0:
            break
        if inside == 2 and hits[i, j] > 0 and hits[i, j] >= free[i, j]:
            return i * n + j
        t += step
    return -1


@njit(cache=True)
def _seen_through(
    crossed, q, i, j, free, hits, x, y, heading, ranges, stride, extent, cell, inv_cell, gone_range
):  # pragma: no cover - compiled
    """Whether ray ``q``'s neighbour on either side first crossed a wall within two cells of ``(i, j)``
    (``crossed``: each ray's :func:`_first_crossing`, -2 until worked out: only for the rays beside a
    crossing, which are few): the scan sees through the wall there over more than one ray, as
    through an opening, not one ray grazing it at a small error in the estimate."""
    n = free.shape[0]
    m = crossed.size
    for r in ((q + m - 1) % m, (q + 1) % m):
        if crossed[r] == -2:
            crossed[r] = _first_crossing(free, hits, x, y, heading, ranges, stride, r, extent, cell, inv_cell, gone_range)
        k = crossed[r]
        if k >= 0 and abs(k // n - i) <= 2 and abs(k % n - j) <= 2:
            return True
    return False


@njit(cache=True, inline="always")
def _sample(x, y, t, c, s, extent, cell, inv_cell, n, last_i, last_j, inside):  # pragma: no cover - compiled
    """A ray's sample at distance ``t`` along ``(c, s)`` from ``(x, y)``: its cell, and how many
    samples in a row (this one included) fell in that cell, given the last sample's cell and count;
    0 off the grid."""
    i = _grid_index(x + t * c + extent, cell, inv_cell)
    j = _grid_index(y + t * s + extent, cell, inv_cell)
    if i < 0 or j < 0 or i >= n or j >= n:
        return i, j, 0
    return i, j, inside + 1 if i == last_i and j == last_j else 1
