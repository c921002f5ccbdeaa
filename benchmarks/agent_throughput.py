"""Hippocampal agent throughput: act + observe steps per second, learning on, on one core.

For each population size the agent does a short dry run, finds a fixed goal (so the reward map
exists and every later step heads for the goal: by 8-way preplay, or, in the default model, homing
along its map to where the goal was found; if the goal is reached with no place cell
active there, which replays nothing, it runs again, up to ``MAX_GOAL_RUNS`` runs), then is timed alone on a recorded
random walk of real observations: once exploiting, once exploring. One replay is timed too, and
the memory of the place->place tensor is read off the agent. RatInABox (the ``peers`` extra) is timed
beside it at the same cell counts: its agent moving and its place cells and BVCs updating.

``--scaling`` measures how the cost grows instead: every size of ``--scaling-cells`` and
``--target-cells`` in a fresh process (so each row's peak resident memory is its own), with the
time of each step split into its parts (BVC and head-direction rates, place-cell settling, path
integration, learning, preplay; exclusive times of those methods, the rest is ``other``) and one
replay into building the rows of ``max_k W_pp`` it reaches and the rest (spreading), the log-log slope of the cost against the number of place cells, the part that dominates at each end,
and the issue's targets at 10,000 cells (steps/s, resident memory, one replay). It writes the
table and a figure (``.png`` beside the JSON). RatInABox is not timed there.

    python -m benchmarks.agent_throughput            # writes benchmarks/results/agent_throughput.json
    python -m benchmarks.agent_throughput --cells 250 --steps 500 --out /tmp/quick.json
    python -m benchmarks.agent_throughput --scaling  # benchmarks/results/agent_scaling_default.json and .png
    python -m benchmarks.agent_throughput --scaling --scaling-cells 250 500 --target-cells 1000 \\
        --steps 200 --repeats 1 --dry-run-steps 300 --out /tmp/scaling.json   # a quick look
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import datetime
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import hippo_env
from benchmarks.common import (
    SplitTimer,
    command_line,
    cost_growth,
    in_fresh_process,
    load_average,
    log_log_slope,
    machine_info,
    output_path,
    parse_dataclass_args,
    peak_resident_megabytes,
    resident_megabytes,
)
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_env.dmtp import rollout


@dataclass
class Args:
    cells: tuple[int, ...] = (250, 1000, 4000)
    """place-cell counts to time"""
    steps: int = 3_000
    """recorded steps each timing replays"""
    repeats: int = 3
    """timed repeats; the best is reported (other load only slows a run down)"""
    dry_run_steps: int = 3_000
    """the agent's goal-free dry run before timing"""
    n_rays: int = 720
    """rangefinder rays (the paper's 720)"""
    seed: int = 0
    """seeds the environment, the agent and the recorded walk"""
    model: str = "default"
    """default (AgentConfig(), with path integration) or paper (AgentConfig.paper())"""
    target: float = 10_000.0
    """exploiting steps/s aimed for at 1000 place cells"""
    target_x_ratinabox: float = 25.0
    """exploiting steps/s aimed for at 1000 place cells, as a multiple of RatInABox's"""
    target_scaling: float = 2_000.0
    """steps/s aimed for at --target-cells, in both walks (with --scaling)"""
    peer_steps: int = 500
    """steps of RatInABox (an agent moving, its place cells and 400 BVCs updating, no learning) timed
    per repeat at each cell count, beside the agent; 0 skips it. Needs the ``peers`` extra."""
    scaling: bool = False
    """measure how the cost grows instead (see above): --scaling-cells and --target-cells, each in a fresh process"""
    scaling_cells: tuple[int, ...] = (250, 500, 1000, 2000, 4000, 8000, 16000)
    """place-cell counts of the scaling table"""
    target_cells: int = 10_000
    """the scaling table's row checked against the targets (added to the table if missing)"""
    target_rss_mb: float = 1_000.0
    """peak resident memory aimed for at --target-cells (MB)"""
    target_replay_ms: float = 100.0
    """time of one replay aimed for at --target-cells (ms)"""
    against: str = ""
    """also time this model ('paper' or 'default') at each cell count, its repeats alternating with
    --model's, exploiting: each pair's ratio of steps/s is then read on one load of the machine"""
    against_reference: float = 17_320.0
    """the --against model's exploiting steps/s at 1000 place cells on the machine where the targets
    were set (17,320: the paper's model in benchmarks/results/agent_throughput.json at commit 794bf4b);
    with --against, the median ratio times this estimates --model's steps/s there (0: no estimate)"""
    out: str = ""
    """where the JSON goes (relative to the repository root unless absolute); '' = benchmarks/results/
    agent_throughput.json, or with --scaling benchmarks/results/agent_scaling_<model>.json (the figure beside it)"""


# The parts of a step, as the agent's methods (attribute path from the agent, method) whose
# exclusive time each part is; what none of them covers (act/observe themselves, exploration,
# unpacking the observation) is "other".
AGENT_TERMS: dict[str, tuple[tuple[str, str], ...]] = {
    "bvc_hd_rates": (("bvc", "update"), ("hd", "update")),
    "place_settle": (("place", "step"), ("place", "step_with_sense"), ("place", "settle"), ("place", "reset_state")),
    "path_integration": (
        ("pi", "move"),
        ("pi", "correct"),
        ("pi", "start_run"),
        ("pi", "lagged_estimate"),
        ("place", "sensory_vote"),
        ("place", "pi_input"),
        ("place", "learn_centres"),
        ("place", "learn_spread"),
    ),
    "learning": (("place", "learn_pb"), ("place", "learn_pp"), ("place", "update_trace"), ("place", "update_hd_trace")),
    "preplay": (("place", "imagined_values"), ("reward", "value"), ("reward", "depress")),
}


# Runs from the same start to find the goal before a row gives up on timing an exploiting agent.
MAX_GOAL_RUNS = 5

# The parts of one replay (``HippocampalAgent.learn_reward``); the rest is "other".
REPLAY_TERMS: dict[str, tuple[tuple[str, str], ...]] = {"replay_weights": (("place", "replay_links"),)}


def make_config(model: str, n_place: int, dry_run_steps: int) -> AgentConfig:
    if model not in ("default", "paper"):
        raise ValueError(f"model {model!r} is unknown; allowed: default, paper")
    if model == "paper":
        return AgentConfig.paper().with_values({"model.n_place": n_place, "model.dry_run_steps": dry_run_steps})
    # the cost of n_place cells: no recruitment beyond them
    return AgentConfig().with_values({"model.n_place": n_place, "model.dry_run_steps": dry_run_steps, "exploration.place_cells_per_m2": 0.0})


def measure(n_place: int, args: Args, split: bool = False) -> dict[str, Any]:
    """One row: the agent with ``n_place`` place cells, after its dry run and the runs that find the
    goal and replay, timed on a recorded random walk exploiting and exploring; one replay timed;
    its memory. With ``split``, one more (instrumented) pass of each walk splits the time of a step
    into :data:`AGENT_TERMS` (microseconds per step)."""
    resident_at_start = resident_megabytes()
    env, agent, dry_run_seconds, goal_runs, run = _trained(args.model, n_place, args)
    before_timing = copy.deepcopy(agent.reward)  # replaying again adds to the reward weights: put them back after
    replay_from_cells = int(np.count_nonzero(agent.place.v > 0))  # replay spreads from the cells active at the goal
    replay_ms = []
    for _ in range(args.repeats):
        began = time.perf_counter()
        agent.learn_reward()
        replay_ms.append(1e3 * (time.perf_counter() - began))
    replay_split = _replay_split(agent) if split else None
    agent.reward = before_timing
    recorded = _recorded_walk(env, args)
    row: dict[str, Any] = {"n_place": n_place, "n_bvc": agent.bvc.n}
    for mode, exploit in (("exploiting", True), ("exploring", False)):
        wall, cpu, stats = _timed(agent, recorded, exploit, args.repeats)
        row[f"{mode}_steps_per_second"] = round(wall)
        row[f"{mode}_steps_per_cpu_second"] = round(cpu)
        row["exploit_decisions" if exploit else "explore_decisions"] = stats
        if split:
            row[f"{mode}_split_us_per_step"] = _split(agent, recorded, exploit)
    w_pp_bytes = sum(a.nbytes for a in vars(agent.place).values() if isinstance(a, np.ndarray) and a.ndim == 3)
    w_pb = getattr(agent.place, "W_pb", None)
    row |= {
        "replay_ms": round(min(replay_ms), 2),
        **({} if replay_split is None else {"replay_split_ms": replay_split}),
        "dry_run_steps_per_second": round(args.dry_run_steps / dry_run_seconds) if args.dry_run_steps else None,
        "goal_runs": goal_runs,
        "goal_run_steps": run.steps,
        "found_goal": bool(run.terminated),
        "replay_from_cells": replay_from_cells,
        "W_pp_megabytes": round(w_pp_bytes / 2**20, 1),
        "W_pb_megabytes": None if w_pb is None else round(w_pb.nbytes / 2**20, 1),
        "max_rss_megabytes": round(peak_resident_megabytes() * 1e6 / 2**20, 1),  # MiB, as before
        "peak_rss_mb": round(peak_resident_megabytes(), 1),
        "peak_rss_above_start_mb": round(peak_resident_megabytes() - resident_at_start, 1),
    }
    return row


def _trained(model: str, n_place: int, args: Args) -> tuple[gym.Env, HippocampalAgent, float, int, Any]:
    """The environment and the ``model`` agent with ``n_place`` cells after its dry run and the runs
    that find the goal (which replay); the dry run's seconds, the runs made and the last one."""
    env = gym.make("HippoMaze-v0", maze="open", n_rays=args.n_rays, odometry=True)
    env.reset(seed=args.seed)
    agent = HippocampalAgent(env.observation_space, env.action_space, make_config(model, n_place, args.dry_run_steps), seed=args.seed)
    began = time.perf_counter()
    agent.dry_run(env)
    dry_run_seconds = time.perf_counter() - began
    agent.start_trial(0)
    for goal_runs in range(1, MAX_GOAL_RUNS + 1):  # explore until the goal, which triggers the replay
        observation, info = env.reset(options={"goal": [0.0, 0.0]})
        agent.reset(observation, info)
        run = rollout(env, agent, observation)
        if agent.goal_rewarded:  # (a goal reached with no place cell active there teaches nothing: run again)
            break
    return env, agent, dry_run_seconds, goal_runs, run


def _recorded_walk(env: gym.Env, args: Args) -> list:
    """A random walk of ``args.steps`` steps with no goal, as (action, observation, info); closes ``env``."""
    walk = np.random.default_rng(args.seed).integers(0, 8, args.steps)
    recorded = []
    observation, info = env.reset(options={"goal": None})
    for action in walk.tolist():
        observation, _, _, _, info = env.step(action)
        recorded.append((action, observation, info))
    env.close()
    return recorded


def alternating(n_place: int, args: Args) -> dict[str, Any]:
    """``args.model`` and ``args.against``, each trained and given its own recorded walk as in
    :func:`measure`, timed exploiting in alternation, ``args.repeats`` times each: the steps/s of
    each pair, their ratios, and the median ratio (at 1000 cells and with ``args.against_reference``,
    times it: an estimate of ``args.model`` on the machine that reference was measured on)."""
    walks = []
    for model in (args.model, args.against):  # (the same model twice measures the machine's noise)
        env, agent, *_ = _trained(model, n_place, args)
        walks.append((agent, _recorded_walk(env, args)))
        agent.goal_rewarded = True
    pairs = []
    for _ in range(args.repeats):
        pairs.append([len(recorded) / _walk(agent, recorded)[0] for agent, recorded in walks])
    ratios = [a / b for a, b in pairs]
    median = float(np.median(ratios))
    return {
        "against": args.against,
        "steps_per_second_pairs": [[round(a), round(b)] for a, b in pairs],
        "ratios": [round(r, 3) for r in ratios],
        "median_ratio": round(median, 3),
        "estimate_at_reference": round(median * args.against_reference) if args.against_reference > 0 and n_place == 1000 else None,
    }


@contextlib.contextmanager
def _heading_for_the_goal(agent: HippocampalAgent, exploit: bool) -> Iterator[None]:
    """Exploiting: the agent knows the goal (its reward map, and in the default model the place
    where it found it), so it preplays or homes at every step. Exploring: it knows neither (the
    remembered place is hidden for the walk, or the default model would home), so it searches as
    in a run 1."""
    found = agent.reward.found_count.copy()
    agent.goal_rewarded = exploit
    if not exploit:
        agent.reward.found_count[:] = 0.0
    try:
        yield
    finally:
        agent.reward.found_count[:] = found


def _timed(agent: HippocampalAgent, recorded: list, exploit: bool, repeats: int) -> tuple[float, float, dict]:
    """Best steps/s (wall and CPU) of act + observe over the recorded walk, and the last walk's decisions."""
    best_wall = best_cpu = 0.0
    with _heading_for_the_goal(agent, exploit):
        for _ in range(repeats):
            wall, cpu = _walk(agent, recorded)
            best_wall = max(best_wall, len(recorded) / wall)
            best_cpu = max(best_cpu, len(recorded) / max(cpu, 1e-9))
    return best_wall, best_cpu, dict(agent.episode_stats)


def _walk(agent: HippocampalAgent, recorded: list) -> tuple[float, float]:
    """Wall and CPU seconds of act + observe over the recorded walk (after a reset, untimed)."""
    agent.reset(recorded[0][1], recorded[0][2])
    began, began_cpu = time.perf_counter(), time.process_time()
    for action, observation, info in recorded:
        agent.act(observation)
        agent.observe(action, observation, 0.0, False, False, info)
    return time.perf_counter() - began, time.process_time() - began_cpu


def _split(agent: HippocampalAgent, recorded: list, exploit: bool) -> dict[str, Any]:
    """Microseconds per step in each of :data:`AGENT_TERMS` and ``other``, from one instrumented
    walk (slightly slower than the timed ones: the shares are what to read)."""
    with _heading_for_the_goal(agent, exploit):
        return _split_walk(agent, recorded)


def _split_walk(agent: HippocampalAgent, recorded: list) -> dict[str, Any]:
    timer = SplitTimer()
    for term, methods in AGENT_TERMS.items():
        for owner, name in methods:
            timer.wrap(getattr(agent, owner, None), name, term)
    agent.reset(recorded[0][1], recorded[0][2])
    timer.reset()  # the reset's own settling is not a step
    began = time.perf_counter()
    for action, observation, info in recorded:
        agent.act(observation)
        agent.observe(action, observation, 0.0, False, False, info)
    total = time.perf_counter() - began
    timer.unwrap()
    out: dict[str, Any] = {term: round(1e6 * seconds / len(recorded), 2) for term, seconds in timer.split(total).items()}
    out["total"] = round(1e6 * total / len(recorded), 2)
    if timer.missing:
        out["methods_not_found"] = timer.missing
    return out


def _replay_split(agent: HippocampalAgent) -> dict[str, Any]:
    """One more (instrumented) replay, in milliseconds: building the rows of ``max_k W_pp`` it reaches
    (:data:`REPLAY_TERMS`) and the rest ("other": spreading the activity through those rows, with
    the replay's own buffers, and adding to the reward weights)."""
    timer = SplitTimer()
    for term, methods in REPLAY_TERMS.items():
        for owner, name in methods:
            timer.wrap(getattr(agent, owner, None), name, term)
    began = time.perf_counter()
    agent.learn_reward()
    total = time.perf_counter() - began
    timer.unwrap()
    out: dict[str, Any] = {term: round(1e3 * seconds, 3) for term, seconds in timer.split(total).items()}
    out["total"] = round(1e3 * total, 3)
    if timer.missing:
        out["methods_not_found"] = timer.missing
    return out


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    if args.scaling:
        scaling(args)
        return
    load_at_start = load_average()
    print(f"hippomaze agent throughput: {args.steps} recorded steps x {args.repeats} repeats, {args.n_rays} rays")
    rows = []
    for n_place in args.cells:
        row = measure(n_place, args)
        if args.against:
            row["alternating"] = alternating(n_place, args)
            alt = row["alternating"]
            print(
                f"  {n_place:5d} place cells, alternating with the {args.against} model: ratios {alt['ratios']}, median {alt['median_ratio']}"
                + ("" if alt["estimate_at_reference"] is None else f", estimate at the reference {alt['estimate_at_reference']:,} steps/s")
            )
        peer = _ratinabox_steps_per_second(n_place, row["n_bvc"], args) if args.peer_steps > 0 else None
        row["ratinabox_steps_per_second"] = None if peer is None else round(peer)
        row["exploiting_x_ratinabox"] = None if peer is None else round(row["exploiting_steps_per_second"] / peer, 2)
        rows.append(row)
        print(
            f"  {n_place:5d} place cells: exploiting {row['exploiting_steps_per_second']:7,} steps/s "
            f"({row['exploiting_steps_per_cpu_second']:,} per CPU second), exploring {row['exploring_steps_per_second']:7,}; "
            f"one replay {row['replay_ms']:.1f} ms; W_pp {row['W_pp_megabytes']:.1f} MB"
            + ("" if peer is None else f"; RatInABox {peer:,.0f} steps/s ({row['exploiting_x_ratinabox']:.1f}x)")
        )

    record = {**_header(args, load_at_start), "rows": rows, "targets_1000_cells": targets_1000_cells(rows, args)}
    if record["targets_1000_cells"] is not None:
        print(f"  targets at 1000 place cells: {record['targets_1000_cells']}")
    out = output_path(args.out or "benchmarks/results/agent_throughput.json")
    hippo_env.write_json(out, record)
    print(f"wrote {out}")


def targets_1000_cells(rows: list[dict[str, Any]], args: Args) -> dict[str, Any] | None:
    """The issue's targets at 1000 place cells, exploiting: steps/s, and steps/s over RatInABox's
    (``None`` where RatInABox was not timed); with ``--against`` and a reference, also the steps/s
    estimated on the reference machine (:func:`alternating`). ``None`` without a 1000-cell row."""
    row = next((r for r in rows if r["n_place"] == 1000), None)
    if row is None:
        return None
    steps, ratio = row["exploiting_steps_per_second"], row.get("exploiting_x_ratinabox")
    out = {
        "steps_per_second": {"target": args.target, "measured": steps, "met": steps >= args.target},
        "x_ratinabox": {
            "target": args.target_x_ratinabox,
            "measured": ratio,
            "met": None if ratio is None else ratio >= args.target_x_ratinabox,
        },
    }
    estimate = row.get("alternating", {}).get("estimate_at_reference")
    if estimate is not None:
        out["steps_per_second_at_reference"] = {"target": args.target, "estimated": estimate, "met": estimate >= args.target}
    return out


def _header(args: Args, load_at_start: list[float] | None) -> dict[str, Any]:
    return {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(numpy=np.__version__, gymnasium=gym.__version__, hippo_env=hippo_env.__version__)
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
    }


# ============================================================================ scaling
def scaling_table(args: Args, fresh_process: bool = True) -> dict[str, Any]:
    """The scaling table (every size of ``args.scaling_cells`` and ``args.target_cells``, smallest
    first, each with its split), its slopes, the dominant part at each end, and the targets."""
    sizes = sorted(set(args.scaling_cells) | {args.target_cells})
    rows = []
    for n_place in sizes:
        row = in_fresh_process(measure, n_place, args, True) if fresh_process else measure(n_place, args, split=True)
        rows.append(row)
        split = row["exploiting_split_us_per_step"]
        print(
            f"  {n_place:6d} place cells: exploiting {row['exploiting_steps_per_second']:7,} steps/s, exploring "
            f"{row['exploring_steps_per_second']:7,}; replay {row['replay_ms']:8.1f} ms; peak RSS {row['peak_rss_mb']:7.0f} MB; "
            f"largest part {_largest(split)}; exploited on {exploit_share(row):.0%} of the exploiting walk"
            + (
                ""
                if replays(row)
                else f"; nothing to replay (in {row['goal_runs']} runs the goal was not found with a place cell active there)"
            ),
            flush=True,
        )
    return {"rows": rows, "growth": growth(rows), "targets": targets(rows, args)}


def growth(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """How each walk's cost per step and each part of it (:func:`cost_growth`), the replay and the
    memory grow with the number of place cells (log-log slopes; 1 = linear)."""
    n = [r["n_place"] for r in rows]
    out: dict[str, Any] = {
        mode: cost_growth(n, [1.0 / r[f"{mode}_steps_per_second"] for r in rows], [r[f"{mode}_split_us_per_step"] for r in rows])
        for mode in ("exploiting", "exploring")
    }
    replayed = [r for r in rows if replays(r)]
    if len(replayed) >= 2 and all("replay_split_ms" in r for r in replayed):
        out["replay"] = cost_growth(
            [r["n_place"] for r in replayed], [r["replay_ms"] for r in replayed], [r["replay_split_ms"] for r in replayed]
        )
    for key, among in (("replay_ms", replayed), ("peak_rss_above_start_mb", rows), ("W_pp_megabytes", rows)):
        slope = log_log_slope([r["n_place"] for r in among], [r[key] for r in among])  # over all sizes
        out[f"{key}_slope"] = None if slope is None else round(slope, 3)
    return out


# An "exploiting" walk in which the agent mostly fell back to exploring does not measure exploiting.
MIN_EXPLOIT_SHARE = 0.5


def exploit_share(row: dict[str, Any]) -> float:
    """The share of the exploiting walk's steps on which the agent headed for the goal (preplay, or
    homing along its map, chose the move)."""
    decisions = row["exploit_decisions"]
    goal_directed = decisions["exploit"] + decisions.get("home", 0)
    return goal_directed / max(goal_directed + decisions["explore"], 1)


def replays(row: dict[str, Any]) -> bool:
    """Whether the row's replay did anything: a run found the goal and some place cell was active there."""
    return row.get("found_goal", True) and row.get("replay_from_cells", 1) > 0


def targets(rows: list[dict[str, Any]], args: Args) -> dict[str, Any]:
    """The issue's targets at ``args.target_cells`` place cells, against that row. They are not
    measured when run 1 never found the goal (no replay to time) or the agent hardly exploited."""
    row = next((r for r in rows if r["n_place"] == args.target_cells), None)
    if row is None:
        return {"n_place": args.target_cells, "measured": False}
    if not replays(row) or exploit_share(row) < MIN_EXPLOIT_SHARE:
        why = (
            f"found the goal: {row.get('found_goal')} (in {row.get('goal_runs')} runs), with {row.get('replay_from_cells')} place cells active there to replay "
            f"from; the exploiting walk exploited on {exploit_share(row):.0%} of its steps"
        )
        return {"n_place": args.target_cells, "measured": False, "why": why}
    slowest = min(row["exploiting_steps_per_second"], row["exploring_steps_per_second"])
    return {
        "n_place": args.target_cells,
        "measured": True,
        "steps_per_second": {"target": args.target_scaling, "slowest_walk": slowest, "met": slowest >= args.target_scaling},
        "peak_rss_mb": {"target": args.target_rss_mb, "measured": row["peak_rss_mb"], "met": row["peak_rss_mb"] < args.target_rss_mb},
        "replay_ms": {"target": args.target_replay_ms, "measured": row["replay_ms"], "met": row["replay_ms"] < args.target_replay_ms},
    }


def _largest(split: dict[str, Any]) -> str:
    parts = {t: v for t, v in split.items() if t != "total" and isinstance(v, float | int)}
    return max(parts, key=parts.get)


def scaling(args: Args) -> None:
    load_at_start = load_average()
    print(
        f"hippomaze agent scaling ({args.model} model): {args.steps} recorded steps x {args.repeats} repeats, "
        f"{args.n_rays} rays, dry run {args.dry_run_steps} steps; each size in a fresh process"
    )
    table = scaling_table(args)
    record = {**_header(args, load_at_start), **table}
    out = output_path(args.out or f"benchmarks/results/agent_scaling_{args.model}.json")
    hippo_env.write_json(out, record)
    figure = out.with_suffix(".png")
    plot_scaling(table, args, figure)
    for mode in ("exploiting", "exploring"):
        g = table["growth"][mode]
        print(
            f"  {mode}: cost per step {g['verdict']}; largest part {g['dominant_at_smallest']} (smallest) -> {g['dominant_at_largest']} (largest)"
        )
    if "replay" in table["growth"]:
        g = table["growth"]["replay"]
        print(f"  replay: {g['verdict']}; largest part {g['dominant_at_smallest']} (smallest) -> {g['dominant_at_largest']} (largest)")
    print(f"  targets at {args.target_cells:,} place cells: {table['targets']}")
    print(f"wrote {out} and {figure}")


def plot_scaling(table: dict[str, Any], args: Args, path: Path) -> None:
    """Four log-log panels against the number of place cells: steps/s (with a cost-proportional-to-n
    reference line and the target), memory, the parts of an exploiting step, and one replay."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = table["rows"]
    n = np.array([r["n_place"] for r in rows], dtype=float)
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    ax = axes[0, 0]
    for mode, marker in (("exploiting", "o"), ("exploring", "s")):
        ax.plot(n, [r[f"{mode}_steps_per_second"] for r in rows], marker=marker, label=mode)
    idle = [i for i, r in enumerate(rows) if exploit_share(r) < MIN_EXPLOIT_SHARE]
    if idle:
        ax.plot(
            n[idle], [rows[i]["exploiting_steps_per_second"] for i in idle], "rx", ms=10, label="hardly exploited: not an exploiting figure"
        )
    anchor = rows[-1]["exploiting_steps_per_second"]
    ax.plot(n, anchor * n[-1] / n, "k:", label="cost proportional to n (slope -1)")
    ax.axhline(args.target_scaling, color="r", ls="--", lw=1, label=f"target {args.target_scaling:,.0f} steps/s")
    ax.axvline(args.target_cells, color="grey", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel="place cells", ylabel="steps / s (best of repeats)", title=f"agent ({args.model} model)")
    ax.legend(fontsize=8)

    ax = axes[0, 1]
    ax.plot(n, [r["peak_rss_mb"] for r in rows], "o-", label="peak resident memory (process)")
    ax.plot(n, [r["W_pp_megabytes"] * 2**20 / 1e6 for r in rows], "s-", label="W_pp (place->place)")
    if rows[0].get("W_pb_megabytes") is not None:
        ax.plot(n, [r["W_pb_megabytes"] * 2**20 / 1e6 for r in rows], "^-", label="W_pb (BVC->place)")
    ax.plot(n, rows[-1]["peak_rss_mb"] * n / n[-1], "k:", label="proportional to n")
    ax.plot(n, rows[-1]["W_pp_megabytes"] * 2**20 / 1e6 * (n / n[-1]) ** 2, "k-.", lw=0.8, label="proportional to n^2")
    ax.axhline(args.target_rss_mb, color="r", ls="--", lw=1, label=f"target {args.target_rss_mb:,.0f} MB")
    ax.axvline(args.target_cells, color="grey", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel="place cells", ylabel="MB", title="memory")
    ax.legend(fontsize=8)

    ax = axes[1, 0]
    splits = [r["exploiting_split_us_per_step"] for r in rows]
    for term in (t for t in splits[0] if t not in ("total", "methods_not_found")):
        values = np.array([s.get(term, 0.0) for s in splits], dtype=float)
        if values.max() > 0.0:
            ax.plot(n, np.where(values > 0.0, values, np.nan), "o-", label=term)
    ax.plot(n, [s["total"] for s in splits], "k-", lw=2, label="whole step (instrumented)")
    ax.set(xscale="log", yscale="log", xlabel="place cells", ylabel="microseconds per step", title="parts of an exploiting step")
    ax.legend(fontsize=8)

    ax = axes[1, 1]
    replayed = [r for r in rows if replays(r)]  # a row with nothing to replay has no replay to show
    n_replayed = np.array([r["n_place"] for r in replayed], dtype=float)
    ax.plot(n_replayed, [r["replay_ms"] for r in replayed], "o-", label="one replay")
    for term in (t for t in rows[0].get("replay_split_ms", {}) if t not in ("total", "methods_not_found")):
        values = np.array([r["replay_split_ms"].get(term, 0.0) for r in replayed], dtype=float)
        if values.size and values.max() > 0.0:
            label = "spreading (the rest)" if term == "other" else term
            ax.plot(n_replayed, np.where(values > 0.0, values, np.nan), "s--", lw=0.8, label=f"{label} (instrumented replay)")
    if replayed:
        last = replayed[-1]["replay_ms"]
        ax.plot(n_replayed, last * n_replayed / n_replayed[-1], "k:", label="proportional to n")
        ax.plot(n_replayed, last * (n_replayed / n_replayed[-1]) ** 2, "k-.", lw=0.8, label="proportional to n^2")
    ax.axhline(args.target_replay_ms, color="r", ls="--", lw=1, label=f"target {args.target_replay_ms:g} ms")
    ax.axvline(args.target_cells, color="grey", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel="place cells", ylabel="ms", title="replay after the goal is found")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _ratinabox_steps_per_second(n_place: int, n_bvc: int, args: Args) -> float | None:
    """Best steps/s of RatInABox updating an agent, ``n_place`` place cells and ``n_bvc`` BVCs in a
    10 m arena (its defaults otherwise; it does not learn), or None if it is not installed."""
    try:
        from ratinabox.Agent import Agent
        from ratinabox.Environment import Environment
        from ratinabox.Neurons import BoundaryVectorCells, PlaceCells
    except ImportError:
        print("  RatInABox is not installed (pip install -e .[peers]): not timed")
        return None
    environment = Environment(params={"scale": 10.0, "dimensionality": "2D"})
    rat = Agent(environment)  # its default time step: a longer one makes its random motion diverge
    cells = [BoundaryVectorCells(rat, params={"n": n_bvc}), PlaceCells(rat, params={"n": n_place})]
    best = 0.0
    for _ in range(args.repeats):
        began = time.perf_counter()
        for _ in range(args.peer_steps):
            rat.update()
            for population in cells:
                population.update()
        best = max(best, args.peer_steps / (time.perf_counter() - began))
    return best


if __name__ == "__main__":
    main()
