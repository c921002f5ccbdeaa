"""The project's targets, read from ``benchmarks/targets.toml`` (their one home).

The README's results table (:mod:`benchmarks.readme_table`), the documentation's tables
(``docs/hooks.py``) and the benchmarks compare measurements with these; none of them types a
target in. ::

    from benchmarks.targets import target

    speed = target("agent_vs_ratinabox")
    speed.met(43.1), speed.text()          # True, '>= 40x'
    target("indirectness").bound("maze2")  # 0.7
"""

from __future__ import annotations

import functools
import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: The targets file.
TARGETS_FILE = Path(__file__).resolve().with_name("targets.toml")
#: The bounds a target may have, and the comparison each stands for.
BOUNDS = {"at_least": ">=", "at_most": "<=", "below": "<"}
#: A generated maze's name in the maze suite (``benchmarks.maze_suite.generated_name``): kind, maze seed, and the
#: arena's side in metres when it is not 10.
GENERATED_NAME = re.compile(r"^gen-(?P<kind>[a-z]+)-(?P<seed>\d+)(?:-(?P<size>\d+)m)?$")


def generated_maze(name: str) -> tuple[str, float] | None:
    """A generated maze's kind and arena side (m) from its suite name; None for any other maze."""
    match = GENERATED_NAME.match(name)
    return None if match is None else (match["kind"], float(match["size"] or 10))


@dataclass(frozen=True)
class Target:
    """One target: what is measured (``what``), the comparison (``>=``, ``<=`` or ``<``), and its
    bound: one number, or one per maze (:meth:`bound`). ``extra``: the file's other keys
    (``place_cells``, ...)."""

    name: str
    what: str
    op: str
    limits: float | dict[str, float]
    extra: dict[str, Any]

    def bound(self, maze: str | None = None) -> float | None:
        """The bound, or for a per-maze target the bound of ``maze``: by its name, then its kind and
        size (``gen-perfect-10m``), then ``generated`` for any generated maze; None if none applies."""
        if not isinstance(self.limits, dict):
            return self.limits
        if maze is None:
            raise ValueError(f"target {self.name!r} has a bound per maze ({', '.join(self.limits)}): name the maze")
        if maze in self.limits:
            return self.limits[maze]
        generated = generated_maze(maze)
        if generated is None:
            return None
        kind, size = generated
        return self.limits.get(f"gen-{kind}-{size:g}m", self.limits.get("generated"))

    def met(self, value: float | None, maze: str | None = None) -> bool | None:
        """Whether ``value`` meets the target (None when there is no value or no bound for ``maze``)."""
        bound = self.bound(maze)
        if value is None or bound is None or (isinstance(value, float) and math.isnan(value)):
            return None
        return {">=": value >= bound, "<=": value <= bound, "<": value < bound}[self.op]

    def text(self, maze: str | None = None, unit: str = "") -> str:
        """The target as the tables print it: ``>= 40x``, ``< 500 MB``, ``-`` where no bound applies."""
        bound = self.bound(maze)
        return "-" if bound is None else f"{self.op} {shown(bound)}{unit}"

    def __getitem__(self, key: str) -> Any:
        return self.extra[key]


@functools.cache
def targets(path: Path = TARGETS_FILE) -> dict[str, Target]:
    """Every target in the file, by name (read once per process).

    Raises:
        ValueError: a target without a one-line ``what``, or without exactly one bound.
    """
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    out = {}
    for name, entry in data.items():
        bounds = [key for key in BOUNDS if key in entry]
        what = entry.get("what")
        if not isinstance(what, str) or not what or "\n" in what or len(bounds) != 1:
            raise ValueError(
                f"{path}: target {name!r} needs a one-line 'what' and exactly one of {', '.join(BOUNDS)}; it has {', '.join(entry) or 'nothing'}"
            )
        extra = {k: v for k, v in entry.items() if k not in ("what", bounds[0])}
        out[name] = Target(name, what, BOUNDS[bounds[0]], entry[bounds[0]], extra)
    return out


def target(name: str) -> Target:
    """The target ``name`` (a ValueError naming the known ones if there is none)."""
    known = targets()
    if name not in known:
        raise ValueError(f"no target {name!r} in {TARGETS_FILE.name}; targets: {', '.join(known)}")
    return known[name]


def shown(bound: float) -> str:
    """A bound as the tables print it: ``0.3``, ``1.5``, ``2,500``."""
    return f"{bound:,.0f}" if bound >= 100 else f"{bound:g}"


def verdict(met: bool | None) -> str:
    """``met``, ``**missed**`` or ``not measured``, as the tables print a verdict."""
    return "not measured" if met is None else ("met" if met else "**missed**")
