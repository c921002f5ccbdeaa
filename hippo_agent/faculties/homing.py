"""Homing: back to where the goal was found, and a search round that place.

A faculty of the default model (``AgentConfig.homing``; it needs ``path_integration`` and
``map``). At each reward the agent remembers its estimate (:meth:`Homing.remember`; one found more
than ``rival_radius`` from the others is kept apart, as a rival that takes over once found more
often). In a later run of the same trial, within ``radius`` of the mean of those places, it heads
there instead of preplaying: straight at it while the line to within ``approach_radius`` of it
crosses walkable ground with a cell to spare on either side, else along the map's shortest
walkable path to ground within ``approach_radius`` (the place, where the robot entered the goal
disk, may lie by a wall), then straight on. Where the map knows no path, preplay steers.

Arrived (within ``arrived``), or stopped by a wall on the last stretch, without the reward, it
searches the ground within ``search_radius`` of the place afresh. If that search finds nothing, or
it bumped ``bump_limit`` times on the way into walls its map does not hold, or it steered
``stall_steps`` steps without coming nearer the place, its estimate must be at a look-alike place:
:meth:`Homing.plan` and :meth:`Homing.bumped` say so, and the agent anchors afresh away from
there. After ``attempts`` such failures in a run, the memory itself is taken to be wrong (written
while misplaced, say): neither homing nor the reward map steers for the rest of the run
(:attr:`Homing.gave_up`), and the next reward replaces the memory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from hippo_agent.faculties._map_kernels import distance
from hippo_agent.faculties.localisation import Localisation
from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator
from hippo_agent.sections import Section, param

__all__ = ["Homing", "HomingConfig"]


@dataclass(frozen=True)
class HomingConfig(Section):
    """Homing to the remembered place of the current goal."""

    name: ClassVar[str] = "homing"

    radius: float = param(100.0, gt=0)
    """Within this distance (m, by path integration) of the remembered place, head there instead
    of preplaying (100 m: from anywhere in any arena the generator makes)."""
    approach_radius: float = param(0.6, gt=0)
    """Within this distance (m) of the place the robot goes straight at it; the planned path
    leads to ground this near it, and a bump this near starts the search round it."""
    arrived: float = param(0.1, gt=0)
    """This close (m) to the place without a reward, the robot searches round it."""
    search_radius: float = param(1.0, gt=0)
    """Radius (m) of that search."""
    search_mark: float = param(0.25, gt=0)
    """During that search, ground within this distance (m) of the path counts as searched
    (narrower than a run's marking: the place lies at the goal disk's edge)."""
    bump_limit: int = param(20, ge=1)
    """This many bumps while homing, into walls the map does not hold, and the estimate is taken
    to be at a look-alike place."""
    attempts: int = param(3, ge=1)
    """After this many failed searches in a run, the memory is given up for the rest of the run."""
    rival_radius: float = param(1.0, gt=0)
    """A reward found farther than this (m) from the remembered place is remembered apart, as a
    rival place; the rival replaces the memory once more rewards were found there."""
    stall_steps: int | None = param(400, ge=1)
    """After this many steps homing steered without coming ``stall_progress`` nearer the place
    (by the estimate) than it had been, homing fails as a search that found nothing does: the
    estimate must be at a look-alike place, where the map's way is not the world's (``None``: no
    such limit). Without it, a robot anchored in the wrong one of two look-alike rooms could press
    against a wall for the rest of a run, the map showing a door there."""
    stall_progress: float = param(0.5, gt=0)
    """The progress (m) toward the place that counts for ``stall_steps``."""


class Homing:
    """Homing (module docstring).

    Args:
        config: its parameters.
        map_: the agent's map (paths, and the ground searched in this run).
        pi: the agent's path integrator (the estimate).
        localisation: the agent's localisation, if any (homing waits while it doubts the estimate).
    """

    def __init__(self, config: HomingConfig, map_: ExplorationMap, pi: PathIntegrator, localisation: Localisation | None) -> None:
        self.config = config
        self.map = map_
        self.pi = pi
        self.localisation = localisation
        # per goal, the sum of the estimates at which the reward was found, and their count; and
        # the same for rewards found away from that place (a rival, module docstring)
        self.found_sum = np.zeros((0, 2))
        self.found_count = np.zeros(0)
        self.rival_sum = np.zeros((0, 2))
        self.rival_count = np.zeros(0)
        self.searching = False  # arrived without the reward: searching round the place
        self.failures = 0  # searches that found no reward, this run
        self.bumps = 0  # bumps while homing since the last failed search, this run
        self.closest = math.inf  # the nearest the estimate came to the place since homing last failed or started
        self.stalled = 0  # steps homing steered since it came stall_progress nearer than that
        self.heading: float | None = None  # where to head, as of the last :meth:`plan`

    # ------------------------------------------------------------------ the memory
    def new_goal(self) -> None:
        """A new goal: nothing remembered of it yet."""
        self.found_sum = np.vstack([self.found_sum, np.zeros((1, 2))])
        self.found_count = np.append(self.found_count, 0.0)
        self.rival_sum = np.vstack([self.rival_sum, np.zeros((1, 2))])
        self.rival_count = np.append(self.rival_count, 0.0)

    def remember(self, where: np.ndarray) -> None:
        """The current goal's reward was found at ``where`` (an estimate): added to the memory's
        mean if it lies within ``rival_radius`` of it, else to the rival's (started afresh if the
        rival lies farther too). A rival with more rewards than the memory becomes the memory: a
        reward found while misplaced does not drag the memory off (the mean of two places lies at
        neither), and a memory written while misplaced is outvoted."""
        if self.found_count.size == 0:
            self.new_goal()
        if self.found_count[-1] == 0 or self._near(self.found_sum[-1], self.found_count[-1], where):
            self.found_sum[-1] += where
            self.found_count[-1] += 1.0
            return
        if not self._near(self.rival_sum[-1], self.rival_count[-1], where):
            self.rival_sum[-1], self.rival_count[-1] = 0.0, 0.0  # a rival elsewhere: start afresh here
        self.rival_sum[-1] += where
        self.rival_count[-1] += 1.0
        if self.rival_count[-1] > self.found_count[-1]:
            self.found_sum[-1], self.rival_sum[-1] = self.rival_sum[-1].copy(), self.found_sum[-1].copy()
            self.found_count[-1], self.rival_count[-1] = self.rival_count[-1], self.found_count[-1]

    def _near(self, total: np.ndarray, count: float, where: np.ndarray) -> bool:
        """Whether ``where`` lies within ``rival_radius`` of the mean ``total / count`` (False if none)."""
        return bool(count > 0) and _distance(*(total / count).tolist(), *where.tolist()) <= self.config.rival_radius

    def forget(self) -> None:
        """Forget where the current goal was found."""
        if self.found_count.size:
            self.found_sum[-1] = 0.0
            self.found_count[-1] = 0.0
            self.rival_sum[-1] = 0.0
            self.rival_count[-1] = 0.0

    def memory(self) -> dict[str, np.ndarray]:
        """Copies of the goal memories' arrays (what :meth:`restore_memory` takes)."""
        return {name: getattr(self, name).copy() for name in _MEMORY}

    def clear_memory(self) -> None:
        """No goal remembered (a new world)."""
        self.found_sum, self.found_count = np.zeros((0, 2)), np.zeros(0)
        self.rival_sum, self.rival_count = np.zeros((0, 2)), np.zeros(0)

    def restore_memory(self, arrays: dict[str, np.ndarray]) -> None:
        """Set the goal memories from :meth:`memory`'s arrays (a memory saved before rivals were
        kept has none)."""
        missing = [name for name in _MEMORY[:2] if name not in arrays]
        if missing:
            raise ValueError(f"homing's arrays {missing} are missing (a goal memory needs {list(_MEMORY[:2])})")
        found_sum = np.asarray(arrays["found_sum"], dtype=np.float64).reshape(-1, 2)
        found_count = np.asarray(arrays["found_count"], dtype=np.float64).reshape(-1)
        goals = len(found_count)
        rival_sum = np.asarray(arrays.get("rival_sum", np.zeros((goals, 2))), dtype=np.float64).reshape(-1, 2)
        rival_count = np.asarray(arrays.get("rival_count", np.zeros(goals)), dtype=np.float64).reshape(-1)
        if not (len(found_sum) == goals == len(rival_sum) == len(rival_count)) or not all(
            np.all(np.isfinite(a)) for a in (found_sum, found_count, rival_sum, rival_count)
        ):
            raise ValueError(
                f"homing's arrays 'found_sum' ({len(found_sum)} places), 'found_count' ({goals}), 'rival_sum' "
                f"({len(rival_sum)}) and 'rival_count' ({len(rival_count)}) do not match, or are not finite"
            )
        self.found_sum, self.found_count, self.rival_sum, self.rival_count = found_sum, found_count, rival_sum, rival_count

    def remembered(self) -> np.ndarray | None:
        """Where the current goal's reward was found, on average; ``None`` before it was found."""
        place = self._remembered_xy()
        return None if place is None else np.array(place)

    def _remembered_xy(self) -> tuple[float, float] | None:
        """:meth:`remembered` as two floats (faster arithmetic than on NumPy scalars)."""
        count = self.found_count[-1].item() if self.found_count.size else 0
        if count == 0:
            return None
        sx, sy = self.found_sum[-1].tolist()
        return sx / count, sy / count

    @property
    def gave_up(self) -> bool:
        """The memory failed ``attempts`` times in this run: it steers no more."""
        return self.failures >= self.config.attempts

    # ------------------------------------------------------------------ a run
    def reset(self) -> None:
        """A run begins."""
        self.searching = False
        self.failures = 0
        self.bumps = 0
        self.closest, self.stalled = math.inf, 0
        self.heading = None

    def distance(self) -> float:
        """How far (m, by path integration) the remembered place is; inf if none."""
        target = self.remembered()
        if target is None:
            return math.inf
        return _distance(*target.tolist(), *self.pi.estimate.tolist())

    def plan(self) -> bool:
        """Decide :attr:`heading` for this step (``None``: homing does not steer: no memory, too
        far, no known path, or the estimate is lost or doubted). Starts the search round the place
        on arrival. ``True`` when that search is done without the reward: the estimate must be at
        a look-alike place (and :attr:`heading` is ``None``)."""
        c = self.config
        self.heading = None
        target = self._remembered_xy()
        trusted = self.localisation.trusted if self.localisation is not None else self.pi.anchored
        if target is None or not trusted:
            self.closest, self.stalled = math.inf, 0  # (a new anchoring may put the place farther)
            return False
        here = self.pi.estimate
        (tx, ty), (x, y) = target, here.tolist()
        distance = _distance(tx, ty, x, y)
        if distance > c.radius:
            return False
        if distance < c.arrived and not self.searching:
            self._start_search()
        if self.searching:
            heading = self.map.heading_to_unsearched_near(here, np.array(target), c.search_radius)
            if heading is None:  # searched all round the place without finding the reward
                self._failed()
                return True
        elif distance <= c.approach_radius or self.map.in_sight(here, _toward(x, y, tx, ty, distance - c.approach_radius)):
            heading = math.atan2(ty - y, tx - x)  # straight at it (a bump this near ends homing)
        else:
            # the place itself may be by a wall, off the walkable map: path to walkable ground
            # within approach_radius of it, the ground from which the robot goes straight on
            heading = self.map.heading_to_near(here, np.array(target), c.approach_radius)
        if heading is not None and not self.searching and c.stall_steps is not None:
            if distance < self.closest - c.stall_progress:
                self.closest, self.stalled = distance, 0
            else:
                self.stalled += 1
                if self.stalled >= c.stall_steps:
                    self._failed()
                    return True
        self.heading = heading
        return False

    def bumped(self, surprising: bool) -> bool:
        """A bump while homing (``surprising``: where the map shows no wall). ``True`` after
        ``bump_limit`` such bumps: the map's free way was not free, the estimate must be at a
        look-alike place. A bump on the last stretch starts the search round the place."""
        self.bumps += surprising
        if self.bumps >= self.config.bump_limit:
            self._failed()
            return True
        if not self.searching and self.distance() <= self.config.approach_radius:
            self._start_search()  # as near the place as the wall lets it
        return False

    @property
    def search_mark(self) -> float | None:
        """The radius (m) within which the map counts ground searched while searching round the
        place; ``None`` (the map's own) otherwise."""
        return self.config.search_mark if self.searching else None

    def _start_search(self) -> None:
        """Arrived without the reward: search all round the place afresh."""
        self.searching = True
        target = self.remembered()
        if target is not None:
            self.map.forget_searched_near(target, self.config.search_radius)

    def _failed(self) -> None:
        self.searching = False
        self.bumps = 0
        self.closest, self.stalled = math.inf, 0
        self.failures += 1

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        closest = None if math.isinf(self.closest) else self.closest  # (JSON has no infinity)
        run = {"searching": self.searching, "failures": self.failures, "bumps": self.bumps, "closest": closest, "stalled": self.stalled}
        return run, self.memory()

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        self.restore_memory(arrays)
        self.searching, self.failures, self.bumps = bool(state["searching"]), int(state["failures"]), int(state["bumps"])
        closest = state.get("closest")  # (saves before 0.19 hold neither)
        self.closest, self.stalled = math.inf if closest is None else float(closest), int(state.get("stalled", 0))


_MEMORY = ("found_sum", "found_count", "rival_sum", "rival_count")


def _distance(tx: float, ty: float, x: float, y: float) -> float:
    """From ``(x, y)`` to ``(tx, ty)``, m (NumPy's hypot, the one homing has always used, compiled:
    :func:`~hippo_agent.faculties._map_kernels.distance`)."""
    return distance(tx, ty, x, y)


def _toward(x: float, y: float, tx: float, ty: float, length: float) -> tuple[float, float]:
    """The point ``length`` metres from ``(x, y)`` toward ``(tx, ty)``."""
    dx, dy = tx - x, ty - y
    f = length / math.hypot(dx, dy)
    return x + f * dx, y + f * dy
