"""Localisation against the map: the path integrator's belief checked against what the map holds.

A faculty of the default model (``AgentConfig.localisation``; it needs ``path_integration`` and
``map``). The place code alone gives look-alike places the same cells; the map holds their
surroundings beyond the nearest walls, where they differ (a door here, not there). So, in runs:

- **while the estimate is lost** (the robot was put down somewhere), each sample of the belief
  is weighed by how well the current scan fits the map from there (:meth:`Localisation.evidence`),
  and the map proposes walkable places where the scan fits it, which the place code's vote may
  never propose;
- **once anchored**, a running mean of the scan's fit at the estimate is kept: when it falls
  below ``lost_agreement``, the robot anchors afresh; while it is below ``learn_agreement`` the
  cells do not learn (:attr:`Localisation.trusted`);
- **look-alike doubt**: on anchoring, the ``look_alikes`` places where the scan fits the map best
  (at least ``rule_out_radius`` away) are carried along by odometry; when one of them fits better
  than the estimate by ``doubt_margin`` (and, with ``doubt_nearby``, no place that far from the
  estimate fits the scan as well), the estimate is taken to be at a look-alike place;
- **crossings**: a running share of the checks at which rays of the scan pass through walls the
  map holds, one through a wall's middle, while others are short (the world changed round the
  robot); past ``lost_crossing``, the robot anchors afresh, away from the estimate;
- **surprising bumps**: a running rate of bumps where the map shows no wall; past
  ``lost_bump_rate``, the robot anchors afresh.

The fit is a beam model's (Thrun, Burgard and Fox, *Probabilistic Robotics*, ch. 6, as AMCL uses
it): a ray is explained by a wall the map holds where it ended (a hit), by an obstacle the map does
not hold (a short reading: the world changed, or a wrong place), or not at all (a ray through a
wall the map holds: a wrong place, or a wall removed). Short readings weigh ``short_weight``, so new
walls round the robot lower the fit at its true place little, and the map written while it is well
placed (:meth:`ExplorationMap.revise`) soon holds them. An estimate is anchored only on ground the
map knows: a place off the map cannot be where the robot stands.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator
from hippo_agent.sections import Section, param

__all__ = ["Localisation", "LocalisationConfig"]


@dataclass(frozen=True)
class LocalisationConfig(Section):
    """Localisation against the map."""

    name: ClassVar[str] = "localisation"

    beta: float = param(30.0, ge=0)
    """While a run's estimate is lost, each sample is weighed by ``exp(beta * agreement)``, the
    agreement (in [-1, 1]) of the scan with the map seen from there."""
    proposals: int = param(16, ge=0)
    """While lost, the map proposes this many walkable places (of every second map cell), drawn
    with probability ``exp(beta * agreement)``; the belief redraws some samples round them (0: none)."""
    check_every: int = param(2, ge=1)
    """Once anchored, the scan's fit at the estimate is checked every this many steps."""
    fit_rate: float = param(0.1, gt=0, le=1)
    """Rate per step of the running mean of the fit: it spans about 10 steps."""
    lost_agreement: float = param(0.4, ge=-1, le=1)
    """When the running fit falls below this, the estimate is taken to be wrong: anchor afresh."""
    learn_agreement: float = param(0.6, ge=-1, le=1)
    """The cells learn only while the running fit is at least this (-1: whenever anchored): an
    estimate at a look-alike place would teach the place code the wrong place."""
    look_alikes: int = param(8, ge=0)
    """On anchoring in a run, this many places where the scan fits the map best, at least
    ``path_integration.rule_out_radius`` away and apart, are followed beside the estimate (0: off)."""
    doubt_margin: float = param(0.1, ge=0)
    """A look-alike place whose running fit exceeds the estimate's by this takes the anchoring to be wrong."""
    doubt_nearby: float | None = param(0.25, gt=0)
    """Before a look-alike place's better running fit takes the anchoring to be wrong, the scan is
    fitted also at the places this far (m) from the estimate along each axis and diagonal; if one
    of them fits it at least as well as the look-alike place does, the estimate stands (``None``:
    no such check). A look-alike place was picked, on a grid, as the best fit at the
    anchoring: in a maze of identical rooms it can fit its copy of the room better than an
    estimate a few decimetres off the truth fits the true one, and without this check, in 20 m
    mazes of 3 x 3 rooms, such estimates were doubted and anchored afresh a room or two away. It
    also keeps an anchoring in a wrong room that nearby places fit as well as the true one, until
    something else ends it, such as a failed search round the goal (docs/parameters.md)."""
    lost_bump_rate: float | None = param(0.15, gt=0)
    """Anchored in a run, when the running rate of bumps where the map shows no wall exceeds
    this, the estimate is taken to be wrong (``None``: off). A well-placed robot bumps rarely; one
    following its map in the wrong room, often."""
    bump_rate_steps: int = param(50, ge=1)
    """The window (steps) of that running rate."""
    revise_agreement: float = param(0.8, ge=-1, le=1)
    """In runs, the map is revised from the scan (:meth:`ExplorationMap.revise`) only while the fit at
    the estimate, over the rays the map can judge with short readings left out, is at least this:
    rays through the walls it holds, which only a wrong place (or a removed wall) explains, are
    rare. A map revised from a wrong place would drift with the estimate."""
    new_wall_agreement: float = param(0.95, ge=-1, le=1)
    """The same threshold for the map also to gain walls (from boundaries where it knows free ground,
    and from bumps); above ``revise_agreement``: only a scan that crosses no wall the map holds may
    write one. Misplaced by a metre or so among new blocks, the robot sees walls of the map through
    the gaps between them; a map that gained walls from such scans would fit the wrong place next
    time. Walls that are gone are still cleared at ``revise_agreement``: rays through them are the
    evidence."""
    short_weight: float = param(0.25, ge=0, le=1)
    """In runs, how much a reading shorter than the map predicts (a boundary on ground the map
    knows free) counts in the scan's fit, against 1 for a ray through a wall: the beam model's
    "short" readings, explained by an obstacle the map does not hold yet as well as by a wrong
    place (1: a new obstacle counts fully against the place; 0: not at all)."""
    lost_crossing: float | None = param(0.4, ge=0, le=1)
    """Once anchored in a run, when the running share of checks that cross the map's walls where the
    world changed exceeds this, the estimate is taken to be wrong: anchor afresh, away from it
    (``None``: off). A check crosses them when rays pass through walls the map holds, at least one
    through a wall's middle (the fit as ``revise_agreement`` judges it is below ``crossing_fit``: in
    the beam model only a wrong place, or a wall removed, explains such rays) while at least
    ``changed_share`` of the rays are short readings (something the map does not hold)."""
    crossing_fit: float = param(0.9, ge=-1, le=1)
    """A check crosses the map's walls only if the fit at the estimate, over the rays the map can
    judge with short readings left out, is below this."""
    changed_share: float = param(0.05, ge=0, le=1)
    """A check crosses the map's walls only if at least this share of the scan's rays are short
    readings too: where the map holds everything round the robot, rays through a wall's end or along
    a thin wall at a small error in the estimate are common at the true place (a maze's walls), and
    anchoring afresh there only costs steps."""
    crossing_rate: float = param(0.2, gt=0, le=1)
    """Rate per check of the running share of checks that cross the map's walls: it spans about 5 checks."""
    new_wall_weight: float = param(0.5, ge=0, le=1)
    """In runs, how much a reading ending by a wall the map wrote in a run (:attr:`ExplorationMap.new_walls`)
    counts for a place, against 1 for a wall from the dry run: such walls come and go (the blocks of
    an earlier layout may linger in the map), and blocks on a grid repeat, so a place a block's width
    off can fit them as well as the true one."""
    lost_new_wall_weight: float = param(0.0, ge=0, le=1)
    """``new_wall_weight`` while the robot is lost (the samples' weights, the map's proposals): a
    robot put down among blocks that moved since the map wrote them fits a wrong place that holds
    them better than the true place, and anchors there; once anchored, the walls of the layout it
    has seen again count ``new_wall_weight`` in the checks."""


class Localisation:
    """The belief checked against the map (module docstring).

    Args:
        config: its parameters.
        map_: the agent's map.
        pi: the agent's path integrator, whose belief this faculty weighs and may declare lost.
        max_range: the rangefinder's maximum range (m).
        rng: the agent's generator (the map's proposals).
    """

    def __init__(
        self, config: LocalisationConfig, map_: ExplorationMap, pi: PathIntegrator, max_range: float, rng: np.random.Generator
    ) -> None:
        self.config = config
        self.map = map_
        self.pi = pi
        self.max_range = max_range
        self.rng = rng
        self.fit = 1.0  # running mean of how well the scan fits the map at the estimate (runs)
        self.bump_rate = 0.0  # running mean of surprising bumps per step while anchored (runs)
        self.crossing = 0.0  # running share of checks whose scan crosses walls the map holds (runs)
        self.look_alikes = np.empty((0, 2))  # offsets from the estimate of places it may be confused with
        self.look_alike_fit = np.empty(0)  # running means of the scan's fit there
        self.own_fit = 1.0  # the same at the estimate, from its value when they were picked
        self._candidates: np.ndarray | None = None  # walkable map places, cached while the map does not change
        # from check's ray march at the estimate: its fit as placement judges it, the share of short
        # readings and the rays through a wall's middle; and what the fit was for (_key)
        self._judged = np.empty(3)
        self._judged_fit = 1.0
        self._judged_key: tuple[Any, ...] | None = None
        self._judged_ranges: np.ndarray | None = None

    @property
    def trusted(self) -> bool:
        """Anchored, and the scan fits the map well enough for the cells to learn."""
        return self.pi.anchored and self.fit >= self.config.learn_agreement

    def placement(self, ranges: np.ndarray, heading: float) -> tuple[bool, bool]:
        """(whether the map may be revised from this scan, whether it may also gain walls): trusted,
        and the scan at the estimate crosses few walls of the map (``revise_agreement``), or, for new
        walls, fewer still (``new_wall_agreement``)."""
        if not self.trusted:
            return False, False
        fit = self._judged_fit if ranges is self._judged_ranges and self._judged_key == self._key(heading) else None
        if fit is None:
            fit = float(
                self.map.scan_agreement(
                    self.pi.estimate[None, :],
                    heading,
                    ranges,
                    self.max_range,
                    short_weight=0.0,
                    judged_only=True,
                    new_wall_weight=self.config.new_wall_weight,
                )[0]
            )
        return fit >= self.config.revise_agreement, fit >= self.config.new_wall_agreement

    def _key(self, heading: float) -> tuple[Any, ...]:
        """What a fit at the estimate depends on, besides the scan's ranges: heading, estimate, the map's state."""
        return (heading, *self.pi.estimate.tolist(), self.map.revision)

    def reset(self) -> None:
        """A run begins: no doubt yet."""
        self._relocalised()

    def relocalise(self, rule_out: bool = False) -> None:
        """The estimate is taken to be at a look-alike place: anchor afresh (with ``rule_out``,
        away from where the estimate was)."""
        self.pi.lose(rule_out=rule_out)
        self._relocalised()

    def _relocalised(self) -> None:
        self._candidates = None
        self.look_alikes, self.look_alike_fit = np.empty((0, 2)), np.empty(0)
        self.fit = 1.0
        self.bump_rate = 0.0
        self.crossing = 0.0

    # ------------------------------------------------------------------ while lost
    def evidence(
        self, ranges: np.ndarray, heading: float, dry: bool
    ) -> tuple[Callable[[np.ndarray], np.ndarray | None], Callable[[], np.ndarray | None]]:
        """The map's evidence for :meth:`PathIntegrator.correct`: a likelihood of each sample and
        proposed places, both ``None`` (no evidence) in the dry run and once anchored."""

        def likelihood(particles: np.ndarray) -> np.ndarray | None:
            if dry or self.pi.anchored:
                return None
            return np.exp(self.config.beta * self._fit(particles, heading, ranges, lost=True))

        def proposals() -> np.ndarray | None:
            c = self.config
            if c.proposals == 0 or dry or self.pi.anchored:
                return None
            candidates = self._walkable()
            if candidates.shape[0] == 0:
                return None
            fit = self._fit(candidates, heading, ranges, lost=True)
            p = np.exp(c.beta * (fit - fit.max()))
            return candidates[self.rng.choice(fit.size, size=c.proposals, p=p / p.sum())]

        return likelihood, proposals

    def _fit(
        self,
        points: np.ndarray,
        heading: float,
        ranges: np.ndarray,
        around: np.ndarray | None = None,
        judged: np.ndarray | None = None,
        lost: bool = False,
    ) -> np.ndarray:
        """The beam model's fit of the scan to the map from each of ``points`` (:meth:`ExplorationMap.scan_agreement`;
        ``judged``: the first place's fit as :meth:`placement` judges it, from the same ray march)."""
        return self.map.scan_agreement(
            points,
            heading,
            ranges,
            self.max_range,
            around,
            self.config.short_weight,
            judged=judged,
            new_wall_weight=self.config.lost_new_wall_weight if lost else self.config.new_wall_weight,
        )

    def _walkable(self) -> np.ndarray:
        if self._candidates is None:  # (the map does not change while the robot is lost)
            self._candidates = self.map.walkable_points()
        return self._candidates

    # ------------------------------------------------------------------ once anchored
    def check(self, ranges: np.ndarray, heading: float, step: int, dry: bool, just_anchored: bool) -> None:
        """After the belief's correction in a run: on anchoring, pick the look-alike places; every
        ``check_every`` steps, update the running fits and the share of checks crossing the map's
        walls, and anchor afresh if the estimate's fit is too low, that share too high
        (``lost_crossing``) or a look-alike place fits better by ``doubt_margin``."""
        if dry:
            return
        if (
            just_anchored
            and not (self.map.known_ground(self.pi.estimate) and self.map.reaches_dry_ground(self.pi.estimate))
            and self.map.explored_area() > 0.0
        ):
            self.relocalise()  # off the map it holds: not where the robot can stand
            return
        if just_anchored:
            self._pick_look_alikes(ranges, heading)
        every = self.config.check_every
        if not self.pi.anchored or step % every:
            return
        c = self.config
        fits = self._fit(self.look_alikes, heading, ranges, around=self.pi.estimate, judged=self._judged)
        judged_fit, short_share, middles = self._judged.tolist()
        self._judged_fit, self._judged_key, self._judged_ranges = judged_fit, self._key(heading), ranges
        rate = min(1.0, c.fit_rate * every)
        own, *others = fits.tolist()  # (the estimate's fit, then the look-alike places'; floats: faster than NumPy on a few values)
        self.fit = (1.0 - rate) * self.fit + rate * own
        if c.lost_crossing is not None:
            crossing = judged_fit < c.crossing_fit and short_share >= c.changed_share and middles > 0
            self.crossing += c.crossing_rate * (float(crossing) - self.crossing)
        if self.fit < c.lost_agreement:
            self.relocalise()
        elif c.lost_crossing is not None and self.crossing > c.lost_crossing:
            self.relocalise(rule_out=True)
        elif len(self.look_alikes):
            self.own_fit = (1.0 - rate) * self.own_fit + rate * own
            running = [(1.0 - rate) * old + rate * new for old, new in zip(self.look_alike_fit.tolist(), others)]
            self.look_alike_fit = np.array(running)
            if max(running) > self.own_fit + c.doubt_margin and not self._fits_nearby(heading, ranges, max(others)):
                self.relocalise(rule_out=True)

    def _fits_nearby(self, heading: float, ranges: np.ndarray, fit: float) -> bool:
        """Whether the scan fits the map at least ``fit`` at one of the places ``doubt_nearby`` from
        the estimate along each axis and diagonal (``False`` without ``doubt_nearby``, and where at
        least ``changed_share`` of the scan's rays are short readings: where the world may have
        changed, the doubt stands as it is)."""
        d = self.config.doubt_nearby
        if d is None or self._judged[1] >= self.config.changed_share:
            return False
        around = np.array([(dx, dy) for dx in (-d, 0.0, d) for dy in (-d, 0.0, d) if dx or dy])
        return bool(np.max(self._fit(around, heading, ranges, around=self.pi.estimate)[1:]) >= fit)

    def _pick_look_alikes(self, ranges: np.ndarray, heading: float) -> None:
        """Remember, as offsets from the estimate, the ``look_alikes`` places at least
        ``rule_out_radius`` away (and apart) where the scan fits the map best."""
        c, radius = self.config, self.pi.config.rule_out_radius
        self.look_alikes, self.look_alike_fit = np.empty((0, 2)), np.empty(0)
        if c.look_alikes == 0:
            return
        candidates = self._walkable()
        fit = self._fit(candidates, heading, ranges)
        offsets = candidates - self.pi.estimate
        chosen: list[int] = []
        for i in np.argsort(-fit, kind="stable"):
            if all(math.hypot(*(offsets[i] - offsets[j])) > radius for j in chosen) and math.hypot(*offsets[i]) > radius:
                chosen.append(int(i))
                if len(chosen) == c.look_alikes:
                    break
        if chosen:
            self.look_alikes = offsets[chosen]
            self.look_alike_fit = fit[chosen]
            self.own_fit = float(self._fit(self.pi.estimate[None, :], heading, ranges)[0])

    def count_bump(self, surprising: bool) -> None:
        """A step of a run while anchored: the running rate of bumps where the map shows no wall;
        past ``lost_bump_rate``, anchor afresh."""
        c = self.config
        if c.lost_bump_rate is None:
            return
        self.bump_rate += (float(surprising) - self.bump_rate) / c.bump_rate_steps
        if self.bump_rate > c.lost_bump_rate:
            self.relocalise()

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        return {"fit": self.fit, "bump_rate": self.bump_rate, "own_fit": self.own_fit, "crossing": self.crossing}, {
            "look_alikes": self.look_alikes,
            "look_alike_fit": self.look_alike_fit,
        }

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        self.fit, self.bump_rate, self.own_fit = float(state["fit"]), float(state["bump_rate"]), float(state["own_fit"])
        self.crossing = float(state.get("crossing", 0.0))  # (saves before 0.17 hold none)
        offsets = np.asarray(arrays["look_alikes"], dtype=np.float64).reshape(-1, 2)
        fits = np.asarray(arrays["look_alike_fit"], dtype=np.float64).reshape(-1)
        if len(offsets) != len(fits) or not (np.all(np.isfinite(offsets)) and np.all(np.isfinite(fits))):
            raise ValueError(f"{len(offsets)} look-alike places but {len(fits)} fits to them, or values not finite")
        self.look_alikes, self.look_alike_fit = offsets, fits
        self._candidates = None
