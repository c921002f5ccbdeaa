"""The committed benchmark records (``benchmarks/results/*.json``) as the README and the docs read them.

One reader for both (:mod:`benchmarks.readme_table`, ``docs/hooks.py``): a record that is missing
or cannot be read is a :class:`RecordError` naming the file, never a quiet gap; the figures are
printed one way (:func:`num`, :func:`pct`); and the figures checked against the targets
(:mod:`benchmarks.targets`) are picked out of a record here, once: the speed ratios timed side
by side (:func:`side_by_side`), the agent at 10,000 place cells (:func:`scaling_figures`) and the
environment beside its peer (:func:`env_peer`).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from benchmarks.targets import target

#: Where the committed records are.
RESULTS = Path(__file__).resolve().parent / "results"
#: An "exploiting" walk in which the agent mostly fell back to exploring does not measure exploiting.
MIN_EXPLOIT_SHARE = 0.5


class RecordError(Exception):
    """A committed record is missing, or is not laid out as its reader expects."""


def load(name: str, results: Path | None = None) -> Any:
    """The record ``name`` (a path under ``results``, default :data:`RESULTS`), parsed.

    Raises:
        RecordError: the file is missing or is not JSON.
    """
    path = (results or RESULTS) / name
    try:
        return json.loads(path.read_text())
    except FileNotFoundError as err:
        raise RecordError(f"benchmarks/results/{name} is missing (run the benchmark that writes it)") from err
    except (OSError, ValueError) as err:
        raise RecordError(f"benchmarks/results/{name} cannot be read as JSON: {err}") from err


# ------------------------------------------------------------------ figures as printed


def num(value: Any, digits: int = 2) -> str:
    """A figure as the README and the docs print it: thousands separated, ``digits`` decimals below 100."""
    if value is None:
        return "-"
    if isinstance(value, str):
        return value
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    if isinstance(value, float) and (abs(value) < 100 and value != int(value)):
        return f"{value:.{digits}f}"
    return f"{round(value):,}"


def pct(share: float | None) -> str:
    """A share as a whole percentage; ``-`` for None."""
    return "-" if share is None else f"{100 * share:.0f} %"


def table(header: list[str], rows: list[list[Any]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows]
    return "\n".join(lines)


def spread(summary: dict[str, Any] | None, unit: str = "x") -> str:
    """A median and its quartiles (:func:`hippomaze.stats.median_and_quartiles`): ``0.52x (0.48-0.55x)``."""
    if not summary or summary.get("median") is None:
        return "-"
    q1, q3 = summary["quartiles"]
    return f"{num(summary['median'])}{unit} ({num(q1)}-{num(q3)}{unit})"


# ------------------------------------------------------------------ the maze suite


def later_runs_median(row: dict[str, Any]) -> float:
    """A maze suite row's runs 2-4 median indirectness, a run that missed the goal counted as
    infinite: the record's ``None`` (an infinite median) is ``inf``, a miss."""
    value = row["runs_2_4_median_miss_inf"]
    return math.inf if value is None else float(value)


# ------------------------------------------------------------------ the agent's speed, side by side


def side_by_side(record: dict[str, Any], n_place: int) -> dict[str, Any] | None:
    """The row of ``benchmarks.agent_throughput``'s record timed side by side at ``n_place`` place
    cells; None if the record holds no such row (it predates side-by-side timing, or other sizes).

    Raises:
        RecordError: a row without the ratios every side-by-side row has.
    """
    for row in record.get("side_by_side", []):
        if row.get("n_place") == n_place:
            if not isinstance(row.get("ratios"), dict):
                raise RecordError(f"agent_throughput's side-by-side row at {n_place} place cells has no ratios")
            return row
    return None


# ------------------------------------------------------------------ the agent at 10,000 place cells


def exploit_share(decisions: dict[str, int]) -> float:
    """The share of a walk's steps on which the agent headed for the goal (preplay, or homing along its map)."""
    goal_directed = decisions["exploit"] + decisions.get("home", 0)
    return goal_directed / max(goal_directed + decisions["explore"], 1)


def replays(row: dict[str, Any]) -> bool:
    """Whether a scaling row's replay did anything: a run found the goal and some place cell was active there."""
    return row.get("found_goal", True) and row.get("replay_from_cells", 1) > 0


def scaling_figures(record: dict[str, Any]) -> dict[str, Any]:
    """What a scaling record (``agent_scaling_<model>.json``) says at the targets' number of place
    cells: the slower walk's steps/s over the same model's at the smaller number, the peak memory
    and one replay. ``measured`` is False (with ``why``) when a row is missing, run 1 never found
    the goal (no replay to time), or the agent hardly exploited."""
    speed = target("scaling_speed")
    cells, against = speed["place_cells"], speed["against_place_cells"]
    rows = {row["n_place"]: row for row in record["rows"]}
    out: dict[str, Any] = {"n_place": cells, "against_n_place": against, "measured": False}
    if cells not in rows or against not in rows:
        return out | {"why": f"no row at {cells:,} and {against:,} place cells"}
    row = rows[cells]
    if not replays(row) or exploit_share(row["exploit_decisions"]) < MIN_EXPLOIT_SHARE:
        return out | {
            "why": f"at {cells:,} place cells the goal was not found with a place cell active there, or the agent hardly exploited"
        }

    def slower_walk(r: dict[str, Any]) -> float:
        return min(r["exploiting_steps_per_second"], r["exploring_steps_per_second"])

    return out | {
        "measured": True,
        "speed_ratio": round(slower_walk(row) / slower_walk(rows[against]), 3),
        "peak_rss_mb": row["peak_rss_mb"],
        "replay_ms": row["replay_ms"],
    }


# ------------------------------------------------------------------ the environment beside its peer


def env_peer(record: dict[str, Any]) -> dict[str, Any] | None:
    """``benchmarks.env_throughput``'s steps/s over its peer's at 720 rays, timed interleaved: per maze
    (its ``x_peer``) and the slowest maze's, with its quartiles over the repeats; None if the peer was not timed."""
    peer = record["peer"]
    if not peer.get("timed"):
        return None
    rows = {row["maze"]: row for row in record["single_env"] if "x_peer" in row}
    per_maze = {maze: row["x_peer"] for maze, row in rows.items()}
    slowest = min(per_maze, key=per_maze.get)
    return {
        "name": peer["name"],
        "per_maze": per_maze,
        "slowest_maze": slowest,
        "slowest": per_maze[slowest],
        "slowest_quartiles": rows[slowest].get("x_peer_quartiles"),
    }
