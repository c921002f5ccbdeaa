"""The shipped reference results: what ``hippomaze bench`` sets the user's agent beside.

One JSON file per variant in ``hippomaze/bench/reference_results/`` (package data, in the wheel), each a
:class:`~hippomaze.bench.summary.VariantResult` with ``made``: the command that wrote it, when,
and, per job record it was made from, the command, date, package versions and code fingerprint of
the run (or, for records older than that bookkeeping, what is known of them). They are regenerated from a
checkout with::

    python -m benchmarks.sample_efficiency --out benchmarks/results --write-references

which reuses the job records in ``benchmarks/results/sample_efficiency/`` that are still current
(:func:`hippomaze.bench.jobs.reusable`) and runs the others.
"""

from __future__ import annotations

import importlib.resources
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hippomaze.bench.summary import VariantResult

#: The variants shipped as references, in the order tables and figures show them.
REFERENCE_VARIANTS: tuple[str, ...] = ("hippo", "hippo-paper", "dqn", "ppo", "random")
#: The ``format`` key of a reference file.
FORMAT = "hippomaze.bench.reference/1"
#: The reference file of the changing-world measures (``hippomaze bench --changing-world``): not a variant.
CHANGING_WORLD = "changing_world"


@dataclass
class Reference:
    """A shipped reference: the variant's result and how it was made."""

    result: VariantResult
    made: dict[str, Any]


def folder() -> Path:
    """The package folder holding the reference files."""
    return Path(str(importlib.resources.files("hippomaze.bench.reference_results")))


def available() -> list[str]:
    """The variants with a shipped reference, in :data:`REFERENCE_VARIANTS` order."""
    present = {p.stem for p in folder().glob("*.json")} - {CHANGING_WORLD}
    return [v for v in REFERENCE_VARIANTS if v in present] + sorted(present - set(REFERENCE_VARIANTS))


def load_references(names: list[str] | tuple[str, ...] | None = None) -> dict[str, Reference]:
    """The shipped references ``names`` (default: all of them), by variant.

    Raises:
        ValueError: a name with no reference (the message lists those shipped).
    """
    shipped = available()
    names = shipped if names is None else list(names)
    unknown = [n for n in names if n not in shipped]
    if unknown:
        raise ValueError(f"no shipped reference for {', '.join(map(repr, unknown))}; references: {', '.join(shipped) or 'none'}")
    out = {}
    for name in names:
        data = json.loads((folder() / f"{name}.json").read_text())
        if data.get("format") != FORMAT:
            raise ValueError(f"reference file {name}.json has format {data.get('format')!r}; expected {FORMAT!r}")
        out[name] = Reference(VariantResult.from_dict(data["result"]), data["made"])
    return out


def reference_document(result: VariantResult, made: dict[str, Any]) -> dict[str, Any]:
    """What a reference file holds."""
    return {"format": FORMAT, "variant": result.variant, "made": made, "result": result.to_dict()}
