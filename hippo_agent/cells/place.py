"""Place cells (paper eqs. 3-8): BVC-driven rates, Oja learning, direction-specific recurrence."""

from __future__ import annotations

import numpy as np

from hippo_agent.cells import _kernels

__all__ = ["PlaceCells"]


class PlaceCells:
    """``n`` place cells driven by ``n_bvc`` boundary vector cells, with a ``W_pp`` tensor.

    State: membrane potentials ``s``, rates ``v`` (eqs. 3-4), the place-cell trace ``Upsilon_p``
    and head-direction trace ``Upsilon_h`` (eq. 6). Weights: ``W_pb`` (n, n_bvc) float32, learnt by
    Oja's rule (eq. 5), and the direction-specific recurrent tensor ``W^pp_{kij}`` (the synapse from
    place cell ``j`` to ``i`` on the branch for direction ``k``), zero at the start (eq. 7).

    ``W^pp`` is stored compactly: only cells that have taken part in eq. 7 (been active or traced
    on a learning step; many cells never fire) get a *slot*, and the weights live in a dense
    float32 block ``W_slots[slot_j, k, slot_i]`` over slots, pre-synaptic first, grown by
    doubling. Every other entry of the full tensor is exactly zero, so this is the full tensor,
    not an approximation, and its memory grows with the cells that learn rather than with N^2.
    Pre-synaptic-first storage makes everything the few active cells drive (preplay, replay) one
    contiguous row gather. :meth:`W_pp_slice` gives the paper's ``W^pp_k`` as a full
    ``(i, j)`` matrix and :attr:`W_pp` the full ``(j, k, i)`` tensor (copies, for analysis).

    Every update touches only the cells that matter: Oja only the rows of active cells (a silent
    cell's ``v_i = 0`` makes its eq.-5 update exactly zero), and eq. 7 only the entries with an
    active cell on one side and an active-or-traced cell on the other (``v_i Upsilon_j - v_j
    Upsilon_i`` is zero elsewhere). Traces below ``trace_floor`` are set to zero so those sets stay
    small.

    With the unrectified cosine head-direction code, ``h_{k+n_hd/2} = -h_k`` exactly, so eq. 7 makes
    the opposite slice learn the negative of slice ``k``; and since ``v Upsilon^T - Upsilon v^T`` is
    antisymmetric, each slice is antisymmetric too, hence ``W^pp_{k+n_hd/2} = (W^pp_k)^T``: moving
    east from j's field into i's also teaches "west from i leads to j". The max over directions
    used by replay, ``max_k W^pp_{kij} = max_k |W^pp_{kij}|``, is therefore symmetric, and replay
    spreads both ways along a path. This is the paper's model as written; we keep it.

    Besides the rates, the cells keep the response to their BVC input alone (``s_sense``,
    ``v_sense``): the same as the rates unless a faculty adds a drive of its own (path
    integration, :meth:`step_sense` and :meth:`step_driven`).

    Args (the keyword ones come from the agent's config, :meth:`hippo_agent.ModelConfig.place_kwargs`):
        n: number of place cells.
        n_bvc: number of BVC inputs.
        n_hd: number of head-direction cells (``W_pp`` slices).
        rng: the generator for the random binary ``W_pb``.
        k, Gamma_pb, Gamma_pp, psi: eq. 3-4 constants.
        p_pb: probability that an initial ``W_pb`` weight is 1.
        eta_pb, alpha_pb: eq. 5 rate and normaliser.
        trace_rate, hd_trace_rate, trace_floor: eq. 6 trace rates and floor.
        eta_pp: eq. 7 rate.
    """

    W_bp: np.ndarray  # the BVC -> place weights, BVC-first (set through :attr:`W_pb`)

    def __init__(
        self,
        n: int,
        n_bvc: int,
        n_hd: int,
        rng: np.random.Generator,
        *,
        k: float,
        Gamma_pb: float,
        Gamma_pp: float,
        psi: float,
        p_pb: float,
        eta_pb: float,
        alpha_pb: float,
        trace_rate: float,
        hd_trace_rate: float,
        trace_floor: float,
        eta_pp: float,
    ) -> None:
        self.n, self.n_bvc, self.n_hd = int(n), int(n_bvc), int(n_hd)
        self.k, self.Gamma_pb, self.Gamma_pp, self.psi = k, Gamma_pb, Gamma_pp, psi
        self.eta_pb, self.alpha_pb = eta_pb, alpha_pb
        self.trace_rate, self.hd_trace_rate, self.trace_floor = trace_rate, hd_trace_rate, trace_floor
        self.eta_pp = eta_pp
        self.p_pb = p_pb
        # W_pb(0) binary, 1 with probability p_pb (paper, eq. 5)
        self.W_pb = (rng.random((self.n, self.n_bvc)) < p_pb).astype(np.float32)
        # W_pp(0) = 0 (eq. 7): no slots yet
        self.slot = np.full(self.n, -1, dtype=np.int64)  # cell -> slot (-1: none, its W_pp is all 0)
        self.slot_cells = np.zeros(0, dtype=np.int64)  # slot -> cell
        self.W_slots = np.zeros((0, self.n_hd, 0), dtype=np.float32)
        self.s = np.zeros(self.n)
        self.v = np.zeros(self.n)
        self.trace = np.zeros(self.n)  # Upsilon^p
        self.hd_trace = np.zeros(self.n_hd)  # Upsilon^h
        # the response to the BVC input alone (what the boundary code says, without a faculty's drive)
        self.s_sense = np.zeros(self.n)
        self.v_sense = np.zeros(self.n)
        self._drive: tuple[np.ndarray, float] | None = None  # this step's W_pb b and sum(b), from step_sense
        # a step's W_pb b and extra drive (scratch, resized when cells are recruited)
        self._step_drive, self._extra_drive = np.empty(self.n), np.empty(self.n)

    def grow(self, extra: int, rng: np.random.Generator) -> None:
        """Recruit ``extra`` new cells: binary ``W_pb`` rows as at the start (eq. 5), everything
        else zero (no ``W_pp`` slot), at rest."""
        new_rows = (rng.random((extra, self.n_bvc)) < self.p_pb).astype(np.float32)
        self.W_bp = np.ascontiguousarray(np.concatenate([self.W_bp, new_rows.T], axis=1))
        self.n += int(extra)

        def longer(a: np.ndarray, fill: float = 0.0) -> np.ndarray:
            return np.concatenate([a, np.full((extra, *a.shape[1:]), fill, dtype=a.dtype)])

        self.slot = longer(self.slot, -1)
        for name in ("s", "v", "trace", "s_sense", "v_sense"):
            setattr(self, name, longer(getattr(self, name)))

    @property
    def W_pb(self) -> np.ndarray:
        """The BVC -> place weights, ``(n, n_bvc)`` float32: a view of :attr:`W_bp`, which stores them
        BVC-first so that a step reads only the rows of the BVCs that fire (about half)."""
        return self.W_bp.T

    @W_pb.setter
    def W_pb(self, value: np.ndarray) -> None:
        self.W_bp = np.ascontiguousarray(np.asarray(value, dtype=np.float32).T)

    # ------------------------------------------------------------------ state
    def reset_state(self) -> None:
        """Rest: zero potentials, rates and traces (weights kept)."""
        self.s = np.zeros(self.n)
        self.v = np.zeros(self.n)
        self.trace = np.zeros(self.n)
        self.hd_trace = np.zeros(self.n_hd)
        self.s_sense = np.zeros(self.n)
        self.v_sense = np.zeros(self.n)

    def _bvc_drive(self, b: np.ndarray) -> tuple[np.ndarray, float]:
        """``W_pb b`` (summed over the BVCs that fire) and ``sum(b)``."""
        Wb = np.empty(self.n)
        return Wb, _kernels.bvc_drive(self.W_bp, np.asarray(b, dtype=np.float64), Wb)

    def _advance(
        self, s: np.ndarray, v: np.ndarray, Wb: np.ndarray, b_sum: float, extra: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """One eq.-3/4 update given ``W_pb b``, ``sum(b)`` and an optional extra input (path integration)."""
        # eq. 3 (Euler step, k = dt / tau_p): s += k (-s + W_pb b - Gamma_pb sum(b) - Gamma_pp sum(v) [+ extra]); eq. 4
        s_new, v_new = np.empty(self.n), np.empty(self.n)
        has_extra = extra is not None
        _kernels.advance(
            s, v, Wb, self.Gamma_pb * b_sum, self.Gamma_pp, extra if has_extra else s, has_extra, self.k, self.psi, s_new, v_new
        )
        return s_new, v_new

    def step(self, b: np.ndarray, n_steps: int = 1) -> np.ndarray:
        """Advance eqs. 3-4 by ``n_steps`` updates with BVC rates ``b``; return the rates."""
        Wb, b_sum = self._bvc_drive(b)
        for _ in range(n_steps):
            self.s, self.v = self._advance(self.s, self.v, Wb, b_sum)
        return self.v

    def step_sense(self, b: np.ndarray) -> None:
        """One update of the response to the BVC rates ``b`` alone (``s_sense``, ``v_sense``);
        :meth:`step_driven` then updates the rates with the same ``b``."""
        if self._step_drive.size != self.n:
            self._step_drive, self._extra_drive = np.empty(self.n), np.empty(self.n)
        Wb, s, v = self._step_drive, np.empty(self.n), np.empty(self.n)
        b_sum = _kernels.sense_step(
            self.W_bp, np.asarray(b, dtype=np.float64), self.Gamma_pb, self.Gamma_pp, self.k, self.psi, self.s_sense, self.v_sense, Wb, s, v
        )
        self._drive = Wb, b_sum
        self.s_sense, self.v_sense = s, v

    def step_driven(self, extra: np.ndarray | None) -> None:
        """One update of the rates with the BVC rates given to :meth:`step_sense` and the extra
        drive ``extra``; ``None``: no extra drive, the rates are the BVC-only response."""
        if extra is None:
            self.s, self.v = self.s_sense.copy(), self.v_sense.copy()
        else:
            assert self._drive is not None, "step_sense comes first"
            self.s, self.v = self._advance(self.s, self.v, *self._drive, extra)

    def step_driven_by_centres(
        self,
        centres: np.ndarray,
        centre_mass: np.ndarray,
        position: np.ndarray,
        constants: tuple[float, float, float, float, float, float],
    ) -> None:
        """:meth:`step_driven` with the extra drive of cells with centres round ``position``, as
        :meth:`PathIntegrator.drive <hippo_agent.faculties.path_integration.PathIntegrator.drive>`
        gives it (``constants`` are :func:`_kernels.centre_drive`'s after the position): the drive
        and the update in one compiled call."""
        assert self._drive is not None, "step_sense comes first"
        Wb, b_sum = self._drive
        s, v, extra = np.empty(self.n), np.empty(self.n), self._extra_drive
        _kernels.centre_driven_advance(
            self.s, self.v, Wb, self.Gamma_pb * b_sum, self.Gamma_pp, self.k, self.psi, centres, centre_mass, position, constants,
            extra, s, v,
        )  # fmt: skip
        self.s, self.v = s, v

    def settle_sense(self, b: np.ndarray, n_steps: int) -> None:
        """``n_steps`` updates of the BVC-only response with ``b``; the rates then equal it."""
        Wb, b_sum = self._bvc_drive(b)
        for _ in range(n_steps):
            self.s_sense, self.v_sense = self._advance(self.s_sense, self.v_sense, Wb, b_sum)
        self.s, self.v = self.s_sense.copy(), self.v_sense.copy()

    def settle(self, b: np.ndarray, extra: np.ndarray | None, n_steps: int) -> np.ndarray:
        """Rates from rest after ``n_steps`` updates with ``b`` and the extra drive (the BVC-only
        response is left as it is)."""
        self.s, self.v = np.zeros(self.n), np.zeros(self.n)
        Wb, b_sum = self._bvc_drive(b)
        for _ in range(n_steps):
            self.s, self.v = self._advance(self.s, self.v, Wb, b_sum, extra)
        return self.v

    def rates_for(self, b: np.ndarray, n_steps: int, extra: np.ndarray | None = None) -> np.ndarray:
        """Rates after ``n_steps`` updates from rest with input ``b`` (and ``extra``); the state is not touched."""
        s, v = np.zeros(self.n), np.zeros(self.n)
        Wb, b_sum = self._bvc_drive(b)
        for _ in range(n_steps):
            s, v = self._advance(s, v, Wb, b_sum, extra)
        return v

    # ------------------------------------------------------------------ learning
    def learn_pb(self, b: np.ndarray) -> None:
        """Oja's rule (eq. 5) on the rows of the active cells only."""
        # eq. 5: W_i += eta_pb v_i (b - v_i W_i / alpha_pb), in float64 per active row i; weights decayed
        # below 1e-12 are flushed to 0 before they become slow denormal float32s
        _kernels.oja_active_rows(self.W_bp, self.v, np.asarray(b, dtype=np.float64), self.eta_pb, self.alpha_pb)

    def learn(self, b: np.ndarray, h: np.ndarray, trusted: bool, pp: bool) -> None:
        """A step's learning in one compiled call: Oja's rule (eq. 5, :meth:`learn_pb`) if
        ``trusted``; the head-direction trace (:meth:`update_hd_trace`); eq. 7 (:meth:`learn_pp`)
        if ``pp``; the place-cell trace (:meth:`update_trace`) if ``trusted``, else the trace set
        to 0 (an untrusted code is not traced)."""
        if _kernels.learn_step(
            self.W_bp, self.v, np.asarray(b, dtype=np.float64), self.eta_pb, self.alpha_pb, self.hd_trace, h, self.hd_trace_rate,
            self.W_slots, self.slot, self.trace, self.eta_pp, self.trace_rate, self.trace_floor, trusted, pp,
        ):  # fmt: skip
            # eq. 7 reached cells holding no slot yet (nothing of it done): give them slots, then eq. 7 and the trace
            self.learn_pp()
            self.update_trace()

    def update_hd_trace(self, h: np.ndarray) -> None:
        """Move the head-direction trace Upsilon^h toward ``h`` (eq. 6c)."""
        _kernels.update_trace(self.hd_trace, h, self.hd_trace_rate, -np.inf)  # eq. 6 (no floor)

    def update_trace(self) -> None:
        """Move the place-cell trace Upsilon^p toward the rates (eqs. 6a-b), flooring tiny values."""
        _kernels.update_trace(self.trace, self.v, self.trace_rate, self.trace_floor)  # eq. 6

    @property
    def n_slots(self) -> int:
        """Number of cells holding ``W_pp`` slots."""
        return int(self.slot_cells.size)

    def _ensure_slots(self, cells: np.ndarray) -> np.ndarray:
        """Give slots to the cells that lack one (growing the block by doubling); return their slots."""
        new = cells[self.slot[cells] < 0]
        if new.size:
            used = self.n_slots
            need = used + new.size
            cap = self.W_slots.shape[0]
            if need > cap:
                cap = min(self.n, max(need, 2 * cap, 64))
                grown = np.zeros((cap, self.n_hd, cap), dtype=np.float32)
                grown[:used, :, :used] = self.W_slots[:used, :, :used]
                self.W_slots = grown
            self.slot[new] = np.arange(used, need)
            self.slot_cells = np.concatenate([self.slot_cells, new])
        return self.slot[cells]

    def learn_pp(self) -> None:
        """Eq. 7 with the current rates, the current traces and Upsilon^h.

        ``dW^pp_{kij} = eta_pp Upsilon^h_k (v_i Upsilon_j - v_j Upsilon_i)``, applied to the two blocks
        where it can be nonzero: post-synaptic ``i`` active (any traced or active ``j``), and
        pre-synaptic ``j`` active (the other ``i``).
        """
        if _kernels.pp_update(self.W_slots, self.slot, self.v, self.trace, self.eta_pp, self.hd_trace):  # eq. 7
            # some of the cells it touches hold no slot yet: give them one and update
            self._ensure_slots(np.flatnonzero((self.v > 0.0) | (self.trace > 0.0)))
            _kernels.pp_update(self.W_slots, self.slot, self.v, self.trace, self.eta_pp, self.hd_trace)

    def set_W_pp(self, pre: int, post: int, weights: np.ndarray) -> None:
        """Set ``W^pp_{k, post, pre}`` for every direction ``k`` (for tests and experiments)."""
        s = self._ensure_slots(np.array([pre, post], dtype=np.int64))
        self.W_slots[s[0], :, s[1]] = np.asarray(weights, dtype=np.float32)

    def load_W_pp(self, slot_cells: np.ndarray, W_slots: np.ndarray) -> None:
        """Restore the compact ``W_pp`` (as saved: the cells holding slots and their block)."""
        slot_cells = np.asarray(slot_cells, dtype=np.int64)
        m = slot_cells.size
        if (
            slot_cells.ndim != 1
            or W_slots.shape != (m, self.n_hd, m)
            or (m and (slot_cells.min() < 0 or slot_cells.max() >= self.n))
            or np.unique(slot_cells).size != m
        ):
            raise ValueError(
                f"W_pp slots {W_slots.shape} for {slot_cells.shape} cells do not fit {self.n} cells and {self.n_hd} directions"
            )
        self.slot = np.full(self.n, -1, dtype=np.int64)
        self.slot[slot_cells] = np.arange(m)
        self.slot_cells = slot_cells.copy()
        self.W_slots = np.ascontiguousarray(W_slots, dtype=np.float32)

    @property
    def W_pp_used(self) -> np.ndarray:
        """The used part of the slot block, ``(n_slots, n_hd, n_slots)`` (a view)."""
        m = self.n_slots
        return self.W_slots[:m, :, :m]

    @property
    def W_pp(self) -> np.ndarray:
        """The full tensor as ``W_pp[j, k, i] = W^pp_{kij}``, shape ``(n, n_hd, n)`` (a dense copy)."""
        full = np.zeros((self.n, self.n_hd, self.n), dtype=np.float32)
        c = self.slot_cells
        full[c[:, None], :, c[None, :]] = self.W_pp_used.transpose(0, 2, 1)
        return full

    def W_pp_slice(self, k: int) -> np.ndarray:
        """The paper's ``W^pp_k`` as an ``(n_post, n_pre)`` matrix (a copy)."""
        out = np.zeros((self.n, self.n), dtype=np.float32)
        c = self.slot_cells
        out[c[:, None], c[None, :]] = self.W_pp_used[:, k, :].T
        return out

    # ------------------------------------------------------------------ imagination
    def imagine(self, v: np.ndarray | None = None) -> np.ndarray:
        """Eq. 8 for the cells holding slots: their imagined rates one step away in each direction,
        shape ``(n_hd, n_slots)``, in the order of :attr:`slot_cells`. Every other cell's is 0."""
        v = np.asarray(self.v if v is None else v, dtype=np.float64)
        out = np.empty((self.n_hd, self.n_slots))
        _kernels.imagined_rates(self.W_slots, self.slot, self.slot_cells, v, out)
        return out

    def imagined_values(self, W: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """Eq. 9 of the imagined rates (eq. 8): the rate one step away in each direction, shape
        ``(n_hd,)``, of a reward cell with weights ``W`` (one per place cell)."""
        v = np.asarray(self.v if v is None else v, dtype=np.float64)
        values = np.empty(self.n_hd)
        _kernels.imagined_values(self.W_slots, self.slot, self.slot_cells, v, np.asarray(W, dtype=np.float64), values)
        return values

    def preplay(self, v: np.ndarray | None = None) -> np.ndarray:
        """Imagined rates one step away in each direction (eq. 8), shape ``(n_hd, n)``."""
        x = np.zeros((self.n_hd, self.n))
        x[:, self.slot_cells] = self.imagine(v)
        return x

    def replay_links(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The nonzero entries of the rows ``rows`` (pre-synaptic cells) of ``M[j, i] = max_k
        W^pp_{kij}``, what replay spreads along (Algorithm 1): per row their count, then their
        columns (post-synaptic cells) and float32 values, row after row."""
        return _kernels.max_over_directions(self.W_slots, self.slot, self.slot_cells, np.asarray(rows, dtype=np.int64))

    def replay_weights(self, rows: np.ndarray | None = None) -> np.ndarray:
        """``M[j, i] = max_k W^pp_{kij}`` as dense rows (pre-synaptic first; ``rows`` selects
        pre-synaptic cells, ``None`` = all), for analysis: ``v_bar @ M`` is replay's recurrent drive."""
        rows = np.arange(self.n) if rows is None else np.asarray(rows, dtype=np.int64)
        counts, targets, weights = self.replay_links(rows)
        out = np.zeros((rows.size, self.n), dtype=np.float32)
        out[np.repeat(np.arange(rows.size), counts), targets] = weights
        return out
