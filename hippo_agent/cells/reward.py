"""Reward cells (paper eqs. 9, 11 and Algorithm 1): one cell per goal, weights from replay."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hippo_agent.cells import _kernels

__all__ = ["RewardCells", "replay"]


Links = tuple[np.ndarray, np.ndarray, np.ndarray]  # per row the count of nonzero entries, then their columns and values


def replay(
    v: np.ndarray,
    W_max: np.ndarray | Callable[[np.ndarray], Links],
    iterations: int,
    tau_r: float,
) -> np.ndarray | None:
    """Backward replay (Algorithm 1) from place rates ``v``; return the normalised ``Delta W_rp``.

    ``W_max[j, i] = max_k W^pp_{kij}`` (pre-synaptic first), either as an ``(n, n)`` array or as a
    function giving the nonzero entries of the rows of given pre-synaptic cells, as
    :meth:`PlaceCells.replay_links` does. Only the rows of the cells replay reaches are read, once
    each, and only their nonzero entries (a cell links to the few cells it was active next to) are
    kept: an iteration costs the links of the active cells, not ``n`` per active cell.
    Returns ``None`` when there is nothing to learn (no place cell active at the start: the
    division by ``||v||_inf`` would be 0/0).
    """
    v_bar = np.asarray(v, dtype=np.float64).copy()
    if not np.any(v_bar > 0.0):
        return None
    n = v_bar.size
    links = _LinkStore(n, W_max if callable(W_max) else _dense_links(W_max))
    dW = np.zeros_like(v_bar)
    for t_r in range(iterations):
        dW += v_bar / v_bar.max() * np.exp(-t_r / tau_r)  # Algorithm 1, line 3
        active = np.flatnonzero(v_bar > 0.0)
        links.fetch(active)
        spread = np.zeros(n)  # sum_l (max_k W^pp_{kjl}) v_bar_l
        _kernels.spread_along(v_bar, active, links.start, links.count, links.target, links.weight, spread)
        v_bar = np.tanh(np.maximum(v_bar + spread, 0.0))  # Algorithm 1, line 4
        if not np.any(v_bar > 0.0):
            break
    return dW / dW.max()  # Algorithm 1, line 6 (dW.max() >= 1: iteration 0 adds v/max v)


def _dense_links(W: np.ndarray) -> Callable[[np.ndarray], Links]:
    """The nonzero entries of given rows of a dense ``W``."""

    def links_of(rows: np.ndarray) -> Links:
        r, c = np.nonzero(W[rows])
        return np.bincount(r, minlength=rows.size), c, W[rows[r], c]

    return links_of


class _LinkStore:
    """The links of the cells fetched so far: for cell ``j``, ``target[start[j] : start[j] +
    count[j]]`` with weights ``weight[...]`` (float64); ``start`` is -1 until fetched."""

    def __init__(self, n: int, links_of: Callable[[np.ndarray], Links]) -> None:
        self.links_of = links_of
        self.start = np.full(n, -1, dtype=np.int64)
        self.count = np.zeros(n, dtype=np.int64)
        self.target = np.empty(0, dtype=np.int64)
        self.weight = np.empty(0)

    def fetch(self, cells: np.ndarray) -> None:
        """Read the links of the ``cells`` not fetched yet."""
        need = cells[self.start[cells] < 0]
        if need.size == 0:
            return
        counts, targets, weights = self.links_of(need)
        self.start[need] = self.target.size + np.cumsum(counts) - counts
        self.count[need] = counts
        self.target = np.concatenate((self.target, targets))
        self.weight = np.concatenate((self.weight, np.asarray(weights, dtype=np.float64)))


class RewardCells:
    """Reward cells, one per goal, each reading out the place cells through a row of ``W_rp``.

    A new cell (row of zeros) is added by :meth:`add_goal`; the last one is the current goal's.
    ``W_eff`` is the effective copy ``\\bar W^rp`` of the current goal's row that eq. 11 depresses
    during an exploiting run; :meth:`reset_effective` restores it from ``W_rp``.

    Args:
        n_place: number of place cells.
    """

    def __init__(self, n_place: int) -> None:
        self.n_place = int(n_place)
        self.W_rp = np.zeros((0, self.n_place))
        self.W_eff = np.zeros(self.n_place)

    @property
    def n(self) -> int:
        """Number of reward cells (goals seen)."""
        return self.W_rp.shape[0]

    @property
    def current(self) -> int:
        """Index of the current goal's cell (``-1`` if none)."""
        return self.n - 1

    def grow(self, extra: int) -> None:
        """Room for ``extra`` more place cells, with zero weights."""
        self.n_place += int(extra)
        self.W_rp = np.concatenate([self.W_rp, np.zeros((self.n, extra))], axis=1)
        self.W_eff = np.concatenate([self.W_eff, np.zeros(extra)])

    def add_goal(self) -> int:
        """Add a reward cell for a new goal; return its index."""
        self.W_rp = np.vstack([self.W_rp, np.zeros((1, self.n_place))])
        self.reset_effective()
        return self.current

    def reset_effective(self) -> None:
        """Start a run: ``\\bar W^rp <- W^rp`` for the current goal."""
        self.W_eff = self.W_rp[-1].copy() if self.n else np.zeros(self.n_place)

    def learn(self, v: np.ndarray, W_max: np.ndarray | Callable[[np.ndarray], Links], iterations: int, tau_r: float) -> bool:
        """Replay from ``v`` and add the result to the current goal's weights (Algorithm 1).

        Returns ``False`` (and learns nothing) when no place cell is active.
        """
        if self.n == 0:
            self.add_goal()
        dW = replay(v, W_max, iterations, tau_r)
        if dW is None:
            return False
        self.W_rp[-1] += dW  # Algorithm 1, line 6: W_rp += dW / ||dW||_inf
        self.reset_effective()
        return True

    def forget_current(self) -> None:
        """Forget the current goal's reward map."""
        if self.n:
            self.W_rp[-1] = 0.0
            self.reset_effective()

    def value(self, v: np.ndarray, W: np.ndarray | None = None) -> np.ndarray | float:
        """Reward-cell rate for place rates ``v`` (eq. 9): ``W v / sum v``; 0 where ``sum v = 0``.

        ``v`` may be one rate vector ``(n,)`` (returns a float) or a stack ``(m, n)`` (returns one
        value each); ``W`` defaults to the effective weights ``W_eff``.
        """
        W = self.W_eff if W is None else W
        if v.ndim == 1:
            return _kernels.value(np.asarray(v, dtype=np.float64), np.asarray(W, dtype=np.float64))  # eq. 9
        total = v.sum(axis=1)
        out = v @ W
        _kernels.divide_where_positive(out, total)  # eq. 9
        return out

    def depress(self, v: np.ndarray, lambda_: float) -> None:
        """Depress the effective weights of the active cells (eq. 11)."""
        _kernels.depress(self.W_eff, np.asarray(v, dtype=np.float64), float(lambda_))  # eq. 11: W_eff -= lambda W_eff v
