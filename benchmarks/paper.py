"""Reproduce every experiment of the paper's "Experimental Results" section on ``HippoMaze-v0``.

    python -m benchmarks.paper --out benchmarks/results/paper     # the committed run (2 workers)
    python -m benchmarks.paper --out /tmp/paper --quick           # every experiment, tiny (CI)
    hippomaze paper --out DIR [--quick] [--seed S] [--workers W]  # the same from the console script

Writes the figures, ``REPORT.md`` (every figure, and a table putting each of the paper's claims
beside our measurement with a plain verdict) and ``paper.json`` (every number) into ``--out``:

1. Place fields after the dry run, open arena and every maze (paper Fig. 2).
2. The reward map implied after run 1, sampled by roaming with learning off (Figs. 3 and 8).
3. Same start, four runs: three trials in the open arena, one in each maze (Figs. 4 and 7).
4. 20 trials with random starts in the open arena: indirectness per run (Fig. 5); beyond the
   paper, the same in every obstacle maze.
5. Run 1's path length against run 2's indirectness, with the Pearson r (Fig. 6; paper -0.53).
6. Generalisation: explore with no goal (extensively, or along one scripted path), put the reward
   at chosen places, replay only, and sample the inferred reward maps (Fig. 10).
7. Perceptual aliasing in maze4: place cells with fields in several compartments (Fig. 9).

Every trial or experiment is one task with its own seed, run in a ``ProcessPoolExecutor``;
results are gathered by task name, so nothing depends on ``--workers``. DMTP trials go through
``hippo_env.protocol.run_dmtp``, one call per trial: trial ``t`` (from 0) in maze ``M`` is exactly
``hippomaze dmtp --maze M --trials 1 --runs 4 --seed <1000 * seed + t>``.

Maps are sampled the paper's way: the robot roams aimlessly (a separate environment; no agent is
stepped, so nothing learns) and at every position visited we read the place cells' steady-state
rates for the observation there (``agent.place_field_map`` / ``agent.reward_map``). Statistics
about field shape and aliasing use a regular grid of positions instead, so that every compartment
is sampled.
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import functools
import heapq
import json
import math
import multiprocessing
import os
import platform
import shlex
import sys
import time
import warnings
from collections import deque
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import hippo_env  # registers HippoMaze-v0
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS
from hippo_env.protocol import DMTPResult, run_dmtp

MAZES = ("open", "maze1", "maze2", "maze3", "maze4")
OBSTACLE_MAZES = MAZES[1:]
# Which of our mazes plays which of the paper's (see REPORT.md, "Mazes").
PAPER_NAME = {"open": "open maze", "maze1": "Maze 1", "maze2": "Maze 2", "maze3": "(not in the paper)", "maze4": "Maze 3 / Fig. 9's maze 4"}

# Generalisation (experiment 6): the scenarios and where the reward is put.
LIMITED_PATH = ((-4.0, -3.0), (3.0, -3.0), (3.0, 3.0))  # an L driven once, by script
SCENARIOS: dict[str, dict[str, Any]] = {
    "open_extensive": {"maze": "open", "explore": "agent", "goals": ((2.5, 2.5), (-3.0, -1.0), (0.5, -3.5)), "title": "(a) open, extensive"},
    "open_limited": {"maze": "open", "explore": "scripted", "goals": ((-1.5, -3.0), (3.0, 2.0), (2.0, 0.5), (-3.0, 3.0)), "title": "(b) open, one path"},
    "maze2_extensive": {"maze": "maze2", "explore": "agent", "goals": ((-3.5, -3.5), (-0.8, -0.8), (3.2, 3.2)), "title": "(c) maze2, extensive"},
}

# Analysis thresholds (the report states them).
FIELD_MIN_PEAK = 0.1  # a cell "has a field" if its peak rate on the grid reaches this
FIELD_LEVEL = 0.5  # the field is where the rate is at least this fraction of the peak
COMPONENT_MIN_MASS = 0.1  # a separate piece of a field counts if it holds this share of the field's rate
NEAR_PATH, FAR_PATH = 0.5, 2.0  # m: "explored" / "far from anything explored"
VISITED = 0.5  # m: a goal this close to the exploration path was visited
SECOND_PEAK = 0.7  # a map's value >= 3 m from the goal this high (share of its peak) is a false goal
SIMILAR_PLACE = 1.0  # m: aliased pieces within this of each other in compartment coordinates
COMPARTMENT = 5.0  # m: maze4's quadrants (and maze3's halves) repeat every 5 m
EXAMPLE_CELLS = 4
TRIAL_SEED_STRIDE = 1000


# ====================================================================================== arguments
@dataclass
class PaperArgs:
    """Everything the benchmark takes (CleanRL style: one dataclass, parsed from the command line)."""

    out: str = "benchmarks/results/paper"
    """Output folder for REPORT.md, paper.json and the figures."""
    quick: bool = False
    """A smoke run of every experiment (3 trials of 2 runs, short dry run and runs, coarse maps; it overrides
    the sizes below): about a minute."""
    seed: int = 0
    """Base seed; every task's seed derives from it (see the module docstring)."""
    workers: int = 2
    """Processes for the independent tasks (1 = run in this process). Results do not depend on it."""
    trials: int = 20
    """Open-arena DMTP trials with random starts (experiments 4 and 5; paper: 20)."""
    runs: int = 4
    """Runs per trial, the first naive (paper: 4)."""
    same_start_trials: int = 3
    """Open-arena trials with every run from the same start (experiment 3; paper: 3)."""
    maze_trials: int = 10
    """DMTP trials with random starts in each obstacle maze (beyond the paper; 0 skips them)."""
    roam_steps: int = 4000
    """Steps of aimless roaming over which place fields and reward maps are sampled."""
    grid_spacing: float = 0.2
    """Metres between the grid positions used for field statistics and aliasing."""
    explore_steps: int = 5000
    """Goal-free exploration (W_pp learning) before the generalisation replays."""
    nav_runs: int = 5
    """Runs from random starts toward each generalisation goal, to test the inferred map."""
    nav_max_steps: int = 3000
    """Step limit of those runs."""
    model: str = "paper"
    """The agent: ``paper`` (``AgentConfig.paper()``, the model as the paper describes it) or
    ``default`` (``AgentConfig()``, with path integration)."""
    dry_run_steps: int | None = None
    """Override the agent's dry run (None: the config's default)."""
    max_episode_steps: int | None = None
    """Override the environment's 10,000-step limit per DMTP run (None: keep it)."""
    progress: bool = True
    """Show a progress bar."""

    def resolved(self) -> PaperArgs:
        """The arguments actually used: ``quick`` shrinks everything."""
        if not self.quick:
            return self
        return dataclasses.replace(
            self, trials=3, runs=2, same_start_trials=1, maze_trials=1, roam_steps=300, grid_spacing=0.5,
            explore_steps=300, nav_runs=1, nav_max_steps=200, dry_run_steps=300, max_episode_steps=400,
        )

    def agent_config(self) -> AgentConfig:
        if self.model not in ("paper", "default"):
            raise ValueError(f"--model {self.model!r} is unknown; allowed: paper, default")
        config = AgentConfig.paper() if self.model == "paper" else AgentConfig()
        return config if self.dry_run_steps is None else config.replace(dry_run_steps=int(self.dry_run_steps))

    def command(self) -> str:
        """The command line that reproduces this run."""
        parts = ["python", "-m", "benchmarks.paper", "--out", self.out, "--seed", str(self.seed), "--workers", str(self.workers)]
        default = PaperArgs()
        for f in dataclasses.fields(self):
            if f.name in ("out", "seed", "workers", "progress"):
                continue
            value = getattr(self, f.name)
            if value != getattr(default, f.name):
                parts += [f"--{f.name.replace('_', '-')}"] if f.type in ("bool",) else [f"--{f.name.replace('_', '-')}", str(value)]
        return shlex.join(parts)


def parse_args(argv: list[str] | None = None) -> PaperArgs:
    """Command-line flags, one per ``PaperArgs`` field (``--no-progress`` turns the bar off)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.paper", description=__doc__.split("\n\n")[0])
    for f in dataclasses.fields(PaperArgs):
        flag = "--" + f.name.replace("_", "-")
        if f.name == "progress":
            parser.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
        elif f.type == "bool":
            parser.add_argument(flag, action="store_true", help=f"(default: {f.default})")
        elif f.type == "int | None":
            parser.add_argument(flag, type=int, default=f.default, help=f"(default: {f.default})")
        else:
            kind = {"int": int, "float": float, "str": str}[f.type]
            parser.add_argument(flag, type=kind, default=f.default, help=f"(default: {f.default})")
    return PaperArgs(**vars(parser.parse_args(argv)))


# ====================================================================================== helpers
def make_agent(observation_space: Any, action_space: Any, seed: int | None = None, config: AgentConfig | None = None) -> HippocampalAgent:
    """The agent factory ``run_dmtp`` calls."""
    return HippocampalAgent(observation_space, action_space, config=config, seed=seed)


def make_env(maze: str, **kwargs: Any) -> gym.Env:
    """The environment with the odometry sensor (the paper's model ignores it; nothing else changes)."""
    return gym.make("HippoMaze-v0", maze=maze, odometry=True, **kwargs)


def roam(maze: str, steps: int, seed: int, legs: int = 16) -> np.ndarray:
    """Positions of an aimless walk (no agent is stepped, so nothing learns).

    ``legs`` walks from random starts, each of straight segments of 5-10 steps with N(0, 30 deg)
    turns between them and a random new heading after a bump: the agent's own exploration
    statistics (model-figures), driven by heading actions.
    """
    env = make_env(maze, action_type="heading")
    rng = np.random.default_rng(seed)
    env.reset(seed=int(seed), options={"goal": None})
    positions = []
    per_leg = max(1, math.ceil(steps / legs))
    for _ in range(legs):
        _, info = env.reset(options={"goal": None})
        heading, left = float(info["heading"]), int(rng.integers(5, 11))
        positions.append(info["position"])
        for _ in range(per_leg):
            if left <= 0:
                heading += rng.normal(0.0, math.radians(30.0))
                left = int(rng.integers(5, 11))
            heading = (heading + math.pi) % (2 * math.pi) - math.pi
            _, _, _, truncated, info = env.step(np.array([heading], np.float32))
            positions.append(info["position"])
            left -= 1
            if info["collision"]:
                heading, left = float(rng.uniform(-math.pi, math.pi)), int(rng.integers(5, 11))
            if truncated:
                break
    env.close()
    return np.asarray(positions, dtype=float)[:steps]


@dataclass
class Grid:
    """A regular grid over a maze: ``positions`` are the free cells' centres, row-major."""

    spacing: float
    origin: np.ndarray  # centre of cell (0, 0)
    shape: tuple[int, int]  # (rows, cols)
    flat: np.ndarray  # flat cell index of each free position
    positions: np.ndarray


def free_mask(spec: MazeSpec, points: np.ndarray, radius: float) -> np.ndarray:
    """Which points a disc of ``radius`` fits at (vectorised ``spec.clearance(p) >= radius``)."""
    from matplotlib.path import Path as PolygonPath

    hw, hh = spec.half_extent
    inside = (np.abs(points[:, 0]) < hw) & (np.abs(points[:, 1]) < hh)
    for poly in spec.obstacles:
        inside &= ~PolygonPath(np.asarray(poly)).contains_points(points)
    seg = spec.segments
    a, b = seg[None, :, :2], seg[None, :, 2:]
    ab = b - a
    t = np.clip(np.sum((points[:, None, :] - a) * ab, axis=2) / np.maximum(np.sum(ab * ab, axis=2), 1e-12), 0.0, 1.0)
    nearest = a + t[:, :, None] * ab
    distance = np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)
    return inside & (distance >= radius)


@functools.lru_cache(maxsize=16)
def grid_for(maze: str, spacing: float) -> Grid:
    """The free positions (clearance >= the robot's radius) of a grid with ``spacing``."""
    spec = MazeSpec.load(maze)
    hw, hh = spec.half_extent
    xs = np.arange(-hw + spacing / 2, hw - 1e-9, spacing)
    ys = np.arange(-hh + spacing / 2, hh - 1e-9, spacing)
    gx, gy = np.meshgrid(xs, ys)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    free = free_mask(spec, points, ROBOT_RADIUS)
    return Grid(spacing, np.array([xs[0], ys[0]]), (len(ys), len(xs)), np.flatnonzero(free), points[free])


@functools.lru_cache(maxsize=64)
def _distance_field(maze: str, goal: tuple[float, float], spacing: float = 0.1) -> tuple[Grid, np.ndarray]:
    """Geodesic distance (8-connected Dijkstra on a 0.1 m grid of free cells) from ``goal`` to every cell."""
    grid = grid_for(maze, spacing)
    rows, cols = grid.shape
    dist = np.full(rows * cols, np.inf)
    free = np.zeros(rows * cols, bool)
    free[grid.flat] = True
    start = grid.flat[np.argmin(np.linalg.norm(grid.positions - np.asarray(goal), axis=1))]
    dist[start] = 0.0
    queue = [(0.0, int(start))]
    moves = [(dr, dc, spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    while queue:
        d, cell = heapq.heappop(queue)
        if d > dist[cell]:
            continue
        r, c = divmod(cell, cols)
        for dr, dc, cost in moves:
            rr, cc = r + dr, c + dc
            if 0 <= rr < rows and 0 <= cc < cols:
                nxt = rr * cols + cc
                if free[nxt] and d + cost < dist[nxt]:
                    dist[nxt] = d + cost
                    heapq.heappush(queue, (d + cost, nxt))
    return grid, dist.reshape(rows, cols)


def geodesic_to(maze: str, goal: Any, positions: np.ndarray) -> np.ndarray:
    """Geodesic distance from ``goal`` to each position (the nearest reachable grid cell's)."""
    grid, field = _distance_field(maze, (float(goal[0]), float(goal[1])))
    rows, cols = grid.shape
    padded = np.pad(field, 1, constant_values=np.inf)
    rc = np.rint((np.asarray(positions) - grid.origin) / grid.spacing).astype(int)
    col = np.clip(rc[:, 0], 0, cols - 1) + 1
    row = np.clip(rc[:, 1], 0, rows - 1) + 1
    near = np.stack([padded[row + dr, col + dc] + (grid.spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1)])
    return near.min(axis=0)


def distance_to_path(positions: np.ndarray, path: np.ndarray, chunk: int = 512) -> np.ndarray:
    """Each position's distance to the nearest point of ``path``."""
    path = np.asarray(path, float).reshape(-1, 2)
    if len(path) == 0:
        return np.full(len(positions), np.inf)
    out = np.empty(len(positions))
    for s in range(0, len(positions), chunk):
        d = np.linalg.norm(positions[s:s + chunk, None, :] - path[None, :, :], axis=2)
        out[s:s + chunk] = d.min(axis=1)
    return out


def spearman(x: np.ndarray, y: np.ndarray) -> float | None:
    """Spearman's rank correlation (NaN-free inputs; None if either is constant or too short)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 5 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return None
    rx, ry = np.argsort(np.argsort(x)), np.argsort(np.argsort(y))
    return float(np.corrcoef(rx, ry)[0, 1])


def pearson_with_ci(x: np.ndarray, y: np.ndarray, seed: int, n_boot: int = 4000) -> dict[str, Any]:
    """Pearson r with a 95 % bootstrap interval over trials, and Spearman's rho."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if len(x) < 3 or np.std(x) == 0 or np.std(y) == 0:
        return {"n": len(x), "r": None, "ci95": None, "spearman": None, "leave_one_out": None}
    rng = np.random.default_rng(seed)
    boots = []
    for _ in range(n_boot):
        idx = rng.integers(0, len(x), len(x))
        if np.std(x[idx]) > 0 and np.std(y[idx]) > 0:
            boots.append(np.corrcoef(x[idx], y[idx])[0, 1])
    ci = [float(np.quantile(boots, 0.025)), float(np.quantile(boots, 0.975))] if boots else None
    loo = [np.corrcoef(np.delete(x, k), np.delete(y, k))[0, 1] for k in range(len(x)) if len(x) > 3]
    loo = [v for v in loo if np.isfinite(v)]
    return {"n": len(x), "r": float(np.corrcoef(x, y)[0, 1]), "ci95": ci, "spearman": spearman(x, y),
            "leave_one_out": [float(min(loo)), float(max(loo))] if loo else None}


def map_stats(maze: str, positions: np.ndarray, values: np.ndarray, goal: Any, explored: np.ndarray, xi: float) -> dict[str, Any]:
    """How a sampled reward map looks: where it reaches, and whether it is graded toward the goal.

    ``coverage``: share of sampled positions whose value exceeds ``xi`` (the agent's exploit
    threshold); ``near``/``band``/``far``: the same among positions <= 0.5 m, 0.5-1.5 m and >= 2 m
    from the explored path; ``spearman``: rank correlation of value with the geodesic distance to
    the goal over the covered positions (negative = graded toward the goal); ``peak_offset``: the
    distance from the goal to the centre of the top 2 % of values; ``second_peak``: the largest
    value at least 3 m (geodesic) from the goal, as a share of the largest anywhere (high = the map
    also peaks somewhere else, e.g. at an aliased place).
    """
    values = np.asarray(values, float)
    ok = np.isfinite(values)
    positions, values = positions[ok], values[ok]
    covered = values > xi
    to_path = distance_to_path(positions, explored)
    dist = geodesic_to(maze, goal, positions)

    def share(mask: np.ndarray) -> float | None:
        return float(covered[mask].mean()) if mask.any() else None

    stats: dict[str, Any] = {
        "coverage": float(covered.mean()) if len(values) else 0.0,
        "near": share(to_path <= NEAR_PATH),
        "band": share((to_path > NEAR_PATH) & (to_path <= 1.5)),
        "far": share(to_path >= FAR_PATH),
        "spearman": spearman(values[covered], dist[covered]) if covered.sum() >= 5 else None,
        "max_value": float(values.max()) if len(values) else 0.0,
        "peak_offset": None,
        "second_peak": None,
    }
    far_from_goal = dist >= 3.0
    if covered.any() and far_from_goal.any() and values.max() > 0:
        stats["second_peak"] = float(values[far_from_goal].max() / values.max())
    if covered.any():
        top = values >= np.quantile(values, 0.98)
        stats["peak_offset"] = float(np.linalg.norm(positions[top].mean(axis=0) - np.asarray(goal, float)))
    return stats


# -------------------------------------------------------------------------------- field analysis
def _cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def _hull_area(points: np.ndarray) -> float:
    """Area of the convex hull (Andrew's monotone chain)."""
    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 3:
        return 0.0
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]

    def half(seq: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-1] - out[-2], p - out[-2]) <= 0:
                out.pop()
            out.append(p)
        return out

    hull = np.array(half(pts)[:-1] + half(pts[::-1])[:-1])
    x, y = hull[:, 0], hull[:, 1]
    return float(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _components(grid: Grid, members: np.ndarray) -> list[np.ndarray]:
    """4-connected pieces of a set of grid positions (indices into ``grid.positions``)."""
    rows, cols = grid.shape
    where = {int(grid.flat[i]): int(i) for i in members}
    seen: set[int] = set()
    pieces = []
    for cell in where:
        if cell in seen:
            continue
        seen.add(cell)
        queue, piece = deque([cell]), []
        while queue:
            cur = queue.popleft()
            piece.append(where[cur])
            r, c = divmod(cur, cols)
            for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
                nxt = rr * cols + cc
                if 0 <= rr < rows and 0 <= cc < cols and nxt in where and nxt not in seen:
                    seen.add(nxt)
                    queue.append(nxt)
        pieces.append(np.array(piece))
    return pieces


def _compartment_coords(points: np.ndarray) -> np.ndarray:
    """Positions folded into one 5 m compartment: maze4's quadrants (and maze3's halves) map onto
    each other by 5 m translations, so aliased places share these coordinates."""
    return np.where(points < 0, points + COMPARTMENT, points)


def analyse_fields(grid: Grid, rates: np.ndarray) -> list[dict[str, Any]]:
    """Per cell with a field: peak, area, pieces, convexity of the main piece, and which quadrants /
    halves its substantial pieces lie in (for aliasing)."""
    out = []
    cell_area = grid.spacing**2
    corners = np.array([[-1, -1], [-1, 1], [1, -1], [1, 1]]) * grid.spacing / 2
    peaks = np.nanmax(np.nan_to_num(rates, nan=0.0), axis=0)
    for cell in np.flatnonzero(peaks >= FIELD_MIN_PEAK):
        r = rates[:, cell]
        members = np.flatnonzero(r >= FIELD_LEVEL * peaks[cell])
        pieces = _components(grid, members)
        total = float(r[members].sum())
        info = []
        for piece in pieces:
            mass = float(r[piece].sum()) / total
            pts = grid.positions[piece]
            centre = (pts * r[piece, None]).sum(axis=0) / r[piece].sum()
            info.append((mass, piece, centre))
        info.sort(key=lambda t: -t[0])
        substantial = [t for t in info if t[0] >= COMPONENT_MIN_MASS]
        main = info[0][1]
        main_pts = grid.positions[main]
        hull = _hull_area((main_pts[:, None, :] + corners[None]).reshape(-1, 2))
        quadrants = {int(c[0] > 0) + 2 * int(c[1] > 0) for _, _, c in substantial}
        halves = {int(c[0] > 0) for _, _, c in substantial}
        folded = _compartment_coords(np.array([c for _, _, c in substantial]))
        spread = float(max(np.linalg.norm(a - b) for a in folded for b in folded)) if len(folded) > 1 else 0.0
        out.append({
            "cell": int(cell),
            "peak": float(peaks[cell]),
            "area": float(len(members) * cell_area),
            "pieces": len(substantial),
            "solidity": float(len(main) * cell_area / hull) if hull > 0 else 1.0,
            "centre": [float(v) for v in info[0][2]],
            "quadrants": len(quadrants),
            "halves": len(halves),
            "folded_spread": spread,
            "min_piece_mass": float(min(t[0] for t in substantial)),
        })
    return out


def summarise_fields(cells: list[dict[str, Any]], n_cells: int, arena_area: float) -> dict[str, Any]:
    if not cells:
        return {"cells": n_cells, "with_field": 0}
    area = np.array([c["area"] for c in cells])
    single = np.array([c["pieces"] == 1 for c in cells])
    multi_q = np.array([c["quadrants"] >= 2 for c in cells])
    return {
        "cells": n_cells,
        "with_field": len(cells),
        "single_piece": float(single.mean()),
        "median_area_m2": float(np.median(area)),
        "median_area_share": float(np.median(area) / arena_area),
        "median_solidity_main_piece": float(np.median([c["solidity"] for c in cells])),
        "quadrants_hist": [int(sum(c["quadrants"] == k for c in cells)) for k in (1, 2, 3, 4)],
        "halves_hist": [int(sum(c["halves"] == k for c in cells)) for k in (1, 2)],
        "multi_quadrant": float(multi_q.mean()),
        "multi_quadrant_similar_place": float(np.mean([c["quadrants"] >= 2 and c["folded_spread"] <= SIMILAR_PLACE for c in cells])),
        "multi_half": float(np.mean([c["halves"] == 2 for c in cells])),
        "multi_half_similar_place": float(np.mean([c["halves"] == 2 and c["folded_spread"] <= SIMILAR_PLACE for c in cells])),
        "median_folded_spread_multi_quadrant": float(np.median([c["folded_spread"] for c in cells if c["quadrants"] >= 2])) if multi_q.any() else None,
    }


def _random_examples(cells: list[dict[str, Any]], count: int, rng: np.random.Generator) -> list[int]:
    """``count`` cells drawn at random among those with a field: examples not picked for shape."""
    chosen = rng.choice(len(cells), size=min(count, len(cells)), replace=False) if cells else []
    return sorted(cells[i]["cell"] for i in chosen)


def _aliasing_examples(cells: list[dict[str, Any]], count: int) -> list[int]:
    """The clearest aliased cells (pieces at similar places, the smallest piece as large as
    possible), taking cells with 3, 4 and 2 quadrants in turn so that every kind is shown."""
    ranked = {k: sorted((c for c in cells if c["quadrants"] == k), key=lambda c: (c["folded_spread"] > SIMILAR_PLACE, -c["min_piece_mass"])) for k in (2, 3, 4)}
    out: list[int] = []
    while len(out) < count and any(ranked.values()):
        for k in (3, 4, 2):
            if ranked[k] and len(out) < count:
                out.append(ranked[k].pop(0)["cell"])
    return out


# ====================================================================================== tasks
# Each task runs in a worker process, is seeded by its arguments only, and returns plain data.
def task_fields(maze: str, seed: int, config: AgentConfig, roam_steps: int, spacing: float) -> dict[str, Any]:
    """Experiments 1 and 7: place fields after the dry run, on a roam and on a grid."""
    env = make_env(maze)
    env.reset(seed=seed, options={"goal": None})
    agent = make_agent(env.observation_space, env.action_space, seed=seed, config=config)
    agent.prepare(env)  # the dry run: only W_pb learns
    grid = grid_for(maze, spacing)
    grid_rates = agent.place_field_map(env, grid.positions)
    cells = analyse_fields(grid, grid_rates)
    rng = np.random.default_rng(seed)
    examples = _random_examples(cells, EXAMPLE_CELLS, rng)
    alias_examples = _aliasing_examples(cells, EXAMPLE_CELLS)
    positions = roam(maze, roam_steps, seed + 1)
    roam_rates = agent.place_field_map(env, positions)
    keep = sorted(set(examples) | set(alias_examples))
    env.close()
    spec = MazeSpec.load(maze)
    return {
        "maze": maze,
        "seed": seed,
        "summary": summarise_fields(cells, config.n_place, spec.size[0] * spec.size[1]),
        "cells": cells,
        "examples": examples,
        "alias_examples": alias_examples,
        "roam_positions": positions.astype(np.float32),
        "roam_rates": {c: roam_rates[:, c].astype(np.float32) for c in keep},
        "grid_positions": grid.positions.astype(np.float32),
        "grid_rates": {c: grid_rates[:, c].astype(np.float32) for c in keep},
    }


def task_dmtp_trial(maze: str, seed: int, runs: int, same_start: bool, config: AgentConfig, max_episode_steps: int | None, map_roam_steps: int) -> dict[str, Any]:
    """Experiments 2-5: one DMTP trial through the protocol runner; optionally the reward map after run 1."""
    captured: dict[str, Any] = {}

    def on_run_end(trial: int, run: int, agent: Any, env: Any) -> None:
        if run != 0 or not map_roam_steps:
            return
        positions = roam(maze, map_roam_steps, seed + 1)
        # the reward cell's rate, no learning; the run's own env, so that a path-integrating agent's
        # frame is placed where the robot stands (observation_at moves nothing)
        values = agent.reward_map(env, positions)
        goal = env.unwrapped.goal
        path = env.unwrapped.path.copy()
        captured.update({
            "positions": positions.astype(np.float32),
            "values": values.astype(np.float32),
            "run1_path": path.astype(np.float32),
            "goal": [float(goal[0]), float(goal[1])],
            "stats": map_stats(maze, positions, values, goal, path, agent.config.xi),
        })

    result = run_dmtp(
        functools.partial(make_agent, config=config), maze, trials=1, runs=runs, seed=seed, agent_name="hippo",
        same_start=same_start, max_episode_steps=max_episode_steps, progress=False, on_run_end=on_run_end,
        env_kwargs={"odometry": True},
    )
    return {"maze": maze, "seed": seed, "same_start": same_start, "result": result, "map": captured or None}


class ScriptedDriver:
    """Drives the robot along waypoints while the agent learns from what it senses.

    Follows the Agent protocol: ``reset`` and ``observe`` go to the agent unchanged (so it learns
    exactly as on its own walks: eq. 5 and eq. 7 in ``observe``), only ``act`` is replaced by the
    script, which (as the experimenter) reads the robot's position from ``info``.
    """

    def __init__(self, agent: HippocampalAgent, waypoints: Any, tolerance: float = 0.08) -> None:
        self.agent, self.waypoints, self.tolerance = agent, [np.asarray(w, float) for w in waypoints], tolerance
        self.target, self.position = 1, self.waypoints[0]

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.position = np.asarray(info["position"], float)
        self.agent.reset(observation, info)

    def done(self) -> bool:
        while self.target < len(self.waypoints) and np.linalg.norm(self.waypoints[self.target] - self.position) < self.tolerance:
            self.target += 1
        return self.target >= len(self.waypoints)

    def act(self, observation: Any) -> int:
        dx, dy = self.waypoints[self.target] - self.position
        return round(math.atan2(dy, dx) / (math.pi / 4)) % 8

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        self.position = np.asarray(info["position"], float)
        self.agent.observe(action, observation, reward, terminated, truncated, info)


def explore_without_goal(env: gym.Env, agent: HippocampalAgent, steps: int) -> np.ndarray:
    """The agent explores on its own with no goal anywhere (learning on); returns the path."""
    obs, info = env.reset(options={"goal": None})
    agent.reset(obs, info)
    path = [info["position"]]
    for _ in range(steps):
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        path.append(info["position"])
        if terminated or truncated:
            obs, info = env.reset(options={"goal": None})
            agent.reset(obs, info)
    return np.asarray(path, float)


def drive_scripted(env: gym.Env, agent: HippocampalAgent, waypoints: Any) -> np.ndarray:
    """Drive along ``waypoints`` once while the agent learns; returns the path."""
    start, nxt = np.asarray(waypoints[0], float), np.asarray(waypoints[1], float)
    heading = math.atan2(*(nxt - start)[::-1])
    obs, info = env.reset(options={"goal": None, "start": start, "heading": heading})
    driver = ScriptedDriver(agent, waypoints)
    driver.reset(obs, info)
    path = [info["position"]]
    limit = int(sum(np.linalg.norm(np.diff(np.asarray(waypoints, float), axis=0), axis=1)) / 0.1) + 50
    for _ in range(limit):
        if driver.done():
            break
        action = driver.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        driver.observe(action, obs, reward, terminated, truncated, info)
        path.append(info["position"])
    return np.asarray(path, float)


def replay_at(agent: HippocampalAgent, env: gym.Env, goal: Any) -> bool:
    """Put the reward at ``goal`` with no further exploration: a new reward cell, the place cells
    set to their steady-state rates there, then the agent's backward replay (Algorithm 1).

    The agent has no public way to set its place-cell state, so this writes ``agent.place.v``
    (the one attribute touched); everything else is the agent's public API.
    """
    agent.start_trial(agent.trial + 1)
    goal = np.asarray(goal, float)  # (with path integration: as if localised at the goal)
    agent.place.v = agent.place_rates_at(env.unwrapped.observation_at(goal), pi_position=goal - agent.frame_offset(env))
    return agent.learn_reward()


def navigate(agent: HippocampalAgent, env: gym.Env, goal: Any, runs: int, seed: int) -> list[dict[str, Any]]:
    """Runs from random starts toward ``goal`` with the inferred map (each run from a copy of the
    agent as it was after the replay, so runs do not learn from each other)."""
    env.reset(seed=seed, options={"goal": [float(goal[0]), float(goal[1])]})
    out = []
    for _ in range(runs):
        runner = copy.deepcopy(agent)
        obs, info = env.reset()
        runner.reset(obs, info)
        terminated = truncated = False
        while not (terminated or truncated):
            action = runner.act(obs)
            obs, reward, terminated, truncated, info = env.step(action)
            runner.observe(action, obs, reward, terminated, truncated, info)
        out.append({"success": bool(info["is_success"]), "indirectness": float(info.get("indirectness", math.nan)), "steps": len(env.unwrapped.path) - 1})
    return out


def task_generalisation(name: str, seed: int, config: AgentConfig, explore_steps: int, roam_steps: int, nav_runs: int, nav_max_steps: int) -> dict[str, Any]:
    """Experiment 6: explore with no goal, then for each goal replay only and sample the map."""
    scenario = SCENARIOS[name]
    maze = scenario["maze"]
    env = make_env(maze)
    env.reset(seed=seed, options={"goal": None})
    agent = make_agent(env.observation_space, env.action_space, seed=seed, config=config)
    agent.prepare(env)  # the dry run, as before every DMTP trial
    if scenario["explore"] == "scripted":
        path = drive_scripted(env, agent, LIMITED_PATH)
    else:
        path = explore_without_goal(env, agent, explore_steps)
    positions = roam(maze, roam_steps, seed + 1)
    rates = agent.place_field_map(env, positions)
    nav_env = make_env(maze, max_episode_steps=nav_max_steps)
    goals = []
    for k, goal in enumerate(scenario["goals"]):
        replayed = copy.deepcopy(agent)
        learnt = replay_at(replayed, env, goal)
        values = np.asarray(replayed.reward.value(rates, replayed.reward.W_rp[-1]), float)  # eq. 9, undepressed
        nav = navigate(replayed, nav_env, goal, nav_runs, seed + 10 + k)
        to_path = float(distance_to_path(np.asarray([goal], float), path)[0])
        goals.append({
            "goal": [float(goal[0]), float(goal[1])],
            "distance_to_explored": to_path,
            "visited": to_path <= VISITED,
            "replay_learnt": bool(learnt),
            "values": values.astype(np.float32),
            "stats": map_stats(maze, positions, values, goal, path, config.xi),
            "nav": nav,
        })
    env.close()
    nav_env.close()
    return {"name": name, "maze": maze, "seed": seed, "path": path.astype(np.float32), "positions": positions.astype(np.float32), "goals": goals}


# ====================================================================================== running
@dataclass
class Task:
    name: str
    fn: Callable[..., Any]
    kwargs: dict[str, Any]
    cost: float  # rough seconds, to start the long ones first


def _timed(fn: Callable[..., Any], kwargs: dict[str, Any]) -> tuple[Any, float]:
    began = time.perf_counter()
    out = fn(**kwargs)
    return out, time.perf_counter() - began


def run_tasks(tasks: list[Task], workers: int, progress: bool) -> tuple[dict[str, Any], dict[str, float]]:
    """Run every task (in ``workers`` processes); results by task name, independent of the order."""
    from tqdm.auto import tqdm

    results: dict[str, Any] = {}
    seconds: dict[str, float] = {}
    order = sorted(tasks, key=lambda t: -t.cost)
    bar = tqdm(total=len(tasks), desc="paper experiments", unit="task", disable=not progress)
    if workers <= 1:
        for task in order:
            bar.set_postfix_str(task.name)
            results[task.name], seconds[task.name] = _timed(task.fn, task.kwargs)
            bar.update(1)
    else:
        # One BLAS thread per worker: the workers already fill the cores. Spawned workers read
        # these variables when they import numpy; the parent's own values are restored after.
        saved = {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
        os.environ.update({k: "1" for k in saved})
        try:
            with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn")) as pool:
                futures = {pool.submit(_timed, task.fn, task.kwargs): task.name for task in order}
                for future in as_completed(futures):
                    name = futures[future]
                    results[name], seconds[name] = future.result()
                    bar.set_postfix_str(name)
                    bar.update(1)
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
    bar.close()
    return results, seconds


def merge_trials(results: list[DMTPResult], seed: int) -> DMTPResult:
    """Single-trial results as one ``DMTPResult`` (trial ``t`` = the ``t``-th result)."""
    first = results[0]
    merged = DMTPResult(maze=first.maze, agent=first.agent, seed=seed, trials=len(results), runs=first.runs)
    for t, r in enumerate(results):
        merged.episodes += [dataclasses.replace(e, trial=t) for e in r.episodes]
        merged.paths += r.paths
        merged.env_steps_total += r.env_steps_total
        merged.seconds += r.seconds
    return merged


def trial_seed(seed: int, trial: int) -> int:
    """The ``hippomaze dmtp --seed`` of DMTP trial ``trial`` (random starts, any maze)."""
    return TRIAL_SEED_STRIDE * seed + trial


def build_tasks(args: PaperArgs) -> list[Task]:
    cfg = args.agent_config()
    base = TRIAL_SEED_STRIDE * args.seed
    tasks = [Task(f"fields/{m}", task_fields, {"maze": m, "seed": base + 300 + i, "config": cfg, "roam_steps": args.roam_steps, "spacing": args.grid_spacing}, 20) for i, m in enumerate(MAZES)]
    for t in range(args.same_start_trials):
        tasks.append(Task(f"same_start/open/{t}", task_dmtp_trial, {"maze": "open", "seed": base + 100 + t, "runs": args.runs, "same_start": True, "config": cfg, "max_episode_steps": args.max_episode_steps, "map_roam_steps": args.roam_steps}, 12))
    for i, m in enumerate(OBSTACLE_MAZES):
        tasks.append(Task(f"same_start/{m}", task_dmtp_trial, {"maze": m, "seed": base + 110 + i, "runs": args.runs, "same_start": True, "config": cfg, "max_episode_steps": args.max_episode_steps, "map_roam_steps": args.roam_steps}, 25))
    for t in range(args.trials):
        tasks.append(Task(f"dmtp/open/{t}", task_dmtp_trial, {"maze": "open", "seed": trial_seed(args.seed, t), "runs": args.runs, "same_start": False, "config": cfg, "max_episode_steps": args.max_episode_steps, "map_roam_steps": 0}, 4))
    for m in OBSTACLE_MAZES:
        for t in range(args.maze_trials):
            tasks.append(Task(f"dmtp/{m}/{t}", task_dmtp_trial, {"maze": m, "seed": trial_seed(args.seed, t), "runs": args.runs, "same_start": False, "config": cfg, "max_episode_steps": args.max_episode_steps, "map_roam_steps": 0}, 25 if m == "maze4" else 10))
    for i, name in enumerate(SCENARIOS):
        tasks.append(Task(f"generalisation/{name}", task_generalisation, {"name": name, "seed": base + 400 + i, "config": cfg, "explore_steps": args.explore_steps, "roam_steps": args.roam_steps, "nav_runs": args.nav_runs, "nav_max_steps": args.nav_max_steps}, 60))
    return tasks


# ====================================================================================== analysis
def _median(values: Any) -> float | None:
    v = np.asarray([x for x in values if x is not None], float)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if len(v) else None


def dmtp_summary(result: DMTPResult, seed: int) -> dict[str, Any]:
    """Medians, success, the Pearson r (with its interval) and the project's targets."""
    ind, ok = result.indirectness(), result.success()
    lengths = np.full((result.trials, result.runs), np.nan)
    for e in result.episodes:
        lengths[e.trial, e.run] = e.path_length
    summary = result.summary()
    later = ind[:, 1:]
    summary.update({
        "median_runs_2_on": float(np.nanmedian(later)) if later.size and np.isfinite(later).any() else None,
        "later_runs_reached": int(ok[:, 1:].sum()),
        "later_runs_total": int(ok[:, 1:].size),
    })
    if result.runs >= 2:
        summary["pearson"] = pearson_with_ci(lengths[:, 0], ind[:, 1], seed)
    return summary


def verdict(ok: bool, partly: bool) -> str:
    return "reproduced" if ok else ("partly" if partly else "not reproduced")


def _fmt(x: Any, digits: int = 2, pct: bool = False) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{100 * x:.0f} %" if pct else f"{x:.{digits}f}"


def assess(args: PaperArgs, data: dict[str, Any]) -> list[dict[str, Any]]:
    """The claims table: what the paper says, what we measured, and a verdict by a stated criterion."""
    rows: list[dict[str, Any]] = []

    def row(rid: str, experiment: str, claim: str, measured: str, result: str, criterion: str, figure: str) -> None:
        rows.append({"id": rid, "experiment": experiment, "paper": claim, "measured": measured, "verdict": result, "criterion": criterion, "figure": figure})

    # 1. place fields
    fields = data["place_fields"]
    plain = [m for m in ("open", "maze1", "maze2") if m in fields and fields[m].get("with_field")]
    single = [fields[m]["single_piece"] for m in plain]
    solid = [fields[m]["median_solidity_main_piece"] for m in plain]
    share = [fields[m]["median_area_share"] for m in plain]
    measured = "; ".join(
        f"{m}: {fields[m]['with_field']} of {fields[m]['cells']} cells have a field, {_fmt(fields[m]['single_piece'], pct=True)} in one piece, "
        f"median {fields[m]['median_area_m2']:.2f} m^2, solidity {fields[m]['median_solidity_main_piece']:.2f}"
        for m in MAZES if fields.get(m, {}).get("with_field"))
    row("P1", "1 place fields", "Place fields are localised and convex (Fig. 2), in the open arena and the mazes.", measured,
        verdict(bool(single) and min(single) >= 0.8 and min(solid) >= 0.8 and max(share) <= 0.05, bool(single) and min(single) >= 0.5),
        "reproduced if in open, maze1 and maze2 >= 80 % of fields are one piece, median solidity >= 0.8 and median area <= 5 % of the arena; partly if >= 50 % are one piece",
        "fig1_place_fields.png")

    # 2. reward maps after run 1
    maps = data["reward_maps_after_run1"]
    found = {k: v for k, v in maps.items() if v["found_goal"]}
    rhos = [v["stats"]["spearman"] for v in found.values()]
    good = [r is not None and r <= -0.5 for r in rhos]
    fair = [r is not None and r <= -0.3 for r in rhos]
    measured = "Spearman(value, geodesic distance to goal): " + ", ".join(f"{k} {_fmt(v['stats']['spearman'])}" for k, v in maps.items())
    row("R1", "2 reward maps", "The reward map after run 1 is graded toward the goal (Figs. 3, 8).", measured,
        verdict(bool(good) and np.mean(good) >= 0.8, bool(fair) and np.mean(fair) >= 0.5),
        "reproduced if rho <= -0.5 in >= 80 % of the maps whose run 1 found the goal; partly if rho <= -0.3 in half", "fig2a_reward_maps_open.png, fig2b_reward_maps_mazes.png")
    near = _median(v["stats"]["near"] for v in found.values())
    far = _median(v["stats"]["far"] for v in found.values())
    cover = _median(v["stats"]["coverage"] for v in found.values())
    row("R2", "2 reward maps", "The map spreads over the regions run 1 explored and depends on how extensive that run was (Figs. 3, 8).",
        f"median share of sampled places with value > xi: within {NEAR_PATH} m of run 1's path {_fmt(near, pct=True)}, >= {FAR_PATH} m from it {_fmt(far, pct=True)}, whole arena {_fmt(cover, pct=True)}",
        verdict(near is not None and far is not None and near >= 0.5 and far <= 0.5 * near, near is not None and far is not None and near > far),
        "reproduced if the median coverage near the path is >= 50 % and far from it at most half that; partly if near > far", "fig2a_reward_maps_open.png, fig2b_reward_maps_mazes.png")

    # 3. same start
    same = data["same_start"]
    open_trials = same["open"]
    better = [all(x < t["indirectness"][0] for x in t["indirectness"][1:]) for t in open_trials]
    direct = [(_median(t["indirectness"][1:]) or math.inf) <= 1.0 for t in open_trials]
    measured = "; ".join(f"trial {k + 1}: " + " / ".join(_fmt(x) for x in t["indirectness"]) for k, t in enumerate(open_trials))
    row("S1", "3 same start", "Open arena, same start: random search on run 1, then progressively more direct paths (Fig. 4).", "indirectness by run, " + measured,
        verdict(bool(better) and all(better) and all(direct), bool(better) and np.mean(better) >= 0.5),
        "reproduced if in every trial each later run beats run 1 and the later runs' median is <= 1; partly if later runs beat run 1 in half the trials", "fig3a_same_start_open.png")

    # 4-5. open arena DMTP
    d = data["open_dmtp"]["summary"]
    med = d["median_indirectness"]
    r1 = med[0]
    later_ok = r1 is not None and all(m is not None and m <= r1 / 3 for m in med[1:])
    later_lower = r1 is not None and all(m is not None and m < r1 for m in med[1:])
    row("D1", "4 indirectness", "Indirectness falls sharply after one rewarded run: runs 2-4 much lower than run 1 (Fig. 5).",
        f"{args.trials} trials, median by run " + " / ".join(_fmt(m) for m in med) + f"; runs 2-{args.runs} reached the goal {d['later_runs_reached']}/{d['later_runs_total']}",
        verdict(later_ok, later_lower), "reproduced if every later run's median is <= a third of run 1's; partly if lower", "fig4_indirectness.png")
    p = d.get("pearson", {})
    r, ci = p.get("r"), p.get("ci95")
    row("D2", "5 correlation", "Pearson r = -0.53 between run 1's path length and run 2's indirectness (Fig. 6).",
        f"r = {_fmt(r)} (95 % bootstrap CI {_fmt(ci[0]) if ci else 'n/a'} to {_fmt(ci[1]) if ci else 'n/a'}), Spearman {_fmt(p.get('spearman'))}, n = {p.get('n')}",
        verdict(r is not None and r <= -0.3 and ci is not None and ci[1] < 0, r is not None and r < 0),
        "reproduced if r <= -0.3 and the interval excludes 0; partly if r < 0", "fig5_length_vs_indirectness.png")

    # project targets (open arena, 20 trials, 4 runs, seed 0)
    targets = [
        ("T1", "run-2 median indirectness <= 1.0", med[1] if len(med) > 1 else None, lambda v: v <= 1.0),
        ("T2", "run-4 median indirectness <= 0.5", med[3] if len(med) > 3 else None, lambda v: v <= 0.5),
        ("T3", ">= 95 % of runs 2-4 reach the goal", d.get("later_runs_success_rate"), lambda v: v >= 0.95),
        ("T4", "run-1 median >= 3x run-4 median", (r1 / med[3]) if len(med) > 3 and r1 is not None and med[3] else None, lambda v: v >= 3.0),
    ]
    official = args.trials == 20 and args.runs == 4 and args.seed == 0
    for rid, text, value, test in targets:
        shown = _fmt(value, pct=True) if rid == "T3" else (f"{_fmt(value)}x" if rid == "T4" else _fmt(value))
        met = value is not None and test(value)
        row(rid, "project target", f"(project issue, open arena, 20 trials, 4 runs, seed 0) {text}", shown + ("" if official else " (not the official setting)"),
            "met" if met else "not met", text, "fig4_indirectness.png")

    # mazes (same-start trials as in the paper; random-start trials beyond it)
    mz = data["maze_dmtp"]
    same_mazes = data["same_start"]["mazes"]

    def later(m: str) -> float | None:
        if m in mz:
            return mz[m]["summary"].get("median_runs_2_on")
        return _median(same_mazes[m]["indirectness"][1:]) if m in same_mazes else None

    def rate(m: str) -> float | None:
        if m in mz:
            return mz[m]["summary"].get("later_runs_success_rate")
        return float(np.mean(same_mazes[m]["success"][1:])) if m in same_mazes else None

    def maze_measured(m: str) -> str:
        same = same_mazes.get(m)
        text = "same start: " + " / ".join(_fmt(x) for x in same["indirectness"]) if same else ""
        if m in mz:
            s_ = mz[m]["summary"]
            text += (f"; {mz[m]['result'].trials} trials with random starts: median by run " + " / ".join(_fmt(x) for x in s_["median_indirectness"])
                     + f", runs 2-{args.runs} median {_fmt(later(m))}, {_fmt(rate(m), pct=True)} reached the goal")
        return text

    source = "the random-start trials" if mz else "the same-start trial"
    for rid, m, name in (("M1", "maze1", "Maze 1"), ("M2", "maze2", "Maze 2")):
        v = later(m)
        row(rid, "3/4 mazes", f"{name} ({m}): a useful value map after one run; efficient, generalised paths on runs 2-4 (Fig. 7).", maze_measured(m),
            verdict(v is not None and v <= 1.0, v is not None and v <= 3.0),
            f"over {source}: reproduced if the median indirectness of runs 2-{args.runs} is <= 1; partly if <= 3", "fig3b_same_start_mazes.png, fig8_mazes_indirectness.png")
    easy = [later(m) for m in ("maze1", "maze2")]
    hard, easy_max = later("maze4"), max((v for v in easy if v is not None), default=None)
    worse = hard is not None and easy_max is not None and hard > easy_max
    rates = [rate(m) for m in ("maze1", "maze2")]
    fails = rate("maze4") is not None and all(r_ is not None for r_ in rates) and rate("maze4") < min(rates)
    row("M3", "3/4 mazes", "The four alike compartments (the paper's Maze 3; our maze4) defeat it: the robot meanders, mistakes one compartment for another (Fig. 7).",
        maze_measured("maze4") + f"; worst of maze1/maze2: runs 2-{args.runs} median {_fmt(easy_max)}",
        verdict(worse and fails, worse or fails),
        f"over {source}: reproduced if maze4's later-run median is above maze1's and maze2's and fewer of its later runs reach the goal; partly if one holds",
        "fig3b_same_start_mazes.png, fig8_mazes_indirectness.png")

    # 6. generalisation
    gen = data["generalisation"]

    def goal_text(g: dict[str, Any]) -> str:
        return (f"goal {tuple(g['goal'])}: covers {_fmt(g['stats']['near'], pct=True)} of the explored area, rho {_fmt(g['stats']['spearman'])}, "
                f"value >= 3 m from the goal up to {_fmt(g['stats']['second_peak'], pct=True)} of the peak, "
                f"{sum(n['success'] for n in g['nav'])}/{len(g['nav'])} runs reached it (median ind. {_fmt(_median(n['indirectness'] for n in g['nav']))})")

    for rid, name, fig in (("G1", "open_extensive", "10a"), ("G2", "maze2_extensive", "10c")):
        visited = [g for g in gen[name]["goals"] if g["visited"]]
        ok = [g["stats"]["near"] is not None and g["stats"]["near"] >= 0.5 and g["stats"]["spearman"] is not None and g["stats"]["spearman"] <= -0.5 for g in visited]
        row(rid, "6 generalisation", f"After extensive goal-free exploration ({gen[name]['maze']}), replay alone at a new reward place gives a map over the known environment (Fig. {fig}).",
            "; ".join(goal_text(g) for g in gen[name]["goals"]),
            verdict(bool(ok) and all(ok), bool(ok) and float(np.mean(ok)) >= 0.5),
            "reproduced if for every visited goal the map covers >= 50 % of the explored area and is graded (rho <= -0.5); partly for half of them", "fig6_generalisation.png")
    lim = gen["open_limited"]["goals"]
    on_path = [g for g in lim if g["visited"]]
    unvisited = [g for g in lim if g["distance_to_explored"] > 2.0]
    on_cov = _median(g["stats"]["coverage"] for g in on_path)
    un_cov = _median(g["stats"]["coverage"] for g in unvisited)
    on_nav = _median(n["indirectness"] for g in on_path for n in g["nav"])
    un_nav = _median(n["indirectness"] for g in unvisited for n in g["nav"])
    row("G3", "6 generalisation", "After exploring along one path, a reward placed where nothing was explored gives no useful map (Fig. 10b, last map).",
        f"share of the arena covered: goals on the path {_fmt(on_cov, pct=True)}, never-visited goal {_fmt(un_cov, pct=True)}; median indirectness from random starts {_fmt(on_nav)} vs {_fmt(un_nav)}",
        verdict(on_cov is not None and un_cov is not None and un_cov <= 0.25 * on_cov and (un_nav or 0) > (on_nav or 0), on_cov is not None and un_cov is not None and un_cov < on_cov),
        "reproduced if the unvisited goal's map covers at most a quarter of what the on-path goals' maps cover and navigation to it is worse; partly if it covers less", "fig6_generalisation.png")
    band = _median(g["stats"]["band"] for g in on_path)
    row("G4", "6 generalisation", "The inferred map is not confined to the exploratory path: place fields have width (the 'field effect', Fig. 10b).",
        f"goals on the path: share of places 0.5-1.5 m from the path with value > xi {_fmt(band, pct=True)}",
        verdict(band is not None and band >= 0.5, band is not None and band >= 0.2), "reproduced if >= 50 %; partly if >= 20 %", "fig6_generalisation.png")

    # 7. aliasing
    a4, a0 = fields.get("maze4", {}), fields.get("open", {})
    if a4.get("with_field") and a0.get("with_field"):
        hist = a4["quadrants_hist"]
        frac, control, similar = a4["multi_quadrant"], a0["multi_quadrant"], a4["multi_quadrant_similar_place"]
        row("A1", "7 aliasing", "In the four-compartment maze place cells fire at perceptually similar places of several compartments (Fig. 9: three of four).",
            f"maze4: of {a4['with_field']} cells with a field, {hist[1]} have separate pieces in 2 quadrants, {hist[2]} in 3, {hist[3]} in 4 ({_fmt(frac, pct=True)}; "
            f"{_fmt(similar, pct=True)} at places within {SIMILAR_PLACE} m of each other once folded into one compartment); open-arena control {_fmt(control, pct=True)}",
            verdict(frac >= 0.05 and frac >= 3 * control and similar >= 0.5 * frac and hist[2] + hist[3] > 0, frac > control),
            "reproduced if >= 5 % of maze4's fields span >= 2 quadrants, >= 3x the open arena, mostly at similar places, and some span 3-4; partly if more than the control",
            "fig7_aliasing_maze4.png")
    a3 = fields.get("maze3", {})
    if a3.get("with_field") and a0.get("with_field"):
        row("A2", "7 aliasing", "(beyond the paper) maze3's two alike cups: cells with fields in both halves.",
            f"maze3 {_fmt(a3['multi_half'], pct=True)} of fields in both halves ({_fmt(a3['multi_half_similar_place'], pct=True)} at similar places); open-arena control {_fmt(a0['multi_half'], pct=True)}",
            verdict(a3["multi_half"] >= 0.05 and a3["multi_half"] >= 3 * a0["multi_half"], a3["multi_half"] > a0["multi_half"]),
            "reproduced if >= 5 % and >= 3x the open arena; partly if more than the control", "fig1_place_fields.png")
    return rows


# ====================================================================================== figures
def _save(fig: Any, path: Path, dpi: int = 90) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def _bare(ax: Any) -> None:
    ax.set_xticks([])
    ax.set_yticks([])


def fig_place_fields(fields: dict[str, dict[str, Any]], out: Path) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_place_field

    mazes = [m for m in MAZES if m in fields]
    fig, axes = plt.subplots(len(mazes), EXAMPLE_CELLS, figsize=(2.7 * EXAMPLE_CELLS, 2.7 * len(mazes)), squeeze=False)
    for row, m in enumerate(mazes):
        f = fields[m]
        spec = MazeSpec.load(m)
        for col in range(EXAMPLE_CELLS):
            ax = axes[row, col]
            if col < len(f["examples"]):
                cell = f["examples"][col]
                plot_place_field(f["roam_positions"], f["roam_rates"][cell], ax, maze=spec, colorbar=False, gridsize=30)
                ax.set_title(f"{m}: cell {cell}", fontsize="small")
            else:
                ax.set_visible(False)
            _bare(ax)
    fig.suptitle("Place fields after the dry run (rate over positions of an aimless roam; unvisited bins empty)", fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / "fig1_place_fields.png")


def fig_reward_maps(entries: list[tuple[str, dict[str, Any]]], out: Path, name: str, title: str) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_reward_map, plot_trajectories

    n = max(len(entries), 1)
    fig, axes = plt.subplots(2, n, figsize=(3.3 * n, 6.6), squeeze=False)
    for col, (label, entry) in enumerate(entries):
        spec = MazeSpec.load(entry["maze"])
        mp = entry["map"]
        plot_trajectories([mp["run1_path"]], axes[0, col], maze=spec, goal=mp["goal"], title=f"{label}: run 1", )
        vmax = float(np.nanmax(mp["values"])) if np.isfinite(mp["values"]).any() else 0.0
        plot_reward_map(mp["positions"], mp["values"], axes[1, col], maze=spec, goal=mp["goal"], colorbar=False, gridsize=30,
                        title=f"value after run 1 (max {vmax:.2f})")
        for ax in axes[:, col]:
            _bare(ax)
            ax.title.set_fontsize("small")
    fig.suptitle(title, fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / name)


def fig_same_start(results: list[tuple[str, DMTPResult, str]], out: Path, name: str, title: str) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.report import plot_trial_paths

    runs = max(r.runs for _, r, _ in results)
    fig, axes = plt.subplots(runs, len(results), figsize=(2.9 * len(results), 2.9 * runs), squeeze=False)
    for col, (label, result, maze) in enumerate(results):
        plot_trial_paths(result, 0, maze, axes=axes[: len(result.paths[0]), col])
        for e in result.episodes:
            mark = "" if e.success else " (not reached)"
            axes[e.run, col].set_title(f"{label}, run {e.run + 1}: {e.indirectness:.2f}{mark}", fontsize="small")
        for ax in axes[len(result.paths[0]):, col]:
            ax.set_visible(False)
    fig.suptitle(title, fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / name)


def fig_dmtp(result: DMTPResult, out: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    from hippo_agent.report import plot_indirectness, plot_length_vs_indirectness

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        fig, ax = plot_indirectness(result, title=f"open arena: {result.trials} trials, random starts")
    if ax.get_legend() is not None and not ax.get_legend_handles_labels()[1]:
        ax.get_legend().remove()
    fig.tight_layout()
    a = _save(fig, out / "fig4_indirectness.png", dpi=110)
    fig, ax = plot_length_vs_indirectness(result)
    ax.set_title(ax.get_title() + " (paper: -0.53)")
    fig.tight_layout()
    b = _save(fig, out / "fig5_length_vs_indirectness.png", dpi=110)
    plt.close("all")
    return [a, b]


def fig_mazes_dmtp(results: dict[str, DMTPResult], out: Path) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.report import plot_indirectness

    fig, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 3.8), squeeze=False)
    for ax, (m, result) in zip(axes[0], results.items()):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # an empty legend when no run failed
            plot_indirectness(result, ax=ax, title=f"{m}: {result.trials} trials")
        if ax.get_legend() is not None and not ax.get_legend_handles_labels()[1]:
            ax.get_legend().remove()
    fig.tight_layout()
    return _save(fig, out / "fig8_mazes_indirectness.png", dpi=100)


def fig_generalisation(gen: dict[str, dict[str, Any]], out: Path) -> Path:
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    from hippo_agent.plots import plot_reward_map, plot_trajectories

    names = [n for n in SCENARIOS if n in gen]
    rows = 1 + max(len(gen[n]["goals"]) for n in names)
    fig, axes = plt.subplots(rows, len(names), figsize=(3.3 * len(names), 3.2 * rows), squeeze=False)
    for col, name in enumerate(names):
        g = gen[name]
        spec = MazeSpec.load(g["maze"])
        plot_trajectories([g["path"]], axes[0, col], maze=spec, title=f"{SCENARIOS[name]['title']}: exploration")
        for row in range(1, rows):
            ax = axes[row, col]
            if row - 1 >= len(g["goals"]):
                ax.set_visible(False)
                continue
            goal = g["goals"][row - 1]
            plot_reward_map(g["positions"], goal["values"], ax, maze=spec, colorbar=False, gridsize=30)
            ax.add_patch(Circle(tuple(goal["goal"]), 0.3, facecolor="none", edgecolor="lime", lw=2.5, zorder=6))
            where = "visited" if goal["visited"] else f"{goal['distance_to_explored']:.1f} m from explored"
            ok = sum(n["success"] for n in goal["nav"])
            ind = _median(n["indirectness"] for n in goal["nav"])
            ax.set_title(f"goal {tuple(goal['goal'])} ({where})\ncovers {_fmt(goal['stats']['coverage'], pct=True)}; runs: {ok}/{len(goal['nav'])} reached, median ind. {_fmt(ind, 1)}", fontsize="small")
        for ax in axes[:, col]:
            _bare(ax)
            ax.title.set_fontsize("small")
    fig.suptitle("Generalisation: replay only at each green goal, maps sampled by roaming", fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / "fig6_generalisation.png")


def fig_aliasing(fields: dict[str, dict[str, Any]], out: Path) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_place_field

    f4 = fields["maze4"]
    spec = MazeSpec.load("maze4")
    cells = f4["alias_examples"]
    fig, axes = plt.subplots(1, EXAMPLE_CELLS + 1, figsize=(2.9 * (EXAMPLE_CELLS + 1), 3.2), squeeze=False)
    by_id = {c["cell"]: c for c in f4["cells"]}
    spacing = np.min(np.diff(np.unique(f4["grid_positions"][:, 0]))) if len(f4["grid_positions"]) > 1 else 0.2
    for k in range(EXAMPLE_CELLS):
        ax = axes[0, k]
        if k < len(cells):
            c = cells[k]
            plot_place_field(f4["grid_positions"], f4["grid_rates"][c], ax, maze=spec, colorbar=False, gridsize=max(10, round(10 / spacing * 0.7)))
            ax.set_title(f"cell {c}: {by_id[c]['quadrants']} quadrants", fontsize="small")
        else:
            ax.set_visible(False)
        _bare(ax)
    ax = axes[0, -1]
    width = 0.38
    ks = np.arange(1, 5)
    for shift, (m, colour) in zip((-width / 2, width / 2), (("maze4", "tab:red"), ("open", "tab:grey"))):
        if m in fields and fields[m]["summary"].get("with_field"):
            hist = np.asarray(fields[m]["summary"]["quadrants_hist"], float)
            ax.bar(ks + shift, hist / hist.sum(), width, color=colour, label=m)
    ax.set_yscale("log")
    ax.set_xticks(ks)
    ax.set_xlabel("quadrants with a piece of the field")
    ax.set_ylabel("share of cells with a field")
    ax.legend(fontsize="small")
    fig.suptitle("maze4: place fields at alike places of several compartments (rates on a grid)", fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / "fig7_aliasing_maze4.png")


# ====================================================================================== report
FIGURES = [
    ("fig1_place_fields.png", "1. Place fields", "Example place fields after the dry run in the open arena and every maze: each cell's rate over the positions of an aimless roam (learning off), hexagonal bins, unvisited bins empty (paper Fig. 2). Four cells drawn at random among those with a field."),
    ("fig2a_reward_maps_open.png", "2. Reward maps after run 1 (open arena)", "Top: run 1 of each same-start trial; bottom: the reward cell's rate over an aimless roam after run 1, learning off (paper Fig. 3). Red: the goal."),
    ("fig2b_reward_maps_mazes.png", "2. Reward maps after run 1 (mazes)", "The same in maze1-maze4 (paper Fig. 8)."),
    ("fig3a_same_start_open.png", "3. Same start, open arena", "Each column a trial, each row a run from the same start; titles give the indirectness (paper Fig. 4)."),
    ("fig3b_same_start_mazes.png", "3. Same start, mazes", "One trial per maze, four runs from one start (paper Fig. 7; the paper's Maze 3 is our maze4)."),
    ("fig4_indirectness.png", "4. Indirectness per run, open arena", "Random starts, every trial a dot; hollow red = goal not reached (paper Fig. 5)."),
    ("fig5_length_vs_indirectness.png", "5. Run 1 length vs run 2 indirectness", "With the Pearson r (paper Fig. 6: -0.53)."),
    ("fig6_generalisation.png", "6. Generalisation", "Top: the goal-free exploration ((a) the agent's own, 5,000 steps by default; (b) one scripted pass along an L; (c) the agent's own in maze2). Below: the map inferred by replay alone at the green goal, sampled by roaming (paper Fig. 10). Titles: share of the roamed places where the value exceeds the exploit threshold; runs from random starts (up to the step limit) that reached the goal, and their median indirectness."),
    ("fig7_aliasing_maze4.png", "7. Perceptual aliasing in maze4", "Cells whose fields have separate pieces in several quadrants (rates on a grid so every compartment is sampled), and the distribution over cells, maze4 against the open arena (paper Fig. 9)."),
    ("fig8_mazes_indirectness.png", "Beyond the paper: indirectness per run in every maze", "Random starts, as figure 4 above but in each obstacle maze."),
]


def _table(rows: list[dict[str, Any]]) -> str:
    lines = ["| # | experiment | the paper | we measured | verdict |", "| --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['id']} | {r['experiment']} | {r['paper']} | {r['measured']} | **{r['verdict']}** |")
    return "\n".join(lines)


def limits(args: PaperArgs, data: dict[str, Any]) -> list[str]:
    """What the measurements say the model (or our reproduction) cannot do; computed, not canned."""
    out = []
    d = data["open_dmtp"]
    result = d["result"]
    ind, ok = result.indirectness(), result.success()
    if ind.shape[1] > 1:
        slow = [(e, result.paths[e.trial][e.run]) for e in result.episodes if e.run > 0 and not (e.indirectness <= 1.0)]
        text = (f"Open arena: {len(slow)} of {ind[:, 1:].size} later runs had indirectness > 1 (worst {np.nanmax(ind[:, 1:]):.1f}); "
                f"{int((~ok[:, 1:]).sum())} did not reach the goal within the step limit.")
        if slow:
            dists = [np.linalg.norm(path - np.asarray(e.goal), axis=1) for e, path in slow]
            near = float(np.median([np.mean(dd <= 1.0) for dd in dists]))
            first = float(np.median([np.argmax(dd <= 1.0) / max(len(dd) - 1, 1) if np.any(dd <= 1.0) else 1.0 for dd in dists]))
            text += f" In those runs the robot first came within 1 m of the goal a median {first:.0%} of the way through the run and spent {near:.0%} of its steps within 1 m of it"
            causes = []
            if first > 0.25:
                causes.append("a search away from the goal before it first gets near (where the map is thin or misleading)")
            if near >= 0.15:
                causes.append("circling close to the goal without entering the 0.3 m disk (near misses)")
            text += (": the excess is " + " and ".join(causes) + "." if causes else ".")
        out.append(text)
    p = d["summary"].get("pearson", {})
    if p.get("ci95"):
        loo = p.get("leave_one_out")
        out.append(f"The run-1-length / run-2-indirectness correlation rests on {p['n']} trials: its 95 % interval ({p['ci95'][0]:.2f} to {p['ci95'][1]:.2f}) is wide"
                   + (f", and leaving out a single trial moves r anywhere from {loo[0]:.2f} to {loo[1]:.2f}" if loo else "") + ", so neither -0.53 nor our r is pinned down.")
    for m, v in data["reward_maps_after_run1"].items():
        if not v["found_goal"]:
            out.append(f"Same-start {m}: run 1 did not find the goal within the step limit, so no reward map was learnt.")
        elif v["stats"]["far"] is not None and v["stats"]["far"] > 0.3:
            out.append(f"Reward map after run 1 in {m}: {v['stats']['far']:.0%} of places >= {FAR_PATH} m from run 1's path still carry value (the field effect, and aliased place cells firing elsewhere).")
    peaks = [f"{m} after run 1 ({v['stats']['second_peak']:.0%})" for m, v in data["reward_maps_after_run1"].items() if v["found_goal"] and (v["stats"]["second_peak"] or 0) >= SECOND_PEAK]
    peaks += [f"{g['maze']} goal {tuple(goal['goal'])} ({goal['stats']['second_peak']:.0%})" for g in data["generalisation"].values() for goal in g["goals"] if (goal["stats"]["second_peak"] or 0) >= SECOND_PEAK]
    if peaks:
        out.append(f"Maps whose value 3 m or more (geodesic) from the goal reaches {SECOND_PEAK:.0%} of the peak or more, i.e. a second, false goal the robot can head for: " + ", ".join(peaks) + " (where they lie: figures 2 and 6).")
    mz = data["maze_dmtp"]
    hard = [m for m in OBSTACLE_MAZES if m in mz and (mz[m]["summary"].get("later_runs_success_rate", 1.0) < 0.95 or (mz[m]["summary"].get("median_runs_2_on") or 0) > 1.0)]
    if hard:
        out.append(f"Obstacle mazes, runs 2-{args.runs} with random starts ({args.maze_trials} trials each): " + "; ".join(
            f"{m} median indirectness {_fmt(mz[m]['summary'].get('median_runs_2_on'))}, {mz[m]['summary']['later_runs_success_rate']:.0%} reached the goal" for m in hard)
            + ".")
    a4 = data["place_fields"].get("maze4", {})
    if a4.get("with_field"):
        out.append(f"Aliasing is structural: in maze4 {a4['multi_quadrant']:.0%} of place fields have pieces in several quadrants; BVC input plus a compass cannot tell alike compartments apart (no path integration or grid cells in this model, as the paper says).")
    for name, g in data["generalisation"].items():
        for goal in g["goals"]:
            if goal["visited"] and goal["stats"]["near"] is not None and goal["stats"]["near"] < 0.5:
                out.append(f"Generalisation {SCENARIOS[name]['title']}: the map for goal {tuple(goal['goal'])} reaches only {goal['stats']['near']:.0%} of the explored area ({g['maze']}).")
    same = data["same_start"]
    out.append(f"The same-start figures are single trials ({len(same['open'])} in the open arena, one per maze), drawn by seed, not chosen; the paper's are presumably showcases. The random-start tables are the measure.")
    return out


def write_report(args: PaperArgs, data: dict[str, Any], rows: list[dict[str, Any]], figures: list[Path], out: Path, wall: float, command: str) -> Path:
    present = {p.name for p in figures}
    cfg = args.agent_config()
    d = data["open_dmtp"]
    lines = [
        "# The paper's experiments, reproduced on HippoMaze-v0",
        "",
        (f"Generated by `benchmarks/paper.py`; {'**quick smoke run** (tiny settings: the numbers mean nothing), ' if args.quick else ''}"
        f"wall time {wall / 60:.1f} min on {args.workers} worker process(es), {platform.machine()} / Python {platform.python_version()}."),
        "",
        "```bash",
        command,
        "```",
        "",
        "Every trial or experiment ran as its own seeded task, so the numbers do not depend on the number of workers. "
        f"DMTP trial `t` (from 0) with random starts in maze `M` is exactly `hippomaze dmtp --maze M --trials 1 --runs {args.runs} --seed "
        + (f"{TRIAL_SEED_STRIDE * args.seed}+t`" if args.seed else "t`")
        + (f" with `--max-steps {args.max_episode_steps}`" if args.max_episode_steps else "")
        + (f" (and the agent's dry run cut to {args.dry_run_steps} steps, which that command does not set)" if args.dry_run_steps is not None else "")
        + "; a same-start trial adds `--same-start` with seed "
        + ", ".join([f"{x['seed']} (open, trial {k + 1})" for k, x in enumerate(data["same_start"]["open"])] + [f"{x['seed']} ({m})" for m, x in data["same_start"]["mazes"].items()]) + ".",
        "",
        "## Claims beside measurements",
        "",
        _table(rows),
        "",
        "How each verdict was decided (the criteria are in `assess` in benchmarks/paper.py):",
        "",
        *[f"- **{r['id']}**: {r['criterion']}." for r in rows],
        "",
        "## Open arena DMTP (experiments 4-5)",
        "",
        "```",
        _format_dmtp(d["result"]),
        "```",
        "",
    ]
    if data["maze_dmtp"]:
        lines += ["## Every maze with random starts (beyond the paper)", "", "| maze | paper's name | trials | median indirectness by run | runs 2+ reaching the goal |", "| --- | --- | --- | --- | --- |"]
        for m, v in data["maze_dmtp"].items():
            s = v["summary"]
            lines.append(f"| {m} | {PAPER_NAME[m]} | {v['result'].trials} | " + " / ".join(_fmt(x) for x in s["median_indirectness"]) + f" | {_fmt(s.get('later_runs_success_rate'), pct=True)} |")
        lines.append("")
    lines += ["## Figures", ""]
    for name, title, caption in FIGURES:
        if name in present:
            lines += [f"### {title}", "", f"![{title}]({name})", "", caption, ""]
    lines += ["## Limits we found", "", *[f"- {x}" for x in limits(args, data)], "",
              "## How this reproduction differs from the paper", "",
              "- **Simulator**: pymunk and a 720-ray rangefinder instead of Webots; one place-cell update per 0.15 m step; discrete actions (8 headings).",
              "- **Mazes**: the paper gives no coordinates. Our maze1 (two offset walls) and maze2 (three parallel diagonal walls) stand for its Mazes 1 and 2; its Maze 3, the four alike compartments, is our maze4 (the \"+\"), which is also Fig. 9's maze. maze3 (two alike cups) is ours, not the paper's.",
              f"- **Maps**: sampled as in the paper by an aimless roam ({args.roam_steps} steps in 16 legs from random starts, a separate environment, no agent stepped so nothing learns), reading the steady-state place-cell rates for the observation at each visited position (`agent.place_field_map` / `agent.reward_map`). Field statistics and aliasing use a {args.grid_spacing} m grid instead, so every compartment is sampled.",
              f"- **Field statistics**: a cell has a field if its peak rate on the grid is >= {FIELD_MIN_PEAK}; the field is where the rate is >= {FIELD_LEVEL:.0%} of the peak; a separate piece counts if it holds >= {COMPONENT_MIN_MASS:.0%} of the field's rate; solidity = main piece's area / its convex hull's. A field 'in several quadrants' has separate pieces in them (a field straddling a gap is one piece); 'similar places' = pieces within {SIMILAR_PLACE} m once folded by 5 m translations into one compartment.",
              f"- **Reward-map statistics**: a place is covered if the value exceeds the agent's exploit threshold xi = {cfg.xi:g}; gradedness is Spearman's rho between value and the geodesic distance to the goal over covered places.",
              "- **Generalisation**: the dry run (place fields everywhere, W_pb only) precedes every scenario, as before every DMTP trial; W_pp is learnt only on the exploration shown. 'Replay only' = a new reward cell, the place cells set to their steady-state rates at the goal, then the agent's own replay (`learn_reward`, Algorithm 1). The maps are then also tested by runs from random starts.",
              f"- **Agent**: `{'AgentConfig.paper()' if args.model == 'paper' else 'AgentConfig()'}`" + (f" with dry_run_steps={args.dry_run_steps}" if args.dry_run_steps is not None else "") + " (see paper.json for every value).",
              ""]
    path = out / "REPORT.md"
    path.write_text("\n".join(lines))
    return path


def _format_dmtp(result: DMTPResult) -> str:
    from hippo_agent.report import format_table

    return format_table(result)


# ====================================================================================== json
def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.bool_,)):
        return bool(x)
    return x


# ====================================================================================== main
def run_paper(args: PaperArgs) -> dict[str, Any]:
    """Run every experiment, write the figures, REPORT.md and paper.json into ``args.out``; return paper.json's content."""
    began = time.perf_counter()
    requested = args
    args = args.resolved()
    if args.workers < 1:
        raise ValueError(f"workers must be >= 1, got {args.workers}")
    for name in ("trials", "runs", "same_start_trials", "roam_steps"):
        if getattr(args, name) < 1:
            raise ValueError(f"{name} must be >= 1, got {getattr(args, name)}")
    if args.runs < 2:
        raise ValueError("runs must be >= 2: the paper's experiments compare run 1 with later runs")
    Path(args.out).mkdir(parents=True, exist_ok=True)
    sources = _source_digest()  # before the workers import the code: this is what runs
    results, seconds = run_tasks(build_tasks(args), args.workers, args.progress)
    return write_outputs(requested, results, seconds, began, sources)


def write_outputs(requested: PaperArgs, results: dict[str, Any], seconds: dict[str, float], began: float, sources: dict[str, str] | None = None) -> dict[str, Any]:
    """Analyse the tasks' results; write the figures, REPORT.md and paper.json."""
    args = requested.resolved()
    out = Path(args.out)
    command = requested.command()

    # ---- gather
    fields = {m: results[f"fields/{m}"] for m in MAZES}
    same_open = [results[f"same_start/open/{t}"] for t in range(args.same_start_trials)]
    same_mazes = {m: results[f"same_start/{m}"] for m in OBSTACLE_MAZES}
    open_result = merge_trials([results[f"dmtp/open/{t}"]["result"] for t in range(args.trials)], args.seed)
    maze_results = {m: merge_trials([results[f"dmtp/{m}/{t}"]["result"] for t in range(args.maze_trials)], args.seed) for m in OBSTACLE_MAZES} if args.maze_trials else {}
    gen = {name: results[f"generalisation/{name}"] for name in SCENARIOS}

    def map_entry(task: dict[str, Any]) -> dict[str, Any]:
        ep = task["result"].episodes[0]
        return {"maze": task["maze"], "seed": task["seed"], "found_goal": bool(ep.success), "run1_steps": ep.steps, "stats": task["map"]["stats"]}

    data: dict[str, Any] = {
        "place_fields": {m: f["summary"] for m, f in fields.items()},
        "reward_maps_after_run1": {**{f"open trial {t + 1}": map_entry(x) for t, x in enumerate(same_open)}, **{m: map_entry(x) for m, x in same_mazes.items()}},
        "same_start": {
            "open": [{"seed": x["seed"], "indirectness": [e.indirectness for e in x["result"].episodes], "success": [e.success for e in x["result"].episodes]} for x in same_open],
            "mazes": {m: {"seed": x["seed"], "indirectness": [e.indirectness for e in x["result"].episodes], "success": [e.success for e in x["result"].episodes]} for m, x in same_mazes.items()},
        },
        "open_dmtp": {"result": open_result, "summary": dmtp_summary(open_result, args.seed)},
        "maze_dmtp": {m: {"result": r, "summary": dmtp_summary(r, args.seed)} for m, r in maze_results.items()},
        "generalisation": gen,
    }
    rows = assess(args, data)

    # ---- figures
    import matplotlib

    matplotlib.use("Agg")
    figures = [fig_place_fields(fields, out)]
    figures.append(fig_reward_maps([(f"open trial {t + 1}", x) for t, x in enumerate(same_open)], out, "fig2a_reward_maps_open.png", "Open arena: reward maps after run 1, sampled by roaming with learning off"))
    figures.append(fig_reward_maps(list(same_mazes.items()), out, "fig2b_reward_maps_mazes.png", "Mazes: reward maps after run 1, sampled by roaming with learning off"))
    figures.append(fig_same_start([(f"open trial {t + 1}", x["result"], "open") for t, x in enumerate(same_open)], out, "fig3a_same_start_open.png", "Open arena: four runs from the same start"))
    figures.append(fig_same_start([(m, x["result"], m) for m, x in same_mazes.items()], out, "fig3b_same_start_mazes.png", "Mazes: four runs from the same start"))
    figures += fig_dmtp(open_result, out)
    figures.append(fig_generalisation(gen, out))
    figures.append(fig_aliasing(fields, out))
    if maze_results:
        figures.append(fig_mazes_dmtp(maze_results, out))

    wall = time.perf_counter() - began
    report = write_report(args, data, rows, figures, out, wall, command)
    paper = {
        "command": command,
        "source_sha256": sources if sources is not None else _source_digest(),
        "args": dataclasses.asdict(args),
        "agent_config": args.agent_config().to_dict(),
        "seeds": {
            "dmtp_trial": f"{TRIAL_SEED_STRIDE} * seed + trial (open arena and every maze)",
            "same_start": {**{f"open/{t}": x["seed"] for t, x in enumerate(same_open)}, **{m: x["seed"] for m, x in same_mazes.items()}},
            "fields": {m: f["seed"] for m, f in fields.items()},
            "generalisation": {n: g["seed"] for n, g in gen.items()},
        },
        "wall_seconds": wall,
        "task_seconds": seconds,
        "claims": rows,
        "experiments": {
            "place_fields": data["place_fields"],
            "reward_maps_after_run1": data["reward_maps_after_run1"],
            "same_start": data["same_start"],
            "open_dmtp": {**open_result.to_dict(), "summary": data["open_dmtp"]["summary"], "trial_seeds": [trial_seed(args.seed, t) for t in range(args.trials)]},
            "maze_dmtp": {m: {**v["result"].to_dict(), "summary": v["summary"]} for m, v in data["maze_dmtp"].items()},
            "generalisation": {
                n: {"maze": g["maze"], "explore": SCENARIOS[n]["explore"], "exploration_steps": int(len(g["path"]) - 1),
                    "goals": [{**{k: v for k, v in goal.items() if k not in ("values", "nav")},
                               "nav": [{k: v for k, v in r.items() if k != "path"} for r in goal["nav"]]} for goal in g["goals"]]}
                for n, g in gen.items()
            },
            "aliasing_examples": {m: {"examples": f["examples"], "alias_examples": f["alias_examples"]} for m, f in fields.items()},
        },
        "figures": [p.name for p in figures],
        "report": report.name,
    }
    paper = _jsonable(paper)
    hippo_env.atomic_write(out / "paper.json", json.dumps(paper, indent=1) + "\n")
    if args.progress:
        print(f"wrote {report} and {out / 'paper.json'} ({len(figures)} figures) in {wall / 60:.1f} min")
    return paper


def _source_digest() -> dict[str, str]:
    """SHA-256 of the model's and the environment's source (they change; this says which ran)."""
    import hashlib

    import hippo_agent

    digests = {}
    for package in (hippo_agent, hippo_env):
        root = Path(package.__file__).parent
        h = hashlib.sha256()
        for path in sorted(root.rglob("*.py")):
            h.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
        digests[package.__name__] = h.hexdigest()
    return digests


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    run_paper(args)
    return 0


if __name__ == "__main__":
    # Import by module name so that worker processes pickle tasks as benchmarks.paper.*
    from benchmarks.paper import main as _main

    sys.exit(_main())
