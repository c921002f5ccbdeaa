"""The paper's model: four kinds of cell, their learning rules, replay, preplay and a random walk.

A. Alabi, D. Vanderelst and A. Minai, *Rapid Learning of Spatial Representations for
Goal-Directed Navigation Based on a Novel Model of Hippocampal Place Fields*. Equation numbers
are the paper's. One place-cell update per environment step (about 0.15 m of travel).

Each step of a run, in the order :class:`~hippo_agent.HippocampalAgent` calls them:

1. :meth:`PaperModel.sense`: the compass drives the head-direction cells (eq. 1), the rangefinder
   scan the boundary vector cells (eq. 2).
2. :meth:`PaperModel.step`: the place cells integrate their BVC input with feed-forward and
   recurrent inhibition (eqs. 3-4).
3. :meth:`PaperModel.learn`: Oja's rule on the BVC -> place weights (eq. 5), the traces (eq. 6)
   and the direction-specific place -> place tensor (eq. 7).
4. On reward, :meth:`PaperModel.replay`: backward replay from the goal writes the reward map
   (Algorithm 1).
5. To choose the next heading, :meth:`PaperModel.preplay`: imagine one step in each direction
   (eq. 8), read the imagined reward (eq. 9), head along the value-weighted mean (eq. 10) and
   depress what was just used (:meth:`PaperModel.depress`, eq. 11). Where the reward map is
   silent, the :class:`RandomWalk` explores: straight segments, then a random turn.

The dry run is that random walk with no goal for ``dry_run_steps`` steps, only eq. 5 learning
(eq. 7 too with ``learn_pp_in_dry_run``). A run starts with :meth:`PaperModel.start_run`.

:meth:`ModelConfig.paper` holds the values the paper's model runs with; the defaults are the
default model's. Where the implementation departs from the paper (values the paper leaves out,
tuned values, the bump reflex), ``docs/model.md`` says so, with the reason, in one table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from hippo_agent.cells import BoundaryVectorCells, HeadDirectionCells, PlaceCells, RewardCells, _kernels
from hippo_agent.sections import Section, param
from hippo_env.geometry import wrap_angle

__all__ = ["ModelConfig", "PaperModel", "RandomWalk"]


@dataclass(frozen=True)
class ModelConfig(Section):
    """The paper's model's parameters. Rates are per place-cell update; ``docs/parameters.md``
    gives each value's source."""

    name: ClassVar[str] = "model"

    # ---------------------------------------------------------------- head direction (eq. 1)
    n_hd: int = param(8, ge=4)
    """Head-direction cells, preferred directions ``2*pi*k/n_hd``; also the preplay directions and
    the ``W_pp`` slices (the paper's theta^h is both). Even, so the opposite slice is the exact
    negative (``cells/place.py``)."""

    # ---------------------------------------------------------------- boundary vector cells (eq. 2)
    n_bvc_directions: int = param(8, ge=1)
    """BVC preferred allocentric directions, evenly spaced from 0 (east) counter-clockwise."""
    n_bvc_distances: int = param(50, ge=2)
    """BVC preferred distances, ``linspace(0, bvc_max_distance, n)``."""
    bvc_max_distance: float | None = param(None, gt=0)
    """Largest preferred distance (m); ``None``: the rangefinder's maximum range."""
    bvc_sigma_r: float = param(0.5, gt=0)
    """Radial tuning width sigma_r (m), the same at every distance."""
    bvc_sigma_theta_deg: float = param(1.0, gt=0, le=45)
    """Angular tuning width sigma_theta (degrees): each BVC sums a handful of rays."""
    bvc_angular_cutoff: float = param(3.0, gt=0)
    """Rays within this many sigma_theta of a BVC's direction enter its sum (the Gaussian beyond
    is under 1.2 % of its peak)."""
    bvc_peak_rate: float = param(0.5, gt=0)
    """BVC rates are scaled so the largest possible response (a boundary at the preferred
    distance across the whole angular window) is this."""

    # ---------------------------------------------------------------- place cells (eqs. 3-5)
    n_place: int = param(1000, ge=1)
    """Place cells N (the faculty ``exploration`` recruits more in larger arenas)."""
    k: float = param(0.5, gt=0, le=1)
    """Rate constant of eq. 3, ``dt / tau_p`` per update."""
    Gamma_pb: float = param(0.3, ge=0)
    """Feed-forward inhibition gain Gamma^pb (eq. 3)."""
    Gamma_pp: float = param(0.5, ge=0)
    """Recurrent inhibition gain Gamma^pp (eq. 3)."""
    psi: float = param(1.0, gt=0)
    """Gain psi of eq. 4, ``v = tanh([psi s]+)``."""
    p_pb: float = param(0.2, ge=0, le=1)
    """Probability that an initial (binary) BVC -> place weight is 1 (eq. 5)."""
    eta_pb: float = param(0.096, ge=0, lt=1)
    """Oja learning rate ``dt / tau_w^pb`` (eq. 5)."""
    alpha_pb: float = param(math.sqrt(0.5), gt=0)
    """Oja normalising factor alpha_pb (eq. 5)."""
    settle_steps: int = param(5, ge=0)
    """Eq.-3 updates from rest on a run's first observation, so a robot put down at a new start
    does not carry the last place's activity."""
    analysis_settle_steps: int = param(30, ge=1)
    """Eq.-3 updates from rest for the analysis maps (``place_rates_at``): a steady state."""

    # ---------------------------------------------------------------- place -> place (eqs. 6-7)
    trace_rate: float = param(0.3, gt=0, le=1)
    """Rate at which the place-cell traces move toward the rates (eq. 6): a window of about 3
    updates (0.5 m), so replay's links stay short and the reward map graded."""
    hd_trace_rate: float = param(1.0, gt=0, le=1)
    """Rate at which the head-direction trace moves toward the head-direction rates (eq. 6); 1:
    the current heading."""
    trace_floor: float = param(1e-3, ge=0, lt=1)
    """Trace values below this are set to 0, so an eq.-7 update touches few cells."""
    eta_pp: float = param(1.0, gt=0)
    """Learning rate ``dt / tau_w^pp`` of eq. 7."""
    learn_pp_in_dry_run: bool = True
    """Eq. 7 learns in the dry run as well (latent learning: replay then reaches everything
    explored, along the paths walked). The paper's dry run learns eq. 5 only."""

    # ---------------------------------------------------------------- replay (Algorithm 1)
    replay_iterations: int = param(40, ge=1)
    """Iterations n_rs of backward replay; each reaches about one place-place link further."""
    tau_r: float = param(2.0, gt=0)
    """Replay decay tau_r in iterations, ``exp(-t_r / tau_r)``: short keeps the reward map steep
    round the goal, long carries value further along winding paths."""

    # ---------------------------------------------------------------- preplay (eqs. 8-11)
    lambda_: float = param(0.05, ge=0, le=1)
    """Depression lambda of eq. 11, at each exploiting step, undone at each run's start."""
    xi: float = param(1e-5, ge=0)
    """Exploit only if the best preplayed direction's value (eq. 9) reaches xi."""
    xi_here: float = param(1e-8, ge=0)
    """Also explore where the value of the current place is at most this: the reward map has
    never reached it."""

    # ---------------------------------------------------------------- the random walk
    segment_min: int = param(5, ge=1)
    """Shortest straight exploration segment (steps)."""
    segment_max: int = param(10, ge=1)
    """Longest straight exploration segment (steps, inclusive)."""
    turn_sigma_deg: float = param(30.0, ge=0)
    """Standard deviation of the turn between segments (degrees)."""
    discrete_rounding: Literal["stochastic", "nearest"] = "stochastic"
    """How an intended heading becomes one of the discrete actions: ``"stochastic"`` takes the
    neighbouring action toward it with probability equal to the fraction of the gap, so the mean
    direction is the intended one; ``"nearest"`` rounds."""
    dry_run_steps: int | None = param(None, ge=0)
    """Steps of the dry run: exactly this many for the random walk, at most this many when the
    faculty ``exploration`` ends it by itself. ``None``: 10,000 for the random walk; with
    ``exploration``, at least 10,000 and more as the map finds ground
    (``exploration.dry_run_steps_per_m2``), so a large world's dry run is not cut short."""

    def _check(self) -> None:
        if self.n_hd % 2:
            raise self.invalid("n_hd", "an even integer >= 4")
        if self.segment_max < self.segment_min:
            raise self.invalid("segment_max", f"an integer >= segment_min ({self.segment_min})")

    @classmethod
    def paper(cls, **changes: Any) -> ModelConfig:
        """The values the paper's model runs with: the dry run a random walk of 5,000 steps that
        learns eq. 5 only; 20 replay iterations (the reference implementation's) with tau_r 1 (chosen
        with the random-walk dry run); the reference's thresholds xi 1e-3 and xi_here 1e-6; the
        rest as the defaults."""
        paper = {"learn_pp_in_dry_run": False, "dry_run_steps": 5000, "tau_r": 1.0, "replay_iterations": 20, "xi": 1e-3, "xi_here": 1e-6}
        return cls(**{**paper, **changes})

    def bvc_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~hippo_agent.cells.BoundaryVectorCells` (besides the sensor's)."""
        return {
            "n_directions": self.n_bvc_directions,
            "n_distances": self.n_bvc_distances,
            "max_distance": self.bvc_max_distance,
            "sigma_r": self.bvc_sigma_r,
            "sigma_theta": math.radians(self.bvc_sigma_theta_deg),
            "angular_cutoff": self.bvc_angular_cutoff,
            "peak_rate": self.bvc_peak_rate,
        }

    def place_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~hippo_agent.cells.PlaceCells` (besides the sizes and the generator)."""
        names = ("k", "Gamma_pb", "Gamma_pp", "psi", "p_pb", "eta_pb", "alpha_pb", "trace_rate", "hd_trace_rate", "trace_floor", "eta_pp")
        return {name: getattr(self, name) for name in names}


class RandomWalk:
    """The paper's exploration: straight segments of ``segment_min..segment_max`` steps, then a
    N(0, ``turn_sigma_deg``) turn; a bump turns it to a random heading and starts a new segment.

    When another behaviour has steered, the walk carries on from there: :meth:`new_segment` starts
    a segment along that heading at once (after preplay), :meth:`follow` keeps the segment going
    along it (after directed exploration), ``length_later`` draws the segment's length only when
    the walk next takes a step (after homing).
    """

    def __init__(self, config: ModelConfig, rng: np.random.Generator) -> None:
        self.config = config
        self.rng = rng
        self.heading = 0.0  # the intended heading (rad)
        self.segment_left = 0  # steps left in the segment; -1: its length is drawn at the next step

    def _length(self) -> int:
        return int(self.rng.integers(self.config.segment_min, self.config.segment_max + 1))

    def new_segment(self, heading: float) -> None:
        """A segment along ``heading`` starts now."""
        self.heading = float(heading)
        self.segment_left = self._length()

    def follow(self, heading: float, length_later: bool = False) -> None:
        """Another behaviour heads along ``heading``: the walk goes on that way."""
        self.heading = float(heading)
        if length_later:
            self.segment_left = -1

    def turn_at_random(self) -> None:
        """A bump: a random heading, a new segment."""
        self.heading = float(self.rng.uniform(-math.pi, math.pi))
        self.segment_left = self._length()

    def step(self) -> float:
        """The walk's heading for this step."""
        if self.segment_left < 0:
            self.segment_left = self._length()
        elif self.segment_left == 0:
            turn = self.rng.normal(0.0, math.radians(self.config.turn_sigma_deg))
            self.heading = wrap_angle(self.heading + turn)
            self.segment_left = self._length()
        self.segment_left -= 1
        return self.heading

    def state(self) -> dict[str, Any]:
        """What :meth:`load_state` restores."""
        return {"heading": self.heading, "segment_left": self.segment_left}

    def load_state(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state`."""
        self.heading, self.segment_left = float(state["heading"]), int(state["segment_left"])


class PaperModel:
    """The paper's cells, learning rules, replay and preplay, and the random walk (module docstring).

    Args:
        config: the model's parameters.
        n_rays: rays of the rangefinder scan.
        max_range: the rangefinder's maximum range (m).
        rng: the agent's one generator (initial ``W_pb``, the walk).

    Attributes:
        hd, bvc, place, reward: the four cell populations (``hippo_agent.cells``).
        walk: the :class:`RandomWalk`.
        goal_rewarded: the current goal's reward map has been written at least once.
        last_values: the values of the last preplay (eq. 9), one per direction.
    """

    def __init__(self, config: ModelConfig, n_rays: int, max_range: float, rng: np.random.Generator) -> None:
        c = self.config = config
        self.rng = rng
        self.hd = HeadDirectionCells(n=c.n_hd)  # eq. 1
        self.bvc = BoundaryVectorCells(n_rays=n_rays, max_range=max_range, **c.bvc_kwargs())  # eq. 2
        self.place = PlaceCells(c.n_place, self.bvc.n, c.n_hd, rng, **c.place_kwargs())  # eqs. 3-8
        self.reward = RewardCells(c.n_place)  # eqs. 9, 11, Algorithm 1
        self.walk = RandomWalk(c, rng)
        self.goal_rewarded = False
        self.last_values = np.zeros(c.n_hd)
        self._dir_cos, self._dir_sin = np.cos(self.hd.preferred), np.sin(self.hd.preferred)  # theta^h: the preplay directions

    # ------------------------------------------------------------------ a step
    def sense(self, ranges: np.ndarray, heading_vec: np.ndarray, heading: float) -> tuple[np.ndarray, np.ndarray]:
        """The BVC rates (eq. 2) for the scan and the head-direction rates (eq. 1) for the compass."""
        return self.bvc.update(ranges, heading), self.hd.update(heading_vec)

    def step(self, b: np.ndarray) -> None:
        """One place-cell update from the BVC rates ``b`` (eqs. 3-4)."""
        self.place.step(b)

    def learn(self, b: np.ndarray, h: np.ndarray, trusted: bool, dry: bool, bumped: bool) -> None:
        """Eqs. 5-7 for this step. ``trusted``: the place code may learn (always, but for a faculty
        that doubts where the robot is); an untrusted code is not traced, so eq. 7 does not link it
        to the next trusted one. No eq.-7 learning against a wall (``bumped``), nor in the dry run
        unless ``learn_pp_in_dry_run``."""
        # eq. 5 if trusted; eq. 6's head-direction trace; eq. 7; eq. 6's place-cell trace (zeroed if untrusted)
        self.place.learn(b, h, trusted, trusted and not bumped and (not dry or self.config.learn_pp_in_dry_run))

    def replay(self) -> bool:
        """Backward replay (Algorithm 1) from the current place rates into the current goal's
        reward cell. ``False`` if no place cell was active (nothing to learn)."""
        learnt = self.reward.learn(self.place.v, self.place.replay_links, self.config.replay_iterations, self.config.tau_r)
        self.goal_rewarded = self.goal_rewarded or learnt
        return learnt

    def preplay(self) -> float | None:
        """The heading preplay chooses (eqs. 8-10), or ``None`` where the reward map gives no
        direction (not learnt yet, silent here, or no direction's value reaches ``xi``). Keeps the
        values in :attr:`last_values`."""
        c = self.config
        if not self.goal_rewarded or self.reward.n == 0:
            return None
        v = self.place.v
        if self.reward.value(v) <= c.xi_here:
            return None
        values = self.place.imagined_values(self.reward.W_eff, v)  # eqs. 8-9
        self.last_values = values
        # eq. 10: circular mean of the directions weighted by their values (atan2 keeps the quadrant)
        a_star, best = _kernels.circular_mean(values, self._dir_cos, self._dir_sin)
        return None if best < c.xi else a_star

    def depress(self) -> None:
        """Eq. 11: the active cells' effective reward weights are depressed for the rest of the run."""
        self.reward.depress(self.place.v, self.config.lambda_)

    # ------------------------------------------------------------------ runs and goals
    def settle(self, b: np.ndarray, drive: np.ndarray | None = None) -> None:
        """From rest, ``settle_steps`` place-cell updates on a run's first scan (with ``drive``, an
        extra input, the path integrator's)."""
        self.place.settle(b, drive, self.config.settle_steps)

    def start_run(self, h: np.ndarray, heading: float) -> None:
        """A run begins (after :meth:`settle`): the depressed weights are restored and the walk
        starts a segment along the heading."""
        self.place.update_hd_trace(h)
        self.reward.reset_effective()
        self.walk.new_segment(heading)
        self.last_values = np.zeros(self.config.n_hd)

    def new_goal(self) -> None:
        """A new goal (a DMTP trial): a new reward cell takes over."""
        self.reward.add_goal()
        self.goal_rewarded = False

    def grow(self, extra: int) -> None:
        """``extra`` more place cells (and their reward weights)."""
        self.place.grow(extra, self.rng)
        self.reward.grow(extra)

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        p, r = self.place, self.reward
        arrays = {
            "W_pb": p.W_pb, "s": p.s, "v": p.v, "trace": p.trace, "hd_trace": p.hd_trace, "s_sense": p.s_sense, "v_sense": p.v_sense,
            "W_pp_slots": p.W_pp_used, "W_pp_cells": p.slot_cells, "W_rp": r.W_rp, "W_eff": r.W_eff,
            "hd_rates": self.hd.rates, "bvc_rates": self.bvc.rates, "last_values": self.last_values,
        }  # fmt: skip
        return {"place_cells": p.n, "goal_rewarded": self.goal_rewarded, "walk": self.walk.state()}, arrays

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state` (the place cells already grown to ``state["place_cells"]``)."""
        p, r = self.place, self.reward
        for owner, names in ((p, ("W_pb", "s", "v", "trace", "hd_trace", "s_sense", "v_sense")), (r, ("W_eff",))):
            for name in names:
                setattr(owner, name, _checked(arrays, name, getattr(owner, name).shape, getattr(owner, name).dtype))
        W_rp = arrays["W_rp"]
        if W_rp.ndim != 2 or W_rp.shape[1] != p.n or not np.all(np.isfinite(W_rp)):
            raise ValueError(f"array 'W_rp' has shape {W_rp.shape} (expected (goals, {p.n})) or non-finite values")
        r.W_rp = W_rp.astype(np.float64)
        self.hd.rates = _checked(arrays, "hd_rates", self.hd.rates.shape, np.float64)
        self.bvc.rates = _checked(arrays, "bvc_rates", self.bvc.rates.shape, np.float64)
        self.last_values = _checked(arrays, "last_values", self.last_values.shape, np.float64)
        if not np.all(np.isfinite(arrays["W_pp_slots"])):
            raise ValueError("array 'W_pp_slots' has non-finite values")
        p.load_W_pp(arrays["W_pp_cells"], arrays["W_pp_slots"])
        self.goal_rewarded = bool(state["goal_rewarded"])
        self.walk.load_state(state["walk"])


def _checked(arrays: dict[str, np.ndarray], name: str, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
    """``arrays[name]`` as ``dtype`` if it has ``shape`` and finite values, else ``ValueError``."""
    if name not in arrays:
        raise ValueError(f"array {name!r} is missing")
    arr = arrays[name]
    if arr.shape != shape or not np.all(np.isfinite(arr)):
        raise ValueError(f"array {name!r} has shape {arr.shape} (expected {shape}) or non-finite values")
    return arr.astype(dtype)
