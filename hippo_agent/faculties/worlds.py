"""Several worlds: each keeps its own map and memories, and the agent tells which one it is in.

A faculty of the default model (``AgentConfig.worlds``; it needs ``path_integration`` and
``map``). The place cells (their boundary code and their links) are the agent's, whatever the
world; what belongs to one world is kept with it:

- the map (:class:`~hippo_agent.faculties.map.ExplorationMap`) and the path-integration frame it
  is drawn in: the place cells' centres in that frame;
- the goal memories: the reward cells (the reward maps written by replay) and homing's
  remembered places.

When the agent is put down, it takes a *glimpse*: its scans over its first ``glimpse_steps``
steps, with where odometry says each was taken. It asks which world the glimpse fits
(:meth:`Worlds.recognise`): the best, over the walkable places of each world's map, of the mean
fit of the glimpse's scans to that map seen from there and from the places the robot then moved
to (:meth:`ExplorationMap.scan_agreement`, every reading counted in full: a world one has not
seen leaves rays through walls or boundaries on free ground at every place). Offered a dry run
(:meth:`HippocampalAgent.dry_run`), a known world, this one or another, needs none: the agent
enters it and skips the dry run; an unknown one is a new world, with an empty map and a new frame.
In a run without a dry run, the agent moves to another known world only when that fits the
glimpse better than the current one by ``switch_margin`` (a world changed in places still fits
its own map better than any other).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from hippo_agent.faculties.homing import Homing
from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator
from hippo_agent.sections import Section, param

__all__ = ["Worlds", "WorldsConfig"]

# path integration's arrays that belong to a world (one row per place cell): the frame's centres
_CENTRES = ("centres", "centre_mass", "spread", "spread_mass")


@dataclass(frozen=True)
class WorldsConfig(Section):
    """Recognising worlds, and keeping each one's map and memories."""

    name: ClassVar[str] = "worlds"

    known_fit: float = param(0.75, ge=-1, le=1)
    """A world is recognised when its map fits the glimpse this well, at its best place (the
    mean fit of the glimpse's scans, in [-1, 1]; :meth:`ExplorationMap.scan_agreement`)."""
    glimpse_steps: int = param(5, ge=0)
    """The robot tells worlds apart by its scans of this many steps after it is put down (and
    the first): one scan may fit a corner of another world as well as its own. In a run, these
    steps are taken with the memories of the world it was last in, which may be the wrong one:
    a longer glimpse is a longer detour."""
    switch_margin: float = param(0.2, ge=0)
    """At a run's start, the agent moves to another known world only when that fits the scan
    better than the current one by this much."""
    most: int = param(16, ge=1)
    """Worlds kept at most; beyond, the one entered longest ago is forgotten."""


class Worlds:
    """The worlds the agent knows (module docstring).

    Args:
        config: its parameters.
        map_, pi, reward, homing: the parts whose state belongs to a world (``homing`` may be ``None``).
        max_range: the rangefinder's maximum range (m).
    """

    def __init__(
        self, config: WorldsConfig, map_: ExplorationMap, pi: PathIntegrator, model: Any, homing: Homing | None, max_range: float
    ) -> None:
        self.config = config
        self.map, self.pi, self.model, self.homing = map_, pi, model, homing
        self.max_range = max_range
        self.kept: list[dict[str, np.ndarray]] = []  # the worlds not entered now, each as its arrays
        self.names: list[int] = []  # each kept world's number (the order worlds were first met)
        self.current = 0  # the number of the world the agent is in
        self.count = 1  # worlds met so far
        self.last_fits: dict[int, float] = {}  # each world's best fit to the last glimpse (a record)
        self.glimpse: list[tuple[np.ndarray, float, np.ndarray]] = []  # scans since put down, and where from (odometry)
        self._scratch: ExplorationMap | None = None

    # ------------------------------------------------------------------ recognising
    def start_glimpse(self, ranges: np.ndarray, heading: float) -> None:
        """The robot was put down: the first scan of a glimpse."""
        self.glimpse = [(ranges.copy(), float(heading), np.zeros(2))]

    def add_to_glimpse(self, ranges: np.ndarray, heading: float, moved: np.ndarray) -> bool:
        """Another scan of the glimpse, ``moved`` metres (by odometry, compass frame) from the last;
        ``True`` once the glimpse holds ``glimpse_steps + 1`` scans."""
        self.glimpse.append((ranges.copy(), float(heading), self.glimpse[-1][2] + moved))
        return len(self.glimpse) > self.config.glimpse_steps

    def recognise(self) -> int | None:
        """The number of the known world whose map best fits the glimpse, if at least ``known_fit``
        (``None``: a new world). Leaves each world's fit in :attr:`last_fits`."""
        self.last_fits = {self.current: self._best_fit(self.map)}
        for name, arrays in zip(self.names, self.kept):
            self.last_fits[name] = self._best_fit(self._load_scratch(arrays))
        best = max(self.last_fits, key=lambda k: self.last_fits[k])
        return best if self.last_fits[best] >= self.config.known_fit else None

    def elsewhere(self) -> int | None:
        """At a run's start, once the glimpse is complete: another known world that fits it
        better than the current one by ``switch_margin`` (``None``: stay)."""
        if not self.kept:
            return None
        best = self.recognise()
        if best is not None and best != self.current and self.last_fits[best] > self.last_fits[self.current] + self.config.switch_margin:
            return best
        return None

    def _best_fit(self, map_: ExplorationMap) -> float:
        """The best, over the walkable places of ``map_``, of the mean fit of the glimpse's scans
        seen from that place and the places the robot then moved to."""
        points = map_.walkable_points()
        if points.shape[0] == 0:
            return -1.0
        total = np.zeros(points.shape[0])
        for ranges, heading, offset in self.glimpse:
            total += map_.scan_agreement(points + offset, heading, ranges, self.max_range)
        return float(total.max() / len(self.glimpse))

    def _load_scratch(self, arrays: dict[str, np.ndarray]) -> ExplorationMap:
        if self._scratch is None:
            self._scratch = ExplorationMap(self.map.config)
        self._scratch.load_state({}, {k[4:]: v for k, v in arrays.items() if k.startswith("map.")})
        return self._scratch

    # ------------------------------------------------------------------ moving between worlds
    def enter(self, name: int) -> None:
        """Enter the known world ``name``: the current one is kept, ``name``'s map and memories
        are put back."""
        if name == self.current:
            return
        index = self.names.index(name)
        arrays = self.kept.pop(index)
        self.names.pop(index)
        self._keep_current()
        self._put_back(arrays)
        self.current = name

    def new_world(self) -> None:
        """Enter a world never seen: the current one is kept; the map, the frame's centres and the
        goal memories start empty, and the next run sets a new frame."""
        self._keep_current()
        empty_map = ExplorationMap(self.map.config)
        self.map.load_state(*empty_map.state())
        for name in _CENTRES:
            getattr(self.pi, name)[:] = 0.0
        self.pi.frame_started = False
        self.pi.lose()
        reward = self.model.reward
        reward.W_rp = np.zeros((0, reward.n_place))
        reward.reset_effective()
        self.model.goal_rewarded = False
        if self.homing is not None:
            self.homing.clear_memory()
        self.current = self.count
        self.count += 1

    def _keep_current(self) -> None:
        if self.map.explored_area() == 0.0:
            return  # nothing learnt of it: nothing to keep
        self.kept.append(self._current_arrays())
        self.names.append(self.current)
        if len(self.kept) > self.config.most:
            self.kept.pop(0)
            self.names.pop(0)

    def _current_arrays(self) -> dict[str, np.ndarray]:
        arrays = {f"map.{k}": v.copy() for k, v in self.map.state()[1].items()}
        arrays.update({f"pi.{k}": getattr(self.pi, k).copy() for k in _CENTRES})
        arrays["reward.W_rp"] = self.model.reward.W_rp.copy()
        arrays["model.goal_rewarded"] = np.array(self.model.goal_rewarded)
        if self.homing is not None:
            arrays.update({f"homing.{name}": a for name, a in self.homing.memory().items()})
        return arrays

    def _put_back(self, arrays: dict[str, np.ndarray]) -> None:
        """A kept world's arrays into the live parts (rows for place cells recruited since it was
        kept start empty)."""
        n = self.pi.centres.shape[0]
        self.map.load_state({}, {k[4:]: v for k, v in arrays.items() if k.startswith("map.")})
        for name in _CENTRES:
            saved = arrays[f"pi.{name}"]
            value = np.zeros_like(getattr(self.pi, name))
            value[: saved.shape[0]] = saved
            setattr(self.pi, name, value)
        self.pi.frame_started = True
        self.pi.lose()
        W_rp = arrays["reward.W_rp"]
        reward = self.model.reward
        reward.W_rp = np.concatenate([W_rp, np.zeros((W_rp.shape[0], n - W_rp.shape[1]))], axis=1)
        reward.reset_effective()
        self.model.goal_rewarded = bool(arrays["model.goal_rewarded"])
        if self.homing is not None and "homing.found_sum" in arrays:
            self.homing.restore_memory({name[len("homing.") :]: a.copy() for name, a in arrays.items() if name.startswith("homing.")})

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        arrays = {f"{i}.{k}": v for i, world in enumerate(self.kept) for k, v in world.items()}
        if self.glimpse:
            arrays["glimpse.ranges"] = np.array([g[0] for g in self.glimpse])
            arrays["glimpse.headings"] = np.array([g[1] for g in self.glimpse])
            arrays["glimpse.offsets"] = np.array([g[2] for g in self.glimpse])
        return {"current": self.current, "count": self.count, "names": list(self.names)}, arrays

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        names = [int(k) for k in state["names"]]
        kept: list[dict[str, np.ndarray]] = [{} for _ in names]
        glimpse = {k: arrays.pop(k) for k in ("glimpse.ranges", "glimpse.headings", "glimpse.offsets") if k in arrays}
        self.glimpse = []
        if len(glimpse) == 3:
            self.glimpse = [
                (r, float(h), o) for r, h, o in zip(glimpse["glimpse.ranges"], glimpse["glimpse.headings"], glimpse["glimpse.offsets"])
            ]
        for key, value in arrays.items():
            index, _, name = key.partition(".")
            if not index.isdigit() or int(index) >= len(kept):
                raise ValueError(f"worlds: array {key!r} names no kept world (of {len(kept)})")
            kept[int(index)][name] = value
        for world in kept:
            if "map.free" not in world or "reward.W_rp" not in world:
                raise ValueError("worlds: a kept world's map or reward weights are missing")
        self.kept, self.names = kept, names
        self.current, self.count = int(state["current"]), int(state["count"])
