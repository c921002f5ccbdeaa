"""Boundary vector cells (paper eq. 2, after Barry et al. 2006) driven by a rangefinder scan."""

from __future__ import annotations

import math

import numpy as np

from hippo_agent.cells import _kernels

__all__ = ["BoundaryVectorCells"]

TINY = 1e-12  # rates below this (1e-12 of the peak rate's scale) are exactly 0


class BoundaryVectorCells:
    """A grid of BVCs: ``n_directions`` allocentric directions x ``n_distances`` preferred distances.

    Cell ``(d, m)`` (flat index ``d * n_distances + m``) prefers a boundary at allocentric direction
    ``phi_d = 2*pi*d/n_directions`` and distance ``d_m = linspace(0, max_distance, n_distances)[m]``.
    Its rate sums eq. 2 over the rays of the scan, each ray a boundary element at ``(r, theta)``
    subtending ``delta_theta = 2*pi/n_rays``::

        v^b_i = c * sum_rays G(r - d_i; sigma_r(d_i)) * G(theta - phi_i; sigma_theta) * delta_theta

    with ``G`` the normalised Gaussian. Only the rays within ``angular_cutoff * sigma_theta`` of
    ``phi_i`` are summed (their angular weights are precomputed per direction). ``c`` is one
    constant for all cells, chosen so the largest possible response, a boundary at exactly the
    preferred distance across the whole angular window of the most sharply tuned cell, equals
    ``peak_rate``.

    The scan is egocentric (``ranges[i]`` along ``heading + 2*pi*i/n_rays``); it is made allocentric
    by shifting ray indices by the heading, rounded to the nearest ray (at most half a ray,
    0.25 deg at 720 rays).

    Args (the keyword ones come from the agent's config, :meth:`hippo_agent.ModelConfig.bvc_kwargs`):
        n_rays: rays per scan.
        max_range: the rangefinder's maximum range (m).
        n_directions: preferred directions.
        n_distances: preferred distances.
        max_distance: largest preferred distance (m); ``None`` = ``max_range``.
        sigma_r: radial width (m), the same at every distance.
        sigma_theta: angular width (radians).
        angular_cutoff: rays beyond this many ``sigma_theta`` are left out.
        peak_rate: the largest possible response.

    Rays at ``max_range`` have hit nothing: they are not boundaries and drive no cell.
    """

    def __init__(
        self,
        n_rays: int,
        max_range: float,
        *,
        n_directions: int,
        n_distances: int,
        max_distance: float | None,
        sigma_r: float,
        sigma_theta: float,
        angular_cutoff: float,
        peak_rate: float,
    ) -> None:
        if n_rays < 1:
            raise ValueError(f"n_rays={n_rays} is invalid; allowed: an integer >= 1")
        if not (max_range > 0 and math.isfinite(max_range)):
            raise ValueError(f"max_range={max_range} is invalid; allowed: a finite value > 0")
        self.n_rays = int(n_rays)
        self.max_range = float(max_range)
        self.n_directions = int(n_directions)
        self.n_distances = int(n_distances)
        self.n = self.n_directions * self.n_distances
        max_distance = self.max_range if max_distance is None else float(max_distance)

        self.directions = 2.0 * np.pi * np.arange(self.n_directions) / self.n_directions
        self.distances = np.linspace(0.0, max_distance, self.n_distances)
        self.sigma_r = np.full(self.n_distances, float(sigma_r))
        self._inv_two_var_r = 1.0 / (2.0 * self.sigma_r**2)
        self._norm_r = 1.0 / np.sqrt(2.0 * np.pi * self.sigma_r**2)

        # Angular weights per direction, precomputed on the ray grid.
        dtheta = 2.0 * np.pi / self.n_rays
        half = math.floor(angular_cutoff * sigma_theta / dtheta)
        half = min(half, (self.n_rays - 1) // 2)  # never count a ray twice
        offsets = np.arange(-half, half + 1)
        centre = np.rint(self.directions / dtheta).astype(np.int64)  # (D,)
        alloc_idx = centre[:, None] + offsets[None, :]  # (D, W)
        angle_off = alloc_idx * dtheta - self.directions[:, None]
        self._alloc_idx = np.mod(alloc_idx, self.n_rays)
        w = np.exp(-(angle_off**2) / (2.0 * sigma_theta**2)) / math.sqrt(2.0 * np.pi * sigma_theta**2)
        self._ang_w = w * dtheta  # (D, W): G(theta - phi) * delta_theta
        self._dtheta = dtheta

        # Largest possible response: boundary at the preferred distance over the whole window.
        peak = self._norm_r[None, :] * self._ang_w.sum(axis=1)[:, None]  # (D, M)
        self._scale = float(peak_rate / peak.max())
        self._coef = self._scale * self._norm_r  # (M,)
        self.rates = np.zeros(self.n)
        self._w = np.empty(self._ang_w.shape)  # scratch: the scan's angular weights
        # scratch: eq. 2's radial Gaussians, in float32 (the place cells read the rates in float32; NumPy's
        # exp of these 5,200 values then takes 2.9 instead of 4.6 us)
        self._g = np.empty((*self._ang_w.shape, self.n_distances), dtype=np.float32)

    @property
    def preferred(self) -> tuple[np.ndarray, np.ndarray]:
        """(direction, distance) of every cell, flat order, each of shape ``(n,)``."""
        d = np.repeat(self.directions, self.n_distances)
        m = np.tile(self.distances, self.n_directions)
        return d, m

    def heading_shift(self, heading: float) -> int:
        """Rays by which the egocentric scan is rotated: ``round(heading / delta_theta)``."""
        return round(heading / self._dtheta)  # (half to even, as np.rint)

    def rates_for(self, ranges: np.ndarray, heading: float) -> np.ndarray:
        """BVC rates for an egocentric scan and an allocentric heading (radians), without updating.

        Returns an array of shape ``(n_directions * n_distances,)``.
        """
        if ranges.shape != (self.n_rays,):
            raise ValueError(f"ranges has shape {ranges.shape}; expected ({self.n_rays},) as set by n_rays")
        # allocentric ray j is egocentric ray j - shift (the scan rolled by the heading)
        w, g = self._w, self._g
        _kernels.bvc_exponents(
            ranges,
            self._alloc_idx,
            self.heading_shift(heading),
            self._ang_w,
            self.max_range,
            True,  # rays that hit nothing are not boundaries
            self.distances,
            self._inv_two_var_r,
            w,
            g,
        )
        np.exp(g, out=g)
        # eq. 2: sum over rays of G(r - d_i; sigma_r) * G(theta - phi_i; sigma_theta) * dtheta; the Gaussian's far
        # tail (below TINY) is flushed to 0: denormal float32s slow every product
        out = np.empty(self.n)
        _kernels.bvc_sum(w, g, self._coef, TINY, out)
        return out

    def update(self, ranges: np.ndarray, heading: float) -> np.ndarray:
        """Set and return the rates for a scan (see :meth:`rates_for`)."""
        self.rates = self.rates_for(ranges, heading)
        return self.rates
