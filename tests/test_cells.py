"""Each equation of the model on small cases: head direction, BVC (eq. 2), place cells (eqs. 3-5),
W_pp (eqs. 6-7), replay (Algorithm 1), preplay and readout (eqs. 8-9), depression (eq. 11)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hippo_agent import ModelConfig
from hippo_agent.cells import BoundaryVectorCells, HeadDirectionCells, PlaceCells, RewardCells, _kernels, replay

BVC = ModelConfig().bvc_kwargs()  # the cells' parameters as the agent passes them


def square_ranges(pos, heading, n_rays=720, half=5.0, max_range=10.0):
    """Egocentric scan in a square room [-half, half]^2 (analytic ray casting)."""
    ang = heading + 2 * np.pi * np.arange(n_rays) / n_rays
    c, s = np.cos(ang), np.sin(ang)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(c > 0, (half - pos[0]) / c, np.where(c < 0, (-half - pos[0]) / c, np.inf))
        ty = np.where(s > 0, (half - pos[1]) / s, np.where(s < 0, (-half - pos[1]) / s, np.inf))
    return np.minimum(np.minimum(tx, ty), max_range).astype(np.float32)


# ------------------------------------------------------------------ head direction (eq. 1)
def test_head_direction_cosine_unrectified():
    hd = HeadDirectionCells(8)
    rates = hd.update(np.array([math.cos(0.3), math.sin(0.3)]))
    np.testing.assert_allclose(rates, np.cos(0.3 - hd.preferred), atol=1e-12)
    assert rates.min() < 0  # not rectified
    np.testing.assert_allclose(rates[4:], -rates[:4], atol=1e-12)  # the opposite cell is the negative
    assert np.argmax(hd.update(np.array([0.0, 2.0]))) == 2  # unnormalised (cos, sin) is fine: 90 deg
    with pytest.raises(ValueError, match="no direction"):
        hd.update(np.zeros(2))


# ------------------------------------------------------------------ BVCs (eq. 2)
def arc_scan(n_rays=720, max_range=10.0, direction=0.0, distance=3.0, width_deg=40.0):
    """Allocentric scan (heading 0): nothing in range except an arc at ``distance`` around ``direction``."""
    ang = 2 * np.pi * np.arange(n_rays) / n_rays
    off = np.angle(np.exp(1j * (ang - direction)))
    return np.where(np.abs(off) <= math.radians(width_deg) / 2, distance, max_range).astype(np.float32)


def test_bvc_peaks_at_preferred_distance_and_direction():
    bvc = BoundaryVectorCells(720, 10.0, **BVC)
    rates = bvc.update(arc_scan(direction=math.pi / 2, distance=3.06), 0.0).reshape(8, 50)
    d, m = np.unravel_index(np.argmax(rates), rates.shape)
    assert d == 2  # direction index 2 = 90 deg
    assert abs(bvc.distances[m] - 3.06) < 0.11  # nearest preferred distance (spacing 0.204 m)
    assert np.all(rates[[0, 4, 6]] < 1e-9)  # no boundary in those directions
    # tuning falls off with distance from the preferred one
    row = rates[2]
    assert np.all(np.diff(row[: m + 1]) >= 0) and np.all(np.diff(row[m:]) <= 0)


def test_bvc_largest_response_is_peak_rate():
    bvc = BoundaryVectorCells(720, 10.0, **BVC)
    # circular room with radius exactly a preferred distance: every direction's cell at that distance peaks
    r = bvc.distances[20]
    rates = bvc.update(np.full(720, r, np.float32), 1.234).reshape(8, 50)
    np.testing.assert_allclose(rates[:, 20], 0.5, rtol=1e-6)
    assert rates.max() <= 0.5 + 1e-9
    # a square room never exceeds it either
    rates = bvc.update(square_ranges((1.0, -2.0), 0.7), 0.7)
    assert 0 < rates.max() <= 0.5 + 1e-9


def test_bvc_is_allocentric():
    """The same place seen with different headings gives the same BVC rates."""
    bvc = BoundaryVectorCells(720, 10.0, **BVC)
    pos = (1.5, -0.5)
    a = bvc.rates_for(square_ranges(pos, 0.0), 0.0)
    for heading in (0.5 * math.pi / 180 * 37, 1.0, -2.5, math.pi):
        b = bvc.rates_for(square_ranges(pos, heading), heading)
        np.testing.assert_allclose(a, b, atol=0.02)
    # east wall at 3.5 m: direction 0 peaks near 3.5 m
    m = np.argmax(a.reshape(8, 50)[0])
    assert abs(bvc.distances[m] - 3.5) < 0.11


def test_bvc_ignores_rays_at_max_range():
    scan = np.full(720, 10.0, np.float32)
    assert BoundaryVectorCells(720, 10.0, **BVC).rates_for(scan, 0.0).max() == 0.0
    assert np.all(BoundaryVectorCells(720, 10.0, **BVC).sigma_r == 0.5)  # (the same radial width at every distance)


def test_bvc_rejects_wrong_scan_length():
    with pytest.raises(ValueError, match="expected \\(720,\\)"):
        BoundaryVectorCells(720, 10.0, **BVC).rates_for(np.zeros(360, np.float32), 0.0)


# ------------------------------------------------------------------ place cells (eqs. 3-5)
def make_place(n=50, n_bvc=400, seed=0, **kw):
    return PlaceCells(n, n_bvc, 8, np.random.default_rng(seed), **{**ModelConfig().place_kwargs(), **kw})


def test_place_rates_are_tanh_of_rectified_potential():
    pc = make_place()
    b = BoundaryVectorCells(720, 10.0, **BVC).rates_for(square_ranges((0.0, 0.0), 0.0), 0.0)
    v = pc.step(b, 30)
    np.testing.assert_allclose(v, np.tanh(np.maximum(pc.s, 0)))
    assert np.all((v >= 0) & (v < 1))
    # steady state of eq. 3: s = W_pb b - Gamma_pb sum b - Gamma_pp sum v
    expected = pc.W_pb.astype(np.float64) @ b - 0.3 * b.sum() - 0.5 * v.sum()
    np.testing.assert_allclose(pc.s, expected, rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(pc.rates_for(b, 30), v)  # rates_for from rest gives the same


def test_oja_keeps_weights_bounded_and_only_touches_active_rows():
    pc = make_place(n=200)
    bvc = BoundaryVectorCells(720, 10.0, **BVC)
    rng = np.random.default_rng(1)
    norms0 = np.linalg.norm(pc.W_pb, axis=1)
    for t in range(500):
        b = bvc.rates_for(square_ranges(rng.uniform(-4.5, 4.5, 2), 0.0), 0.0)
        before = pc.W_pb.copy()
        pc.step(b, 2)
        pc.learn_pb(b)
        silent = pc.v == 0
        np.testing.assert_array_equal(pc.W_pb[silent], before[silent])
    norms = np.linalg.norm(pc.W_pb, axis=1)
    assert np.all(np.isfinite(pc.W_pb)) and pc.W_pb.min() >= 0
    learnt = norms != norms0
    assert learnt.any()
    assert norms[learnt].max() < norms0.max()  # Oja shrank the binary rows, never blew up


@given(st.floats(0.25, 1.0), st.integers(0, 2**31 - 1))
@settings(max_examples=30, deadline=None)
def test_oja_fixed_point_is_bounded(v_i, seed):
    """For any constant input and rate, repeated eq.-5 steps converge to W = alpha b / v (bounded)."""
    rng = np.random.default_rng(seed)
    b = rng.uniform(0, 0.5, 10)
    W = rng.uniform(0, 2, 10)
    for _ in range(3000):
        W = W + 0.096 * v_i * (b - v_i * W / math.sqrt(0.5))
    np.testing.assert_allclose(W, math.sqrt(0.5) * b / v_i, rtol=1e-3, atol=1e-6)


# ------------------------------------------------------------------ W_pp (eqs. 6-7)
def drive(pc, sequence, heading):
    """Impose rate vectors (one per step) while moving along ``heading``; learn eq. 7 each step."""
    h = np.cos(heading - 2 * np.pi * np.arange(8) / 8)
    for v in sequence:
        pc.v = np.asarray(v, dtype=float)
        pc.update_hd_trace(h)
        pc.learn_pp()
        pc.update_trace()


def field_sequence(n, first, second, steps=5):
    seq = []
    for cell in (first, second):
        for _ in range(steps):
            v = np.zeros(n)
            v[cell] = 0.8
            seq.append(v)
    return seq


def test_w_pp_grows_moving_from_j_into_i_along_k_and_falls_the_other_way():
    pc = make_place(n=4, n_bvc=4)
    j, i = 0, 1
    drive(pc, field_sequence(4, j, i), heading=0.0)  # east from j's field into i's
    W0 = pc.W_pp_slice(0)  # W^pp_0 as (post, pre)
    assert W0[i, j] > 0 and W0[j, i] < 0
    np.testing.assert_allclose(pc.W_pp_slice(4), -W0, atol=1e-7)  # opposite slice: negative
    np.testing.assert_allclose(pc.W_pp_slice(4), W0.T, atol=1e-7)  # ... = the transpose
    assert pc.W_pp_slice(2)[i, j] == pytest.approx(0.0, abs=1e-6)  # perpendicular: cos 90 = 0
    before = W0[i, j]
    pc.reset_state()
    drive(pc, field_sequence(4, i, j), heading=0.0)  # east again, but from i's field into j's
    assert pc.W_pp_slice(0)[i, j] < before


def test_w_pp_is_learnt_only_over_involved_cells_and_matches_dense_rule():
    rng = np.random.default_rng(3)
    pc = make_place(n=30, n_bvc=4, trace_floor=0.05)
    W_dense = np.zeros((8, 30, 30))
    for t in range(60):
        v = np.where(rng.random(30) < 0.1, rng.uniform(0.1, 0.9, 30), 0.0)
        heading = rng.uniform(-np.pi, np.pi)
        h = np.cos(heading - 2 * np.pi * np.arange(8) / 8)
        pc.v = v
        pc.update_hd_trace(h)
        y = pc.trace.copy()
        W_dense += h[:, None, None] * (np.outer(v, y) - np.outer(y, v))[None]  # eq. 7, dense
        pc.learn_pp()
        pc.update_trace()
    for k in range(8):
        np.testing.assert_allclose(pc.W_pp_slice(k), W_dense[k], atol=1e-4)


def test_trace_floor_zeroes_small_traces():
    pc = make_place(n=3, n_bvc=4)
    pc.v = np.array([1.0, 0.0, 0.0])
    pc.update_trace()
    pc.v = np.zeros(3)
    for _ in range(40):
        pc.update_trace()
    assert np.all(pc.trace == 0.0)


# ------------------------------------------------------------------ replay (Algorithm 1)
def chain(n=10, w=2.0):
    """Place cells 0..n-1 along a path, neighbours linked both ways (max over directions)."""
    M = np.zeros((n, n), np.float32)
    for a in range(n - 1):
        M[a, a + 1] = M[a + 1, a] = w
    return M


def test_replay_peaks_at_goal_and_falls_along_the_path():
    v = np.zeros(10)
    v[0] = 0.7  # the goal's place cell
    dW = replay(v, chain(), iterations=20, tau_r=2.0)
    assert dW.argmax() == 0 and dW.max() == pytest.approx(1.0)
    assert np.all(np.diff(dW) < 0)  # strictly decreasing with distance along the path
    rc = RewardCells(10)
    rc.add_goal()
    assert rc.learn(v, chain(), 20, 2.0)
    np.testing.assert_allclose(rc.W_rp[0], dW)
    rc.learn(v, chain(), 20, 2.0)  # accumulates over replays
    np.testing.assert_allclose(rc.W_rp[0], 2 * dW)


def test_replay_with_no_active_cell_learns_nothing():
    rc = RewardCells(10)
    rc.add_goal()
    assert replay(np.zeros(10), chain(), 20, 2.0) is None
    assert rc.learn(np.zeros(10), chain(), 20, 2.0) is False
    assert np.all(rc.W_rp == 0)


def test_replay_with_slow_decay_spreads_further():
    v = np.zeros(10)
    v[0] = 0.7
    fast, slow = replay(v, chain(), 20, 1.0), replay(v, chain(), 20, 6.0)
    assert slow[5] > fast[5]


# ------------------------------------------------------------------ preplay and readout (eqs. 8, 9, 11)
def test_preplay_imagines_the_next_field_in_the_learnt_direction():
    pc = make_place(n=4, n_bvc=4)
    drive(pc, field_sequence(4, 0, 1), heading=0.0)  # east: 0 -> 1
    drive(pc, field_sequence(4, 0, 2), heading=math.pi / 2)  # north: 0 -> 2
    v = np.zeros(4)
    v[0] = 0.8
    v_bar = pc.preplay(v)
    assert v_bar.shape == (8, 4)
    assert v_bar[0].argmax() == 1 and v_bar[2].argmax() == 2
    assert np.all(v_bar[4] < 1e-6)  # west leads nowhere learnt
    assert np.all(v_bar >= 0) and np.all(v_bar < 1)


def test_value_readout_and_depression():
    rc = RewardCells(4)
    rc.add_goal()
    rc.W_rp[0] = [0.0, 1.0, 0.5, 0.0]
    rc.reset_effective()
    assert rc.value(np.array([0.0, 0.5, 0.5, 0.0])) == pytest.approx(0.75)  # eq. 9, normalised
    assert rc.value(np.zeros(4)) == 0.0
    np.testing.assert_allclose(rc.value(np.array([[0, 1.0, 0, 0], [0, 0, 0, 0]])), [1.0, 0.0])
    rc.depress(np.array([0.0, 1.0, 0.0, 0.0]), 0.05)  # eq. 11
    np.testing.assert_allclose(rc.W_eff, [0.0, 0.95, 0.5, 0.0])
    np.testing.assert_allclose(rc.W_rp[0], [0.0, 1.0, 0.5, 0.0])  # W_rp itself untouched
    rc.reset_effective()
    np.testing.assert_allclose(rc.W_eff, rc.W_rp[0])
    assert rc.add_goal() == 1 and np.all(rc.W_eff == 0)  # a new goal: a new, empty reward cell


def test_replay_with_lazy_rows_equals_dense_matrix():
    pc = make_place(n=40, n_bvc=4)
    rng = np.random.default_rng(5)
    for _ in range(200):  # a random walk of single active cells
        heading = rng.uniform(-np.pi, np.pi)
        drive(pc, [np.where(np.arange(40) == rng.integers(40), 0.7, 0.0)], heading)
    v = np.zeros(40)
    v[[3, 4]] = [0.5, 0.2]
    dense = replay(v, pc.replay_weights(), 20, 2.0)
    lazy = replay(v, pc.replay_links, 20, 2.0)
    np.testing.assert_array_equal(dense, lazy)
    np.testing.assert_array_equal(pc.replay_weights(np.array([3, 4])), pc.replay_weights()[[3, 4]])


# ------------------------------------------------------------------ the compiled kernels against plain NumPy
def learnt_place(n=60, steps=300, seed=5):
    """Place cells whose W_pp has been learnt on a random walk of a few active cells at a time."""
    pc = make_place(n=n, n_bvc=16)
    rng = np.random.default_rng(seed)
    for _ in range(steps):
        v = np.zeros(n)
        v[rng.choice(n, 3, replace=False)] = rng.uniform(0.1, 0.9, 3)
        drive(pc, [v], rng.uniform(-np.pi, np.pi))
    return pc, rng


def test_bvc_drive_is_the_float64_product_to_float32_precision():
    pc = make_place(n=300, n_bvc=400)
    rng = np.random.default_rng(2)
    pc.W_pb = rng.uniform(0, 1, (300, 400)) * (rng.random((300, 400)) < 0.4)
    b = rng.uniform(0, 0.5, 400) * (rng.random(400) < 0.55)  # about half the BVCs silent, as in a scan
    Wb, b_sum = pc._bvc_drive(b)
    np.testing.assert_allclose(Wb, pc.W_pb.astype(np.float64) @ b, rtol=1e-5)
    assert b_sum == pytest.approx(b.sum(), rel=1e-12)
    assert pc.W_pb.shape == (300, 400) and pc.W_bp.flags.c_contiguous  # stored BVC-first, read as (place, BVC)


@pytest.mark.parametrize("n_firing", [0, 1, 7, 8, 399])
def test_bvc_drive_sums_row_after_row_in_float32(n_firing):
    n = 4101
    rng = np.random.default_rng(n_firing)
    W_bp = (rng.uniform(0, 1, (400, n)) * (rng.random((400, n)) < 0.4)).astype(np.float32)
    b = np.zeros(400)
    b[rng.choice(400, n_firing, replace=False)] = rng.uniform(0.01, 0.5, n_firing)
    expected = np.zeros(n, dtype=np.float32)
    for c in np.flatnonzero(b > 0):  # one firing row at a time, in BVC order, as one float32 sum per cell
        expected += W_bp[c] * np.float32(b[c])
    out = np.empty(n)
    assert _kernels.bvc_drive(W_bp, b, out) == pytest.approx(b.sum(), rel=1e-12)
    assert np.array_equal(out, expected)


def test_imagined_values_equal_eq_8_and_9_on_the_full_tensor():
    pc, rng = learnt_place()
    rc = RewardCells(pc.n)
    rc.add_goal()
    rc.W_rp[0] = rng.uniform(0, 1, pc.n)
    rc.reset_effective()
    for _ in range(5):
        v = np.zeros(pc.n)
        v[rng.choice(pc.n, 4, replace=False)] = [0.9, 0.5, 0.1, 0.01]
        # eq. 8 from the dense slices W^pp_k (post, pre), then eq. 9
        dense = np.stack([np.tanh(np.maximum(pc.W_pp_slice(k).astype(np.float64) @ v - v, 0.0)) for k in range(pc.n_hd)])
        np.testing.assert_allclose(pc.preplay(v), dense, rtol=1e-6, atol=1e-7)
        expected = (dense @ rc.W_eff) / np.where(dense.sum(axis=1) > 0, dense.sum(axis=1), 1.0)
        values = pc.imagined_values(rc.W_eff, v)
        np.testing.assert_allclose(values, expected, rtol=1e-6, atol=1e-9)
        # the rates imagine() gives, summed in slot order
        for value, rates in zip(values, pc.imagine(v)):
            num = total = 0.0
            for rate, weight in zip(rates.tolist(), rc.W_eff[pc.slot_cells].tolist()):
                if rate > 0.0:
                    num, total = num + weight * rate, total + rate
            assert value == (num / total if total > 0.0 else 0.0)


def test_replay_matches_algorithm_1_written_in_numpy():
    pc, rng = learnt_place(n=200, steps=30)
    M = pc.replay_weights().astype(np.float64)
    assert 0 < np.count_nonzero(M) < M.size / 2  # links and gaps both
    v = np.zeros(pc.n)
    v[rng.choice(pc.n, 3, replace=False)] = [0.8, 0.4, 0.1]
    v_bar, dW = v.copy(), np.zeros(pc.n)
    for t in range(20):  # Algorithm 1, dense
        dW += v_bar / v_bar.max() * np.exp(-t / 2.0)
        v_bar = np.tanh(np.maximum(v_bar + v_bar @ M, 0.0))
    np.testing.assert_allclose(replay(v, pc.replay_links, 20, 2.0), dW / dW.max(), rtol=1e-12)


def test_eq_10_heads_along_the_value_weighted_circular_mean():
    theta = 2 * np.pi * np.arange(8) / 8
    values = np.array([0.0, 0.2, 0.9, 0.3, 0.0, 0.0, 0.0, 0.1])
    heading, best = _kernels.circular_mean(values, np.cos(theta), np.sin(theta))
    assert heading == pytest.approx(math.atan2(values @ np.sin(theta), values @ np.cos(theta)), abs=1e-12)
    assert best == 0.9
    assert _kernels.circular_mean(np.array([0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0]), np.cos(theta), np.sin(theta))[0] == pytest.approx(
        3 * np.pi / 4
    )
