"""The records the paper's experiments pass between modules, and their layout in ``paper.json``.

Arrays (positions, rates, values, paths) feed the figures only; ``to_dict`` gives what
``paper.json`` keeps of each record, in its key order.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hippo_env.dmtp import DMTPResult


# ------------------------------------------------------------------------------- place fields
@dataclass
class FieldCell:
    """One place cell's field on the grid: its peak rate, area (m^2), substantial pieces, the main
    piece's solidity and centre, the quadrants / halves its pieces lie in, and how far apart the
    pieces are once folded into one compartment."""

    cell: int
    peak: float
    area: float
    pieces: int
    solidity: float
    centre: list[float]
    quadrants: int
    halves: int
    folded_spread: float
    min_piece_mass: float


@dataclass
class FieldSummary:
    """The fields of one maze's place cells, summarised (everything but the counts is None when no cell has a field)."""

    cells: int
    with_field: int
    single_piece: float | None = None
    median_area_m2: float | None = None
    median_area_share: float | None = None
    median_solidity_main_piece: float | None = None
    quadrants_hist: list[int] | None = None
    halves_hist: list[int] | None = None
    multi_quadrant: float | None = None
    multi_quadrant_similar_place: float | None = None
    multi_half: float | None = None
    multi_half_similar_place: float | None = None
    median_folded_spread_multi_quadrant: float | None = None

    def to_dict(self) -> dict[str, Any]:
        if not self.with_field:
            return {"cells": self.cells, "with_field": self.with_field}
        return dataclasses.asdict(self)


@dataclass
class FieldsResult:
    """Experiments 1 and 7 in one maze: every field, the example cells, and their rates on a roam and on the grid."""

    maze: str
    seed: int
    summary: FieldSummary
    cells: list[FieldCell]
    examples: list[int]
    alias_examples: list[int]
    roam_positions: np.ndarray
    roam_rates: dict[int, np.ndarray]
    grid_positions: np.ndarray
    grid_rates: dict[int, np.ndarray]


# ------------------------------------------------------------------------------- reward maps
@dataclass
class MapStats:
    """How a sampled reward map looks (see ``analysis.map_stats``)."""

    coverage: float
    near: float | None
    band: float | None
    far: float | None
    spearman: float | None
    max_value: float
    peak_offset: float | None = None
    second_peak: float | None = None


@dataclass
class RewardMap:
    """The reward cell's rate over a roam after run 1, with run 1's path and the goal."""

    positions: np.ndarray
    values: np.ndarray
    run1_path: np.ndarray
    goal: list[float]
    stats: MapStats


@dataclass
class TrialResult:
    """One DMTP trial (experiments 2-5), with the reward map after run 1 if it was sampled."""

    maze: str
    seed: int
    same_start: bool
    result: DMTPResult
    map: RewardMap | None


# ------------------------------------------------------------------------------- generalisation
@dataclass
class NavRun:
    """One run from a random start toward a goal whose map was inferred by replay."""

    success: bool
    indirectness: float
    steps: int


@dataclass
class GoalResult:
    """One goal of a generalisation scenario: where it lies from the exploration, the replayed map and the runs to it."""

    goal: list[float]
    distance_to_explored: float
    visited: bool
    replay_learnt: bool
    values: np.ndarray
    stats: MapStats
    nav: list[NavRun]

    def to_dict(self) -> dict[str, Any]:
        return {
            "goal": self.goal,
            "distance_to_explored": self.distance_to_explored,
            "visited": self.visited,
            "replay_learnt": self.replay_learnt,
            "stats": dataclasses.asdict(self.stats),
            "nav": [dataclasses.asdict(n) for n in self.nav],
        }


@dataclass
class GeneralisationResult:
    """Experiment 6, one scenario: the goal-free exploration, the roamed positions and every goal."""

    name: str
    maze: str
    seed: int
    path: np.ndarray
    positions: np.ndarray
    goals: list[GoalResult]

    def to_dict(self, explore: str) -> dict[str, Any]:
        return {
            "maze": self.maze,
            "explore": explore,
            "exploration_steps": int(len(self.path) - 1),
            "goals": [g.to_dict() for g in self.goals],
        }


# ------------------------------------------------------------------------------- gathered
@dataclass
class MapEntry:
    """A same-start trial's reward map after run 1, as the claims and paper.json see it."""

    maze: str
    seed: int
    found_goal: bool
    run1_steps: int
    stats: MapStats


@dataclass
class SameStartTrial:
    """A same-start trial's indirectness and success by run."""

    seed: int
    indirectness: list[float]
    success: list[bool]


@dataclass
class SameStart:
    open: list[SameStartTrial]
    mazes: dict[str, SameStartTrial]


@dataclass
class DMTPSummary:
    """``DMTPResult.summary()`` (``protocol``) plus the later runs' median and reach, and the run-1-length /
    run-2-indirectness correlation (``statistics.pearson_with_ci``)."""

    protocol: dict[str, Any]
    median_runs_2_on: float | None
    later_runs_reached: int
    later_runs_total: int
    pearson: dict[str, Any] | None = None

    @property
    def median_indirectness(self) -> list[float | None]:
        return self.protocol["median_indirectness"]

    @property
    def later_runs_success_rate(self) -> float | None:
        return self.protocol.get("later_runs_success_rate")

    def to_dict(self) -> dict[str, Any]:
        out = {
            **self.protocol,
            "median_runs_2_on": self.median_runs_2_on,
            "later_runs_reached": self.later_runs_reached,
            "later_runs_total": self.later_runs_total,
        }
        if self.pearson is not None:
            out["pearson"] = self.pearson
        return out


@dataclass
class DMTPOutcome:
    """Several DMTP trials merged into one result, with their summary."""

    result: DMTPResult
    summary: DMTPSummary


@dataclass
class PaperData:
    """Every experiment's outcome, gathered: what the claims, the report and paper.json read."""

    place_fields: dict[str, FieldSummary]
    reward_maps_after_run1: dict[str, MapEntry]
    same_start: SameStart
    open_dmtp: DMTPOutcome
    maze_dmtp: dict[str, DMTPOutcome] = field(default_factory=dict)
    generalisation: dict[str, GeneralisationResult] = field(default_factory=dict)


@dataclass
class Claim:
    """One row of the claims table: what the paper says, what we measured, and the verdict by the stated criterion."""

    id: str
    experiment: str
    paper: str
    measured: str
    verdict: str
    criterion: str
    figure: str
