"""Hippocampal agent throughput: the default model, the paper's model and RatInABox timed side by side.

At each size of ``--cells`` (1000 place cells by default) the default model and the paper's model
are trained in the open arena (:mod:`benchmarks.agent_timing`: a dry run, then runs until one
finds a fixed goal and replays) and each given a recorded random walk of real observations (720
rays). After one untimed pass of each walk, repeat by repeat, in one process on one core, each of
these is timed once, in an order that rotates from repeat to repeat so that none is always first:

- the default model on its walk, exploiting (it knows the goal: it preplays or homes at every step), learning on;
- the paper's model on its walk, the same way;
- RatInABox (the ``peers`` extra): its agent moving, as many place cells and its 400 BVCs updating,
  no learning, with NumPy's BLAS held to one thread (``threadpoolctl``), so that it runs on one
  core as the models do: the ratio the target reads;
- RatInABox again with BLAS's own number of threads (all the cores), for the record;
- the default model's dry run (directed exploration) from scratch, a fresh agent each repeat,
  the environment's own time taken out (the rest at its end, imagined transits with no step
  taken, included; its time is also recorded apart).

Each repeat gives the ratios default / RatInABox and default / paper (steps/s over steps/s) and
the time of a dry-run step over that of an exploiting step; the record holds every repeat's
figures and each ratio's median and quartiles over the repeats (:func:`hippomaze.stats.median_and_quartiles`).
Both programs of a ratio ran on the same load of the same machine, so the ratio holds where
steps/s do not. The targets are in ``benchmarks/targets.toml``.

``--scaling`` measures how the cost of one model (``--model``) grows instead: every size of
``--scaling-cells`` and the targets' sizes (10,000 and 1,000 place cells) in a fresh process (so
each row's peak resident memory is its own), best of ``--scaling-repeats``, with the time of
each step split into its parts (BVC and head-direction rates, place-cell settling, path
integration, learning, preplay; exclusive times of those methods, the rest is ``other``) and
one replay into building the rows of ``max_k W_pp`` it reaches and the rest (spreading), the
log-log slope of the cost against the number of place cells and the part that dominates at each
end. It writes the table and a figure (``.png`` beside the JSON). RatInABox is not timed there.

    python -m benchmarks.agent_throughput            # writes benchmarks/results/agent_throughput.json
    python -m benchmarks.agent_throughput --steps 300 --repeats 2 --dry-run-steps 300 --peer-steps 20 \\
        --out /tmp/quick.json                          # a quick look
    python -m benchmarks.agent_throughput --config '{"localisation.check_every": 4, "map.run_every": 4}' \\
        --out /tmp/lazier.json                         # what a setting of the default model costs or saves
    python -m benchmarks.agent_throughput --scaling  # benchmarks/results/agent_scaling_default.json and .png
    python -m benchmarks.agent_throughput --scaling --scaling-cells 250 500 --steps 200 --scaling-repeats 1 \\
        --dry-run-steps 300 --out /tmp/scaling.json    # a quick look (the targets' sizes are added)
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import hippo_env
from benchmarks.agent_timing import (
    RatInABox,
    heading_for_the_goal,
    make_config,
    measure,
    new_agent,
    overrides,
    recorded_walk,
    timed_dry_run,
    trained,
    walk,
)
from benchmarks.common import (
    command_line,
    cost_growth,
    in_fresh_process,
    load_average,
    log_log_slope,
    machine_info,
    output_path,
    parse_dataclass_args,
)
from benchmarks.records import MIN_EXPLOIT_SHARE, exploit_share, replays, scaling_figures, spread
from benchmarks.targets import target, verdict
from hippomaze.stats import median_and_quartiles


@dataclass
class Args:
    cells: tuple[int, ...] = (1000,)
    """place-cell counts at which the three are timed side by side"""
    steps: int = 3_000
    """recorded steps each exploiting walk replays"""
    repeats: int = 15
    """repeats side by side; each times every program once"""
    dry_run_steps: int = 3_000
    """the longest dry run (the directed one ends when the arena is explored)"""
    n_rays: int = 720
    """rangefinder rays (the paper's 720)"""
    seed: int = 0
    """seeds the environment, the agents and the recorded walks"""
    peer_steps: int = 500
    """RatInABox steps timed per repeat; 0 times the two models without it. Needs the ``peers`` extra."""
    scaling: bool = False
    """measure how the cost of --model grows instead (see above), each size in a fresh process"""
    model: str = "default"
    """with --scaling: default (AgentConfig(), with path integration) or paper (AgentConfig.paper())"""
    scaling_cells: tuple[int, ...] = (250, 500, 1000, 2000, 4000, 8000, 16000)
    """place-cell counts of the scaling table (the targets' sizes are added)"""
    scaling_repeats: int = 3
    """with --scaling: timed repeats of each walk and of the replay; the best is kept (other load only slows a run down)"""
    config: str = ""
    """AgentConfig fields by dotted name as JSON for the default model (the paper's model stays the
    paper's), e.g. '{"localisation.check_every": 4}': what a setting costs or saves"""
    out: str = ""
    """where the JSON goes (relative to the repository root unless absolute); '' = benchmarks/results/
    agent_throughput.json, or with --scaling benchmarks/results/agent_scaling_<model>.json (the figure beside it)"""


#: The programs timed side by side, in the first repeat's order.
PROGRAMS = ("default", "paper", "ratinabox", "ratinabox_blas_threads", "dry_run")


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    try:
        make_config("default", 1000, args.dry_run_steps, overrides(args))  # a bad --config fails now, with its reason
    except (ValueError, TypeError) as err:
        raise SystemExit(f"--config: {err}") from err
    if args.scaling:
        scaling(args)
        return
    load_at_start = load_average()
    print(f"hippomaze agent throughput, side by side: {args.steps} recorded steps, {args.repeats} repeats, {args.n_rays} rays")
    rows = [side_by_side(n_place, args) for n_place in args.cells]
    record = {**_header(args, load_at_start), "side_by_side": rows}
    out = output_path(args.out or "benchmarks/results/agent_throughput.json")
    hippo_env.write_json(out, record)
    for row in rows:
        print(f"  {row['n_place']:,} place cells:")
        for name, (key, what) in RATIOS.items():
            summary = row["ratios"].get(key)
            measured = None if not summary else summary["median"]
            print(f"    {what}: {spread(summary)}; target {target(name).text(unit='x')}: {verdict(target(name).met(measured))}")
        for key, what in INFORMATION.items():
            if key in row["ratios"]:
                print(f"    {what}: {spread(row['ratios'][key])}")
    print(f"wrote {out}")


#: The targets of the side-by-side timing: target name -> (the ratio's key in a row, what it is).
RATIOS = {
    "agent_vs_ratinabox": ("default_x_ratinabox", "default / RatInABox, steps/s"),
    "default_vs_paper": ("default_x_paper", "default / paper's model, steps/s"),
    "dry_run_step": ("dry_run_step_x_exploiting_step", "a dry-run step / an exploiting step, time"),
}


#: Ratios recorded beside the targets' (key in a row -> what it is).
INFORMATION = {
    "default_x_ratinabox_blas_threads": "default / RatInABox with BLAS on all cores, steps/s",
    "dry_run_step_without_rest_x_exploiting_step": "a dry-run step with the rest at its end taken out / an exploiting step, time",
}


def side_by_side(n_place: int, args: Args) -> dict[str, Any]:
    """The default model, the paper's model, RatInABox and the default model's dry run at ``n_place``
    place cells, timed in turn, ``args.repeats`` times: every repeat's steps/s, the ratios per
    repeat, and their medians and quartiles."""
    walks, shares = {}, {}
    for model in ("default", "paper"):
        env, agent, _, _ = trained(model, n_place, args.dry_run_steps, args.n_rays, args.seed, overrides(args))
        walks[model] = (agent, recorded_walk(env, args.steps, args.seed))
    peer = RatInABox(n_place, walks["default"][0].bvc.n) if args.peer_steps > 0 else None
    programs = [p for p in PROGRAMS if not p.startswith("ratinabox") or peer is not None]
    repeats = []
    with contextlib.ExitStack() as stack:
        for agent, recorded in walks.values():
            stack.enter_context(heading_for_the_goal(agent, exploit=True))
            walk(agent, recorded)  # untimed: the first pass compiles and fills caches
        if peer is not None:
            peer.seconds(min(args.peer_steps, 10))
        for r in range(args.repeats):
            order = programs[r % len(programs) :] + programs[: r % len(programs)]
            figures: dict[str, Any] = {"order": order}
            for program in order:
                if program in walks:
                    agent, recorded = walks[program]
                    figures[program] = round(len(recorded) / walk(agent, recorded)[0], 1)
                    shares.setdefault(program, []).append(exploit_share(agent.episode_stats))
                elif program == "ratinabox":
                    with one_blas_thread():
                        figures["ratinabox"] = round(args.peer_steps / peer.seconds(args.peer_steps), 2)
                elif program == "ratinabox_blas_threads":
                    figures[program] = round(args.peer_steps / peer.seconds(args.peer_steps), 2)
                else:
                    env, fresh = new_agent("default", n_place, args.dry_run_steps, args.n_rays, args.seed, overrides(args))
                    steps, seconds, rest = timed_dry_run(env, fresh)
                    env.close()
                    figures |= {
                        "dry_run": round(steps / seconds, 1),
                        "dry_run_steps": steps,
                        "dry_run_rest_seconds": round(rest, 4),
                        "dry_run_without_rest": round(steps / (seconds - rest), 1),
                    }
            repeats.append(figures)
            print(
                f"  {n_place:,} place cells, repeat {r + 1}/{args.repeats}: " + ", ".join(f"{p} {figures[p]:,} steps/s" for p in order),
                flush=True,
            )
    per_repeat = {
        "default_x_paper": [f["default"] / f["paper"] for f in repeats],
        "dry_run_step_x_exploiting_step": [f["default"] / f["dry_run"] for f in repeats],
        "dry_run_step_without_rest_x_exploiting_step": [f["default"] / f["dry_run_without_rest"] for f in repeats],
    }
    if peer is not None:
        per_repeat["default_x_ratinabox"] = [f["default"] / f["ratinabox"] for f in repeats]
        per_repeat["default_x_ratinabox_blas_threads"] = [f["default"] / f["ratinabox_blas_threads"] for f in repeats]
    return {
        "n_place": n_place,
        "n_bvc": walks["default"][0].bvc.n,
        "n_rays": args.n_rays,
        "ratinabox_timed": peer is not None,
        "exploit_share": {model: round(min(s), 3) for model, s in shares.items()},
        "repeats": repeats,
        "steps_per_second": {p: median_and_quartiles([f[p] for f in repeats], 1) for p in [*programs, "dry_run_without_rest"]},
        "ratios": {
            key: {"per_repeat": [round(v, 4) for v in values], **median_and_quartiles(values)} for key, values in per_repeat.items()
        },
    }


def one_blas_thread() -> Any:
    """A context in which NumPy's BLAS runs one thread (RatInABox's products then use one core, as
    the models do)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError as err:
        raise ImportError(f"threadpoolctl is not installed ({err}): pip install -e '.[peers]'") from err
    return threadpool_limits(limits=1, user_api="blas")


def _header(args: Args, load_at_start: list[float] | None) -> dict[str, Any]:
    return {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(numpy=np.__version__, gymnasium=gym.__version__, hippo_env=hippo_env.__version__)
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
    }


# ============================================================================ scaling
def target_sizes() -> tuple[int, int]:
    """The numbers of place cells the scaling targets are read at: the one measured, and the one its speed is compared with."""
    speed = target("scaling_speed")
    return int(speed["place_cells"]), int(speed["against_place_cells"])


def scaling_table(args: Args, fresh_process: bool = True) -> dict[str, Any]:
    """The scaling table (every size of ``args.scaling_cells`` and the targets' sizes, smallest
    first, each with its split), its slopes and the dominant part at each end."""
    sizes = sorted(set(args.scaling_cells) | set(target_sizes()))
    rows = []
    for n_place in sizes:
        row = in_fresh_process(measure, n_place, args, True) if fresh_process else measure(n_place, args, split=True)
        rows.append(row)
        split = row["exploiting_split_us_per_step"]
        print(
            f"  {n_place:6d} place cells: exploiting {row['exploiting_steps_per_second']:7,} steps/s, exploring "
            f"{row['exploring_steps_per_second']:7,}; replay {row['replay_ms']:8.1f} ms; peak RSS {row['peak_rss_mb']:7.0f} MB; "
            f"largest part {_largest(split)}; exploited on {exploit_share(row['exploit_decisions']):.0%} of the exploiting walk"
            + (
                ""
                if replays(row)
                else f"; nothing to replay (in {row['goal_runs']} runs the goal was not found with a place cell active there)"
            ),
            flush=True,
        )
    return {"rows": rows, "growth": growth(rows)}


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


def _largest(split: dict[str, Any]) -> str:
    parts = {t: v for t, v in split.items() if t != "total" and isinstance(v, float | int)}
    return max(parts, key=parts.get)


def scaling(args: Args) -> None:
    load_at_start = load_average()
    print(
        f"hippomaze agent scaling ({args.model} model): {args.steps} recorded steps x {args.scaling_repeats} repeats, "
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
    figures = scaling_figures(record)
    if figures["measured"]:
        for name, key in (("scaling_speed", "speed_ratio"), ("scaling_memory_mb", "peak_rss_mb"), ("scaling_replay_ms", "replay_ms")):
            print(f"  {target(name).what}: {figures[key]} (target {target(name).text()}: {verdict(target(name).met(figures[key]))})")
    else:
        print(f"  the targets at {figures['n_place']:,} place cells are not measured: {figures['why']}")
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
    idle = [i for i, r in enumerate(rows) if exploit_share(r["exploit_decisions"]) < MIN_EXPLOIT_SHARE]
    if idle:
        ax.plot(
            n[idle], [rows[i]["exploiting_steps_per_second"] for i in idle], "rx", ms=10, label="hardly exploited: not an exploiting figure"
        )
    anchor = rows[-1]["exploiting_steps_per_second"]
    ax.plot(n, anchor * n[-1] / n, "k:", label="cost proportional to n (slope -1)")
    (at, against), speed = target_sizes(), target("scaling_speed").bound()
    if against in n:
        floor = speed * min(rows[list(n).index(against)][f"{m}_steps_per_second"] for m in ("exploiting", "exploring"))
        ax.axhline(floor, color="r", ls="--", lw=1, label=f"target: {speed:g}x the slower walk at {against:,} cells")
    ax.axvline(at, color="grey", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel="place cells", ylabel="steps / s (best of repeats)", title=f"agent ({args.model} model)")
    ax.legend(fontsize=8)

    ax = axes[0, 1]
    ax.plot(n, [r["peak_rss_mb"] for r in rows], "o-", label="peak resident memory (process)")
    ax.plot(n, [r["W_pp_megabytes"] * 2**20 / 1e6 for r in rows], "s-", label="W_pp (place->place)")
    if rows[0].get("W_pb_megabytes") is not None:
        ax.plot(n, [r["W_pb_megabytes"] * 2**20 / 1e6 for r in rows], "^-", label="W_pb (BVC->place)")
    ax.plot(n, rows[-1]["peak_rss_mb"] * n / n[-1], "k:", label="proportional to n")
    ax.plot(n, rows[-1]["W_pp_megabytes"] * 2**20 / 1e6 * (n / n[-1]) ** 2, "k-.", lw=0.8, label="proportional to n^2")
    ax.axhline(
        target("scaling_memory_mb").bound(), color="r", ls="--", lw=1, label=f"target {target('scaling_memory_mb').text(unit=' MB')}"
    )
    ax.axvline(at, color="grey", lw=0.8)
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
    ax.axhline(
        target("scaling_replay_ms").bound(), color="r", ls="--", lw=1, label=f"target {target('scaling_replay_ms').text(unit=' ms')}"
    )
    ax.axvline(at, color="grey", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel="place cells", ylabel="ms", title="replay after the goal is found")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
