"""HippocampalAgent: the paper's model (head direction, BVC, place and reward cells) as a policy.

The agent follows the protocol in :mod:`hippo_env.agent_protocol` (``dry_run`` / ``start_trial`` /
``reset`` / ``act`` / ``observe``). It sees only the observation (the rangefinder scan and the
compass heading), the reward, and the bump sensor ``info["collision"]``; never the position or
the goal.

Behaviour (paper section "Modes of Operation"):

- ``dry_run(env)``: the dry run. Goal-free exploration for ``config.dry_run_steps`` steps with only
  the BVC -> place weights plastic (eq. 5), to clean up the place fields.
- ``start_trial``: a new DMTP trial; a new reward cell for the new goal.
- Each step, if the current goal's reward map is known where the agent is, it preplays one step
  in each of the ``n_hd`` directions (eq. 8), reads their values (eq. 9), heads along their
  value-weighted circular mean (eq. 10) and depresses the active cells' reward weights (eq. 11).
  Otherwise (no reward map yet, i.e. run 1, or values below ``xi``) it explores: straight
  segments of 5-10 steps, then a N(0, 30 deg) turn; a bump starts a new segment in a random
  direction.
- In runs (not the dry run) the place-place tensor learns (eq. 7) on every step without a bump,
  and on reward the agent replays backward (Algorithm 1) to add to the goal's reward weights.

The model does one place-cell update per environment step.

Two settings (:class:`~hippo_agent.config.AgentConfig`): ``AgentConfig.paper()`` is the model as
the paper describes it. The default adds, beyond the paper:

- **path integration** (``cells/path_integration.py``): the wheel odometry (the env's opt-in
  ``odometry`` observation) rotated by the compass moves a position estimate in the agent's own
  frame. Each place cell learns where in that frame it fires (its centre) and gets an extra drive,
  positive near its centre, negative far from it and silencing beyond ``pi_field_radius``, so a
  distant place that merely looks alike no longer fires it. At each run's start the robot has
  been put down somewhere unknown: the place code driven by the BVCs alone votes for positions
  (the centres of its active cells) until one candidate holds most of the belief; until then the
  path-integration input and all plasticity are off, and the place-cell trace is held at zero.
  Afterwards the same vote keeps correcting the estimate.
- **directed exploration and localisation against its map** (``explore.py``): the dry run maps
  the maze from the rangefinder and sweeps it; while a run's estimate is lost, the map also
  proposes and weighs candidate places by how well the scan fits it there (look-alike rooms
  differ in their doors); a poor fit later re-opens the question, and the cells learn only while
  the scan fits the map.
- **latent learning**: the place-place tensor also learns during the dry run, so replay spreads
  over everything explored, along the paths actually walked.
- **homing**: at each reward the agent remembers its estimate; in later runs it heads there
  along its map, searches round the place if the reward is not there, and anchors afresh if
  that search finds nothing or the way its map showed free keeps bumping into walls.

What each setting measures, per maze, is in the README and ``benchmarks/results/``.
"""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from hippo_agent import analysis, persistence
from hippo_agent.cells import BoundaryVectorCells, HeadDirectionCells, PathIntegrator, PlaceCells, RewardCells, _kernels
from hippo_agent.config import AgentConfig
from hippo_agent.explore import ExplorationMap
from hippo_env.checks import check_int
from hippo_env.dmtp import rollout
from hippo_env.geometry import wrap_angle

__all__ = ["HippocampalAgent"]


def _describe_space(space: Any) -> str:
    return str(space)


class HippocampalAgent:
    """The hippocampal navigation model as an agent for ``HippoMaze-v0``.

    Args:
        observation_space: ``Dict(ranges=Box(0, max_range, (n_rays,)), heading=Box(-1, 1, (2,)))``.
        action_space: ``Discrete(n)`` (action k = allocentric heading ``2*pi*k/n``; the env's
            ``Discrete(8)``) or ``Box(-pi, pi, (1,))`` (the heading itself). Anything else, e.g. the
            wheels ``Box(-1, 1, (2,))``, raises ``ValueError``.
        config: the model's parameters; ``None`` = ``AgentConfig()``.
        seed: seed of the agent's one random generator (initial ``W_pb``, exploration, stochastic
            rounding); ``None`` = fresh entropy.

    Attributes:
        hd, bvc, place, reward: the four cell populations (``hippo_agent.cells``).
        last_decision: ``"explore"`` or ``"exploit"``, how the last action was chosen.
        episode_stats: counters for the current run (explore/exploit steps, bumps).
    """

    def __init__(
        self,
        observation_space: Any,
        action_space: Any,
        config: AgentConfig | None = None,
        seed: int | None = None,
    ) -> None:
        if config is None:
            config = AgentConfig()
        if not isinstance(config, AgentConfig):
            raise TypeError(f"config must be an AgentConfig, got {type(config).__name__}")
        if seed is not None:
            seed = check_int(seed, "seed", 0, "None or an integer >= 0")
        self.config = config
        self.seed = seed
        self.n_rays, self.max_range, self.has_odometry = self._check_observation_space(observation_space)
        self.action_kind, self.n_actions = self._check_action_space(action_space)
        if config.path_integration and not self.has_odometry:
            raise ValueError(
                "the observation space has no 'odometry', which AgentConfig.path_integration=True needs: make the env "
                "with gym.make('HippoMaze-v0', odometry=True), or use AgentConfig.paper() (the model without path integration)"
            )
        self.observation_space = observation_space
        self.action_space = action_space

        self.rng = np.random.default_rng(seed)
        c = config
        self.hd = HeadDirectionCells(n=c.n_hd)
        self.bvc = BoundaryVectorCells(n_rays=self.n_rays, max_range=self.max_range, **c.bvc_kwargs())
        self.place = PlaceCells(c.n_place, self.bvc.n, c.n_hd, self.rng, **c.place_kwargs())
        self.reward = RewardCells(c.n_place)
        self.pi = PathIntegrator(c.pi_particles, self.rng, **c.path_integrator_kwargs())
        self.map = ExplorationMap(**c.map_kwargs()) if c.exploration == "directed" else None
        self._directions = self.hd.preferred  # theta^h: the preplay / exploitation directions
        self._dir_cos = np.cos(self._directions)
        self._dir_sin = np.sin(self._directions)

        # behaviour state
        self.phase = "trial"  # "dry" inside dry_run(), else "trial"
        self.trial = -1
        self.goal_rewarded = False  # the current goal's reward map has been learnt at least once
        self.started = False  # reset() has been called for the current run
        self.intended_heading = 0.0  # exploration's continuous intended heading (rad)
        self.segment_left = 0  # exploration steps left in the current straight segment (-1: not drawn yet)
        self.escape_left = 0  # exploration steps left after a bump while exploiting
        self.homing_done = False  # this run reached the remembered goal place without reward
        self.memory_failures = 0  # searches round the remembered place that found no reward, this run
        self.homing_bumps = 0  # bumps while homing since the last failed search, this run
        self.heading = 0.0  # last observed compass heading (rad)
        self.last_decision = "explore"
        self.last_values = np.zeros(c.n_hd)
        self.episode_stats = {"explore": 0, "exploit": 0, "home": 0, "bumps": 0, "replays": 0}
        self.total_steps = 0
        # the directed dry run: "sweep" (to unvisited ground), then "transit", then "done"
        self.dry_stage = "sweep"
        self.sweep_steps = 0  # steps the sweep took
        self.transit_left = 0  # transit steps still to go
        self.transit_target = -1  # the current transit's destination (a map cell), -1 = none
        self.plan_failures = 0  # consecutive steps with nowhere to go
        self.fit = 1.0  # running mean of how well the scan fits the map at the estimate (runs)
        self.bump_rate = 0.0  # running mean of bumps per step while anchored (runs)
        self._scan: tuple[np.ndarray, float] | None = None  # the scan being processed: (ranges, heading)
        self._candidates: np.ndarray | None = None  # walkable map places, while the estimate is lost
        self.look_alikes = np.empty((0, 2))  # offsets from the estimate of places it may be confused with (runs)
        self.look_alike_fit = np.empty(0)  # running means of the scan's fit to the map there
        self.own_fit = 1.0  # the same at the estimate, from its value when they were picked (``fit`` starts at 1)
        self.codes: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # dry run: map cell -> place code there (active cells, rates)

    # ================================================================== spaces
    @staticmethod
    def _check_observation_space(space: Any) -> tuple[int, float, bool]:
        import gymnasium as gym

        allowed = "a gymnasium Dict(ranges=Box(0, max_range, (n_rays,)), heading=Box(-1, 1, (2,))), optionally with odometry=Box(..., (2,))"
        if not isinstance(space, gym.spaces.Dict):
            raise TypeError(f"observation space {_describe_space(space)} is unsupported; allowed: {allowed}")
        keys = set(space.spaces)
        if keys not in ({"ranges", "heading"}, {"ranges", "heading", "odometry"}):
            raise ValueError(f"observation space {_describe_space(space)} is unsupported; allowed: {allowed}")
        boxes: dict[str, gym.spaces.Box] = {}
        for key, box in space.spaces.items():
            if not isinstance(box, gym.spaces.Box):
                raise TypeError(f"observation space {key!r} {_describe_space(box)} is unsupported; allowed: a Box")
            boxes[key] = box
        ranges, heading, odometry = boxes["ranges"], boxes["heading"], boxes.get("odometry")
        if len(ranges.shape) != 1 or ranges.shape[0] < 8:
            raise ValueError(
                f"observation space 'ranges' {_describe_space(ranges)} is unsupported; allowed: a 1-D Box with at least 8 rays"
            )
        if heading.shape != (2,):
            raise ValueError(
                f"observation space 'heading' {_describe_space(heading)} is unsupported; "
                "allowed: Box(-1, 1, (2,)) holding (cos, sin) of the heading"
            )
        max_range = float(np.max(ranges.high))
        if not (math.isfinite(max_range) and max_range > 0):
            raise ValueError(f"observation space 'ranges' has upper bound {max_range}; allowed: a finite max range > 0")
        if odometry is not None and odometry.shape != (2,):
            raise ValueError(
                f"observation space 'odometry' {_describe_space(odometry)} is unsupported; "
                "allowed: Box(low, high, (2,)) holding the (forward, left) displacement in metres"
            )
        return int(ranges.shape[0]), max_range, odometry is not None

    @staticmethod
    def _check_action_space(space: Any) -> tuple[str, int]:
        import gymnasium as gym

        allowed = (
            "Discrete(n) with start 0 (action k = heading 2*pi*k/n, the env's action_type='discrete') "
            "or Box(-pi, pi, (1,)) (action_type='heading')"
        )
        if isinstance(space, gym.spaces.Discrete):
            if int(space.start) != 0 or int(space.n) < 4:
                raise ValueError(f"action space {_describe_space(space)} is unsupported; allowed: {allowed}")
            return "discrete", int(space.n)
        if isinstance(space, gym.spaces.Box) and space.shape == (1,):
            lo, hi = float(space.low[0]), float(space.high[0])
            if lo <= -math.pi + 1e-3 and hi >= math.pi - 1e-3:
                return "heading", 1
        if not isinstance(space, gym.spaces.Box):
            raise TypeError(f"action space {_describe_space(space)} is unsupported; allowed: {allowed}")
        raise ValueError(f"action space {_describe_space(space)} is unsupported; allowed: {allowed}")

    # ================================================================== protocol
    def dry_run(self, env: Any) -> None:
        """The dry run: goal-free exploration with no reward learning.

        With ``exploration="random"``, ``config.dry_run_steps`` steps of random exploration. With
        ``"directed"``, a sweep to every place the map shows but the robot has not been near, then
        transits across the known ground (``config.transit_factor``), ending when both are done
        or after ``config.dry_run_steps`` steps. Resets ``env`` with ``options={"goal": None}``
        (and again whenever it truncates).
        """
        if self.config.dry_run_steps == 0:
            return
        self.phase = "dry"
        self.dry_stage = "sweep"
        self.sweep_steps = self.transit_left = self.plan_failures = 0
        self.transit_target = -1
        try:
            obs, info = env.reset(options={"goal": None})
            self.reset(obs, info)
            remaining = self.config.dry_run_steps
            while remaining > 0 and self.dry_stage != "done":
                end = rollout(env, self, obs, max_steps=remaining, keep_going=lambda: self.dry_stage != "done")
                remaining -= end.steps
                obs = end.observation
                if end.terminated or end.truncated:
                    obs, info = env.reset(options={"goal": None})
                    self.reset(obs, info)
            if self.map is not None and self.config.learn_pp_in_dry_run:
                self.rest()
        finally:
            self.codes = {}
            self.phase = "trial"
            self.started = False

    def start_trial(self, trial: int) -> None:
        """A new DMTP trial: the goal has moved, so a new reward cell takes over."""
        self.trial = int(trial)
        self.reward.add_goal()
        self.goal_rewarded = False

    def reset(self, observation: dict, info: dict | None = None) -> None:
        """A run begins: rest the network, settle it on the first observation, new segment."""
        self.place.reset_state()
        ranges, heading_vec, heading = self._unpack(observation)
        b = self.bvc.update(ranges, heading)
        h = self.hd.update(heading_vec)
        if self.config.path_integration:
            # put down somewhere: the boundary code alone votes where in the frame that is
            self.pi.start_run()
            self.fit = 1.0
            self.bump_rate = 0.0
            self._scan = (ranges, heading)
            self.place.step_with_sense(b, lambda: None, self.config.settle_steps)
            self._candidates = None
            self._forget_look_alikes()
            self.pi.correct(
                *self.place.sensory_vote(self.config.pi_min_mass), likelihood=self._map_likelihood, proposals=self._map_proposals
            )
            if self.pi.anchored:
                self.place.settle(b, self._pi_input(), self.config.settle_steps)
        else:
            self.place.step(b, self.config.settle_steps)
        self.place.update_hd_trace(h)
        self.reward.reset_effective()
        if self.map is not None:
            self.map.new_run()
        self.heading = heading
        self._new_segment(heading)
        self.last_decision = "explore"
        self.escape_left = 0
        self.homing_done = False
        self.homing_bumps = 0
        self.memory_failures = 0
        self.last_values = np.zeros(self.config.n_hd)
        self.episode_stats = {"explore": 0, "exploit": 0, "home": 0, "bumps": 0, "replays": 0}
        self.started = True

    def act(self, observation: dict) -> Any:
        """Choose an action for the observation last given to ``reset`` / ``observe``."""
        if not self.started:
            self.reset(observation, {})
        heading = None
        escaping = self.escape_left > 0
        if escaping:
            self.escape_left -= 1
        elif self.phase == "trial" and self.memory_failures < self.config.home_attempts:
            heading = self._home_heading()
            if heading is not None:
                self.last_decision = "home"
            else:
                heading = self._exploit_heading()
                self.last_decision = "exploit"
        if heading is None:
            heading = self._random_heading() if escaping else self._explore_heading()
            self.last_decision = "explore"
        self.episode_stats[self.last_decision] += 1
        return self._to_action(heading)

    def observe(
        self,
        action: Any,
        observation: dict,
        reward: float,
        terminated: bool,
        truncated: bool,
        info: dict,
    ) -> None:
        """Update every cell population from the new observation; learn; replay on reward."""
        c = self.config
        collision = bool(info.get("collision", False)) if info else False
        ranges, heading_vec, heading = self._unpack(observation)
        self.heading = heading
        b = self.bvc.update(ranges, heading)
        h = self.hd.update(heading_vec)
        plastic = True
        if c.path_integration:
            self.pi.move(self._odometry_step(observation, heading_vec))
            self._scan = (ranges, heading)
            self.place.step_with_sense(b, self._corrected_pi_input)
            # no learning while the robot does not know where it is, or doubts it (the scan fits the map poorly)
            plastic = self.pi.anchored and self.fit >= c.learn_agreement
        else:
            self.place.step(b)
        dry = self.phase == "dry"
        if plastic and (dry or c.learn_pb_in_trials):
            self.place.learn_pb(b)
        if plastic and c.path_integration:
            self.place.learn_centres(self.pi.lagged_estimate(), c.pi_centre_max_mass, spread=c.pi_vote_by_spread)
        self.place.update_hd_trace(h)
        learn_pp = (not dry or c.learn_pp_in_dry_run) and (c.learn_pp_in_exploitation or self.last_decision == "explore")
        if plastic and learn_pp and not collision:  # no W_pp learning against a wall (model-figures)
            self.place.learn_pp()
        if c.path_integration and not plastic:
            # a code the robot does not trust (lost, or the scan fits the map poorly) may be a
            # look-alike place's: traced, eq. 7 would link it to the next trusted code, far away
            self.place.trace[:] = 0.0
        else:
            self.place.update_trace()
        # evidence of a look-alike place: a bump where the map shows no wall (a wall it holds explains the bump)
        surprising_bump = collision and (self.map is None or not self.map.wall_near(self.pi.estimate, heading, c.map_bump_distance))
        if self.map is not None and self.pi.anchored:
            if dry or self.total_steps % c.run_map_every == 0:
                mark = c.home_search_mark if self.homing_done else None
                self.map.observe(self.pi.estimate, heading, ranges, self.max_range, not (dry or c.map_in_runs), mark)
            if dry:
                if self.total_steps % c.recruit_every == 0:
                    self._recruit()
                active = np.flatnonzero(self.place.v > 0.0)
                self.codes[self.map.flat_index(*self.pi.lagged_estimate())] = (active, self.place.v[active])
            if collision and (dry or c.map_in_runs):
                self.map.mark_bump(self.pi.estimate, heading, c.map_bump_distance)
        if self.map is not None and not dry and self.pi.anchored and c.lost_bump_rate > 0:
            self.bump_rate += (float(surprising_bump) - self.bump_rate) / c.bump_rate_steps
            if self.bump_rate > c.lost_bump_rate:
                self._relocalise()  # walls where the map shows free ground: a look-alike place
        if collision:  # a bump: a random turn and a new segment (and a short escape if exploiting)
            self.episode_stats["bumps"] += 1
            if self.last_decision == "home":
                self.homing_bumps += surprising_bump
                if self.homing_bumps >= c.home_bump_limit:
                    self._memory_failed()  # the map's free way was not free: a look-alike place
                elif not self.homing_done and self._home_distance() <= c.search_radius:
                    self._start_local_search()  # on the last straight stretch: as near the place as the wall lets it
            self.intended_heading = float(self.rng.uniform(-math.pi, math.pi))
            self.segment_left = int(self.rng.integers(c.segment_min, c.segment_max + 1))
            if self.last_decision == "exploit" or self.map is not None:
                self.escape_left = c.bump_escape_steps
        if reward > 0 and not dry:
            if plastic and self.memory_failures >= c.home_attempts:
                self.reward.forget_current()  # the memory led nowhere: this find replaces it
            self.learn_reward()
            if c.path_integration and plastic:
                self.reward.remember_place(self.pi.estimate)
        self.total_steps += 1
        if terminated or truncated:
            self.started = False

    # ================================================================== path integration
    def _odometry_step(self, observation: dict, heading_vec: np.ndarray) -> np.ndarray:
        """The allocentric displacement: the encoders' (forward, left) rotated by the compass."""
        try:
            forward, left = np.asarray(observation["odometry"], dtype=np.float64).tolist()  # (floats: faster arithmetic)
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError("observation must hold 'odometry' (forward, left) in metres: path integration needs it") from exc
        hx, hy = heading_vec.tolist()
        norm = math.hypot(hx, hy) or 1.0
        c, s = hx / norm, hy / norm
        return np.array([c * forward - s * left, s * forward + c * left])

    def _pi_input(self) -> np.ndarray:
        c = self.config
        return self.place.pi_input(self.pi.estimate, c.pi_gain, c.pi_sigma, c.pi_threshold, c.pi_field_radius, c.pi_far_inhibition)

    def _corrected_pi_input(self) -> np.ndarray | None:
        """Correct the estimate with the BVC-only vote just computed (and, while not anchored in a
        run, with the exploration map, :meth:`_map_likelihood`); the path-integration drive if
        anchored, else ``None`` (the boundary code alone drives the place cells)."""
        was_anchored = self.pi.anchored
        self.pi.correct(*self.place.sensory_vote(self.config.pi_min_mass), likelihood=self._map_likelihood, proposals=self._map_proposals)
        if self.pi.anchored and not was_anchored:
            self._pick_look_alikes()
        self._check_localisation()
        return self._pi_input() if self.pi.anchored else None

    def _map_likelihood(self, particles: np.ndarray) -> np.ndarray | None:
        """While a run's estimate is not anchored: how well the current scan fits the exploration
        map from each sample, ``exp(map_beta * agreement)``, so that of the look-alike places the
        place code votes for, the one whose surroundings match wins. ``None`` otherwise."""
        if self.map is None or self.phase == "dry" or self.pi.anchored or self._scan is None:
            return None
        ranges, heading = self._scan
        return np.exp(self.config.map_beta * self.map.scan_agreement(particles, heading, ranges, self.max_range))

    def _map_proposals(self) -> np.ndarray | None:
        """While a run's estimate is not anchored: ``map_proposals`` walkable places drawn with
        probability ``exp(map_beta * agreement)`` of the current scan with the exploration map
        there (global localisation from the map, which also holds the places the place code's
        vote leaves out, and every look-alike of them). ``None`` when off."""
        c = self.config
        if self.map is None or c.map_proposals == 0 or self.phase == "dry" or self.pi.anchored or self._scan is None:
            return None
        if self._candidates is None:  # the map does not change while the robot is lost
            self._candidates = self.map.walkable_points()
        if self._candidates.shape[0] == 0:
            return None
        ranges, heading = self._scan
        fit = self.map.scan_agreement(self._candidates, heading, ranges, self.max_range)
        p = np.exp(c.map_beta * (fit - fit.max()))
        return self._candidates[self.rng.choice(fit.size, size=c.map_proposals, p=p / p.sum())]

    def _pick_look_alikes(self) -> None:
        """Just anchored in a run: remember, as offsets from the estimate, the ``doubt_look_alikes``
        places at least ``pi_rule_out_radius`` away (and apart) where the scan fits the map best,
        the look-alikes the anchoring may have confused with the true place (:meth:`_check_localisation`)."""
        c = self.config
        self._forget_look_alikes()
        if c.doubt_look_alikes == 0 or self.map is None or self.phase == "dry" or self._scan is None:
            return
        if self._candidates is None:
            self._candidates = self.map.walkable_points()
        ranges, heading = self._scan
        fit = self.map.scan_agreement(self._candidates, heading, ranges, self.max_range)
        offsets = self._candidates - self.pi.estimate
        chosen: list[int] = []
        for i in np.argsort(-fit, kind="stable"):
            if (
                all(math.hypot(*(offsets[i] - offsets[j])) > c.pi_rule_out_radius for j in chosen)
                and math.hypot(*offsets[i]) > c.pi_rule_out_radius
            ):
                chosen.append(int(i))
                if len(chosen) == c.doubt_look_alikes:
                    break
        if chosen:
            self.look_alikes = offsets[chosen]
            self.look_alike_fit = fit[chosen]
            self.own_fit = float(self.map.scan_agreement(self.pi.estimate[None, :], heading, ranges, self.max_range)[0])

    def _forget_look_alikes(self) -> None:
        self.look_alikes, self.look_alike_fit = np.empty((0, 2)), np.empty(0)

    def _check_localisation(self) -> None:
        """In a run, once anchored: a running mean of how well the scan fits the map at the
        estimate; when it falls below ``lost_agreement``, or the same mean at one of the
        look-alike places (:meth:`_pick_look_alikes`, carried along by odometry) exceeds it by
        ``doubt_margin``, the estimate is at a look-alike place: anchor afresh elsewhere."""
        every = self.config.run_map_every
        if self.map is None or self.phase == "dry" or not self.pi.anchored or self._scan is None or self.total_steps % every:
            return
        ranges, heading = self._scan
        fits = self.map.scan_agreement(self.look_alikes, heading, ranges, self.max_range, around=self.pi.estimate)
        rate = min(1.0, self.config.map_fit_rate * every)
        own = float(fits[0])
        self.fit = (1.0 - rate) * self.fit + rate * own
        if self.fit < self.config.lost_agreement:
            self._relocalise()
        elif len(self.look_alikes):
            self.own_fit = (1.0 - rate) * self.own_fit + rate * own
            # (in floats: faster than NumPy on a few values)
            running = [(1.0 - rate) * old + rate * new for old, new in zip(self.look_alike_fit.tolist(), fits.tolist()[1:])]
            self.look_alike_fit = np.array(running)
            if max(running) > self.own_fit + self.config.doubt_margin:
                self._relocalise(rule_out=True)

    def _relocalise(self, rule_out: bool = False) -> None:
        """The estimate is taken to be at a look-alike place: anchor afresh from the map (with
        ``rule_out``, away from the place the estimate was at)."""
        self.pi.lose(rule_out=rule_out)
        self._candidates = None
        self._forget_look_alikes()
        self.fit = 1.0
        self.bump_rate = 0.0

    # ================================================================== learning
    def learn_reward(self) -> bool:
        """Backward replay (Algorithm 1) from the current place rates into the current goal's
        reward cell. Returns ``False`` if no place cell was active (nothing to learn)."""
        learnt = self.reward.learn(self.place.v, self.place.replay_links, self.config.replay_iterations, self.config.tau_r)
        if learnt:
            self.goal_rewarded = True
            self.episode_stats["replays"] += 1
        return learnt

    # ================================================================== decisions
    def _exploit_heading(self) -> float | None:
        """One-step preplay (eqs. 8-10) and depression (eq. 11); ``None`` means explore."""
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
        if best < c.xi:
            return None
        self.reward.depress(v, c.lambda_)  # eq. 11
        if c.exploit_clearance > 0.0 and self._scan is not None:
            a_star = self._clear_heading(a_star, *self._scan)
        self._new_segment(a_star)  # if exploration takes over, it starts from here
        return a_star

    def _home_heading(self) -> float | None:
        """Toward where the current goal's reward was found (by path integration).

        Within ``home_radius`` of that place: straight at it while the line to within
        ``search_radius`` of it crosses walkable ground only, a cell to spare on either side
        (:meth:`ExplorationMap.in_sight`), else along the map's walkable path to
        ground within ``search_radius`` of it (the place, where the robot entered the goal disk, may
        lie by a wall, off the walkable map), then straight on. Once there (``home_arrived``), or stopped by
        a wall on that last stretch, without the reward: a local search, the nearest ground within
        ``home_search_radius`` not yet searched (afresh, marked ``home_search_mark`` wide). When
        none is left, or after ``home_bump_limit`` bumps while homing, the agent anchors afresh;
        after ``home_attempts`` such failures :meth:`act` stops asking for the rest of the run.
        ``None`` farther away, with no known path, while the estimate is lost or doubted, and on
        anchoring afresh."""
        c = self.config
        if c.home_radius <= 0.0 or self.map is None:
            return None
        target = self.reward.remembered_place()
        if target is None or not self.pi.anchored or self.fit < c.learn_agreement:
            return None
        here = self.pi.estimate
        distance = self._home_distance(target)
        if distance > c.home_radius:
            return None
        if distance < c.home_arrived and not self.homing_done:
            self._start_local_search()
        if self.homing_done:
            heading = self.map.heading_to_unsearched_near(here, target, c.home_search_radius)
            if heading is None:
                self._memory_failed()  # searched all round the place without finding the reward
        elif distance <= c.search_radius:
            heading = math.atan2(target[1] - here[1], target[0] - here[0])  # straight on; a bump ends homing
        elif self.map.in_sight(here, self._toward(here, target, distance - c.search_radius)):
            heading = math.atan2(target[1] - here[1], target[0] - here[0])  # walkable all the way: straight at it
        else:
            # the place itself may be by a wall, off the walkable map: path to walkable ground
            # within search_radius of it, the ground from which the robot goes straight on
            heading = self.map.heading_to_near(here, target, c.search_radius)
            if heading is None:
                return None  # no known path: preplay or exploration instead of pushing at a wall
        if heading is not None:
            # if exploration takes over, it goes on this way; its segment's length is drawn then
            self.intended_heading, self.segment_left = heading, -1
        return heading

    @staticmethod
    def _toward(start: np.ndarray, end: np.ndarray, length: float) -> tuple[float, float]:
        """The point ``length`` metres from ``start`` toward ``end``."""
        x, y = float(start[0]), float(start[1])
        dx, dy = float(end[0]) - x, float(end[1]) - y
        f = length / math.hypot(dx, dy)
        return x + f * dx, y + f * dy

    def _memory_failed(self) -> None:
        """Homing led nowhere: the estimate is most likely at a look-alike place; anchor afresh
        elsewhere (``pi_rule_out_radius``), and home again once anchored (up to ``home_attempts``
        times in a run)."""
        self._relocalise(rule_out=True)
        self.homing_done = False
        self.homing_bumps = 0
        self.memory_failures += 1

    def _home_distance(self, target: np.ndarray | None = None) -> float:
        """How far (m, by path integration) the remembered place of the current goal (``target``,
        if already looked up) is; inf if none."""
        target = self.reward.remembered_place() if target is None else target
        if target is None:
            return math.inf
        here = self.pi.estimate
        return float(np.hypot(float(target[0]) - float(here[0]), float(target[1]) - float(here[1])))

    def _start_local_search(self) -> None:
        """Arrived at the remembered place without the reward: search all round it afresh."""
        self.homing_done = True
        target = self.reward.remembered_place()
        if self.map is not None and target is not None:
            self.map.forget_searched_near(target, self.config.home_search_radius)

    def _clear_heading(self, heading: float, ranges: np.ndarray, facing: float) -> float:
        """``heading`` if the scan (``ranges``, ray 0 along ``facing``) shows ``exploit_clearance``
        metres free within 15 degrees of it; else the nearest heading (in 15 degree steps, up to 90
        either way) that does, or ``heading`` if none does. A reflex: eq. 10's mean of two open
        directions at a corner points at the corner's wall."""
        n = ranges.size
        half_cone = max(1, n // 24)
        for turn in (0.0, 15.0, -15.0, 30.0, -30.0, 45.0, -45.0, 60.0, -60.0, 75.0, -75.0, 90.0, -90.0):
            a = heading + math.radians(turn)
            centre = round(((a - facing) % (2.0 * math.pi)) / (2.0 * math.pi) * n)
            if np.min(ranges.take(np.arange(centre - half_cone, centre + half_cone + 1), mode="wrap")) >= self.config.exploit_clearance:
                return a
        return heading

    def _new_segment(self, heading: float) -> None:
        c = self.config
        self.intended_heading = float(heading)
        self.segment_left = int(self.rng.integers(c.segment_min, c.segment_max + 1))

    def _explore_heading(self) -> float:
        """Directed exploration where the map can plan (:meth:`_directed_heading`), else straight
        segments of ``segment_min..segment_max`` steps, then a N(0, sigma) turn."""
        if self.map is not None and self.pi.anchored:
            heading = self._directed_heading()
            if heading is not None:
                self.intended_heading = heading
                return heading
        return self._random_heading()

    def _directed_heading(self) -> float | None:
        """Where the map says to go next, or ``None`` for a random step.

        Dry run: the sweep heads for the nearest ground not yet visited, over walkable cells or,
        when none is left that way, through any free cell that is not a wall (a doorway too narrow
        for walkable cells would otherwise end the sweep with the rooms beyond it unvisited); once
        none is reachable (for ``sweep_patience`` steps in a row) transits to random visited places
        follow, for ``transit_factor`` times the sweep's steps; then the dry run is done. A run: the nearest
        ground not searched in this run, over walkable cells or, when none is left that way, through
        any free cell that is not a wall; once everything is searched, the search starts afresh (the
        marking radius is wider than the goal disk, so one pass can miss it).
        """
        assert self.map is not None  # directed exploration only
        here = self.pi.estimate
        if self.phase != "dry":
            heading = self.map.heading_to_unvisited(here, this_run=True)
            if heading is None:  # a doorway too narrow for walkable cells may wall the robot in
                heading = self.map.heading_to_unvisited(here, this_run=True, squeeze=True)
            if heading is None:  # everything searched and no goal: search again
                self.map.new_run()
                heading = self.map.heading_to_unvisited(here, this_run=True, squeeze=True)
            return heading
        if self.dry_stage == "sweep":
            heading = self.map.heading_to_unvisited(here)
            if heading is None:
                heading = self.map.heading_to_unvisited(here, squeeze=True)
            self.sweep_steps += 1
            if heading is not None:
                self.plan_failures = 0
                return heading
            self.plan_failures += 1
            if self.plan_failures < self.config.sweep_patience:
                return None
            self.dry_stage = "transit"
            self.transit_left = math.ceil(self.config.transit_factor * self.sweep_steps)
        if self.transit_left <= 0:
            self.dry_stage = "done"
            return None
        self.transit_left -= 1
        heading = self.map.heading_to(here, self.transit_target) if self.transit_target >= 0 else None
        if heading is None:  # arrived, or the destination cannot be reached: a new one
            self.transit_target = self._transit_destination(here)
            heading = self.map.heading_to(here, self.transit_target) if self.transit_target >= 0 else None
        return heading

    def _transit_destination(self, here: np.ndarray) -> int:
        """A random visited place at least ``transit_min_distance`` away along the known ground
        (a map cell's flat index), or -1 if there is none."""
        assert self.map is not None  # directed exploration only
        cells, steps = self.map.reachable_visited(here)
        far = cells[steps * self.config.map_cell >= self.config.transit_min_distance]
        if far.size == 0:
            return -1
        return int(far[self.rng.integers(far.size)])

    def _recruit(self) -> None:
        """Recruit place cells up to ``place_cells_per_m2`` of the free ground the map knows
        (at least ``recruit_min`` at a time, at most ``max_place_cells`` in all)."""
        assert self.map is not None  # directed exploration only
        c = self.config
        wanted = min(math.ceil(c.place_cells_per_m2 * self.map.explored_area()), c.max_place_cells)
        if wanted > self.place.n:
            self.grow_place_cells(min(max(wanted - self.place.n, c.recruit_min), c.max_place_cells - self.place.n))

    def grow_place_cells(self, extra: int) -> None:
        """Add ``extra`` place cells (:meth:`PlaceCells.grow`) and their reward weights."""
        self.place.grow(extra, self.rng)
        self.reward.grow(extra)

    def rest(self) -> None:
        """Imagined transits at rest, after the directed dry run: sequences of remembered place
        codes along shortest paths across the map, between random visited places, with the
        place-place rule (eq. 7) on. Nothing moves: no environment step is taken.

        Rats replay, at rest, sequences through places they know, including routes they never
        ran (shortcuts). Here the sequence is read from the map: every ``imagined_step`` metres
        along the path, the place code the dry run last saw in that map cell (cells without one
        are passed over). ``rest_factor`` imagined steps per step of the sweep. Why: one sweep lays
        place-place links along one path only; replay then spreads value along the sweep's
        lanes, not along direct routes, and links laid by walking direct routes (transits) are
        what made later runs direct, at the cost of environment steps.
        """
        assert self.map is not None  # directed exploration only
        c = self.config
        budget = round(c.rest_factor * self.sweep_steps)
        if budget <= 0 or not self.codes:
            return
        place = self.place
        saved = place.v, place.trace, place.hd_trace
        remembered = np.fromiter(self.codes.keys(), dtype=np.int64)
        try:
            for _ in range(budget):  # (at most as many transits as steps: each usually takes dozens)
                if budget <= 0:
                    break
                start = self.map.centre(int(remembered[self.rng.integers(remembered.size)]))
                target = self._transit_destination(np.asarray(start))
                if target < 0:
                    break
                path = np.array([self.map.centre(cell) for cell in self.map.path(np.asarray(start), target)])
                lengths = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))))
                along = np.arange(0.0, lengths[-1], c.imagined_step)
                points = np.column_stack([np.interp(along, lengths, path[:, 0]), np.interp(along, lengths, path[:, 1])])
                place.trace = np.zeros(place.n)
                place.hd_trace = np.zeros(place.n_hd)
                for k in range(1, points.shape[0]):
                    code = self.codes.get(self.map.flat_index(*points[k]))
                    if code is None:
                        continue
                    dx, dy = points[k] - points[k - 1]
                    place.v = np.zeros(place.n)
                    place.v[code[0]] = code[1]
                    place.update_hd_trace(self.hd.rates_for(np.array([dx, dy]) / math.hypot(dx, dy)))
                    place.learn_pp()  # eq. 7
                    place.update_trace()  # eq. 6
                    budget -= 1
        finally:
            place.v, place.trace, place.hd_trace = saved

    def _random_heading(self) -> float:
        """Straight segments of ``segment_min..segment_max`` steps, then a N(0, sigma) turn."""
        c = self.config
        if self.segment_left < 0:  # homing's heading: a segment along it, of a length drawn now
            self.segment_left = int(self.rng.integers(c.segment_min, c.segment_max + 1))
        elif self.segment_left == 0:
            turn = self.rng.normal(0.0, math.radians(c.turn_sigma_deg))
            self.intended_heading = wrap_angle(self.intended_heading + turn)
            self.segment_left = int(self.rng.integers(c.segment_min, c.segment_max + 1))
        self.segment_left -= 1
        return self.intended_heading

    def _to_action(self, heading: float) -> Any:
        """Turn an allocentric heading into an action of the action space."""
        if self.action_kind == "heading":
            return np.array([wrap_angle(heading)], dtype=np.float32)
        x = (heading % (2.0 * math.pi)) / (2.0 * math.pi / self.n_actions)
        if self.config.discrete_rounding == "nearest":
            k = math.floor(x + 0.5)
        else:  # stochastic rounding: the expected direction is the intended one
            lo = math.floor(x)
            k = lo + int(self.rng.random() < x - lo)
        return int(k % self.n_actions)

    # ================================================================== observation
    def _unpack(self, observation: dict) -> tuple[np.ndarray, np.ndarray, float]:
        try:
            ranges = np.asarray(observation["ranges"])
            heading_vec = np.asarray(observation["heading"], dtype=np.float64)
        except (KeyError, TypeError, IndexError) as exc:
            raise ValueError("observation must be a dict with 'ranges' (n_rays,) and 'heading' (cos, sin)") from exc
        if heading_vec.shape != (2,):
            raise ValueError(f"observation 'heading' has shape {heading_vec.shape}; expected (2,)")
        heading = math.atan2(float(heading_vec[1]), float(heading_vec[0]))
        return ranges, heading_vec, heading

    # ================================================================== analysis
    @property
    def place_rates(self) -> np.ndarray:
        """The place cells' current rates (a copy)."""
        return self.place.v.copy()

    def place_rates_at(self, observation: dict, pi_position: np.ndarray | None = None) -> np.ndarray:
        """Steady-state place rates for an observation, from rest; the agent's state is untouched.

        ``pi_position`` is the path-integrated position to assume there (frame coordinates);
        ``None`` = the boundary code alone (also whenever path integration is off).
        """
        ranges, _, heading = self._unpack(observation)
        b = self.bvc.rates_for(ranges, heading)
        extra = None
        if self.config.path_integration and pi_position is not None:
            c = self.config
            extra = self.place.pi_input(
                np.asarray(pi_position, dtype=np.float64), c.pi_gain, c.pi_sigma, c.pi_threshold, c.pi_field_radius, c.pi_far_inhibition
            )
        return self.place.rates_for(b, self.config.analysis_settle_steps, extra)

    def value_at(self, observation: dict, goal: int = -1, pi_position: np.ndarray | None = None) -> float:
        """Reward cell ``goal``'s rate (eq. 9, undepressed weights) at an observation."""
        if self.reward.n == 0:
            return 0.0
        v = self.place_rates_at(observation, pi_position)
        return float(self.reward.value(v, self.reward.W_rp[goal]))

    def frame_offset(self, env: Any) -> np.ndarray:
        """Where the path-integration frame's origin lies in the world (analysis only, privileged):
        the robot's true position minus the agent's current estimate."""
        return np.asarray(env.unwrapped.world.position, dtype=np.float64) - self.pi.estimate

    def place_field_map(self, env: Any, positions: np.ndarray, heading: float = 0.0) -> np.ndarray:
        """Place rates at each position, shape ``(len(positions), n_place)``, NaN rows where the env
        rejects a position (see :func:`hippo_agent.analysis.place_field_map`)."""
        return analysis.place_field_map(self, env, positions, heading)

    def reward_map(self, env: Any, positions: np.ndarray, goal: int = -1, heading: float = 0.0) -> np.ndarray:
        """Reward cell ``goal``'s value (eq. 9) at each position, NaN where the env rejects it
        (see :func:`hippo_agent.analysis.reward_map`)."""
        return analysis.reward_map(self, env, positions, goal, heading)

    # ================================================================== save / load
    def save(self, path: str | os.PathLike) -> None:
        """Write the whole agent (weights, state, generator state, config) to ``path`` (npz).

        The file holds the arrays plus a JSON metadata entry with a format tag and version;
        :meth:`load` restores an agent whose future behaviour is identical (``hippo_agent.persistence``).
        """
        persistence.save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> HippocampalAgent:
        """Read an agent written by :meth:`save`; a corrupt, truncated or foreign file raises
        ``ValueError``."""
        return persistence.load(cls, path)
