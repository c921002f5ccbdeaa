"""Compiled loops (numba) for the cells' per-step updates.

Each kernel does the arithmetic of the equation written out in its docstring and in the calling
method's comments, touching only the cells that matter (active, traced, holding a slot, firing
BVCs), in plain IEEE arithmetic: no fused multiply-adds, no fast-math reordering of sums. ``exp``
and ``tanh`` are libm's (scalar), called only where the result is needed; where thousands of
exponentials are needed at once (the BVCs' radial Gaussians, the path integrator's vote) a kernel
writes the exponents and NumPy's vectorised ``exp``, faster per value, takes them.
The per-step kernels write into arrays they are given rather than return new ones (handing a new
array back to Python costs more than many of the updates themselves). ``error_model="numpy"``: a division by 0 gives inf or
nan, as in NumPy, not an exception.
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
def _tanh_positive(x):  # pragma: no cover - compiled
    """``x = tanh(x)`` where ``x > 0``. A pass of its own: inside a loop doing more, the compiler
    evaluates tanh on every element, silent cells included."""
    for i in range(x.size):
        if x[i] > 0.0:
            x[i] = math.tanh(x[i])


@njit(cache=True, error_model="numpy")
def oja_active_rows(W_bp, v, b, eta, alpha):  # pragma: no cover - compiled
    """Eq. 5 on the weights onto the active cells (``v_i > 0``; for the others the update is
    exactly 0), ``W_bp[c, i]`` float32 BVC-first, in float64, flushing results below 1e-12 to 0.
    A cell's weights are copied out of their column into ``w`` and back: on a contiguous copy the
    update, with its division, runs in vector registers."""
    w = np.empty(b.size)
    for i in range(v.size):
        va = v[i]
        if not va > 0.0:
            continue
        eta_va = eta * va
        for c in range(b.size):
            w[c] = np.float64(W_bp[c, i])
        for c in range(b.size):
            x = w[c] + eta_va * (b[c] - va * w[c] / alpha)
            w[c] = 0.0 if x < 1e-12 else x
        for c in range(b.size):
            W_bp[c, i] = np.float32(w[c])


@njit(cache=True, error_model="numpy")
def bvc_drive(W_bp, b, out):  # pragma: no cover - compiled
    """``out = W_pb b`` from the BVC-first float32 ``W_bp``, summed in float32 (as a BLAS float32
    product would) over the rows of the BVCs with ``b_c > 0`` only, in BVC order; returns ``sum(b)``.

    Four firing rows are added per pass over the cells: the same sums in the same order as one pass
    per row, with the partial sums read and written a quarter as often."""
    firing = np.empty(b.size, np.int64)
    b32 = np.empty(b.size, np.float32)
    n_firing = 0
    total = 0.0
    for c in range(b.size):
        total += b[c]
        if b[c] > 0.0:
            firing[n_firing] = c
            b32[n_firing] = np.float32(b[c])
            n_firing += 1
    acc = np.zeros(out.size, np.float32)
    f = 0
    while f + 4 <= n_firing:
        r0, r1, r2, r3 = W_bp[firing[f]], W_bp[firing[f + 1]], W_bp[firing[f + 2]], W_bp[firing[f + 3]]
        b0, b1, b2, b3 = b32[f], b32[f + 1], b32[f + 2], b32[f + 3]
        for i in range(acc.size):
            x = acc[i]
            x += r0[i] * b0
            x += r1[i] * b1
            x += r2[i] * b2
            x += r3[i] * b3
            acc[i] = x
        f += 4
    for g in range(f, n_firing):
        row, bg = W_bp[firing[g]], b32[g]
        for i in range(acc.size):
            acc[i] += row[i] * bg
    for i in range(out.size):
        out[i] = acc[i]
    return total


@njit(cache=True, error_model="numpy")
def pp_update(W_slots, slot, v, trace, eta, hd_trace):  # pragma: no cover - compiled
    """Eq. 7 on its two nonzero blocks, ``W[slot_j, k, slot_i] += float32(v_i Y_j - v_j Y_i) * h_k``
    with ``h_k = float32(eta Upsilon^h_k)``: post ``i`` active (``v > 0``) and pre ``j`` active or
    traced; pre ``j`` active and post ``i`` silent but traced (there ``v_i = 0``: ``float32(-(v_j Y_i))
    * h_k``). Returns how many of those cells hold no slot yet (0 with no active cell): if any,
    nothing is updated."""
    n = v.size
    act, idx, rest = np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64)
    n_act = n_idx = n_rest = 0
    unslotted = 0
    for i in range(n):
        on, traced = v[i] > 0.0, trace[i] > 0.0
        if on:
            act[n_act] = i
            n_act += 1
        if on or traced:
            idx[n_idx] = i
            n_idx += 1
            if slot[i] < 0:
                unslotted += 1
        if traced and not on:
            rest[n_rest] = i
            n_rest += 1
    if n_act == 0:
        return 0
    if unslotted:
        return unslotted
    h = np.empty(hd_trace.size, np.float32)
    for k in range(h.size):
        h[k] = np.float32(eta * hd_trace[k])
    for j in idx[:n_idx]:
        sj = slot[j]
        for i in act[:n_act]:
            d = np.float32(trace[j] * v[i] - v[j] * trace[i])
            si = slot[i]
            for k in range(h.size):
                W_slots[sj, k, si] += d * h[k]
    for j in act[:n_act]:
        sj = slot[j]
        for i in rest[:n_rest]:
            d = np.float32(-(v[j] * trace[i]))
            si = slot[i]
            for k in range(h.size):
                W_slots[sj, k, si] += d * h[k]
    return 0


@njit(cache=True, error_model="numpy")
def update_trace(trace, v, rate, floor):  # pragma: no cover - compiled
    """Eq. 6: ``Y += rate (v - Y)``, values below ``floor`` set to 0."""
    for i in range(v.size):
        y = trace[i] + rate * (v[i] - trace[i])
        trace[i] = 0.0 if y < floor else y


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
    """``out[d * M + m] = (sum_k w[d, k] g[d, k, m]) * coef[m]`` summed in ray order, below ``tiny`` set to 0.
    (The distances ``m`` are the inner loop: contiguous, so it runs in vector registers.)"""
    D, W, M = g.shape
    acc = np.empty(M)
    for d in range(D):
        acc[:] = 0.0
        for k in range(W):
            wk = w[d, k]
            for m in range(M):
                acc[m] += wk * g[d, k, m]
        for m in range(M):
            x = acc[m] * coef[m]
            out[d * M + m] = 0.0 if x < tiny else x


@njit(cache=True, error_model="numpy")
def advance(s, v, Wb, b_inhibition, Gamma_pp, extra, has_extra, k, psi, s_out, v_out):  # pragma: no cover - compiled
    """Eq. 3's Euler step into ``s_out``, with the drive ``Wb - b_inhibition - Gamma_pp sum(v)``
    (plus ``extra`` if ``has_extra``), and eq. 4's rates ``tanh([psi s]+)`` into ``v_out``."""
    inhibition = b_inhibition + Gamma_pp * np.sum(v)
    for i in range(s.size):
        drive = Wb[i] - inhibition
        if has_extra:
            drive = drive + extra[i]
        si = s[i] + k * (-s[i] + drive)
        s_out[i] = si
        v_out[i] = _maximum0(psi * si)
    _tanh_positive(v_out)


@njit(cache=True, error_model="numpy")
def sense_step(W_bp, b, Gamma_pb, Gamma_pp, k, psi, s, v, Wb, s_out, v_out):  # pragma: no cover - compiled
    """:func:`bvc_drive` into ``Wb``, then :func:`advance` with that drive and no extra input:
    one call for the BVC-only update of a step. Returns ``sum(b)``."""
    b_sum = bvc_drive(W_bp, b, Wb)
    advance(s, v, Wb, Gamma_pb * b_sum, Gamma_pp, s, False, k, psi, s_out, v_out)
    return b_sum


@njit(cache=True, error_model="numpy")
def learn_step(
    W_bp, v, b, eta_pb, alpha_pb, hd_trace, h, hd_trace_rate, W_slots, slot, trace, eta_pp, trace_rate, trace_floor, trusted, pp
):  # pragma: no cover - compiled
    """A step's learning, in this order: eq. 5 (:func:`oja_active_rows`) if ``trusted``; the
    head-direction trace toward ``h`` (eq. 6, no floor); eq. 7 (:func:`pp_update`) if ``pp``; the
    place-cell trace toward ``v`` (eq. 6) if ``trusted``, else the trace set to 0. Returns what
    :func:`pp_update` returns: if it is not 0 (cells without a slot), eq. 7 and the place-cell
    trace are left to the caller."""
    if trusted:
        oja_active_rows(W_bp, v, b, eta_pb, alpha_pb)
    update_trace(hd_trace, h, hd_trace_rate, -np.inf)
    if pp:
        unslotted = pp_update(W_slots, slot, v, trace, eta_pp, hd_trace)
        if unslotted:
            return unslotted
    if trusted:
        update_trace(trace, v, trace_rate, trace_floor)
    else:
        trace[:] = 0.0
    return 0


@njit(cache=True, error_model="numpy")
def centre_drive(
    centres, centre_mass, position, two_var, gain, threshold, far_sq, far_inhibition, negligible_sq, out
):  # pragma: no cover - compiled
    """``gain * (exp(-|p - c_i|^2 / two_var) - threshold)``, less ``far_inhibition`` beyond
    ``sqrt(far_sq)``, for the cells with a centre, 0 for the others. Beyond ``sqrt(negligible_sq)``
    the exponential is taken as 0 (the caller's bound: where that gives the same result)."""
    for i in range(centre_mass.size):
        if centre_mass[i] > 0.0:
            dx = centres[i, 0] - position[0]
            dy = centres[i, 1] - position[1]
            d_sq = dx * dx + dy * dy
            gauss = 0.0 if d_sq > negligible_sq else math.exp(-d_sq / two_var)
            out[i] = gain * (gauss - threshold)
            if d_sq > far_sq:
                out[i] -= far_inhibition
        else:
            out[i] = 0.0


@njit(cache=True, error_model="numpy")
def centre_driven_advance(
    s, v, Wb, b_inhibition, Gamma_pp, k, psi, centres, centre_mass, position, constants, extra, s_out, v_out
):  # pragma: no cover - compiled
    """:func:`centre_drive` into ``extra`` (``constants``: its arguments after the position), then
    :func:`advance` with that extra input: one call for the update of a step driven by path integration."""
    two_var, gain, threshold, far_sq, far_inhibition, negligible_sq = constants
    centre_drive(centres, centre_mass, position, two_var, gain, threshold, far_sq, far_inhibition, negligible_sq, extra)
    advance(s, v, Wb, b_inhibition, Gamma_pp, extra, True, k, psi, s_out, v_out)


@njit(cache=True, error_model="numpy")
def learn_centres(v, centres, centre_mass, x, y, max_mass, with_spread, v_sense, spread, spread_mass):  # pragma: no cover - compiled
    """Each active cell's centre moves toward the position ``(x, y)`` by ``v_i / mass_i`` (mass capped at
    ``max_mass``); then, ``with_spread``, :func:`learn_spread` there."""
    for i in range(v.size):
        if v[i] > 0.0:
            mass = centre_mass[i] + v[i]
            mass = min(mass, max_mass)
            rate = v[i] / mass
            centres[i, 0] += rate * (x - centres[i, 0])
            centres[i, 1] += rate * (y - centres[i, 1])
            centre_mass[i] = mass
    if with_spread:
        learn_spread(v_sense, centres, centre_mass, spread, spread_mass, x, y, max_mass)


@njit(cache=True, error_model="numpy")
def learn_spread(v_sense, centres, centre_mass, spread, spread_mass, x, y, max_mass):  # pragma: no cover - compiled
    """Running mean, weighted by the BVC-only rate, of each centred cell's squared distance to ``(x, y)``."""
    for i in range(v_sense.size):
        if v_sense[i] > 0.0 and centre_mass[i] > 0.0:
            mass = spread_mass[i] + v_sense[i]
            mass = min(mass, max_mass)
            dx = centres[i, 0] - x
            dy = centres[i, 1] - y
            spread[i] += v_sense[i] / mass * ((dx * dx + dy * dy) - spread[i])
            spread_mass[i] = mass


@njit(cache=True, error_model="numpy")
def shift(particles, x, y, spread, noise):  # pragma: no cover - compiled
    """Move every sample by the step ``(x, y)`` plus ``spread`` times its standard normal ``noise`` (none if ``spread`` is 0)."""
    for p in range(particles.shape[0]):
        particles[p, 0] += x
        if spread > 0.0:
            particles[p, 0] += spread * noise[p, 0]
        particles[p, 1] += y
        if spread > 0.0:
            particles[p, 1] += spread * noise[p, 1]


@njit(cache=True, error_model="numpy")
def vote_exponents(particles, lag, last_step, centres, spreads, vote_var, out):  # pragma: no cover - compiled
    """``out[p, a] = -|(x_p - lag last_step) - c_a|^2 / (2 (vote_var + spreads_a))``: the exponent of
    cell ``a``'s Gaussian vote at sample ``p``, where the sample was ``lag`` steps ago. Cell by cell,
    over all the samples at once: the divisions, the slow step, then run in vector registers."""
    offset_x, offset_y = lag * last_step[0], lag * last_step[1]
    n = particles.shape[0]
    x, y, column = np.empty(n), np.empty(n), np.empty(n)
    for p in range(n):
        x[p] = particles[p, 0] - offset_x
        y[p] = particles[p, 1] - offset_y
    for a in range(centres.shape[0]):
        cx, cy, two_var = centres[a, 0], centres[a, 1], 2.0 * (vote_var + spreads[a])
        for p in range(n):
            dx = x[p] - cx
            dy = y[p] - cy
            column[p] = -(dx * dx + dy * dy) / two_var
        for p in range(n):
            out[p, a] = column[p]


@njit(cache=True, error_model="numpy")
def reweigh(gauss, rates, spreads, vote_var, floor, weights):  # pragma: no cover - compiled
    """Multiply each sample's weight by its vote plus ``floor`` and normalise; return the
    effective sample size ``1 / sum w^2``. The vote is the normalised sum over the voting cells
    ``a`` of ``rates_a vote_var / (vote_var + spreads_a) gauss[p, a]``: each cell's Gaussian
    (:func:`vote_exponents`, exponentiated) scaled by the cell's say."""
    n_cells = rates.size
    reliability = np.empty(n_cells)
    total_rate = 0.0
    for a in range(n_cells):
        reliability[a] = rates[a] * (vote_var / (vote_var + spreads[a]))
        total_rate += rates[a]
    wsum = 0.0
    for p in range(weights.size):
        vote = 0.0
        for a in range(n_cells):
            vote += gauss[p, a] * reliability[a]
        w = weights[p] * (vote / total_rate + floor)
        weights[p] = w
        wsum += w
    sq = 0.0
    for p in range(weights.size):
        weights[p] /= wsum
        sq += weights[p] * weights[p]
    return 1.0 / sq


@njit(cache=True, error_model="numpy")
def cluster_mean(particles, weights, radius_sq):  # pragma: no cover - compiled
    """The weighted mean (x, y) of the samples within ``sqrt(radius_sq)`` of the heaviest one, and their weight."""
    best = 0
    for p in range(1, weights.size):
        if weights[p] > weights[best]:
            best = p
    bx, by = particles[best, 0], particles[best, 1]
    mass = mx = my = 0.0
    for p in range(weights.size):
        dx = particles[p, 0] - bx
        dy = particles[p, 1] - by
        if dx * dx + dy * dy <= radius_sq:
            mass += weights[p]
            mx += weights[p] * particles[p, 0]
            my += weights[p] * particles[p, 1]
    return mx / mass, my / mass, mass


@njit(cache=True, error_model="numpy")
def _recurrent_drive(W_slots, slot, v, n_hd, m):  # pragma: no cover - compiled
    """``rec[k, c] = sum_j W_slots[slot_j, k, c] v_j`` in float32 over the active cells ``j`` with a slot."""
    rec = np.zeros((n_hd, m), np.float32)
    for j in range(v.size):
        if v[j] > 0.0 and slot[j] >= 0:
            vj = np.float32(v[j])
            sj = slot[j]
            for k in range(n_hd):
                for c in range(m):
                    rec[k, c] += W_slots[sj, k, c] * vj
    return rec


@njit(cache=True, error_model="numpy")
def imagined_rates(W_slots, slot, slot_cells, v, out):  # pragma: no cover - compiled
    """Eq. 8 for the cells holding slots, ``out[k, c] = tanh([sum_j W_slots[slot_j, k, c] v_j - v_i]+)``
    for the cell ``i = slot_cells[c]``, the sum in float32 over the active cells ``j`` with a slot.
    (Every other cell's imagined rate is 0: it has no recurrent drive and ``[0 - v_i]+ = 0``.)"""
    n_hd, m = out.shape
    rec = _recurrent_drive(W_slots, slot, v, n_hd, m)
    for k in range(n_hd):
        for c in range(m):
            out[k, c] = _maximum0(np.float64(rec[k, c]) - v[slot_cells[c]])
    _tanh_positive(out.reshape(-1))


@njit(cache=True, error_model="numpy")
def imagined_values(W_slots, slot, slot_cells, v, W, values):  # pragma: no cover - compiled
    """Eq. 9 of eq. 8's imagined rates (:func:`imagined_rates`) in each direction ``k``: ``values[k] =
    sum_c W[cells_c] x_kc / sum_c x_kc`` over the positive rates ``x_kc``, 0 where there are none.
    The rates themselves are not kept."""
    n_hd, m = values.size, slot_cells.size
    rec = _recurrent_drive(W_slots, slot, v, n_hd, m)
    v_slotted, W_slotted = v[slot_cells], W[slot_cells]
    for k in range(n_hd):
        num = total = 0.0
        for c in range(m):
            if rec[k, c] > 0.0:  # (most cells get no recurrent drive: skip them before the float64 arithmetic)
                x = np.float64(rec[k, c]) - v_slotted[c]
                if x > 0.0:
                    x = math.tanh(x)
                    num += W_slotted[c] * x
                    total += x
        values[k] = num / total if total > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def value(v, W):  # pragma: no cover - compiled
    """Eq. 9 for one rate vector, ``sum_i W_i v_i / sum_i v_i`` over the active cells (``v_i > 0``; rates
    are never negative), 0 when none is active."""
    num = total = 0.0
    for i in range(v.size):
        if v[i] > 0.0:
            num += W[i] * v[i]
            total += v[i]
    return num / total if total > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def circular_mean(values, cos, sin):  # pragma: no cover - compiled
    """Eq. 10: the direction of ``sum_k values_k (cos theta_k, sin theta_k)``, and the largest value."""
    x = y = 0.0
    best = -np.inf
    for k in range(values.size):
        x += values[k] * cos[k]
        y += values[k] * sin[k]
        best = max(best, values[k])
    return math.atan2(y, x), best


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
def voting_cells(v_sense, centre_mass, min_mass, centres, spread, rates, where, spreads):  # pragma: no cover - compiled
    """Of the active cells (``v_sense > 0``), those whose centre has at least ``min_mass``: their
    BVC-only rates, centres and spreads into the first rows of ``rates``, ``where`` and ``spreads``.
    Returns how many, and their share of all the active cells' rate."""
    a = 0
    total = voted = 0.0
    for i in range(v_sense.size):
        if v_sense[i] > 0.0:
            total += v_sense[i]
            if centre_mass[i] >= min_mass:
                rates[a] = v_sense[i]
                where[a, 0] = centres[i, 0]
                where[a, 1] = centres[i, 1]
                spreads[a] = spread[i]
                voted += v_sense[i]
                a += 1
    return a, voted / total if total > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def vote_with_exponents(
    v_sense, centre_mass, min_mass, centres, spread, min_share, particles, lag, last_step, vote_var, rates, where, spreads, exponents
):  # pragma: no cover - compiled
    """:func:`voting_cells` into ``rates``, ``where`` and ``spreads``, then, if any cell votes and
    their share is at least ``min_share``, :func:`vote_exponents` of them into the first
    ``n_samples * n`` values of the flat ``exponents`` (sample-major): one call for the vote of a
    step once anchored. Returns ``n``, 0 where the vote is ignored."""
    n, share = voting_cells(v_sense, centre_mass, min_mass, centres, spread, rates, where, spreads)
    if n == 0 or not share >= min_share:
        return 0
    n_samples = particles.shape[0]
    out = exponents[: n_samples * n].reshape((n_samples, n))
    vote_exponents(particles, lag, last_step, where[:n], spreads[:n], vote_var, out)
    return n


@njit(cache=True, error_model="numpy")
def reweigh_and_cluster(gauss, n, rates, spreads, vote_var, floor, weights, particles, radius_sq):  # pragma: no cover - compiled
    """:func:`reweigh` by the first ``n`` cells' Gaussians (the first ``n_samples * n`` values of the
    flat ``gauss``, sample-major), then :func:`cluster_mean`: returns the effective sample size and
    the cluster's (x, y, weight)."""
    ess = reweigh(gauss[: weights.size * n].reshape((weights.size, n)), rates[:n], spreads[:n], vote_var, floor, weights)
    x, y, mass = cluster_mean(particles, weights, radius_sq)
    return ess, x, y, mass


@njit(cache=True, error_model="numpy")
def max_over_directions(W_slots, slot, slot_cells, rows):  # pragma: no cover - compiled
    """The nonzero entries of ``M[rows[r], slot_cells[c]] = max_k W_slots[slot[rows[r]], k, c]``
    (NaN propagates, as in ``ndarray.max``; a row whose cell has no slot has none): per row their
    count, then their columns and values, row after row."""
    m = slot_cells.size
    counts = np.zeros(rows.size, np.int64)
    # room for every entry: only the pages written are ever touched (the rest stay unmapped)
    targets = np.empty(rows.size * m, np.int64)
    weights = np.empty(rows.size * m, np.float32)
    row = np.empty(m, np.float32)
    used = 0
    for r in range(rows.size):
        s = slot[rows[r]]
        if s < 0:
            continue
        row[:] = W_slots[s, 0, :m]
        for k in range(1, W_slots.shape[1]):
            for c in range(m):
                y = W_slots[s, k, c]
                if y > row[c] or math.isnan(y):
                    row[c] = y
        first = used
        for c in range(m):
            if row[c] != 0.0:
                targets[used] = slot_cells[c]
                weights[used] = row[c]
                used += 1
        counts[r] = used - first
    return counts, targets[:used].copy(), weights[:used].copy()


@njit(cache=True, error_model="numpy")
def spread_along(v, cells, start, count, target, weight, out):  # pragma: no cover - compiled
    """``out[target] += v_j weight`` over the links of each of ``cells`` (replay's spread)."""
    for j in cells:
        vj = v[j]
        for e in range(start[j], start[j] + count[j]):
            out[target[e]] += vj * weight[e]


@njit(cache=True, error_model="numpy")
def imagined_steps(
    W_slots,
    slot,
    v,
    trace,
    hd_trace,
    eta_pp,
    trace_rate,
    hd_trace_rate,
    trace_floor,
    hd_cos,
    hd_sin,
    h,
    code_start,
    code_cells,
    code_rates,
    step_x,
    step_y,
    first,
):  # pragma: no cover - compiled
    """Imagined steps ``first, first + 1, ...`` of a sequence of place codes, each learnt as a run's
    step is: the rates ``v`` set to step ``q``'s code (the cells ``code_cells`` with the rates
    ``code_rates``, from ``code_start[q]`` to ``code_start[q + 1]``; every other cell 0), the
    head-direction trace moved toward eq. 1's rates for the unit step ``(step_x[q], step_y[q])``
    (:func:`hd_rates`, into ``h``), eq. 7 (:func:`pp_update`), the place-cell trace moved toward
    the rates (eq. 6). Returns the number of steps done: it stops at step ``q`` when eq. 7 reaches
    cells holding no ``W_pp`` slot yet (``v`` and the head-direction trace are then step ``q``'s;
    its eq. 7 and place-cell trace are left to the caller)."""
    for q in range(first, step_x.size):
        for i in range(v.size):
            v[i] = 0.0
        for a in range(code_start[q], code_start[q + 1]):
            v[code_cells[a]] = code_rates[a]
        hd_rates(step_x[q], step_y[q], hd_cos, hd_sin, h)
        update_trace(hd_trace, h, hd_trace_rate, -np.inf)
        if pp_update(W_slots, slot, v, trace, eta_pp, hd_trace):
            return q
        update_trace(trace, v, trace_rate, trace_floor)
    return step_x.size
