"""Head-direction cells (paper eq. 1): cosine tuning to the allocentric heading, not rectified."""

from __future__ import annotations

import numpy as np

from hippo_agent.cells import _kernels

__all__ = ["HeadDirectionCells"]


class HeadDirectionCells:
    """``n`` head-direction cells with preferred directions ``theta_k = 2*pi*k/n``.

    Eq. 1 (Erdem & Hasselmo) projects the unit heading vector onto each preferred direction,
    ``v^h_k = cos(heading - theta_k)``: a cosine that goes negative behind the cell. It is kept
    unrectified, as in the reference implementation. Because ``n`` is even, cell ``k + n/2`` is
    always exactly ``-v^h_k``.

    Args:
        n: number of cells (even).
    """

    def __init__(self, n: int) -> None:
        if n < 1:
            raise ValueError(f"n={n} head-direction cells is invalid; allowed: an integer >= 1")
        self.n = int(n)
        self.preferred = 2.0 * np.pi * np.arange(self.n) / self.n
        self.cos_preferred = np.cos(self.preferred)  # (eq. 1's rates are the heading's projections on these)
        self.sin_preferred = np.sin(self.preferred)
        self.rates = np.zeros(self.n)

    def rates_for(self, heading_vec: np.ndarray) -> np.ndarray:
        """Rates for a heading given as ``(cos, sin)`` (need not be unit length), without updating."""
        # eq. 1: v^h_k = <unit heading, (cos theta_k, sin theta_k)> = cos(heading - theta_k)
        rates = np.empty(self.n)
        if _kernels.hd_rates(float(heading_vec[0]), float(heading_vec[1]), self.cos_preferred, self.sin_preferred, rates) == 0.0:
            raise ValueError("heading vector (0, 0) has no direction")
        return rates

    def update(self, heading_vec: np.ndarray) -> np.ndarray:
        """Set and return the rates for the heading ``(cos, sin)``."""
        self.rates = self.rates_for(heading_vec)
        return self.rates
