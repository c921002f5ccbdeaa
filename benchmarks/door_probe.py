"""A door cut in a maze's wall: does the default model's map clear it, and does homing take it once
it is clear?

``python -m benchmarks.door_probe --maze gen-rooms-150 --seed 3`` runs the ``mazes`` task's
schedule of :mod:`hippomaze.changing_world` for one maze and runner seed and records, for each run
of the door's layout, the door's cells the agent's map still holds as walls when the run begins,
their counts of scans that saw through them (``ExplorationMap.change``), and the run's path
against the new shortest way. ``--clear`` (PRIVILEGED, a diagnosis only) clears the door's cells
in the agent's map when the door's layout begins: what homing does once the map knows the door.
The door's cells are the map cells whose clearance the door widened (the door itself and the cells
beside it). Writes ``benchmarks/results/door_probe[_clear].json``.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.common import REPO, command_line, parse_dataclass_args
from hippo_env.changes import change_maze
from hippo_env.dmtp import run_dmtp
from hippo_env.files import write_json
from hippo_env.maze import MazeSpec
from hippomaze.changing_world import Watched, maze_schedule, maze_spec
from hippomaze.registry import agent_factory

WIDENED = 0.05  # m: a cell whose centre is this much farther from the walls with the door is one of the door's


@dataclasses.dataclass
class DoorArgs:
    maze: str = "gen-rooms-150"
    """the maze (built-in name or gen-<kind>-<seed>[-<size>m]); a tuning maze by default"""
    seed: int = 3
    """runner seed (the changes are drawn from it)"""
    clear: bool = False
    """PRIVILEGED: clear the door's cells in the agent's map when the door's layout begins"""
    config: str = ""
    """the hippo agent's overrides as JSON (as ``benchmarks.changing_world --config``)"""
    out: str = ""
    """output JSON ('' = benchmarks/results/door_probe[_clear].json)"""


def door_cells(before: MazeSpec, after: MazeSpec, centres: np.ndarray) -> np.ndarray:
    """Which of the map-cell ``centres`` (world coordinates, an (m, 2) array) the door widened:
    inside the maze, and at least ``WIDENED`` farther from its walls in ``after`` than in ``before``."""
    half = np.asarray(before.size, dtype=np.float64) / 2
    inside = np.all(np.abs(centres) < half, axis=1)
    widened = np.zeros(len(centres), dtype=bool)
    for k in np.flatnonzero(inside):
        point = tuple(centres[k])
        widened[k] = after.clearance(point) > before.clearance(point) + WIDENED
    return widened


def probe(args: DoorArgs) -> dict[str, Any]:
    schedule = maze_schedule(args.maze, args.seed)
    names = [p["name"] for p in schedule["phases"]]
    if "door" not in names:
        raise SystemExit(f"maze {args.maze!r} has no door layout at seed {args.seed} (its layouts: {', '.join(names)})")
    door_phase = names.index("door")
    first_door_run = sum(p.get("runs", 4) for p in schedule["phases"][:door_phase])
    before = maze_spec(args.maze)
    overrides = json.loads(args.config) if args.config else {}
    factory = agent_factory("hippo", **overrides)
    cells: dict[str, Any] = {}
    at_start: list[dict[str, Any]] = []

    class Door(Watched):
        def reset(self, observation: Any, info: dict[str, Any]) -> None:
            m = self.agent.map
            if len(self.runs) == first_door_run:  # the door's layout begins
                change = schedule["phases"][door_phase]["maze"]  # drawn as the runner draws it, clear of the goal
                after = change_maze(before, change["change"], change["seed"], keep_clear=[tuple(info["goal"])])
                flat = np.arange(m.n * m.n)
                centres = m.centres(flat) + self.origin
                cells["flat"] = flat[door_cells(before, after, centres)]
                if args.clear:
                    i, j = np.divmod(cells["flat"], m.n)
                    m.hits[i, j] = 0
                    m.free[i, j] = np.maximum(m.free[i, j], 1)
                    m.new_walls[i, j] = False
                    m.change[i, j] = 0
                    m.grids_replaced()
            if "flat" in cells:
                i, j = np.divmod(cells["flat"], m.n)
                walls = (m.hits[i, j] > 0) & (m.hits[i, j] >= m.free[i, j])
                at_start.append({"walls": int(walls.sum()), "counts": m.change[i, j].astype(int).tolist()})
            super().reset(observation, info)

    def make(observation_space: Any, action_space: Any, *, seed: int) -> Watched:
        return Door(factory(observation_space, action_space, seed=seed))

    make.env_kwargs = getattr(factory, "env_kwargs", {})  # type: ignore[attr-defined]
    result = run_dmtp(make, schedule=schedule, seed=args.seed, agent_name="hippo", progress=False)
    runs = [r for r in result.run_records if r.phase == door_phase]
    rows = [
        {"run": r.run, "success": r.success, "path_length": r.path_length, "shortest_path_length": r.shortest_path_length,
         "indirectness": r.indirectness, "door_walls_at_start": s["walls"], "door_counts_at_start": s["counts"]}
        for r, s in zip(runs, at_start)
    ]  # fmt: skip
    return {
        "command": command_line(),
        "maze": args.maze,
        "seed": args.seed,
        "cleared": args.clear,
        "config": overrides,
        "door_cells": len(cells.get("flat", [])),
        "runs": rows,
    }


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(DoorArgs, __doc__.splitlines()[0], argv)
    record = probe(args)
    for row in record["runs"]:
        print(
            f"run {row['run']}: door cells still walls {row['door_walls_at_start']} of {record['door_cells']}, "
            f"indirectness {row['indirectness']:.2f} (path {row['path_length']:.1f} m, shortest {row['shortest_path_length']:.1f} m)"
        )
    out = Path(args.out) if args.out else REPO / "benchmarks" / "results" / f"door_probe{'_clear' if args.clear else ''}.json"
    write_json(out, record)
    print(f"wrote {out}")
    later = record["runs"][1:]
    print(f"runs after the first at most 0.5 indirect: {sum(r['success'] and r['indirectness'] <= 0.5 for r in later)} of {len(later)}")


if __name__ == "__main__":
    main()
