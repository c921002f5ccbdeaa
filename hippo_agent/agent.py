"""HippocampalAgent: the paper's model plus faculties, as a policy for ``HippoMaze-v0``.

The agent follows the protocol in :mod:`hippo_env.agent_protocol` (``dry_run``, ``start_trial``,
``reset``, ``act``, ``observe``). It sees only the observation (the rangefinder scan, the compass
heading and, with path integration, the wheel odometry), the reward, and the bump sensor
``info["collision"]``; never the position or the goal.

This module is the loop only. Each step:

1. **sense**: the scan and the compass drive the BVCs and head-direction cells (eqs. 1-2);
2. **localise**: the place cells update (eqs. 3-4), with path integration's drive once its
   belief, checked against the map, is anchored;
3. **learn**: eqs. 5-7 while the place code is trusted; the faculties take in the step (the
   map, the dry run's recruitment, the bump reflexes, homing's bookkeeping); on reward,
   replay (Algorithm 1);
4. **choose** (in :meth:`HippocampalAgent.act`): the behaviours in priority order, the first
   with a heading wins: an escape after a bump, homing, preplay (eqs. 8-11), directed
   exploration, the random walk;
5. **act**: the heading as an action.

The paper's model is in :mod:`hippo_agent.paper_model`, each faculty in :mod:`hippo_agent.faculties`;
``docs/model.md`` has a table of where each behaviour lives.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from hippo_agent import analysis, persistence, spaces
from hippo_agent.cells import BoundaryVectorCells, HeadDirectionCells, PlaceCells, RewardCells
from hippo_agent.config import AgentConfig
from hippo_agent.faculties.exploration import Exploration
from hippo_agent.faculties.homing import Homing
from hippo_agent.faculties.localisation import Localisation
from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator, odometry_step
from hippo_agent.faculties.reflexes import Reflexes
from hippo_agent.faculties.worlds import Worlds
from hippo_agent.paper_model import PaperModel
from hippo_env.checks import check_int
from hippo_env.dmtp import rollout

__all__ = ["DRY_RUN_STEPS", "HippocampalAgent", "Senses"]

DRY_RUN_STEPS = 10_000
"""The dry run's steps when ``model.dry_run_steps`` is None (at least, with directed exploration)."""


@dataclass
class Senses:
    """One step's senses, as every part reads them."""

    ranges: np.ndarray
    """The rangefinder scan (egocentric: ray ``i`` along ``heading + 2 pi i / n``)."""
    heading_vec: np.ndarray
    """The compass heading as (cos, sin)."""
    heading: float
    """The compass heading (rad)."""
    b: np.ndarray
    """The BVC rates (eq. 2)."""
    h: np.ndarray
    """The head-direction rates (eq. 1)."""
    bumped: bool
    """The bump sensor (``info["collision"]``)."""
    odometry: Any
    """The wheel odometry (forward, left) in metres, if the observation holds it."""


class HippocampalAgent:
    """The hippocampal navigation model as an agent for ``HippoMaze-v0``.

    Args:
        observation_space: ``Dict(ranges=Box(0, max_range, (n_rays,)), heading=Box(-1, 1, (2,)))``,
            with ``odometry=Box(..., (2,))`` for path integration.
        action_space: ``Discrete(n)`` (action k = allocentric heading ``2*pi*k/n``; the env's
            ``Discrete(8)``) or ``Box(-pi, pi, (1,))`` (the heading itself). Anything else, e.g. the
            wheels ``Box(-1, 1, (2,))``, raises ``ValueError``.
        config: the model's parameters; ``None`` = ``AgentConfig()``, the default model;
            ``AgentConfig.paper()`` is the paper's model.
        seed: seed of the agent's one random generator (initial ``W_pb``, exploration, stochastic
            rounding); ``None`` = fresh entropy.

    Attributes:
        model: the paper's model (:class:`~hippo_agent.paper_model.PaperModel`); ``hd``, ``bvc``,
            ``place`` and ``reward`` are its four cell populations.
        pi, map, localisation, exploration, homing, reflexes: the faculties (``None`` when off).
        last_decision: which behaviour chose the last action: ``"explore"``, ``"exploit"`` or ``"home"``.
        episode_stats: counters for the current run (steps per behaviour, bumps, replays).
    """

    def __init__(self, observation_space: Any, action_space: Any, config: AgentConfig | None = None, seed: int | None = None) -> None:
        config = AgentConfig() if config is None else config
        if not isinstance(config, AgentConfig):
            raise TypeError(f"config must be an AgentConfig, got {type(config).__name__}")
        self.seed = None if seed is None else check_int(seed, "seed", 0, "None or an integer >= 0")
        self.config = c = config
        self.n_rays, self.max_range, self.has_odometry = spaces.check_observation_space(observation_space)
        self.action_kind, self.n_actions = spaces.check_action_space(action_space)
        if c.path_integration is not None and not self.has_odometry:
            raise ValueError(
                "the observation space has no 'odometry', which path integration (AgentConfig.path_integration) needs: make the "
                "env with gym.make('HippoMaze-v0', odometry=True), or use AgentConfig.paper() (the model without path integration)"
            )
        self.observation_space, self.action_space = observation_space, action_space
        self.rng = np.random.default_rng(seed)
        self.model = PaperModel(c.model, self.n_rays, self.max_range, self.rng)
        self.reflexes = Reflexes(c.reflexes) if c.reflexes else None
        self.pi = PathIntegrator(c.path_integration, c.model.n_place, c.model.k, self.rng) if c.path_integration else None
        self.map = ExplorationMap(c.map) if c.map else None
        self.localisation = self.exploration = self.homing = self.worlds = None
        if self.pi is not None and self.map is not None:  # (AgentConfig checks that the faculties that need them have them)
            self.localisation = Localisation(c.localisation, self.map, self.pi, self.max_range, self.rng) if c.localisation else None
            self.exploration = Exploration(c.exploration, self.map, self.pi, self.model, self.rng) if c.exploration else None
            self.homing = Homing(c.homing, self.map, self.pi, self.localisation) if c.homing else None
            self.worlds = Worlds(c.worlds, self.map, self.pi, self.model, self.homing, self.max_range) if c.worlds else None
        self.phase = "trial"  # "dry" inside dry_run(), else "trial"
        self.trial = -1
        self.started = False  # reset() has been called for the current run
        self.senses: Senses | None = None  # the last step's
        self.last_decision = "explore"
        self.episode_stats = _new_stats()
        self.total_steps = 0

    # ------------------------------------------------------------------ the paper's cells
    @property
    def hd(self) -> HeadDirectionCells:
        """The head-direction cells (eq. 1)."""
        return self.model.hd

    @property
    def bvc(self) -> BoundaryVectorCells:
        """The boundary vector cells (eq. 2)."""
        return self.model.bvc

    @property
    def place(self) -> PlaceCells:
        """The place cells (eqs. 3-8)."""
        return self.model.place

    @property
    def reward(self) -> RewardCells:
        """The reward cells (eqs. 9, 11, Algorithm 1)."""
        return self.model.reward

    # ------------------------------------------------------------------ the protocol
    def dry_run(self, env: Any) -> None:
        """Goal-free exploration with no reward learning: the random walk for
        ``model.dry_run_steps`` steps or, with directed exploration, the sweep and its transits
        until they are done (at most ``model.dry_run_steps`` steps; by default a cap that grows
        with the ground the map finds), then rest. Resets ``env`` with
        ``options={"goal": None}`` (and again whenever it truncates). With the faculty ``worlds``,
        a world the agent knows (recognised by its first scan) needs no dry run: the agent enters
        it and returns."""
        if self.config.model.dry_run_steps == 0:
            return
        obs, info = env.reset(options={"goal": None})
        if self.worlds is not None and self.map is not None and self.map.explored_area() > 0.0:
            obs, info, known = self._which_world(env, obs, info)
            if known:
                return
        self.phase = "dry"
        if self.exploration is not None:
            self.exploration.start_dry_run()
        try:
            self.reset(obs, info)
            taken = 0
            while taken < self._dry_run_cap() and not self._dry_run_done():
                end = rollout(env, self, obs, max_steps=self._dry_run_cap() - taken, keep_going=lambda: not self._dry_run_done())
                taken += end.steps
                obs = end.observation
                if end.terminated or end.truncated:
                    obs, info = env.reset(options={"goal": None})
                    self.reset(obs, info)
            if self.exploration is not None and self.config.model.learn_pp_in_dry_run:
                self.exploration.rest()
        finally:
            if self.exploration is not None:
                self.exploration.end_dry_run()
            if self.map is not None:
                self.map.end_dry_run()
            self.phase = "trial"
            self.started = False

    def _dry_run_cap(self) -> int:
        """The dry run's most steps: ``model.dry_run_steps``; if None, :data:`DRY_RUN_STEPS` or,
        with directed exploration, more as the map finds more ground."""
        steps = self.config.model.dry_run_steps
        if steps is not None:
            return steps
        if self.exploration is not None and self.map is not None:
            return max(DRY_RUN_STEPS, int(self.exploration.config.dry_run_steps_per_m2 * self.map.explored_area()))
        return DRY_RUN_STEPS

    def _which_world(self, env: Any, obs: dict, info: dict) -> tuple[dict, dict, bool]:
        """Before a dry run, with a world mapped already: a glimpse of ``worlds.glimpse_steps``
        steps of the random walk, then enter the known world it fits (``True``: no dry run
        needed) or start a new one. Returns the last observation, its info, and whether the world is known."""
        assert self.worlds is not None
        ranges, _, heading = spaces.unpack(obs)
        self.worlds.start_glimpse(ranges, heading)
        walk = self.model.walk
        done = self.worlds.config.glimpse_steps == 0
        while not done:
            action = spaces.to_action(walk.step(), self.action_kind, self.n_actions, self.config.model.discrete_rounding, self.rng)
            obs, _, terminated, truncated, info = env.step(action)
            ranges, heading_vec, heading = spaces.unpack(obs)
            if info.get("collision", False):
                walk.turn_at_random()
            done = self.worlds.add_to_glimpse(ranges, heading, odometry_step(obs["odometry"], heading_vec))
            if terminated or truncated:
                obs, info = env.reset(options={"goal": None})
                break
        known = self.worlds.recognise()
        self.worlds.glimpse = []
        if known is None:
            self.worlds.new_world()
        else:
            self.worlds.enter(known)
            self.started = False
        return obs, info, known is not None

    def _dry_run_done(self) -> bool:
        return self.exploration is not None and self.exploration.stage == "done"

    def start_trial(self, trial: int) -> None:
        """A new DMTP trial: the goal has moved, so a new reward cell (and memory) takes over."""
        self.trial = int(trial)
        self.model.new_goal()
        if self.homing is not None:
            self.homing.new_goal()

    def reset(self, observation: dict, info: dict | None = None) -> None:
        """A run begins: the robot was put down somewhere; the network settles on its first scan."""
        senses = self._sense(observation, info)
        if self.worlds is not None:  # a glimpse of the run's first steps tells which world this is
            self.worlds.glimpse = []
            if self.phase == "trial" and self.worlds.kept:
                self.worlds.start_glimpse(senses.ranges, senses.heading)
        for faculty in (self.reflexes, self.localisation, self.homing):
            if faculty is not None:
                faculty.reset()
        if self.map is not None:
            self.map.new_run()
        self._settle(senses)
        self.model.start_run(senses.h, senses.heading)
        self.last_decision = "explore"
        self.episode_stats = _new_stats()
        self.started = True

    def act(self, observation: dict) -> Any:
        """Choose an action for the observation last given to ``reset`` / ``observe``."""
        if not self.started:
            self.reset(observation, {})
        heading, self.last_decision = self._choose()
        self.episode_stats[self.last_decision] += 1
        return spaces.to_action(heading, self.action_kind, self.n_actions, self.config.model.discrete_rounding, self.rng)

    def observe(self, action: Any, observation: dict, reward: float, terminated: bool, truncated: bool, info: dict) -> None:
        """Sense, localise and learn from the new observation; replay on reward."""
        senses = self._sense(observation, info)
        if self.worlds is not None and self.worlds.glimpse:
            self._glimpse(senses)
        trusted = self._localise(senses)
        dry = self.phase == "dry"
        self.model.learn(senses.b, senses.h, trusted, dry, senses.bumped)  # eqs. 5-7
        if self.pi is not None and trusted:
            self.pi.learn_centres(self.model.place)
        self._take_in(senses)
        if reward > 0 and not dry:
            self._rewarded(trusted)
        self.total_steps += 1
        if terminated or truncated:
            self.started = False

    # ------------------------------------------------------------------ the steps
    def _sense(self, observation: dict, info: dict | None) -> Senses:
        ranges, heading_vec, heading = spaces.unpack(observation)
        b, h = self.model.sense(ranges, heading_vec, heading)  # eqs. 1-2
        odometry = observation.get("odometry") if isinstance(observation, dict) else None
        self.senses = Senses(ranges, heading_vec, heading, b, h, bool(info.get("collision", False)) if info else False, odometry)
        return self.senses

    def _settle(self, s: Senses) -> None:
        """A run's first scan: the place cells from rest; with path integration, the belief is put
        down afresh (a kidnap, but for the agent's first run, which sets the frame), corrected by
        the place code's vote, and the cells settle again with its drive once anchored."""
        place = self.model.place
        place.reset_state()
        if self.pi is None:
            self.model.settle(s.b)  # eqs. 3-4
            return
        self.pi.start_run()
        place.settle_sense(s.b, self.config.model.settle_steps)
        self.pi.correct(*self.pi.vote(place), *self._evidence(s))
        if self.pi.anchored:
            self.model.settle(s.b, self.pi.drive())

    def _glimpse(self, s: Senses) -> None:
        """A step of a run's glimpse; at its end, move to another known world if that fits it
        better (the estimate anchored afresh in that world's map)."""
        assert self.worlds is not None
        if not self.worlds.add_to_glimpse(s.ranges, s.heading, odometry_step(s.odometry, s.heading_vec)):
            return
        other = self.worlds.elsewhere()
        self.worlds.glimpse = []
        if other is not None:
            self.worlds.enter(other)
            for faculty in (self.localisation, self.homing):
                if faculty is not None:
                    faculty.reset()
            if self.map is not None:
                self.map.new_run()

    def _localise(self, s: Senses) -> bool:
        """The place cells' update (eqs. 3-4) and, with path integration, the belief's: moved by
        odometry, corrected by the place code's vote (and the map's evidence while lost), checked
        against the map. Returns whether the place code may learn (anchored and not doubted)."""
        place = self.model.place
        if self.pi is None:
            self.model.step(s.b)
            return True
        if s.odometry is None:
            raise ValueError("observation must hold 'odometry' (forward, left) in metres: path integration needs it")
        pi, localisation = self.pi, self.localisation
        pi.move_by_odometry(s.odometry, s.heading_vec)
        place.step_sense(s.b)  # what the boundary code alone says
        was_anchored = pi.anchored
        if was_anchored:
            pi.correct_anchored(place)
        else:
            pi.correct(*pi.vote(place), *self._evidence(s))
        if localisation is not None:
            localisation.check(s.ranges, s.heading, self.total_steps, self.phase == "dry", pi.anchored and not was_anchored)
        if pi.anchored:
            pi.drive_place(place)  # (the drive of :meth:`PathIntegrator.drive`, and the update)
        else:
            place.step_driven(None)
        return localisation.trusted if localisation is not None else pi.anchored

    def _evidence(self, s: Senses) -> tuple[Any, Any]:
        """The map's evidence for the belief's correction, if localisation is on (else none);
        none once anchored (:meth:`Localisation.evidence` gives none then)."""
        if self.localisation is None or (self.pi is not None and self.pi.anchored):
            return None, None
        return self.localisation.evidence(s.ranges, s.heading, self.phase == "dry")

    def _take_in(self, s: Senses) -> None:
        """The faculties take in the step: the map, the dry run's recruitment and place codes,
        surprising bumps (localisation, homing), and the bump's reflexes (the walk's random turn,
        the escape)."""
        dry = self.phase == "dry"
        pi = self.pi
        # a bump where the map shows no wall is evidence of a look-alike place (a wall it holds explains the bump)
        surprising = s.bumped and (
            self.map is None or pi is None or not self.map.wall_near(pi.estimate, s.heading, self.map.config.bump_distance)
        )
        # in runs the map is revised only where the robot is well placed (a misplaced scan would
        # write walls where there are none); the ground it passes counts as searched once anchored
        if self.map is not None and pi is not None and pi.anchored:
            mapping = not dry and self.total_steps % self.map.config.run_every == 0
            well_placed, walls_too = self._placement(s) if (mapping or s.bumped) and not dry else (False, False)  # (one fit a step)
            if dry:
                self.map.observe(pi.estimate, s.heading, s.ranges, self.max_range)
            elif mapping:
                mark = self.homing.search_mark if self.homing is not None else None
                if well_placed:
                    self.map.revise(pi.estimate, s.heading, s.ranges, self.max_range, search_radius=mark, write_new=walls_too)
                else:
                    self.map.mark(pi.estimate, search_radius=mark)
            if dry and self.exploration is not None:
                extra = self.exploration.recruits(self.total_steps)
                if extra:
                    self.grow_place_cells(extra)
                self.exploration.remember_code()
            if s.bumped and (dry or (self.map.config.new_wall_evidence is not None and walls_too)):
                self.map.mark_bump(pi.estimate, s.heading, self.map.config.bump_distance, new=not dry)
        if self.localisation is not None and not dry and pi is not None and pi.anchored:
            self.localisation.count_bump(surprising)
        if s.bumped:
            self.episode_stats["bumps"] += 1
            if self.homing is not None and self.last_decision == "home" and self.homing.bumped(surprising):
                self._misplaced()
            self.model.walk.turn_at_random()
            if self.reflexes is not None:
                self.reflexes.bumped(self.last_decision)

    def _placement(self, s: Senses) -> tuple[bool, bool]:
        """In a run: whether the map may be revised from this step's senses, and whether it may also
        gain walls (:meth:`Localisation.placement`)."""
        if self.localisation is not None:
            return self.localisation.placement(s.ranges, s.heading)
        anchored = bool(self.pi and self.pi.anchored)
        return anchored, anchored

    def _rewarded(self, trusted: bool) -> None:
        """The reward: replay (Algorithm 1) writes the goal's reward map, and homing remembers
        the place. A memory given up in this run is replaced, not added to."""
        if trusted and self.homing is not None and self.homing.gave_up:
            self.model.reward.forget_current()
            self.homing.forget()
        self.learn_reward()
        if self.homing is not None and self.pi is not None and trusted:
            self.homing.remember(self.pi.estimate)

    def learn_reward(self) -> bool:
        """Backward replay (Algorithm 1) from the current place rates into the current goal's
        reward cell; ``False`` if no place cell was active (nothing to learn)."""
        learnt = self.model.replay()
        self.episode_stats["replays"] += learnt
        return learnt

    def _misplaced(self) -> None:
        """Homing found its estimate wrong: anchor afresh, away from where it was."""
        if self.localisation is not None:
            self.localisation.relocalise(rule_out=True)
        elif self.pi is not None:
            self.pi.lose(rule_out=True)

    def _choose(self) -> tuple[float, str]:
        """The behaviours in priority order; the first with a heading wins. The walk carries on
        from whatever heading won."""
        walk = self.model.walk
        if self.reflexes is not None and self.reflexes.escape():
            return walk.step(), "explore"
        if self.phase == "trial" and (self.homing is None or not self.homing.gave_up):
            if self.homing is not None:
                if self.homing.plan():
                    self._misplaced()
                if self.homing.heading is not None:
                    walk.follow(self.homing.heading, length_later=True)
                    return self.homing.heading, "home"
            heading = self.model.preplay()  # eqs. 8-10
            if heading is not None:
                self.model.depress()  # eq. 11
                if self.reflexes is not None and self.senses is not None:
                    heading = self.reflexes.clear(heading, self.senses.ranges, self.senses.heading)
                walk.new_segment(heading)
                return heading, "exploit"
        if self.exploration is not None and self.pi is not None and self.pi.anchored:
            heading = self.exploration.plan(self.phase == "dry")
            if heading is not None:
                walk.follow(heading)
                return heading, "explore"
        return walk.step(), "explore"

    def restore_senses(self, ranges: np.ndarray, heading_vec: np.ndarray) -> None:
        """Take back the last scan as :meth:`save` kept it (the clearance reflex reads it when the
        agent next acts)."""
        ranges, heading_vec = np.asarray(ranges), np.asarray(heading_vec, dtype=np.float64)
        if (
            ranges.shape != (self.n_rays,)
            or heading_vec.shape != (2,)
            or not (np.all(np.isfinite(ranges)) and np.all(np.isfinite(heading_vec)))
        ):
            raise ValueError(
                f"the last scan has shape {ranges.shape} (expected ({self.n_rays},)) or its heading {heading_vec} is not finite"
            )
        heading = math.atan2(float(heading_vec[1]), float(heading_vec[0]))
        self.senses = Senses(ranges, heading_vec, heading, self.model.bvc.rates, self.model.hd.rates, False, None)

    def grow_place_cells(self, extra: int) -> None:
        """Add ``extra`` place cells (with their reward weights and, with path integration, room
        for their centres)."""
        self.model.grow(extra)
        if self.pi is not None:
            self.pi.grow(extra)

    # ------------------------------------------------------------------ analysis
    @property
    def place_rates(self) -> np.ndarray:
        """The place cells' current rates (a copy)."""
        return self.model.place.v.copy()

    def place_rates_at(self, observation: dict, pi_position: np.ndarray | None = None) -> np.ndarray:
        """Steady-state place rates for an observation, from rest; the agent's state is untouched.

        ``pi_position`` is the path-integrated position to assume there (frame coordinates);
        ``None`` = the boundary code alone (also whenever path integration is off).
        """
        ranges, _, heading = spaces.unpack(observation)
        b = self.model.bvc.rates_for(ranges, heading)
        extra = self.pi.drive(pi_position) if self.pi is not None and pi_position is not None else None
        return self.model.place.rates_for(b, self.config.model.analysis_settle_steps, extra)

    def value_at(self, observation: dict, goal: int = -1, pi_position: np.ndarray | None = None) -> float:
        """Reward cell ``goal``'s rate (eq. 9, undepressed weights) at an observation."""
        if self.model.reward.n == 0:
            return 0.0
        v = self.place_rates_at(observation, pi_position)
        return float(self.model.reward.value(v, self.model.reward.W_rp[goal]))

    def frame_offset(self, env: Any) -> np.ndarray:
        """Where the path-integration frame's origin lies in the world (analysis only, privileged):
        the robot's true position minus the agent's current estimate."""
        if self.pi is None:
            raise ValueError("frame_offset needs path integration (AgentConfig.path_integration)")
        return np.asarray(env.unwrapped.world.position, dtype=np.float64) - self.pi.estimate

    def place_field_map(self, env: Any, positions: np.ndarray, heading: float = 0.0) -> np.ndarray:
        """Place rates at each position, shape ``(len(positions), n_place)``, NaN rows where the env
        rejects a position (see :func:`hippo_agent.analysis.place_field_map`)."""
        return analysis.place_field_map(self, env, positions, heading)

    def reward_map(self, env: Any, positions: np.ndarray, goal: int = -1, heading: float = 0.0) -> np.ndarray:
        """Reward cell ``goal``'s value (eq. 9) at each position, NaN where the env rejects it
        (see :func:`hippo_agent.analysis.reward_map`)."""
        return analysis.reward_map(self, env, positions, goal, heading)

    # ------------------------------------------------------------------ save / load
    def save(self, path: str | os.PathLike) -> None:
        """Write the whole agent (weights, state, generator state, config) to ``path`` (npz):
        each part saves its own state; :meth:`load` restores an agent whose future behaviour is
        identical (:mod:`hippo_agent.persistence`)."""
        persistence.save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> HippocampalAgent:
        """Read an agent written by :meth:`save`; a corrupt, truncated or foreign file raises ``ValueError``."""
        return persistence.load(cls, path)


def _new_stats() -> dict[str, int]:
    return {"explore": 0, "exploit": 0, "home": 0, "bumps": 0, "replays": 0}
