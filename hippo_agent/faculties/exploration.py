"""Directed exploration: where the map says to go next, in the dry run and in a run's search.

A faculty of the default model (``AgentConfig.exploration``; it needs ``map``). Rats do not
random-walk a new place: they explore it systematically. Here, from the agent's own map:

- **the dry run** sweeps to the nearest ground it has not been near (over walkable cells or,
  when none is left that way, through any free cell that is not a wall: a doorway too narrow
  for walkable cells would otherwise end the sweep); once none is reachable, it crosses the known
  ground on shortest paths between random visited places (*transits*, ``transit_factor`` times the
  sweep's steps) so that the place-place links (eq. 7) lie along direct routes; then it *rests*:
  imagined transits replay the place codes it saw along map paths with eq. 7 on, taking no step
  (:meth:`Exploration.rest`). Place cells are recruited with the ground found (``place_cells_per_m2``).
- **a run** searches the nearest ground not yet searched in that run; once all is searched, it
  searches afresh (one pass can miss the 0.3 m goal disk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from hippo_agent.cells import _kernels
from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator
from hippo_agent.paper_model import PaperModel
from hippo_agent.sections import Section, param

__all__ = ["Exploration", "ExplorationConfig"]


@dataclass(frozen=True)
class ExplorationConfig(Section):
    """Directed exploration, the dry run's rest, and place cells recruited with the arena."""

    name: ClassVar[str] = "exploration"

    sweep_patience: int = param(3, ge=1)
    """The sweep counts as done after this many steps in a row with no unvisited ground reachable
    (a single step may find none while the map is filled in)."""
    transit_factor: float = param(0.9, ge=0)
    """Transits take this many times the steps the sweep took."""
    transit_min_distance: float = param(3.0, ge=0)
    """A transit's destination lies at least this far (m, along the path) from where it starts."""
    rest_factor: float = param(5.0, ge=0)
    """Imagined steps at rest per step of the sweep."""
    imagined_step: float = param(0.15, gt=0)
    """Metres between the place codes of an imagined transit: one step's travel."""
    place_cells_per_m2: float = param(10.0, ge=0)
    """Place cells are recruited so there are at least this many per square metre of free ground
    the map knows (up to ``max_place_cells``): a larger arena gets more cells."""
    max_place_cells: int = param(16000, ge=1)
    """The most place cells recruitment grows to."""
    recruit_every: int = param(50, ge=1)
    """Steps between checks of whether the place cells fall short."""
    recruit_min: int = param(250, ge=1)
    """Place cells recruited at least at a time (recruitment in a few large steps)."""
    dry_run_steps_per_m2: float = param(30.0, ge=0)
    """With ``model.dry_run_steps`` None, the dry run's cap is 10,000 steps or this many steps per
    square metre of free ground the map has found, whichever is more: the cap grows with the
    world (the sweep takes about 14 steps a square metre)."""


Stage = Literal["sweep", "transit", "done"]


class Exploration:
    """Directed exploration (module docstring).

    Args:
        config: its parameters.
        map_: the agent's map.
        pi: the agent's path integrator (the estimate is where the robot plans from).
        model: the paper's model (its place codes are replayed at rest).
        rng: the agent's generator (transit destinations).
    """

    def __init__(
        self, config: ExplorationConfig, map_: ExplorationMap, pi: PathIntegrator, model: PaperModel, rng: np.random.Generator
    ) -> None:
        self.config = config
        self.map = map_
        self.pi = pi
        self.model = model
        self.rng = rng
        self.stage: Stage = "sweep"  # the dry run's: to unvisited ground, then transits, then done
        self.sweep_steps = 0  # steps the sweep took
        self.transit_left = 0  # transit steps still to go
        self.transit_target = -1  # the current transit's destination (a map cell), -1 = none
        self.plan_failures = 0  # consecutive sweep steps with nowhere to go
        self.codes: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # dry run: map cell -> place code there (active cells, rates)

    # ------------------------------------------------------------------ the dry run
    def start_dry_run(self) -> None:
        """The dry run begins with the sweep."""
        self.stage = "sweep"
        self.sweep_steps = self.transit_left = self.plan_failures = 0
        self.transit_target = -1

    def end_dry_run(self) -> None:
        """The dry run is over: the place codes it saw are let go."""
        self.codes = {}

    def recruits(self, step: int) -> int:
        """Dry run, every ``recruit_every`` steps: how many place cells to recruit so there are
        ``place_cells_per_m2`` of the free ground the map knows (at least ``recruit_min`` at a
        time, at most ``max_place_cells`` in all); 0 for none."""
        c = self.config
        if step % c.recruit_every:
            return 0
        n = self.model.place.n
        wanted = min(math.ceil(c.place_cells_per_m2 * self.map.explored_area()), c.max_place_cells)
        return min(max(wanted - n, c.recruit_min), c.max_place_cells - n) if wanted > n else 0

    def remember_code(self) -> None:
        """Dry run: the place code seen in the map cell where the rates formed (rest replays it)."""
        place = self.model.place
        active = np.flatnonzero(place.v > 0.0)
        self.codes[self.map.flat_index(*self.pi.lagged_xy())] = (active, place.v[active])

    # ------------------------------------------------------------------ where to go
    def plan(self, dry: bool) -> float | None:
        """Where the map says to go next, or ``None`` (the random walk then steps). Advances this
        faculty's own plan: the sweep's patience, the stage, the transits. In a run, once all is
        searched, the search starts afresh."""
        here = self.pi.estimate
        m = self.map
        if not dry:
            heading = m.heading_to_unvisited(here, this_run=True)
            if heading is None:  # a doorway too narrow for walkable cells may wall the robot in
                heading = m.heading_to_unvisited(here, this_run=True, squeeze=True)
            if heading is None:  # everything searched and no goal: search again
                m.new_run()
                heading = m.heading_to_unvisited(here, this_run=True, squeeze=True)
            return heading
        if self.stage == "sweep":
            heading = m.heading_to_unvisited(here)
            if heading is None:
                heading = m.heading_to_unvisited(here, squeeze=True)
            self.sweep_steps += 1
            if heading is not None:
                self.plan_failures = 0
                return heading
            self.plan_failures += 1
            if self.plan_failures < self.config.sweep_patience:
                return None
            self.stage = "transit"
            self.transit_left = math.ceil(self.config.transit_factor * self.sweep_steps)
        if self.transit_left <= 0:
            self.stage = "done"
            return None
        self.transit_left -= 1
        heading = m.heading_to(here, self.transit_target) if self.transit_target >= 0 else None
        if heading is None:  # arrived, or the destination cannot be reached: a new one
            self.transit_target = self._transit_destination(here)
            heading = m.heading_to(here, self.transit_target) if self.transit_target >= 0 else None
        return heading

    def _transit_destination(self, here: np.ndarray) -> int:
        """A random visited place at least ``transit_min_distance`` away along the known ground
        (a map cell's flat index), or -1 if there is none."""
        cells, steps = self.map.reachable_visited(here)
        far = cells[steps * self.map.cell >= self.config.transit_min_distance]
        if far.size == 0:
            return -1
        return int(far[self.rng.integers(far.size)])

    # ------------------------------------------------------------------ rest
    def rest(self) -> None:
        """Imagined transits at rest, after the dry run: sequences of remembered place codes along
        shortest paths across the map, between random visited places, with the place-place rule
        (eq. 7) on. Nothing moves: no environment step is taken.

        Rats replay, at rest, sequences through places they know, including routes they never
        ran. Here the sequence is read from the map: every ``imagined_step`` metres along the path,
        the place code the dry run last saw in that map cell (cells without one are passed over).
        ``rest_factor`` imagined steps per step of the sweep. One sweep lays place-place links
        along one path only; links along direct routes are what make later runs direct.
        """
        c = self.config
        budget = round(c.rest_factor * self.sweep_steps)
        if budget <= 0 or not self.codes:
            return
        place = self.model.place
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
                path = self.map.centres(self.map.path(np.asarray(start), target))
                lengths = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))))
                along = np.arange(0.0, lengths[-1], c.imagined_step)
                points = np.column_stack([np.interp(along, lengths, path[:, 0]), np.interp(along, lengths, path[:, 1])])
                place.trace = np.zeros(place.n)
                place.hd_trace = np.zeros(place.n_hd)
                budget -= self._imagine(self.map.flat_indices(points).tolist(), points.tolist())
        finally:
            place.v, place.trace, place.hd_trace = saved

    def _imagine(self, cells: list[int], xy: list[list[float]]) -> int:
        """One imagined transit through the points ``xy`` (in the map cells ``cells``): at each
        point after the first whose cell holds a remembered code, the rates are that code, the
        heading is from the point before, and the place-place rule (eq. 7) and the traces (eq. 6)
        learn as in a run. Returns the number of imagined steps. (The steps run in one compiled
        loop, which stops where a cell needs a ``W_pp`` slot: :meth:`PlaceCells.learn_pp` gives it.)"""
        place, hd = self.model.place, self.model.hd
        steps = [(self.codes[cells[k]], k) for k in range(1, len(cells)) if cells[k] in self.codes]
        if not steps:
            return 0
        step_x, step_y = np.empty(len(steps)), np.empty(len(steps))
        for q, (_, k) in enumerate(steps):
            dx, dy = xy[k][0] - xy[k - 1][0], xy[k][1] - xy[k - 1][1]
            length = math.hypot(dx, dy)
            step_x[q], step_y[q] = dx / length, dy / length
        code_start = np.zeros(len(steps) + 1, dtype=np.int64)
        np.cumsum([code[0].size for code, _ in steps], out=code_start[1:])
        code_cells = np.concatenate([code[0] for code, _ in steps])
        code_rates = np.concatenate([code[1] for code, _ in steps])
        place.v = np.zeros(place.n)
        h = np.empty(place.n_hd)
        done = 0
        while done < len(steps):
            done = _kernels.imagined_steps(
                place.W_slots, place.slot, place.v, place.trace, place.hd_trace, place.eta_pp, place.trace_rate,
                place.hd_trace_rate, place.trace_floor, hd.cos_preferred, hd.sin_preferred, h, code_start, code_cells,
                code_rates, step_x, step_y, done,
            )  # fmt: skip
            if done < len(steps):  # a cell needs a slot: this step's eq. 7 and trace, then on
                place.learn_pp()
                place.update_trace()
                done += 1
        return len(steps)

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores (the dry run's place codes
        are not kept: a saved agent rests no more)."""
        names = ("stage", "sweep_steps", "transit_left", "transit_target", "plan_failures")
        return {name: getattr(self, name) for name in names}, {}

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        if state["stage"] not in ("sweep", "transit", "done"):
            raise ValueError(f"exploration stage {state['stage']!r} is not 'sweep', 'transit' or 'done'")
        self.stage = state["stage"]
        self.sweep_steps, self.transit_left = int(state["sweep_steps"]), int(state["transit_left"])
        self.transit_target, self.plan_failures = int(state["transit_target"]), int(state["plan_failures"])
