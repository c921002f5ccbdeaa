"""REPORT.md: the claims table, the DMTP tables, the figures with their captions, the limits the
measurements show, and how this reproduction differs from the paper."""

from __future__ import annotations

import platform
from pathlib import Path

import numpy as np

from hippo_env.dmtp import DMTPResult

from .analysis import COMPONENT_MIN_MASS, FAR_PATH, FIELD_LEVEL, FIELD_MIN_PEAK, SIMILAR_PLACE
from .args import PaperArgs
from .design import OBSTACLE_MAZES, PAPER_NAME, SCENARIOS, TRIAL_SEED_STRIDE
from .figures import FIGURES
from .formatting import fmt
from .results import Claim, PaperData

SECOND_PEAK = 0.7  # a map's value >= 3 m from the goal this high (share of its peak) is a false goal


def claims_table(rows: list[Claim]) -> str:
    lines = ["| # | experiment | the paper | we measured | verdict |", "| --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r.id} | {r.experiment} | {r.paper} | {r.measured} | **{r.verdict}** |")
    return "\n".join(lines)


def _slow_runs_text(result: DMTPResult) -> str:
    """How the open arena's later runs fell short: how many, how badly, and where the time went."""
    ind, ok = result.indirectness(), result.success()
    slow = [(r, result.paths[r.trial][r.run]) for r in result.run_records if r.run > 0 and not (r.indirectness <= 1.0)]
    text = (
        f"Open arena: {len(slow)} of {ind[:, 1:].size} later runs had indirectness > 1 (worst {np.nanmax(ind[:, 1:]):.1f}); "
        f"{int((~ok[:, 1:]).sum())} did not reach the goal within the step limit."
    )
    if slow:
        dists = [np.linalg.norm(path - np.asarray(r.goal), axis=1) for r, path in slow]
        near = float(np.median([np.mean(dd <= 1.0) for dd in dists]))
        first = float(np.median([np.argmax(dd <= 1.0) / max(len(dd) - 1, 1) if np.any(dd <= 1.0) else 1.0 for dd in dists]))
        text += (
            f" In those runs the robot first came within 1 m of the goal a median {first:.0%} of the way through the run"
            f" and spent {near:.0%} of its steps within 1 m of it"
        )
        causes = []
        if first > 0.25:
            causes.append("a search away from the goal before it first gets near (where the map is thin or misleading)")
        if near >= 0.15:
            causes.append("circling close to the goal without entering the 0.3 m disk (near misses)")
        text += ": the excess is " + " and ".join(causes) + "." if causes else "."
    return text


def limits(args: PaperArgs, data: PaperData) -> list[str]:
    """What the measurements say the model (or our reproduction) cannot do; computed, not canned."""
    out = []
    result = data.open_dmtp.result
    if result.indirectness().shape[1] > 1:
        out.append(_slow_runs_text(result))
    p = data.open_dmtp.summary.pearson or {}
    if p.get("ci95"):
        loo = p.get("leave_one_out")
        out.append(
            f"The run-1-length / run-2-indirectness correlation rests on {p['n']} trials: its 95 % interval ({p['ci95'][0]:.2f} "
            f"to {p['ci95'][1]:.2f}) is wide"
            + (f", and leaving out a single trial moves r anywhere from {loo[0]:.2f} to {loo[1]:.2f}" if loo else "")
            + ", so neither -0.53 nor our r is pinned down."
        )
    for m, v in data.reward_maps_after_run1.items():
        if not v.found_goal:
            out.append(f"Same-start {m}: run 1 did not find the goal within the step limit, so no reward map was learnt.")
        elif v.stats.far is not None and v.stats.far > 0.3:
            out.append(
                f"Reward map after run 1 in {m}: {v.stats.far:.0%} of places >= {FAR_PATH} m from run 1's path still carry value "
                "(the field effect, and aliased place cells firing elsewhere)."
            )
    peaks = [
        f"{m} after run 1 ({v.stats.second_peak:.0%})"
        for m, v in data.reward_maps_after_run1.items()
        if v.found_goal and (v.stats.second_peak or 0) >= SECOND_PEAK
    ]
    peaks += [
        f"{g.maze} goal {tuple(goal.goal)} ({goal.stats.second_peak:.0%})"
        for g in data.generalisation.values()
        for goal in g.goals
        if (goal.stats.second_peak or 0) >= SECOND_PEAK
    ]
    if peaks:
        out.append(
            f"Maps whose value 3 m or more (geodesic) from the goal reaches {SECOND_PEAK:.0%} of the peak or more, i.e. a "
            "second, false goal the robot can head for: " + ", ".join(peaks) + " (where they lie: figures 2 and 6)."
        )
    mz = data.maze_dmtp
    hard = [
        m
        for m in OBSTACLE_MAZES
        if m in mz and (mz[m].summary.protocol.get("later_runs_success_rate", 1.0) < 0.95 or (mz[m].summary.median_runs_2_on or 0) > 1.0)
    ]
    if hard:
        out.append(
            f"Obstacle mazes, runs 2-{args.runs} with random starts ({args.maze_trials} trials each): "
            + "; ".join(
                f"{m} median indirectness {fmt(mz[m].summary.median_runs_2_on)}, "
                f"{mz[m].summary.protocol['later_runs_success_rate']:.0%} reached the goal"
                for m in hard
            )
            + "."
        )
    a4 = data.place_fields["maze4"]
    if a4.with_field:
        out.append(
            f"Aliasing is structural: in maze4 {a4.multi_quadrant:.0%} of place fields have pieces in several quadrants; BVC "
            "input plus a compass cannot tell "
            "alike compartments apart (no path integration or grid cells in this model, as the paper says)."
        )
    for name, g in data.generalisation.items():
        for goal in g.goals:
            if goal.visited and goal.stats.near is not None and goal.stats.near < 0.5:
                out.append(
                    f"Generalisation {SCENARIOS[name].title}: the map for goal {tuple(goal.goal)} reaches only "
                    f"{goal.stats.near:.0%} of the explored area ({g.maze})."
                )
    out.append(
        f"The same-start figures are single trials ({len(data.same_start.open)} in the open arena, one per maze), drawn by seed, "
        "not chosen; "
        "the paper's are presumably showcases. The random-start tables are the measure."
    )
    return out


def _reproduce_text(args: PaperArgs, data: PaperData) -> str:
    """How any one trial of the run is reproduced with ``hippomaze dmtp``."""
    return (
        "Every trial or experiment ran as its own seeded task, so the numbers do not depend on the number of workers. "
        f"DMTP trial `t` (from 0) with random starts in maze `M` is exactly `hippomaze dmtp --maze M --trials 1 --runs {args.runs} --seed "
        + (f"{TRIAL_SEED_STRIDE * args.seed}+t`" if args.seed else "t`")
        + (f" with `--max-steps {args.max_episode_steps}`" if args.max_episode_steps else "")
        + (
            f" (and the agent's dry run cut to {args.dry_run_steps} steps, which that command does not set)"
            if args.dry_run_steps is not None
            else ""
        )
        + "; a same-start trial adds `--same-start` with seed "
        + ", ".join(
            [f"{x.seed} (open, trial {k + 1})" for k, x in enumerate(data.same_start.open)]
            + [f"{x.seed} ({m})" for m, x in data.same_start.mazes.items()]
        )
        + "."
    )


def _differences(args: PaperArgs) -> list[str]:
    """How this reproduction differs from the paper: simulator, mazes, sampling, statistics, agent."""
    cfg = args.agent_config()
    return [
        (
            "- **Simulator**: pymunk and a 720-ray rangefinder instead of Webots; one place-cell update per 0.15 m step; discrete "
            "actions (8 headings)."
        ),
        (
            "- **Mazes**: the paper gives no coordinates. Our maze1 (two offset walls) and maze2 (three parallel diagonal "
            "walls) stand for its Mazes 1 and 2; its Maze 3, "
            'the four alike compartments, is our maze4 (the "+"), which is also Fig. 9\'s maze. maze3 (two alike cups) is '
            "ours, not the paper's."
        ),
        (
            f"- **Maps**: sampled as in the paper by an aimless roam ({args.roam_steps} steps in 16 legs from random starts, a "
            "separate environment, no agent stepped so nothing "
            "learns), reading the steady-state place-cell rates for the observation at each visited position "
            "(`agent.place_field_map` / `agent.reward_map`). "
            f"Field statistics and aliasing use a {args.grid_spacing} m grid instead, so every compartment is sampled."
        ),
        (
            f"- **Field statistics**: a cell has a field if its peak rate on the grid is >= {FIELD_MIN_PEAK}; the field is where "
            f"the rate is >= {FIELD_LEVEL:.0%} of the peak; "
            f"a separate piece counts if it holds >= {COMPONENT_MIN_MASS:.0%} of the field's rate; solidity = main piece's area "
            "/ its convex hull's. A field 'in several "
            "quadrants' has separate pieces in them (a field straddling a gap is one piece); 'similar places' = pieces within "
            f"{SIMILAR_PLACE} m once folded by 5 m "
            "translations into one compartment."
        ),
        (
            "- **Reward-map statistics**: a place is covered if the value exceeds the agent's exploit threshold xi = "
            f"{cfg.model.xi:g}; gradedness is Spearman's rho between "
            "value and the geodesic distance to the goal over covered places."
        ),
        (
            "- **Generalisation**: the dry run (place fields everywhere, W_pb only) precedes every scenario, as before every "
            "DMTP trial; W_pp is learnt only on the "
            "exploration shown. 'Replay only' = a new reward cell, the place cells set to their steady-state rates at the goal, "
            "then the agent's own replay "
            "(`learn_reward`, Algorithm 1). The maps are then also tested by runs from random starts."
        ),
        f"- **Agent**: `{'AgentConfig.paper()' if args.model == 'paper' else 'AgentConfig()'}`"
        + (f" with dry_run_steps={args.dry_run_steps}" if args.dry_run_steps is not None else "")
        + " (see paper.json for every value).",
    ]


def write_report(args: PaperArgs, data: PaperData, rows: list[Claim], figures: list[Path], out: Path, wall: float, command: str) -> Path:
    from hippomaze.report import format_table

    present = {p.name for p in figures}
    lines = [
        "# The paper's experiments, reproduced on HippoMaze-v0",
        "",
        (
            f"Generated by `benchmarks/paper.py`; {'**quick smoke run** (tiny settings: the numbers mean nothing), ' if args.quick else ''}"
            f"wall time {wall / 60:.1f} min on {args.workers} worker process(es), {platform.machine()} / Python "
            f"{platform.python_version()}."
        ),
        "",
        "```bash",
        command,
        "```",
        "",
        _reproduce_text(args, data),
        "",
        "## Claims beside measurements",
        "",
        claims_table(rows),
        "",
        "How each verdict was decided (each criterion sits beside its claim in hippomaze/paper/claims.py):",
        "",
        *[f"- **{r.id}**: {r.criterion}." for r in rows],
        "",
        "## Open arena DMTP (experiments 4-5)",
        "",
        "```",
        format_table(data.open_dmtp.result),
        "```",
        "",
    ]
    if data.maze_dmtp:
        lines += [
            "## Every maze with random starts (beyond the paper)",
            "",
            "| maze | paper's name | trials | median indirectness by run | runs 2+ reaching the goal |",
            "| --- | --- | --- | --- | --- |",
        ]
        for m, v in data.maze_dmtp.items():
            s = v.summary
            lines.append(
                f"| {m} | {PAPER_NAME[m]} | {v.result.trials} | "
                + " / ".join(fmt(x) for x in s.median_indirectness)
                + f" | {fmt(s.later_runs_success_rate, pct=True)} |"
            )
        lines.append("")
    lines += ["## Figures", ""]
    for name, title, caption in FIGURES:
        if name in present:
            lines += [f"### {title}", "", f"![{title}]({name})", "", caption, ""]
    lines += [
        "## Limits we found",
        "",
        *[f"- {x}" for x in limits(args, data)],
        "",
        "## How this reproduction differs from the paper",
        "",
        *_differences(args),
        "",
    ]
    path = out / "REPORT.md"
    path.write_text("\n".join(lines))
    return path
