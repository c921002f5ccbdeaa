"""Compiled loops (numba) for the cells' per-step updates.

Each kernel does, element by element and in the same order, exactly the arithmetic of the NumPy
expression it replaces (the equations stay written out in the calling method's comments), so the
results are identical to the last bit: no reordered sums, no fused multiply-adds. Transcendentals
(``exp``, ``tanh``) and BLAS products stay in NumPy, whose vectorised versions round differently
from numba's. ``error_model="numpy"``: a division by 0 gives inf or nan, as in NumPy, not an exception.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def _maximum0(x):  # pragma: no cover - compiled
    """``np.maximum(x, 0.0)`` exactly: keeps -0.0 and NaN as NumPy does."""
    return x if x >= 0.0 or math.isnan(x) else 0.0


@njit(cache=True, error_model="numpy")
def oja_active_rows(W_pb, v, b, eta, alpha):  # pragma: no cover - compiled
    """Eq. 5 on the rows of the float32 ``W_pb`` whose cell is active (``v_i > 0``; for the others
    the update is exactly 0), in float64, flushing results below 1e-12 to 0."""
    for row in range(v.size):
        va = v[row]
        if not va > 0.0:
            continue
        eta_va = eta * va
        for c in range(b.size):
            w = np.float64(W_pb[row, c])
            x = w + eta_va * (b[c] - va * w / alpha)
            if x < 1e-12:
                x = 0.0
            W_pb[row, c] = np.float32(x)


@njit(cache=True, error_model="numpy")
def pp_cells(v, trace):  # pragma: no cover - compiled
    """The cells eq. 7 touches: active (``v > 0``), active or traced, and traced but silent."""
    n = v.size
    act, idx, rest = np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64)
    n_act = n_idx = n_rest = 0
    for i in range(n):
        on, traced = v[i] > 0.0, trace[i] > 0.0
        if on:
            act[n_act] = i
            n_act += 1
        if on or traced:
            idx[n_idx] = i
            n_idx += 1
        if traced and not on:
            rest[n_rest] = i
            n_rest += 1
    return act[:n_act], idx[:n_idx], rest[:n_rest]


@njit(cache=True, error_model="numpy")
def pp_update(W_slots, slot, v, trace, act, idx, rest, h):  # pragma: no cover - compiled
    """Eq. 7 on its two nonzero blocks, ``W[slot_j, k, slot_i] += float32(v_i Y_j - v_j Y_i) * h_k``:
    post ``i`` active and pre ``j`` active or traced; pre ``j`` active and post ``i`` silent but
    traced (there ``v_i = 0``: ``float32(-(v_j Y_i)) * h_k``)."""
    for j in idx:
        sj = slot[j]
        for i in act:
            d = np.float32(trace[j] * v[i] - v[j] * trace[i])
            si = slot[i]
            for k in range(h.size):
                W_slots[sj, k, si] += d * h[k]
    for j in act:
        sj = slot[j]
        for i in rest:
            d = np.float32(-(v[j] * trace[i]))
            si = slot[i]
            for k in range(h.size):
                W_slots[sj, k, si] += d * h[k]


@njit(cache=True, error_model="numpy")
def update_trace(trace, v, rate, floor):  # pragma: no cover - compiled
    """Eq. 6: ``Y += rate (v - Y)``, values below ``floor`` set to 0."""
    for i in range(v.size):
        y = trace[i] + rate * (v[i] - trace[i])
        trace[i] = 0.0 if y < floor else y


@njit(cache=True, error_model="numpy")
def within(points, centre, radius_sq):  # pragma: no cover - compiled
    """Which rows of ``points`` (n, 2) lie within ``sqrt(radius_sq)`` of ``centre``."""
    out = np.empty(points.shape[0], np.bool_)
    for p in range(points.shape[0]):
        dx = points[p, 0] - centre[0]
        dy = points[p, 1] - centre[1]
        out[p] = dx * dx + dy * dy <= radius_sq
    return out


@njit(cache=True, error_model="numpy")
def bvc_exponents(
    ranges, alloc_idx, shift, ang_w, max_range, ignore_max_range, distances, inv_two_var_r, w_out, arg_out
):  # pragma: no cover - compiled
    """For the scan rolled by ``shift`` rays: each ray's angular weight (0 for a ray at max range
    if ignored) and eq. 2's Gaussian exponents ``-(r - d_m)^2 / (2 sigma_r^2)``."""
    n_rays = ranges.size
    D, W = alloc_idx.shape
    for d in range(D):
        for k in range(W):
            r = np.float64(ranges[(alloc_idx[d, k] - shift) % n_rays])
            w_out[d, k] = 0.0 if ignore_max_range and r >= max_range - 1e-6 else ang_w[d, k]
            for m in range(distances.size):
                diff = r - distances[m]
                arg_out[d, k, m] = -(diff * diff) * inv_two_var_r[m]


@njit(cache=True, error_model="numpy")
def bvc_sum(w, g, coef, tiny, out):  # pragma: no cover - compiled
    """``out[d * M + m] = (sum_k w[d, k] g[d, k, m]) * coef[m]`` summed in ray order, below ``tiny`` set to 0."""
    D, W, M = g.shape
    for d in range(D):
        for m in range(M):
            acc = 0.0
            for k in range(W):
                acc += w[d, k] * g[d, k, m]
            x = acc * coef[m]
            out[d * M + m] = 0.0 if x < tiny else x


@njit(cache=True, error_model="numpy")
def advance(s, Wb, inhibition, extra, has_extra, k, psi, s_out, x_out, nonzero):  # pragma: no cover - compiled
    """Eq. 3's Euler step into ``s_out`` (drive ``Wb - inhibition``, plus ``extra`` if ``has_extra``)
    and eq. 4's rectified argument ``[psi s]+`` into ``x_out`` (the caller takes its tanh); the
    indices where that argument is not 0 go to ``nonzero``, their count is returned."""
    count = 0
    for i in range(s.size):
        drive = np.float64(Wb[i]) - inhibition
        if has_extra:
            drive = drive + extra[i]
        si = s[i] + k * (-s[i] + drive)
        s_out[i] = si
        x = _maximum0(psi * si)
        x_out[i] = x
        if x != 0.0:
            nonzero[count] = i
            count += 1
    return count


@njit(cache=True, error_model="numpy")
def centre_exponents(centres, centre_mass, position, two_var, out):  # pragma: no cover - compiled
    """``-|p - c_i|^2 / two_var`` for the cells with a centre, 0 for the others."""
    for i in range(centre_mass.size):
        if centre_mass[i] > 0.0:
            dx = centres[i, 0] - position[0]
            dy = centres[i, 1] - position[1]
            out[i] = -(dx * dx + dy * dy) / two_var
        else:
            out[i] = 0.0


@njit(cache=True, error_model="numpy")
def centre_drive(g, centre_mass, gain, threshold, out):  # pragma: no cover - compiled
    """``gain * (g_i - threshold)`` for the cells with a centre, 0 for the others."""
    for i in range(centre_mass.size):
        out[i] = gain * (g[i] - threshold) if centre_mass[i] > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def learn_centres(v, centres, centre_mass, position, max_mass):  # pragma: no cover - compiled
    """Each active cell's centre moves toward ``position`` by ``v_i / mass_i`` (mass capped at ``max_mass``)."""
    for i in range(v.size):
        if v[i] > 0.0:
            mass = centre_mass[i] + v[i]
            mass = min(mass, max_mass)
            rate = v[i] / mass
            centres[i, 0] += rate * (position[0] - centres[i, 0])
            centres[i, 1] += rate * (position[1] - centres[i, 1])
            centre_mass[i] = mass


@njit(cache=True, error_model="numpy")
def learn_spread(v_sense, centres, centre_mass, spread, spread_mass, position, max_mass):  # pragma: no cover - compiled
    """Running mean, weighted by the BVC-only rate, of each centred cell's squared distance to ``position``."""
    for i in range(v_sense.size):
        if v_sense[i] > 0.0 and centre_mass[i] > 0.0:
            mass = spread_mass[i] + v_sense[i]
            mass = min(mass, max_mass)
            dx = centres[i, 0] - position[0]
            dy = centres[i, 1] - position[1]
            spread[i] += v_sense[i] / mass * ((dx * dx + dy * dy) - spread[i])
            spread_mass[i] = mass


@njit(cache=True, error_model="numpy")
def vote_exponents(particles, offset, centres, variance, out):  # pragma: no cover - compiled
    """``-|(x_p - offset) - c_a|^2 / (2 variance_a)`` for every sample ``p`` and voting cell ``a``."""
    for p in range(particles.shape[0]):
        x = particles[p, 0] - offset[0]
        y = particles[p, 1] - offset[1]
        for a in range(centres.shape[0]):
            dx = x - centres[a, 0]
            dy = y - centres[a, 1]
            out[p, a] = -(dx * dx + dy * dy) / (2.0 * variance[a])


@njit(cache=True, error_model="numpy")
def preplay_argument(rec, slot_cells, slot, v, out, nonzero):  # pragma: no cover - compiled
    """``out[k, i] = [rec[k, slot_i] - v_i]+``, the float32 recurrent drive ``rec`` over the slots
    (``slot_cells`` their cells, ``slot`` each cell's slot or -1) taken as 0 for a cell without one:
    eq. 8's argument. The flat indices where it is not 0 go to ``nonzero`` (in no particular
    order), their count is returned."""
    n_hd, n = out.shape
    count = 0
    for i in range(n):  # no recurrent drive: the same in every direction
        out[0, i] = _maximum0(0.0 - v[i])
    for k in range(1, n_hd):
        out[k, :] = out[0, :]
    for i in range(n):
        if slot[i] < 0 and out[0, i] != 0.0:
            for k in range(n_hd):
                nonzero[count] = k * n + i
                count += 1
    for k in range(n_hd):
        for c in range(slot_cells.size):
            i = slot_cells[c]
            x = _maximum0(np.float64(rec[k, c]) - v[i])
            out[k, i] = x
            if x != 0.0:
                nonzero[count] = k * n + i
                count += 1
    return count


@njit(cache=True, error_model="numpy")
def hd_rates(c, s, cos, sin, out):  # pragma: no cover - compiled
    """Eq. 1, ``(c cos theta_k + s sin theta_k) / |(c, s)|``; returns the norm (0: no direction)."""
    norm = math.hypot(c, s)
    for k in range(out.size):
        out[k] = (c * cos[k] + s * sin[k]) / norm
    return norm


@njit(cache=True, error_model="numpy")
def divide_where_positive(x, total):  # pragma: no cover - compiled
    """``x /= total`` where ``total > 0``, ``x = 0`` elsewhere."""
    for r in range(x.size):
        x[r] = x[r] / total[r] if total[r] > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def depress(W, v, lambda_):  # pragma: no cover - compiled
    """Eq. 11: ``W -= lambda W v`` elementwise."""
    for i in range(W.size):
        W[i] -= lambda_ * W[i] * v[i]


@njit(cache=True, error_model="numpy")
def voting_cells(v_sense, centre_mass, min_mass):  # pragma: no cover - compiled
    """The BVC-only rates of the active cells (``v_sense > 0``), and the indices of those among
    them whose centre has at least ``min_mass``."""
    n_on = n_act = 0
    for i in range(v_sense.size):
        if v_sense[i] > 0.0:
            n_on += 1
            if centre_mass[i] >= min_mass:
                n_act += 1
    on_rates, act = np.empty(n_on), np.empty(n_act, np.int64)
    n_on = n_act = 0
    for i in range(v_sense.size):
        if v_sense[i] > 0.0:
            on_rates[n_on] = v_sense[i]
            n_on += 1
            if centre_mass[i] >= min_mass:
                act[n_act] = i
                n_act += 1
    return on_rates, act


@njit(cache=True, error_model="numpy")
def max_over_directions(W_slots, slot, slot_cells, rows, out):  # pragma: no cover - compiled
    """``out[r, slot_cells[c]] = max_k W_slots[slot[rows[r]], k, c]`` for each row whose cell has a
    slot (NaN propagates, as in ``ndarray.max``); other entries are left as they are."""
    for r in range(rows.size):
        s = slot[rows[r]]
        if s < 0:
            continue
        for c in range(slot_cells.size):
            x = W_slots[s, 0, c]
            for k in range(1, W_slots.shape[1]):
                y = W_slots[s, k, c]
                if y > x or math.isnan(y):
                    x = y
            out[r, slot_cells[c]] = x


@njit(cache=True, error_model="numpy")
def rows_as_float64(M, rows):  # pragma: no cover - compiled
    """``M[rows].astype(np.float64)`` without the intermediate copy."""
    out = np.empty((rows.size, M.shape[1]))
    for r in range(rows.size):
        for c in range(M.shape[1]):
            out[r, c] = M[rows[r], c]
    return out
