"""Path integration: where the robot is in its own frame, from odometry, anchored by the place code.

The paper's robot has only its rangefinder and compass, and its boundary-vector place code gives
distant places that look alike the same cells. Animals also integrate their self-motion; this
module adds that input, as the improved model's extension of the paper (off in
``AgentConfig.paper()``).

The estimate lives in a self-centred frame: the origin is where the agent first stood, the axes
are the compass's. Each step it moves by the odometry (the wheel encoders' displacement rotated
by the compass heading). The belief is a set of weighted samples (a particle filter: a sampled
stand-in for the activity packet of a continuous-attractor path integrator), so that after the
robot is picked up and put down elsewhere (a new run) several candidate places can be held at
once until the senses single one out.

The senses enter through the place cells: each cell keeps the position, in this frame, where it
fires (its *centre*, a rate-weighted running mean: the place -> path-integration synapses). The
boundary-vector code alone (the place cells' response with the path-integration input left out)
then votes for positions: a sample near the centres of the active cells is likely, one far from
all of them is not. That vote

- *anchors* the estimate at the start of a run: samples are drawn around the voted centres until
  one cluster holds most of the weight; and
- *corrects* it on every later step, so odometry noise never accumulates: samples spread by the
  odometry's noise and are re-weighted by the vote.

Args (the keyword ones come from the agent's config, :meth:`hippo_agent.AgentConfig.path_integrator_kwargs`):
    n_particles: number of samples.
    rng: the agent's generator.
    motion_noise: spread added to each sample per step, as a fraction of the distance moved,
        plus ``min_motion_noise`` metres.
    vote_sigma: width (m) of each active cell's vote around its centre.
    anchor_radius: samples within this distance (m) of the best one form its cluster.
    anchor_weight: the cluster's share of the weight at which a lost estimate counts as anchored.
    redraw_fraction: while lost, this share of the samples is drawn afresh from the vote each step.
    lost_vote_floor: while lost, the vote's floor (``None``: ``vote_floor``, as once anchored): a
        higher one makes the vote weaker evidence, so that places it does not propose but a map
        fits can win.
    proposal_share: while lost, this share of the redrawn samples comes from :meth:`correct`'s
        ``proposals`` (when given) instead of the vote.
    collapse_on_anchor: on anchoring, drop the samples outside the anchored cluster
        (:meth:`_keep_cluster`).
    rule_out_radius: when the estimate is found wrong (:meth:`lose` with ``rule_out``), samples
        within this distance (m) of where it was, carried along by the odometry, are weighed down
        until the estimate is anchored again (0 = off).
    min_anchor_steps: a lost estimate is not anchored before this many corrections, so that
        evidence that accumulates (a map's fit, :meth:`correct`'s ``likelihood``) can single out
        one of several look-alike places.
    vote_floor: the likelihood of a sample far from every voted centre (never exactly 0).
    min_mapped: once anchored, a vote from a place mapped less than this is ignored (:meth:`correct`).
    resample_ess: resample when the effective number of samples falls below this share of them.
    lag: the place rates lag the input by this many steps (``(1 - k) / k`` for eq. 3's Euler update),
        so the vote is compared with where each sample was that many steps ago (``lag`` times the
        last step back), and cells learn their centres there too (:meth:`lagged_estimate`).
        Without it the vote pulls the estimate back along the path and the centres drift with it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from hippo_agent.cells import _kernels

__all__ = ["PathIntegrator"]

RULED_OUT_WEIGHT = 1e-3
"""The share of its weight a sample keeps near a place ruled out (:meth:`PathIntegrator.lose`)."""


class PathIntegrator:
    """A self-localising path integrator (see the module docstring)."""

    def __init__(
        self,
        n_particles: int,
        rng: np.random.Generator,
        *,
        motion_noise: float,
        min_motion_noise: float,
        vote_sigma: float,
        anchor_radius: float,
        anchor_weight: float,
        redraw_fraction: float,
        lag: float,
        min_anchor_steps: int,
        vote_floor: float,
        min_mapped: float,
        resample_ess: float,
        lost_vote_floor: float | None = None,
        proposal_share: float = 0.0,
        collapse_on_anchor: bool = False,
        rule_out_radius: float = 0.0,
    ) -> None:
        self.n_particles = int(n_particles)
        self.rng = rng
        self.motion_noise = float(motion_noise)
        self.min_motion_noise = float(min_motion_noise)
        self.vote_sigma = float(vote_sigma)
        self.anchor_radius = float(anchor_radius)
        self.anchor_weight = float(anchor_weight)
        self.redraw_fraction = float(redraw_fraction)
        self.particles = np.zeros((self.n_particles, 2))
        self.weights = np.full(self.n_particles, 1.0 / self.n_particles)
        self.estimate = np.zeros(2)
        self.confidence = 0.0
        self.frame_started = False  # the frame's origin has been set (the agent's first run)
        self.anchored = False
        self.fresh = False  # kidnapped and no sample drawn from the vote yet
        self.lag = float(lag)
        self.min_anchor_steps = int(min_anchor_steps)
        self.lost_vote_floor = float(vote_floor if lost_vote_floor is None else lost_vote_floor)
        self.proposal_share = float(proposal_share)
        self.collapse_on_anchor = bool(collapse_on_anchor)
        self.rule_out_radius = float(rule_out_radius)
        self.ruled_out = np.empty((0, 2))  # where estimates found wrong since the last anchoring are now, by odometry
        self.lost_steps = 0  # corrections since the estimate was last lost
        self.min_mapped = float(min_mapped)
        self.vote_floor = float(vote_floor)
        self.resample_ess = float(resample_ess)
        self.last_step = np.zeros(2)
        self._noise = np.zeros((self.n_particles, 2))  # scratch: one step's motion noise

    def start_run(self) -> None:
        """A run begins. The first ever run sets the frame (origin here); later ones are kidnaps."""
        self.last_step = np.zeros(2)
        self.lost_steps = 0
        self.ruled_out = np.empty((0, 2))
        if not self.frame_started:
            self.frame_started = True
            self.particles[:] = 0.0
            self.weights[:] = 1.0 / self.n_particles
            self.estimate = np.zeros(2)
            self.confidence = 1.0
            self.anchored = True
        else:
            self.anchored = False
            self.fresh = True
            self.confidence = 0.0

    def move(self, step: np.ndarray) -> None:
        """Path integration: shift every sample by the allocentric ``step`` (m), plus noise."""
        self.last_step = np.asarray(step, dtype=np.float64)
        spread = self.motion_noise * math.hypot(*self.last_step.tolist()) + self.min_motion_noise
        if spread > 0:
            self.rng.standard_normal(out=self._noise)
        _kernels.shift(self.particles, self.last_step, spread, self._noise)
        if self.ruled_out.size:
            self.ruled_out += self.last_step

    def correct(
        self,
        rates: np.ndarray,
        centres: np.ndarray,
        mapped: float = 1.0,
        spreads: np.ndarray | None = None,
        likelihood: Callable[[np.ndarray], np.ndarray | None] | None = None,
        proposals: Callable[[], np.ndarray | None] | None = None,
    ) -> None:
        """Weigh the samples by the sensory vote of cells with ``rates`` > 0 and ``centres``.

        ``rates`` and ``centres`` are those of the active cells that have a centre; ``mapped`` is
        their share of the activity. Once anchored, a vote from a place mapped less than
        ``min_mapped`` is ignored: at the edge of the map only the cells behind the robot have
        centres, and their vote would pull the estimate back. With no voting cell there is no
        evidence and the samples keep their weights.

        ``spreads`` (m^2, ``None`` = 0) is how far from its centre each cell is also known to fire
        on boundary input alone: a cell's vote is a 2-D Gaussian of variance ``vote_sigma^2 +
        spread`` around its centre, normalised, so a cell that also fires at a distant look-alike
        place votes broadly and weakly, and the cells that fire in one place only decide.

        ``likelihood(particles)``, if given, returns a further likelihood per sample (or ``None``
        for none), e.g. how well the current scan fits a map from there; it weighs the samples
        after the vote.

        ``proposals()``, if given, returns candidate positions (an (m, 2) array, or ``None``) from
        which, while lost, ``proposal_share`` of the redrawn samples are drawn: places that the
        vote may not propose (a look-alike room whose cells the boundary code drives less).
        """
        if rates.size and (not self.anchored or mapped >= self.min_mapped):
            spreads = np.zeros(rates.size) if spreads is None else np.asarray(spreads, dtype=np.float64)
            if not self.anchored:
                reliability = rates * (self.vote_sigma**2 / (self.vote_sigma**2 + spreads))  # each cell's say
                n = self.n_particles if self.fresh else round(self.redraw_fraction * self.n_particles)
                self._redraw(reliability, centres, n, None if proposals is None else proposals())
                self.fresh = False
            # each sample's likelihood: the cells' Gaussians around their centres, where the sample was lag steps ago
            vote_var = self.vote_sigma**2
            gauss = np.empty((self.n_particles, rates.size))
            _kernels.vote_exponents(self.particles, self.lag, self.last_step, centres, spreads, vote_var, gauss)
            np.exp(gauss, out=gauss)  # NumPy's vectorised exp, over the whole block at once
            floor = self.vote_floor if self.anchored else self.lost_vote_floor
            ess = _kernels.reweigh(gauss, rates, spreads, vote_var, floor, self.weights)
            if ess < self.resample_ess * self.n_particles:
                self._resample()
        if not self.anchored:
            self.lost_steps += 1
        more = likelihood(self.particles) if likelihood is not None else None
        if more is not None:
            self.weights *= more
            self.weights /= self.weights.sum()
            if 1.0 / np.sum(self.weights**2) < self.resample_ess * self.n_particles:
                self._resample()
        if not self.anchored and len(self.ruled_out):
            self._weigh_down_ruled_out()
        self._summarise()

    def lose(self, rule_out: bool = False) -> None:
        """The estimate is known to be wrong: anchor afresh, as after a kidnap. With ``rule_out``
        (and ``rule_out_radius`` > 0), the robot is known not to be where the estimate is: until
        anchored again, samples near there are weighed down (:meth:`_weigh_down_ruled_out`)."""
        if rule_out and self.rule_out_radius > 0.0:
            self.ruled_out = np.vstack((self.ruled_out, self.estimate))
        self.anchored = False
        self.fresh = True
        self.confidence = 0.0
        self.lost_steps = 0

    def lagged_estimate(self) -> np.ndarray:
        """Where the estimate was ``lag`` steps ago: what the place rates reflect now."""
        (x, y), (dx, dy) = self.estimate.tolist(), self.last_step.tolist()  # (as floats: faster than on two-element arrays)
        return np.array((x - self.lag * dx, y - self.lag * dy))

    def _redraw(self, rates: np.ndarray, centres: np.ndarray, n: int, proposed: np.ndarray | None = None) -> None:
        """Replace the ``n`` lightest samples by draws around the voted centres and, with
        ``proposed`` positions, ``proposal_share`` of them around those (while lost)."""
        if n < 1:
            return
        which = np.argsort(self.weights)[:n]
        if proposed is None or len(proposed) == 0:
            proposed = np.empty((0, 2))
        n_proposed = round(self.proposal_share * n) if len(proposed) else 0
        cells = self.rng.choice(rates.size, size=n - n_proposed, p=rates / rates.sum())
        drawn = centres[cells] + self.lag * self.last_step
        if n_proposed:
            drawn = np.concatenate((drawn, proposed[self.rng.integers(len(proposed), size=n_proposed)]))
        self.particles[which] = drawn + self.rng.normal(0.0, self.vote_sigma, (n, 2))
        self.weights[which] = 1.0 / self.n_particles
        self.weights /= self.weights.sum()

    def _weigh_down_ruled_out(self) -> None:
        """Samples within ``rule_out_radius`` of a place ruled out keep ``RULED_OUT_WEIGHT`` of their
        weight: strong evidence against them, but not a zero, which could leave no weight at all."""
        d2 = np.min(np.sum((self.particles[:, None, :] - self.ruled_out[None, :, :]) ** 2, axis=2), axis=1)
        near = d2 < self.rule_out_radius**2
        if not near.any():
            return
        self.weights[near] *= RULED_OUT_WEIGHT
        self.weights /= self.weights.sum()
        if 1.0 / np.sum(self.weights**2) < self.resample_ess * self.n_particles:
            self._resample()

    def _keep_cluster(self) -> None:
        """Anchoring commits to the cluster: the samples farther than twice ``anchor_radius``
        from the estimate are dropped (the rest resampled), so that a look-alike place the vote still favours cannot take the estimate
        over once the robot knows where it is (the map's fit, ``lost_agreement``, re-opens the
        question if the commitment was wrong)."""
        far = np.sum((self.particles - self.estimate) ** 2, axis=1) > (2 * self.anchor_radius) ** 2
        if far.all():
            return
        self.weights[far] = 0.0
        self.weights /= self.weights.sum()
        self._resample()

    def _resample(self) -> None:
        """Systematic resampling: heavy samples are copied, light ones dropped."""
        positions = (self.rng.random() + np.arange(self.n_particles)) / self.n_particles
        idx = np.minimum(np.searchsorted(np.cumsum(self.weights), positions), self.n_particles - 1)
        self.particles = self.particles[idx]
        self.weights = np.full(self.n_particles, 1.0 / self.n_particles)

    def _summarise(self) -> None:
        """The estimate is the weighted mean of the heaviest sample's cluster; its weight is the confidence."""
        x, y, self.confidence = _kernels.cluster_mean(self.particles, self.weights, self.anchor_radius**2)
        self.estimate = np.array([x, y])
        if not self.anchored and not self.fresh and self.confidence >= self.anchor_weight and self.lost_steps >= self.min_anchor_steps:
            self.anchored = True  # (a fresh belief is still where the last run ended: no evidence yet)
            self.ruled_out = np.empty((0, 2))
            if self.collapse_on_anchor:
                self._keep_cluster()
