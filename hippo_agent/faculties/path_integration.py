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

The faculty's parameters are :class:`PathIntegrationConfig`, its state the belief and each place
cell's centre; off (``AgentConfig.path_integration = None``) in the paper's model.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from hippo_agent.cells import PlaceCells, _kernels
from hippo_agent.sections import Section, param

__all__ = ["PathIntegrationConfig", "PathIntegrator", "odometry_step"]


@dataclass(frozen=True)
class PathIntegrationConfig(Section):
    """Path integration: the belief (a particle filter) and its coupling to the place cells."""

    name: ClassVar[str] = "path_integration"

    # ---------------------------------------------------------------- the place cells' drive
    gain: float = param(3.0, ge=0)
    """Gain of a place cell's drive: ``gain * (exp(-d^2 / 2 sigma^2) - threshold)``, ``d`` the
    distance from the estimate to the cell's centre."""
    sigma: float = param(0.7, gt=0)
    """Width (m) of the drive round a cell's centre."""
    threshold: float = param(0.7, ge=0)
    """Offset of the drive: far from its centre a cell is inhibited by ``gain * threshold``, so a
    look-alike place elsewhere no longer fires it."""
    field_radius: float = param(2.0, gt=0)
    """Beyond this distance (m) from its centre a cell is silenced by ``far_inhibition``: a cell
    firing far from its centre would link distant places in ``W_pp``."""
    far_inhibition: float = param(10.0, ge=0)
    """Inhibition of a cell beyond ``field_radius`` (the drive's units)."""
    centre_max_mass: float = param(1000.0, gt=0)
    """Cap of the rate a centre's running mean accumulates; later firing still moves it by at
    least ``rate / centre_max_mass``."""
    # ---------------------------------------------------------------- the belief
    particles: int = param(200, ge=2)
    """Samples of the belief."""
    motion_noise: float = param(0.0, ge=0)
    """Spread added to each sample per step, as a fraction of the distance moved."""
    min_motion_noise: float = param(0.001, ge=0)
    """Spread (m) added to each sample per step whatever the distance moved."""
    vote_sigma: float = param(0.4, gt=0)
    """Width (m) of an active cell's vote round its centre."""
    anchor_radius: float = param(1.0, gt=0)
    """Samples within this distance (m) of the heaviest one form the estimate's cluster, the
    candidate place whose share of the weight decides anchoring; look-alike places lie farther
    apart."""
    anchor_weight: float = param(0.8, gt=0, le=1)
    """Share of the weight the cluster needs before a run's estimate counts as anchored; until then
    the drive and all plasticity are off."""
    min_anchor_steps: int = param(5, ge=0)
    """A run's estimate is anchored no sooner than this many steps after the robot was put down
    (or found misplaced), so evidence that accumulates (the map's fit) can tell look-alike places
    apart."""
    redraw_fraction: float = param(0.2, gt=0, le=1)
    """While not anchored, this share of the samples is drawn afresh round the voted centres each step."""
    min_mass: float = param(1.0, ge=0)
    """A cell's centre enters the vote once the cell has fired there with a summed rate of at least this."""
    vote_floor: float = param(1e-3, gt=0, le=1)
    """Likelihood of a sample far from every voted centre, so that no weight becomes 0 and the
    belief can recover from a wrong vote."""
    lost_vote_floor: float = param(0.5, ge=0, le=1)
    """The same while not anchored: a higher floor makes the vote weaker evidence against places it
    does not propose (in look-alike rooms often where the robot is)."""
    min_mapped: float = param(0.8, ge=0, le=1)
    """Once anchored, a vote is ignored where the cells with a centre hold less than this share of
    the boundary code's activity (at the edge of the mapped ground the vote would pull back)."""
    resample_ess: float = param(0.5, ge=0, le=1)
    """Resample when the effective number of samples falls below this share of them."""
    proposal_share: float = param(0.5, ge=0, le=1)
    """While not anchored, this share of the redrawn samples comes from the map's proposals (the
    faculty ``localisation``), if any."""
    collapse_on_anchor: bool = True
    """On anchoring, the samples farther than twice ``anchor_radius`` from the estimate are
    dropped, so a look-alike place the vote favours cannot take the estimate over afterwards."""
    rule_out_radius: float = param(2.0, ge=0)
    """When the estimate is found wrong (a failed homing search), samples within this distance (m)
    of where it was, carried along by odometry, are weighed down until it is anchored again (0: off)."""


def odometry_step(odometry: Any, heading_vec: np.ndarray) -> np.ndarray:
    """The encoders' (forward, left) displacement rotated by the compass: the step in the frame."""
    return np.array(_odometry_xy(odometry, heading_vec))


def _odometry_xy(odometry: Any, heading_vec: np.ndarray) -> tuple[float, float]:
    """:func:`odometry_step` as two floats."""
    try:
        # (floats: faster arithmetic; those of an array of float64 or narrower are its float64 copy's)
        is_float_array = isinstance(odometry, np.ndarray) and odometry.dtype.kind == "f" and odometry.itemsize <= 8
        forward, left = (odometry if is_float_array else np.asarray(odometry, dtype=np.float64)).tolist()
    except (TypeError, ValueError) as exc:
        raise ValueError("observation 'odometry' must be (forward, left) in metres: path integration needs it") from exc
    hx, hy = heading_vec.tolist()
    norm = math.hypot(hx, hy) or 1.0
    c, s = hx / norm, hy / norm
    return c * forward - s * left, s * forward + c * left


RULED_OUT_WEIGHT = 1e-3
"""The share of its weight a sample keeps near a place ruled out (:meth:`PathIntegrator.lose`)."""


class PathIntegrator:
    """A self-localising path integrator (see the module docstring).

    Args:
        config: its parameters.
        n_place: place cells (each gets a centre).
        k: the place cells' rate constant (eq. 3): their rates lag the input by ``(1 - k) / k``
            steps, so the vote is compared with where each sample was that many steps ago, and
            cells learn their centres there too (:meth:`lagged_estimate`).
        rng: the agent's generator.
    """

    def __init__(self, config: PathIntegrationConfig, n_place: int, k: float, rng: np.random.Generator) -> None:
        c = self.config = config
        self.rng = rng
        self.n_particles = c.particles
        self.motion_noise, self.min_motion_noise = c.motion_noise, c.min_motion_noise
        self.vote_sigma, self.anchor_radius, self.anchor_weight = c.vote_sigma, c.anchor_radius, c.anchor_weight
        self.redraw_fraction, self.min_anchor_steps = c.redraw_fraction, c.min_anchor_steps
        self.vote_floor, self.lost_vote_floor, self.min_mapped = c.vote_floor, c.lost_vote_floor, c.min_mapped
        self.resample_ess, self.proposal_share = c.resample_ess, c.proposal_share
        self.collapse_on_anchor, self.rule_out_radius = c.collapse_on_anchor, c.rule_out_radius
        self.lag = (1.0 - k) / k  # eq. 3's Euler update lags the input by this many steps
        self.particles = np.zeros((self.n_particles, 2))
        self.weights = np.full(self.n_particles, 1.0 / self.n_particles)
        self.estimate = np.zeros(2)
        self.confidence = 0.0
        self.frame_started = False  # the frame's origin has been set (the agent's first run)
        self.anchored = False
        self.fresh = False  # kidnapped and no sample drawn from the vote yet
        self.ruled_out = np.empty((0, 2))  # where estimates found wrong since the last anchoring are now, by odometry
        self.lost_steps = 0  # corrections since the estimate was last lost
        self.last_step = np.zeros(2)
        self._noise = np.zeros((self.n_particles, 2))  # scratch: one step's motion noise
        # each place cell's centre in the frame (the place -> path-integration synapses) and how far
        # from it the boundary code alone fires the cell (its spread, m^2)
        self.centres = np.zeros((n_place, 2))
        self.centre_mass = np.zeros(n_place)  # 0: no centre yet
        self.spread = np.zeros(n_place)
        self.spread_mass = np.zeros(n_place)
        self._vote = (np.empty(n_place), np.empty((n_place, 2)), np.empty(n_place))  # scratch for the vote
        self._exponents = np.empty(self.n_particles * n_place)  # scratch: the vote's Gaussians, sample by sample
        two_var = 2.0 * c.sigma * c.sigma
        # beyond this squared distance the Gaussian is below threshold * 2^-54 (with a margin of a factor e
        # for exp's rounding), less than half a float's spacing at the threshold: subtracting it leaves
        # -threshold exactly, so it is not computed
        negligible_sq = two_var * (54.0 * math.log(2.0) - math.log(c.threshold) + 1.0) if c.threshold > 0.0 else math.inf
        # drive()'s constants, as centre_drive takes them after the position (the config is frozen)
        self._drive_constants = (two_var, c.gain, c.threshold, c.field_radius * c.field_radius, c.far_inhibition, negligible_sq)

    def grow(self, extra: int) -> None:
        """Room for ``extra`` more place cells, without centres."""
        self.centres = np.concatenate([self.centres, np.zeros((extra, 2))])
        for name in ("centre_mass", "spread", "spread_mass"):
            setattr(self, name, np.concatenate([getattr(self, name), np.zeros(extra)]))
        n = self.centre_mass.size
        self._vote = (np.empty(n), np.empty((n, 2)), np.empty(n))
        self._exponents = np.empty(self.n_particles * n)

    # ------------------------------------------------------------------ the place cells
    def drive(self, position: np.ndarray | None = None) -> np.ndarray:
        """Each place cell's drive at ``position`` (``None``: the estimate):
        ``gain * (exp(-|p - c_i|^2 / 2 sigma^2) - threshold)`` for cells with a centre ``c_i``,
        less ``far_inhibition`` beyond ``field_radius`` from it; 0 for the others (they stay free
        to take new places)."""
        out = np.empty(self.centre_mass.size)
        where = self.estimate if position is None else np.asarray(position, dtype=np.float64)
        _kernels.centre_drive(self.centres, self.centre_mass, where, *self._drive_constants, out)
        return out

    def drive_place(self, place: PlaceCells) -> None:
        """The place cells' update of this step (after :meth:`PlaceCells.step_sense`) with the
        drive at the estimate (:meth:`drive`): :meth:`PlaceCells.step_driven_by_centres`."""
        place.step_driven_by_centres(self.centres, self.centre_mass, self.estimate, self._drive_constants)

    def learn_centres(self, place: PlaceCells) -> None:
        """Each active cell's centre moves toward where the estimate was when the rates formed
        (:meth:`lagged_estimate`) by its rate over its accumulated rate (a running mean, capped at
        ``centre_max_mass``); each centred cell the boundary code alone fires here learns how far
        from its centre that happens (its spread: wide for a cell that also fires at a distant
        look-alike place)."""
        x, y = self.lagged_xy()
        _kernels.learn_centres(
            place.v, self.centres, self.centre_mass, x, y, self.config.centre_max_mass,
            True, place.v_sense, self.spread, self.spread_mass,
        )  # fmt: skip

    def vote(self, place: PlaceCells) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        """(rates, centres) of the cells active in the BVC-only response whose centre has
        accumulated at least ``min_mass``, their share of all the BVC-only activity (low at the
        edge of what has been mapped, where cells without a centre yet are active), and their
        spreads: :meth:`correct`'s evidence. Views of scratch that the next call overwrites."""
        rates, where, spreads = self._vote
        n, share = _kernels.voting_cells(
            place.v_sense, self.centre_mass, self.config.min_mass, self.centres, self.spread, rates, where, spreads
        )
        return rates[:n], where[:n], share, spreads[:n]

    def move_by_odometry(self, odometry: Any, heading_vec: np.ndarray) -> None:
        """Path integration: the encoders' (forward, left) displacement rotated by the compass."""
        self._move(*_odometry_xy(odometry, heading_vec))

    # ------------------------------------------------------------------ the belief
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
        x, y = np.asarray(step, dtype=np.float64).tolist()
        self._move(x, y)

    def _move(self, x: float, y: float) -> None:
        """:meth:`move` by the step ``(x, y)``."""
        self.last_step = np.array((x, y))
        spread = self.min_motion_noise
        if self.motion_noise:  # (0 * length adds nothing)
            spread += self.motion_noise * math.hypot(x, y)
        if spread > 0:
            self.rng.standard_normal(out=self._noise)
        _kernels.shift(self.particles, x, y, spread, self._noise)
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

    def correct_anchored(self, place: PlaceCells) -> None:
        """Once anchored, :meth:`correct` by the place code's :meth:`vote` with no further evidence
        (none comes from the map then): the same arithmetic, with the vote and its Gaussians'
        exponents in one compiled call and, after NumPy's exp, the re-weighting and the estimate
        in another."""
        if not self.anchored:
            raise ValueError("correct_anchored is for an anchored belief: use correct(*vote(place), ...)")
        rates, where, spreads = self._vote
        vote_var = self.vote_sigma**2
        n = _kernels.vote_with_exponents(
            place.v_sense, self.centre_mass, self.config.min_mass, self.centres, self.spread, self.min_mapped,
            self.particles, self.lag, self.last_step, vote_var, rates, where, spreads, self._exponents,
        )  # fmt: skip
        radius_sq = self.anchor_radius**2
        if n:
            gauss = self._exponents[: self.n_particles * n]
            np.exp(gauss, out=gauss)  # NumPy's vectorised exp, as in correct
            ess, x, y, self.confidence = _kernels.reweigh_and_cluster(
                gauss, n, rates, spreads, vote_var, self.vote_floor, self.weights, self.particles, radius_sq
            )
            if not ess < self.resample_ess * self.n_particles:
                self.estimate = np.array([x, y])
                return
            self._resample()  # (the cluster is then that of the samples drawn)
        x, y, self.confidence = _kernels.cluster_mean(self.particles, self.weights, radius_sq)
        self.estimate = np.array([x, y])

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
        return np.array(self.lagged_xy())

    def lagged_xy(self) -> tuple[float, float]:
        """:meth:`lagged_estimate` as two floats."""
        (x, y), (dx, dy) = self.estimate.tolist(), self.last_step.tolist()  # (as floats: faster than on two-element arrays)
        return x - self.lag * dx, y - self.lag * dy

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

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        flags = {name: getattr(self, name) for name in ("frame_started", "anchored", "fresh", "confidence", "lost_steps")}
        arrays = {name: getattr(self, name) for name in _ARRAYS}
        return {**flags, "ruled_out": self.ruled_out.tolist()}, arrays

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state` (the place cells already grown to their saved number)."""
        for name in _ARRAYS:
            ref, arr = getattr(self, name), arrays.get(name)
            if arr is None or arr.shape != ref.shape or not np.all(np.isfinite(arr)):
                raise ValueError(f"path integration's array {name!r} is missing, not of shape {ref.shape} or not finite")
            setattr(self, name, arr.astype(np.float64))
        self.frame_started, self.anchored, self.fresh = bool(state["frame_started"]), bool(state["anchored"]), bool(state["fresh"])
        self.confidence, self.lost_steps = float(state["confidence"]), int(state["lost_steps"])
        ruled_out = np.asarray(state["ruled_out"], dtype=np.float64).reshape(-1, 2)
        if not np.all(np.isfinite(ruled_out)):
            raise ValueError("path integration's 'ruled_out' places are not finite")
        self.ruled_out = ruled_out


_ARRAYS = ("particles", "weights", "estimate", "last_step", "centres", "centre_mass", "spread", "spread_mass")
