"""Why the hippocampal agent finds its way, or does not: the model's diagnosis in one maze.

Runs DMTP trials with the agent, watching it from outside (this harness reads the true position;
the agent never does) and measures, per maze:

- **across walls**: the mean place-code cosine of places less than 1.6 m apart in a straight line
  but more than 2 m apart by path (the two sides of a thin wall).
- **twins**: the share of places (a 0.5 m grid over the free space) whose place code has a
  distant look-alike: another place more than 2 m away by path whose place-rate vector has cosine
  > 0.5 with it. Measured after each trial's last run on the code the agent navigates with (with path
  integration: as if localised there), and on the boundary code alone (``twins_bvc``).
- **reward map** after run 1: ``coverage`` (share of places with value > ``xi_here``) and
  ``spearman`` (rank correlation of value with the geodesic distance to the goal over covered
  places; -1 = perfectly graded toward the goal).
- **replay reach**: for replay iteration t of run 1's replay, the median and 90th-percentile
  geodesic distance from the goal of the field peaks of the cells replay has reached.
- **preplay progress**: on exploiting steps of runs 2-4, the mean geodesic progress toward the
  goal per step, as a share of the step's length (1 = straight down the shortest path). A mean:
  the geodesic is read from a 0.1 m grid, so one step's progress takes only a few values, and
  their median says little.
- **exploit**: in runs 2-4, the share of steps where the agent fell back to exploring, the share
  it homed (the default model, near where the goal was found), and bumps per exploiting step.
- **path integration**: the median and 90th-percentile distance between the estimate and the true
  position in the agent's frame over the anchored steps of the DMTP runs (the dry run's, whose frame
  starts where the robot stands, separately), the share of runs *misplaced* (anchored more than
  1 m off on most of their steps), and the steps from a run's start to anchoring; the share of
  the anchored steps within 0.5 m of the truth, the share of all the runs' steps that were (the
  steps before anchoring count as not), and the share of anchored steps whose estimate lies off
  the ground the agent's map knows (``ExplorationMap.known_ground``), and off the ground it knew at
  the end of the dry run (a misplaced robot's scans add ground to the map where its frame puts it).
- **dry-run coverage**: the share of the free ground the robot's centre came within 0.5 m of
  against dry-run steps (``benchmarks.coverage``): steps to 80 % and 95 % and the share at the dry
  run's end, median over trials, and a figure of the curves beside the JSON (``.coverage.png``).
- ``--oracle`` (PRIVILEGED, a ceiling for diagnosis only): the same agent whose path-integration
  estimate is replaced by the true position at every step (exact self-localisation), with the
  doubt about look-alike places off (``localisation.look_alikes = 0``): a look-alike place can fit the
  agent's own map better than the true position, and the doubt would then re-anchor an estimate
  that cannot be wrong; and with ``map.dry_reachable_only`` off, for the same reason.

``python -m benchmarks.diagnose --maze maze2 --trials 10 --seed 0`` prints the figures and writes
``benchmarks/results/diagnose/<maze>[-paper|-oracle].json``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from benchmarks.common import REPO, command_line, load_average, machine_info, parse_dataclass_args
from benchmarks.coverage import coverage_curve, plot_curves, steps_to
from benchmarks.maze_suite import maze_source
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_agent.faculties.path_integration import PathIntegrator
from hippo_env.dmtp import run_dmtp
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS
from hippomaze.stats import median_or_none, spearman

TWIN_PATH = 2.0  # m by path: farther than this, a look-alike is a twin
TWIN_COSINE = 0.5
ACROSS_STRAIGHT = 1.6  # m in a straight line (on the 0.5 m grid the nearest places on the two sides of a 0.3 m wall are 1.5 m apart)
SAMPLE_SPACING = 0.5  # m between sampled places
GRAPH_SPACING = 0.1  # m, grid of the geodesic graph
MISPLACED = 1.0  # m: a run whose path-integration estimate is mostly farther off than this is misplaced


@dataclasses.dataclass
class DiagnoseArgs:
    maze: str = "maze2"
    """built-in maze, a JSON path, or a generated maze by the suite's name (gen-rooms-105, gen-arena-108-20m)"""
    trials: int = 10
    """DMTP trials (each a fresh agent)"""
    seed: int = 0
    """seeds goals, starts and agents"""
    paper: bool = False
    """diagnose AgentConfig.paper() (no path integration) instead of the default model"""
    oracle: bool = False
    """PRIVILEGED ceiling: the path-integration estimate is the true position"""
    dry_run_steps: int = -1
    """dry-run steps (-1: the config's default)"""
    config: str = ""
    """more AgentConfig fields as JSON, by dotted name, e.g. '{"path_integration.gain": 2.0}'"""
    out: str = ""
    """output JSON ('' = benchmarks/results/diagnose/<maze>[-paper|-oracle].json)"""


# ------------------------------------------------------------------ geometry (analysis only)
def path_distances(spec: MazeSpec, sources: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Geodesic distance matrix ``(len(sources), len(targets))`` on a ``GRAPH_SPACING`` grid of the free space."""
    return np.array([spec.distance_field(source, ROBOT_RADIUS, GRAPH_SPACING).at(targets) for source in np.asarray(sources, float)])


def sample_places(spec: MazeSpec, spacing: float = SAMPLE_SPACING) -> np.ndarray:
    """Free places on a grid (clearance of at least 0.3 m)."""
    xs, ys, free = spec.free_grid(0.3, spacing)
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx[free], gy[free]])


def across_walls(rates: np.ndarray, places: np.ndarray, path_distance: np.ndarray) -> float | None:
    """Mean place-code cosine over pairs less than ``ACROSS_STRAIGHT`` apart in a straight line but more than
    ``TWIN_PATH`` apart by path (on the two sides of a thin wall); None if there are none."""
    norm = np.linalg.norm(rates, axis=1)
    straight = np.linalg.norm(places[:, None, :] - places[None, :, :], axis=2)
    pairs = (straight < ACROSS_STRAIGHT) & (path_distance > TWIN_PATH) & (norm[:, None] > 0) & (norm[None, :] > 0)
    if not pairs.any():
        return None
    i, j = np.nonzero(pairs)
    return float(np.mean(np.sum(rates[i] * rates[j], axis=1) / (norm[i] * norm[j])))


def twin_share(rates: np.ndarray, path_distance: np.ndarray) -> float | None:
    """Share of active places with a look-alike more than ``TWIN_PATH`` away by path."""
    norm = np.linalg.norm(rates, axis=1)
    active = norm > 0
    if active.sum() < 2:
        return None
    unit = rates[active] / norm[active, None]
    cosine = unit @ unit.T
    far = path_distance[np.ix_(active, active)] > TWIN_PATH
    return float(((cosine > TWIN_COSINE) & far).any(axis=1).mean())


# ------------------------------------------------------------------ watching the agent
class OracleIntegrator(PathIntegrator):
    """PRIVILEGED: the estimate is set from outside to the true position in the agent's frame."""

    truth: np.ndarray | None = None

    def correct(self, *evidence: Any, **more: Any) -> None:
        """Ignores the evidence: the estimate is the truth."""
        if self.truth is not None:
            self.estimate = self.truth.copy()
            self.confidence = 1.0
            self.anchored = True

    def correct_anchored(self, place: Any) -> None:
        """Ignores the vote: the estimate is the truth."""
        self.correct()


class Watcher:
    """Wraps an agent: passes every call through and records what it needs, with the true position."""

    def __init__(self, agent: HippocampalAgent, oracle: bool) -> None:
        self.agent = agent
        self.origin: np.ndarray | None = None
        self.oracle = oracle
        if oracle:
            agent.pi.__class__ = OracleIntegrator  # (in place: the faculties hold the same integrator)
        self.run = -1
        self.in_dry_run = False
        self.dry_pi_errors: list[float] = []  # the dry run's (its frame starts where the robot stands)
        self.dry_positions: list[np.ndarray] = []  # the dry run's true positions, for its coverage
        self.run_pi_errors: list[list[float]] = []  # per DMTP run, after each kidnap
        self.run_steps = 0  # steps of the DMTP runs, anchored or not
        self.off_ground = 0  # anchored steps of the DMTP runs whose estimate lies off the ground the map knows
        self.off_dry_ground = 0  # the same, off the ground it knew at the end of the dry run
        self.dry_ground: np.ndarray | None = None  # that ground (the map's known_free then)
        self.anchor_steps: list[int] = []
        self.progress: list[float] = []
        self.exploit_bumps = 0
        self.exploit_steps = 0
        self.steps_later = 0
        self.explore_later = 0
        self.home_steps = 0
        self._steps_in_run = 0
        self._anchored_at: int | None = None
        self._last_distance: float | None = None
        self.env: Any = None

    # the protocol
    def dry_run(self, env: Any) -> None:
        self.run = -1
        self.env = env
        agent, inner = self.agent, self

        def reset(observation: Any, info: dict[str, Any]) -> None:
            inner._saw(info, reset=True)
            type(agent).reset(agent, observation, info)
            inner._after(info)

        def observe(action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
            inner._saw(info, reset=False)
            type(agent).observe(agent, action, observation, reward, terminated, truncated, info)
            inner._after(info)

        agent.reset, agent.observe = reset, observe  # watch the agent's own dry-run loop
        self.in_dry_run = True
        try:
            agent.dry_run(env)
        finally:
            del agent.reset, agent.observe
            self.in_dry_run = False
        if agent.map is not None:
            self.dry_ground = agent.map.known_free.copy()

    def start_trial(self, trial: int) -> None:
        self.agent.start_trial(trial)
        self.run = -1

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.run += 1
        self.run_pi_errors.append([])
        self._saw(info, reset=True)
        self.agent.reset(observation, info)
        self._after(info)

    def act(self, observation: Any) -> Any:
        return self.agent.act(observation)

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        decision = self.agent.last_decision
        self._saw(info, reset=False)
        self.agent.observe(action, observation, reward, terminated, truncated, info)
        self._after(info)
        if self.run >= 1:
            self.steps_later += 1
            if decision == "exploit":
                self.exploit_steps += 1
                self.exploit_bumps += int(bool(info.get("collision")))
                d = self._goal_distance(info)
                if self._last_distance is not None and math.isfinite(d):
                    self.progress.append((self._last_distance - d) / 0.15)
            elif decision == "home":
                self.home_steps += 1
            else:
                self.explore_later += 1
        self._last_distance = self._goal_distance(info)

    # bookkeeping
    def _goal_distance(self, info: dict[str, Any]) -> float:
        goal = info.get("goal")
        if goal is None or not np.all(np.isfinite(goal)) or self.env is None:
            return math.nan
        return float(self.env.unwrapped._distance_to_goal(np.asarray(info["position"], float)))

    def _saw(self, info: dict[str, Any], reset: bool) -> None:
        position = np.asarray(info["position"], float)
        if self.in_dry_run and not reset:
            self.dry_positions.append(position)
        if self.origin is None:
            self.origin = position.copy()
        if reset:
            self._steps_in_run = 0
            self._anchored_at = None
            self._last_distance = None
        else:
            self._steps_in_run += 1
        if self.oracle:
            self.agent.pi.truth = position - self.origin

    def _after(self, info: dict[str, Any]) -> None:
        pi = self.agent.pi
        if not self.in_dry_run:
            self.run_steps += 1
        if pi is None or not pi.anchored:
            return
        truth = np.asarray(info["position"], float) - self.origin
        error = float(np.linalg.norm(pi.estimate - truth))
        if self.in_dry_run:
            self.dry_pi_errors.append(error)
            return
        if self._anchored_at is None:
            self._anchored_at = self._steps_in_run
            self.anchor_steps.append(self._steps_in_run)
        self.run_pi_errors[-1].append(error)
        if self.agent.map is not None:
            self.off_ground += not self.agent.map.known_ground(pi.estimate)
            self.off_dry_ground += self.dry_ground is not None and not self.agent.map.known_ground(pi.estimate, self.dry_ground)

    @property
    def pi_errors(self) -> list[float]:
        """The estimate's error on every anchored step of the DMTP runs."""
        return [e for run in self.run_pi_errors for e in run]


def spec_name(maze: str) -> str:
    return MazeSpec.load(maze_source(maze)).name


def diagnose(args: DiagnoseArgs) -> tuple[dict[str, Any], list[np.ndarray]]:
    """Run the trials and measure; returns the record written to JSON and each trial's dry-run
    coverage curve."""
    spec = MazeSpec.load(maze_source(args.maze))
    overrides = {} if args.dry_run_steps < 0 else {"model.dry_run_steps": args.dry_run_steps}
    overrides.update(json.loads(args.config) if args.config else {})
    if args.oracle:
        overrides.update({"localisation.look_alikes": 0, "map.dry_reachable_only": False})
    config = (AgentConfig.paper() if args.paper else AgentConfig()).with_values(overrides)
    places = sample_places(spec)
    place_distance = path_distances(spec, places, places)
    watchers: list[Watcher] = []
    per_trial: list[dict[str, Any]] = []

    def make(observation_space: Any, action_space: Any, seed: int) -> Watcher:
        watchers.append(Watcher(HippocampalAgent(observation_space, action_space, config, seed=seed), args.oracle))
        return watchers[-1]

    def on_run_end(trial: int, run: int, watcher: Watcher, env: Any) -> None:
        agent = watcher.agent
        watcher.env = env
        if run == 0:
            goal = np.asarray(env.unwrapped.goal, float)
            to_goal = path_distances(spec, goal[None], places)[0]
            values = agent.reward_map(env, places)
            ok = np.isfinite(values)
            covered = ok & (values > config.model.xi_here)
            record = {
                "trial": trial,
                "coverage": float(covered.sum() / max(ok.sum(), 1)),
                "spearman": spearman(values[covered], to_goal[covered]) if covered.sum() >= 5 else None,
                "replay_reach": replay_reach(agent, env, spec, goal),
            }
            per_trial.append(record)
        if run == args_runs - 1:
            rates = agent.place_field_map(env, places)
            per_trial[-1]["twins"] = twin_share(np.nan_to_num(rates), place_distance)
            per_trial[-1]["across_walls"] = across_walls(np.nan_to_num(rates), places, place_distance)
            if config.path_integration is not None:
                bvc = np.array([agent.place_rates_at(env.unwrapped.observation_at(p)) for p in places])
                per_trial[-1]["twins_bvc"] = twin_share(bvc, place_distance)

    args_runs = 4
    result = run_dmtp(
        make,
        spec,
        trials=args.trials,
        runs=args_runs,
        seed=args.seed,
        env_kwargs={"odometry": True} if config.path_integration is not None else None,
        progress=True,
        on_run_end=on_run_end,
    )
    ind = result.indirectness()
    ok = result.success()

    later = ind[:, 1:]
    coverage = [coverage_curve(spec, np.array(w.dry_positions)) for w in watchers if w.dry_positions]
    run_errors = [e for w in watchers for e in w.pi_errors]
    # a run is misplaced when its estimate was more than MISPLACED m off on most of its anchored steps
    misplaced = [float(np.median(run) > MISPLACED) for w in watchers for run in w.run_pi_errors if run]
    all_progress = [p for w in watchers for p in w.progress]
    exploit = sum(w.exploit_steps for w in watchers)
    explore = sum(w.explore_later for w in watchers)
    home = sum(w.home_steps for w in watchers)
    later_steps = sum(w.steps_later for w in watchers)
    reach = [t["replay_reach"] for t in per_trial]
    n_iter = max((len(r) for r in reach), default=0)
    record = {
        "maze": spec.name,
        "model": "paper" if args.paper else "default",
        "oracle_privileged": args.oracle,
        "trials": args.trials,
        "seed": args.seed,
        "config": config.to_dict(),
        "indirectness_median_per_run": [median_or_none(list(ind[:, r])) for r in range(ind.shape[1])],
        "runs_2_4_median": median_or_none(list(later.ravel())),
        "runs_2_4_reached": float(ok[:, 1:].mean()),
        "runs_2_4_below_1": float((later < 1).mean()),
        "twins": median_or_none([t.get("twins") for t in per_trial]),
        "twins_bvc": median_or_none([t.get("twins_bvc") for t in per_trial]),
        "similarity_across_walls": median_or_none([t.get("across_walls") for t in per_trial]),
        "reward_map_coverage": median_or_none([t["coverage"] for t in per_trial]),
        "reward_map_spearman": median_or_none([t["spearman"] for t in per_trial]),
        "replay_reach_median_m": [median_or_none([r[i][0] for r in reach if i < len(r)]) for i in range(min(n_iter, 8))],
        "replay_reach_p90_m": [median_or_none([r[i][1] for r in reach if i < len(r)]) for i in range(min(n_iter, 8))],
        "preplay_progress": float(np.mean(all_progress)) if all_progress else None,
        "exploit_fallback_share": (explore / later_steps) if later_steps else None,
        "home_share": (home / later_steps) if later_steps else None,
        "exploit_bumps_per_step": (sum(w.exploit_bumps for w in watchers) / exploit) if exploit else None,
        "pi_error_median_m": median_or_none(run_errors),
        "pi_error_p90_m": float(np.quantile(run_errors, 0.9)) if run_errors else None,
        "pi_error_dry_run_median_m": median_or_none([e for w in watchers for e in w.dry_pi_errors]),
        "runs_misplaced_share": float(np.mean(misplaced)) if misplaced else None,
        "pi_within_half_metre_share": float(np.mean(np.array(run_errors) <= 0.5)) if run_errors else None,
        "run_steps_within_half_metre_share": (
            float(np.sum(np.array(run_errors) <= 0.5) / run_steps) if (run_steps := sum(w.run_steps for w in watchers)) else None
        ),
        "anchored_off_known_ground_share": (sum(w.off_ground for w in watchers) / len(run_errors)) if run_errors else None,
        "anchored_off_dry_run_ground_share": (sum(w.off_dry_ground for w in watchers) / len(run_errors)) if run_errors else None,
        "anchor_steps_median": median_or_none([float(s) for w in watchers for s in w.anchor_steps]),
        "dry_run_steps_median": median_or_none([float(c.size) for c in coverage]),
        "dry_run_coverage_steps_to_80": median_or_none([steps_to(c, 0.8) for c in coverage]),
        "dry_run_coverage_steps_to_95": median_or_none([steps_to(c, 0.95) for c in coverage]),
        "dry_run_coverage_at_end": median_or_none([float(c[-1]) for c in coverage]),
        "env_steps_total": result.env_steps_total,
        "per_trial": per_trial,
    }
    return record, coverage


def replay_reach(agent: HippocampalAgent, env: Any, spec: MazeSpec, goal: np.ndarray) -> list[tuple[float, float]]:
    """Run 1's replay again from the goal's rates (nothing learnt) and, per iteration, the median
    and 90th-percentile path distance from the goal of the field peaks of the reached cells."""
    place = agent.place
    v = place.v.copy()
    if not np.any(v > 0):
        return []
    peaks = field_peaks(agent, env)
    to_goal = path_distances(spec, goal[None], peaks[np.isfinite(peaks[:, 0])])[0] if np.isfinite(peaks[:, 0]).any() else np.zeros(0)
    dist_of = np.full(place.n, np.nan)
    dist_of[np.isfinite(peaks[:, 0])] = to_goal
    out = []
    M = place.replay_weights()
    v_bar = v.astype(np.float64)
    for _ in range(agent.config.model.replay_iterations):
        reached = np.flatnonzero(v_bar > 0)
        d = dist_of[reached]
        d = d[np.isfinite(d)]
        out.append((float(np.median(d)) if d.size else math.nan, float(np.quantile(d, 0.9)) if d.size else math.nan))
        v_bar = np.tanh(np.maximum(v_bar + v_bar @ M, 0.0))
    return out


def field_peaks(agent: HippocampalAgent, env: Any, spacing: float = 0.25) -> np.ndarray:
    """Each cell's field peak (NaN for cells silent everywhere) on a grid."""
    points = sample_places(env.unwrapped.maze, spacing)
    rates = np.nan_to_num(agent.place_field_map(env, points))
    peaks = np.full((agent.place.n, 2), np.nan)
    fires = rates.max(axis=0) > 0
    peaks[fires] = points[rates[:, fires].argmax(axis=0)]
    return peaks


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(DiagnoseArgs, __doc__.splitlines()[0], argv)
    load_start = load_average()
    record, coverage = diagnose(args)
    record.update({"command": command_line(), "machine": machine_info(), "load_start": load_start, "load_end": load_average()})
    suffix = "-paper" if args.paper else "-oracle" if args.oracle else ""
    out = Path(args.out) if args.out else REPO / "benchmarks" / "results" / "diagnose" / f"{Path(args.maze).stem}{suffix}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=1) + "\n")
    if coverage:
        plot_curves(
            {spec_name(args.maze): {"directed" if record["config"]["exploration"] is not None else "random": coverage}},
            out.with_suffix(".coverage.png"),
        )
    shown = {k: v for k, v in record.items() if k not in ("per_trial", "config", "machine")}
    for k, v in shown.items():
        print(f"{k}: {json.dumps(v)}")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
