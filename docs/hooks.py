"""mkdocs hooks: the measured figures on the site come from ``benchmarks/results`` at build time.

- A page line ``<!-- results: NAME -->`` becomes the table ``NAME`` below, made from the committed
  JSON (read by :mod:`benchmarks.records`) and the targets (``benchmarks/targets.toml``, read by
  :mod:`benchmarks.targets`); no measured figure or target is typed into a page or in here.
- A page may show a figure from ``benchmarks/results`` as ``results/PATH.png``; it is taken from
  there when the site is built (no copy in ``docs/``).
- The page ``changelog.md`` is the repository's ``CHANGELOG.md``.
- ``<!-- animation -->`` shows ``docs/img/animate.gif`` (written by ``hippomaze animate``) if it
  exists.

Strict by design: a results file that is missing, or laid out otherwise than its table reads it,
fails the build (:class:`~benchmarks.records.RecordError`, raised to mkdocs as a ``PluginError``),
so that a lost table cannot go unnoticed. A record written before its benchmark timed what its
table shows says so on the page ("not measured yet").
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # benchmarks/ is repository code, not installed
    sys.path.insert(0, str(ROOT))

from benchmarks import records
from benchmarks.records import RecordError, num, pct, spread, table
from benchmarks.targets import target, verdict

RESULTS = records.RESULTS
MARKER = re.compile(r"^<!-- results: ([a-z0-9_]+) -->$", re.MULTILINE)
FIGURE = re.compile(r"\]\((?:\.\./)*results/([\w./-]+\.(?:png|gif|svg))\)")


def load(name: str) -> Any:
    return records.load(name, RESULTS)


def source(*names: str) -> str:
    """The line under a table that says where its figures come from, with the commands that made them."""
    commands = []
    for name in names:
        data = load(name)
        if "command" not in data:
            raise RecordError(f"benchmarks/results/{name} does not say the command that made it")
        commands.append(f"`{data['command']}`")
    files = ", ".join(f"`benchmarks/results/{name}`" for name in names)
    return f"\n\n*From {files}, made by {'; '.join(commands)}.*"


def not_measured_yet(what: str, command: str) -> str:
    return f'!!! note "Not measured yet"\n    {what} Run `{command}` to measure it.'


# ------------------------------------------------------------------ the maze suite


def suite_rows(name: str) -> tuple[dict[str, list[dict[str, Any]]], list[int]]:
    by_maze: dict[str, list[dict[str, Any]]] = {}
    for row in load(name)["rows"]:
        by_maze.setdefault(row["maze"], []).append(row)
    seeds = sorted({row["seed"] for rows in by_maze.values() for row in rows})
    return by_maze, seeds


def median_cell(row: dict[str, Any] | None) -> str:
    if row is None:
        return "-"
    return f"{num(row['runs_2_4_median_miss_inf'])} ({pct(row['runs_2_4_reached'])})"


def maze_suite() -> str:
    by_maze, seeds = suite_rows("maze_suite_default.json")
    indirectness, reached, dry_run = target("indirectness"), target("reached"), target("dry_run_length")
    header = ["maze"] + [f"seed {s}" for s in seeds] + ["target", "dry run (steps)", "dry-run target", "place cells", "verdict"]
    rows, met = [], 0
    for maze, found in by_maze.items():
        per_seed = {row["seed"]: row for row in found}
        ok = all(indirectness.met(records.later_runs_median(row), maze) is not False for row in found)
        ok = ok and all(reached.met(row["runs_2_4_reached"], maze) is not False for row in found)
        dry = [per_seed[s]["dry_run_steps_median"] for s in seeds if s in per_seed]
        ok_dry = all(dry_run.met(d, maze) is not False for d in dry)
        cells = sorted({c for row in found for c in row.get("place_cells", [])})
        missed = [what for what, good in (("indirectness", ok), ("dry run", ok_dry)) if not good]
        met += not missed
        goal = indirectness.text(maze) + ("" if reached.bound(maze) is None else f", {reached.op} {pct(reached.bound(maze))} reached")
        rows.append(
            [
                maze,
                *(median_cell(per_seed.get(s)) for s in seeds),
                goal,
                " / ".join(num(d) for d in dry),
                dry_run.text(maze),
                "-".join(num(c) for c in (cells[0], cells[-1]) if cells) if len(cells) > 1 else num(cells[0] if cells else None),
                "met" if not missed else "**missed** (" + ", ".join(missed) + ")",
            ]
        )
    summary = f"\n\n**{met} of {len(rows)} mazes meet every target on every seed.**"
    return table(header, rows) + summary + source("maze_suite_default.json")


def maze_suite_random_walk() -> str:
    now, seeds = suite_rows("maze_suite_default.json")
    before, _ = suite_rows("maze_suite_random_walk.json")
    header = ["maze"] + [f"seed {s}: random walk -> directed" for s in seeds]
    rows = []
    for maze, found in before.items():
        old = {row["seed"]: row for row in found}
        new = {row["seed"]: row for row in now.get(maze, [])}
        rows.append([maze, *(f"{median_cell(old.get(s))} -> {median_cell(new.get(s))}" for s in seeds)])
    return table(header, rows) + source("maze_suite_random_walk.json", "maze_suite_default.json")


# ------------------------------------------------------------------ sample efficiency


SWITCH_COLUMN = "after a goal switch"


def split_table(markdown: str, keep: Callable[[str], bool]) -> str:
    """The columns of a Markdown table whose header ``keep`` accepts (the first, the row names, always)."""
    rows = [[cell.strip() for cell in line.strip().strip("|").split("|")] for line in markdown.strip().splitlines()]
    header, body = rows[0], [row for row in rows[2:] if row]
    columns = [0] + [i for i, name in enumerate(header) if i and keep(name)]
    return table([header[i] for i in columns], [[row[i] for i in columns] for row in body])


def sample_efficiency_table(keep: Callable[[str], bool]) -> str:
    """Part of the table ``python -m benchmarks.sample_efficiency`` writes (its ``table_markdown``, made by
    :mod:`hippomaze.bench.report` from the JSON's ``statistics``)."""
    return split_table(load("sample_efficiency.json")["table_markdown"], keep) + source("sample_efficiency.json")


def sample_efficiency() -> str:
    return sample_efficiency_table(lambda column: SWITCH_COLUMN not in column)


def goal_switch() -> str:
    return sample_efficiency_table(lambda column: SWITCH_COLUMN in column)


# ------------------------------------------------------------------ the paper's claims


def paper_claims() -> str:
    models = {"the paper's model": load("paper/paper.json"), "the default model": load("paper_default/paper.json")}
    verdicts = {label: {c["id"]: c for c in data["claims"]} for label, data in models.items()}
    first = next(iter(models.values()))["claims"]
    header = ["#", "the paper says"] + [f"{label}: verdict" for label in models]
    rows = [[c["id"], c["paper"], *(f"**{verdicts[label][c['id']]['verdict']}**" for label in models)] for c in first]
    return table(header, rows) + source("paper/paper.json", "paper_default/paper.json")


def paper_details() -> str:
    paper, default = load("paper/paper.json")["claims"], {c["id"]: c for c in load("paper_default/paper.json")["claims"]}
    rows = [[c["id"], c.get("criterion", ""), c["measured"], default[c["id"]]["measured"]] for c in paper]
    return table(["#", "verdict criterion", "the paper's model measured", "the default model measured"], rows) + source(
        "paper/paper.json", "paper_default/paper.json"
    )


def paper_verdicts() -> str:
    rows = []
    for label, name in (
        ("the paper's model (`AgentConfig.paper()`)", "paper/paper.json"),
        ("the default model (`AgentConfig()`)", "paper_default/paper.json"),
    ):
        claims = load(name)["claims"]
        targets = [c for c in claims if c["id"].startswith("T")]  # the project's own targets, not the paper's claims
        counts = {v: sum(c["verdict"] == v for c in claims if c not in targets) for v in ("reproduced", "partly", "not reproduced")}
        met = sum(c["verdict"] == "met" for c in targets)
        rows.append([label, *(counts[v] for v in counts), f"{met} of {len(targets)}"])
    return table(["model", "reproduced", "partly", "not reproduced", "project targets met"], rows) + source(
        "paper/paper.json", "paper_default/paper.json"
    )


# ------------------------------------------------------------------ speed and memory


def agent_throughput() -> str:
    """The speed ratios timed side by side (``benchmarks.agent_throughput``), with their targets."""
    data = load("agent_throughput.json")
    names = ("agent_vs_ratinabox", "default_vs_paper", "dry_run_step")
    keys = {
        "agent_vs_ratinabox": "default_x_ratinabox",
        "default_vs_paper": "default_x_paper",
        "dry_run_step": "dry_run_step_x_exploiting_step",
    }
    sizes = sorted({target(name)["place_cells"] for name in names} | {row["n_place"] for row in data.get("side_by_side", [])})
    rows, speeds = [], []
    for n_place in sizes:
        row = records.side_by_side(data, n_place)
        if row is None:
            continue
        cells: list[Any] = [num(n_place), len(row["repeats"])]
        for name in names:
            summary = row["ratios"].get(keys[name])
            goal = target(name)
            measured = summary["median"] if summary else None
            shown = "not timed" if summary is None else spread(summary)
            cells.append(
                f"{shown}; target {goal.text(unit='x')}: {verdict(goal.met(measured))}" if goal["place_cells"] == n_place else shown
            )
        rows.append(cells)
        s, ratios = row["steps_per_second"], row["ratios"]
        speeds.append(
            f"{num(n_place)} place cells: default {num(s['default']['median'])}, paper's model {num(s['paper']['median'])}"
            + (f", RatInABox {num(s['ratinabox']['median'])} (BLAS on one thread)" if "ratinabox" in s else "")
            + (
                f" and {num(s['ratinabox_blas_threads']['median'])} with BLAS on all cores (default / RatInABox "
                f"{spread(ratios['default_x_ratinabox_blas_threads'])})"
                if "ratinabox_blas_threads" in s
                else ""
            )
            + f"; the default model's dry run {num(s['dry_run']['median'])} (its own time, the environment's taken out)"
            + (
                f", {num(s['dry_run_without_rest']['median'])} with the rest at its end taken out (a step then "
                f"{spread(ratios['dry_run_step_without_rest_x_exploiting_step'])} an exploiting step's time)"
                if "dry_run_without_rest" in s
                else ""
            )
        )
    if not rows:
        return not_measured_yet(
            "`benchmarks/results/agent_throughput.json` was written before the models and RatInABox were timed side by side.",
            "python -m benchmarks.agent_throughput",
        )
    header = [
        "place cells",
        "repeats",
        "default / RatInABox (steps/s)",
        "default / paper's model (steps/s)",
        "dry-run step / exploiting step (time)",
    ]
    note = (
        "\n\nMedians over the repeats (quartiles in brackets) of ratios timed in turn on one load of one machine. Steps/s there (medians): "
        + "; ".join(speeds)
        + "."
    )
    return table(header, rows) + note + source("agent_throughput.json")


def agent_scaling() -> str:
    rows = []
    names = (("scaling_speed", "speed_ratio", "x"), ("scaling_memory_mb", "peak_rss_mb", " MB"), ("scaling_replay_ms", "replay_ms", " ms"))
    for model, name in (("paper's model", "agent_scaling_paper.json"), ("default model", "agent_scaling_default.json")):
        data = load(name)
        figures = records.scaling_figures(data)
        if not figures["measured"]:
            rows.append([model, *(f"not measured ({figures['why']})" for _ in names), data["growth"]["exploiting"]["verdict"]])
            continue
        cells = [
            f"{num(figures[key])}{unit} (target {target(t).text(unit=unit)}: {verdict(target(t).met(figures[key]))})"
            for t, key, unit in names
        ]
        rows.append([model, *cells, data["growth"]["exploiting"]["verdict"]])
    speed = target("scaling_speed")
    header = [
        f"agent at {num(speed['place_cells'])} place cells",
        f"steps/s over its own at {num(speed['against_place_cells'])} (the slower walk)",
        "peak memory",
        "one replay",
        "step time against cells",
    ]
    return table(header, rows) + source("agent_scaling_paper.json", "agent_scaling_default.json")


def agent_growth() -> str:
    models = {"paper's model": load("agent_scaling_paper.json"), "default model": load("agent_scaling_default.json")}
    by_cells: dict[int, dict[str, dict[str, Any]]] = {}
    for model, data in models.items():
        for row in data["rows"]:
            by_cells.setdefault(row["n_place"], {})[model] = row
    header = ["place cells"] + [f"{m}: {what}" for m in models for what in ("steps/s exploiting", "replay (ms)", "peak memory (MB)")]
    rows = []
    for cells, found in sorted(by_cells.items()):
        cells_row: list[Any] = [num(cells)]
        for m in models:
            row = found.get(m)
            cells_row += (
                ["-"] * 3 if row is None else [num(row["exploiting_steps_per_second"]), num(row["replay_ms"]), num(row["peak_rss_mb"], 0)]
            )
        rows.append(cells_row)
    return table(header, rows) + source("agent_scaling_paper.json", "agent_scaling_default.json")


def env_scaling() -> str:
    data = load("env_scaling.json")
    rows, seen = [], set()
    for row in data["rows"]:
        key = (row["maze"], row["size_m"], row["n_rays"])  # the rays and size series share a point
        if key in seen:
            continue
        seen.add(key)
        split = row["split_us_per_step"]
        total = split["total"]
        rows.append(
            [
                row["maze"],
                f"{num(row['size_m'])} m",
                row["n_rays"],
                num(row["steps_per_second"]),
                pct(split["ray_cast"] / total),
                pct(split["physics"] / total),
                pct(split["step_overhead"] / total),
                pct(row["wall_contact_share"]),
            ]
        )
    header = ["maze", "arena", "rays", "steps/s", "ray casting", "physics", "rest of step", "steps touching a wall"]
    verdicts = [f"{name.replace('_', ' against ')}: {g['verdict']}" for name, g in data["growth"].items()]
    return table(header, rows) + "\n\nStep time " + "; ".join(verdicts) + "." + source("env_scaling.json")


def env_throughput() -> str:
    data = load("env_throughput.json")
    by_maze: dict[str, dict[int, int]] = {}
    for row in data["single_env"]:
        by_maze.setdefault(row["maze"], {})[row["n_rays"]] = row["steps_per_second"]
    rays = sorted({r for v in by_maze.values() for r in v})
    rows = [[maze, *(num(v.get(r)) for r in rays)] for maze, v in by_maze.items()]
    text = table(["maze"] + [f"{r} rays (steps/s)" for r in rays], rows)
    peer = records.env_peer(data)
    goal = target("env_vs_pointmaze")
    if peer is not None:
        quartiles = peer["slowest_quartiles"]
        spread = f"quartiles over the repeats {num(quartiles[0])}-{num(quartiles[1])}x; " if quartiles else ""
        text += (
            f"\n\nAt 720 rays, timed interleaved with Gymnasium-Robotics' `{peer['name']}`, the slowest maze ({peer['slowest_maze']})"
            f" ran {num(peer['slowest'])}x as fast ({spread}target {goal.text(unit='x')}: {verdict(goal.met(peer['slowest']))})."
        )
    load_note = data.get("machine", {}).get("load_average_at_start")
    if load_note:
        text += f" Load average at the start: {load_note[0]} on {data['machine'].get('cpu_count')} cores."
    return text + source("env_throughput.json")


def end_to_end() -> str:
    data = load("end_to_end.json")
    summary = {(s["command"], s["checkout"]): s for s in data["summary"]}
    now, before = data["args"]["repos"][0], data["args"]["repos"][1]
    rows = []
    for command in data["args"]["which"]:
        a, b = summary[(command, now)], summary[(command, before)]
        rows.append(
            [
                f"`hippomaze {command}`",
                f"{num(b['median_wall_seconds'], 1)} s -> {num(a['median_wall_seconds'], 1)} s ({b['median_wall_seconds'] / a['median_wall_seconds']:.2f}x)",
                f"{num(b['median_cpu_seconds'], 1)} s -> {num(a['median_cpu_seconds'], 1)} s ({b['median_cpu_seconds'] / a['median_cpu_seconds']:.2f}x)",
            ]
        )
    return table(["command", f"wall, {before} -> now", "CPU"], rows) + source("end_to_end.json")


def footprint() -> str:
    data = load("footprint.json")
    rows = [
        [maze, num(s["make_seconds"], 2), num(s["make_and_reset_seconds"], 2), num(s["peak_above_import_mb"], 0)]
        for maze, s in data["set_up"].items()
    ]
    text = table(["maze", "gym.make (s)", "make + first reset (s)", "peak above the imports (MB)"], rows)
    long_run = data.get("long_run")
    if long_run:
        resident = [s["resident_mb"] for s in long_run["samples"]]
        text += (
            f"\n\nA goal-free run of {num(long_run['steps'])} steps in {long_run['maze']}: resident memory"
            f" {num(resident[0], 0)} MB at the start, at most {num(max(resident), 0)} MB."
        )
    return text + source("footprint.json")


def coverage() -> str:
    data = load("coverage/coverage.json")
    rows = [
        [
            row["maze"],
            row["seed"],
            f"{num(row['directed']['steps'])}: {pct(row['directed']['final'])}, 80 % at {num(row['directed']['steps_to_80'])}",
            f"{num(row['random']['steps'])}: {pct(row['random']['final'])}, 80 % at {num(row['random']['steps_to_80'])}",
        ]
        for row in data["rows"]
    ]
    return table(["maze", "seed", "directed dry run: steps, coverage", "random walk: steps, coverage"], rows) + source(
        "coverage/coverage.json"
    )


def diagnose() -> str:
    rows, names = [], []
    for path in sorted((RESULTS / "diagnose").glob("*.json")):
        d = load(f"diagnose/{path.name}")
        names.append(f"diagnose/{path.name}")
        rows.append(
            [
                d["maze"],
                d["model"] + (" (true position given: privileged)" if d.get("oracle_privileged") else ""),
                d["trials"],
                num(d["runs_2_4_median"]),
                pct(d["runs_2_4_reached"]),
                pct(d.get("runs_misplaced_share")),
                num(d.get("pi_error_median_m")),
                pct(d.get("reward_map_coverage")),
                num(d.get("dry_run_steps_median")),
            ]
        )
    header = [
        "maze",
        "model",
        "trials",
        "runs 2-4 median",
        "reached",
        "runs misplaced",
        "position error (m)",
        "reward map covers",
        "dry run",
    ]
    if not rows:
        raise RecordError("benchmarks/results/diagnose/ holds no record (run python -m benchmarks.diagnose)")
    commands = sorted({f"`{load(n)['command']}`" for n in names})
    return table(header, rows) + f"\n\n*From `benchmarks/results/diagnose/*.json`, made by {'; '.join(commands)}.*"


# ------------------------------------------------------------------ a world that changes


def changing_world() -> str:
    """Per agent: the changed-world measures beside their targets."""
    data = load("changing_world.json")
    rows = []
    measures = (
        ("new blocks: first run in a layout succeeds", "barriers", "first_run_success", "changed_first_run_success", pct),
        ("new blocks: all runs succeed", "barriers", "success", "changed_success", pct),
        ("new blocks: median indirectness of successes", "barriers", "median_indirectness_of_successes", "changed_indirectness", num),
        ("new blocks: anchored steps within 0.5 m", "barriers", "position_within_0_5m", "changed_position", pct),
        ("new blocks: steps anchored", "barriers", "anchored_share", None, pct),
        ("mazes changed: first run in a layout succeeds", "mazes", "first_run_success", None, pct),
        ("mazes changed: all runs succeed", "mazes", "success", None, pct),
        ("mazes changed: median indirectness of successes", "mazes", "median_indirectness_of_successes", None, num),
        ("mazes changed: anchored steps within 0.5 m", "mazes", "position_within_0_5m", None, pct),
        ("a door cut: runs after the first taking it", "shortcut", "taken", "shortcut_taken", pct),
        ("back in a known world: run 1's median indirectness", "worlds", "run1_back_median", "worlds_return", num),
        ("first visit: runs 2-4 median", "worlds", "first_visit_runs_2_4_median", None, num),
        ("back, a new goal: runs 2-4 median", "worlds", "new_goal_back_runs_2_4_median", None, num),
    )
    agents = list(data["summary"])
    for label, task, key, name, show in measures:
        values = []
        for agent in agents:
            entry = data["summary"][agent].get(task, {})
            values.append((entry.get("all", {}) if task == "mazes" else entry).get(key))
        goal = target(name) if name else None
        mine = values[agents.index("hippo")] if "hippo" in agents else None
        bound = "-" if goal is None else (f"{goal.op} {pct(goal.bound())}" if show is pct else goal.text())
        rows.append([label, *(show(v) for v in values), bound, verdict(goal.met(mine)) if goal else "-"])
    return table(["measure", *agents, "target", "default model"], rows) + source("changing_world.json")


TABLES: dict[str, Callable[[], str]] = {
    "maze_suite": maze_suite,
    "maze_suite_random_walk": maze_suite_random_walk,
    "sample_efficiency": sample_efficiency,
    "goal_switch": goal_switch,
    "paper_claims": paper_claims,
    "paper_details": paper_details,
    "paper_verdicts": paper_verdicts,
    "agent_throughput": agent_throughput,
    "agent_scaling": agent_scaling,
    "agent_growth": agent_growth,
    "env_scaling": env_scaling,
    "env_throughput": env_throughput,
    "end_to_end": end_to_end,
    "footprint": footprint,
    "coverage": coverage,
    "diagnose": diagnose,
    "changing_world": changing_world,
}


def render(name: str) -> str:
    """The table ``name``.

    Raises:
        RecordError: a results file it reads is missing or not laid out as the table reads it.
        ValueError: no table is called ``name``.
    """
    if name not in TABLES:
        raise ValueError(f"docs: unknown results table {name!r}; known: {', '.join(TABLES)}")
    try:
        return TABLES[name]()
    except RecordError as err:
        raise RecordError(f"the results table {name!r} cannot be made: {err}") from err
    except (KeyError, IndexError, TypeError, ValueError, ZeroDivisionError) as err:
        raise RecordError(f"the results table {name!r} cannot be made from benchmarks/results ({type(err).__name__}: {err})") from err


# ------------------------------------------------------------------ mkdocs events


def on_files(files: Any, config: Any) -> Any:
    """Add the figures that pages take from ``benchmarks/results`` to the site, as ``results/...``."""
    from mkdocs.structure.files import File

    wanted: set[str] = set()
    for page in Path(config["docs_dir"]).rglob("*.md"):
        wanted.update(FIGURE.findall(page.read_text()))
    for relative in sorted(wanted):
        path = RESULTS / relative
        if path.is_file() and files.get_file_from_path(f"results/{relative}") is None:
            files.append(File.generated(config, f"results/{relative}", abs_src_path=str(path)))
    files.append(File.generated(config, "changelog.md", content=(ROOT / "CHANGELOG.md").read_text()))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    from mkdocs.exceptions import PluginError

    try:
        markdown = MARKER.sub(lambda match: render(match.group(1)), markdown)
    except (RecordError, ValueError) as err:
        raise PluginError(f"{page.file.src_uri}: {err}") from err
    gif = Path(config["docs_dir"]) / "img" / "animate.gif"
    depth = "../" * page.file.src_uri.count("/")
    animation = (
        f"![the hippocampal agent in a maze: a dry run, then runs to the hidden goal]({depth}img/animate.gif)" if gif.exists() else ""
    )
    return markdown.replace("<!-- animation -->", animation)
