"""Writing result files safely: a reader (or a crash, or Ctrl-C) never sees half a file.

Every JSON record the package and its benchmarks write (``dmtp.json``, ``summary.json``, the
sample-efficiency and paper records) goes through :func:`atomic_write`: the bytes go to a
temporary file in the same folder, which then replaces the target in one ``os.replace``.
NaN and infinity are not JSON: :func:`jsonable` writes them as null. :func:`unknown_fields`
is the one check of a record's (or an override's) keys against a dataclass's fields.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np


def atomic_write(path: str | Path, data: str | bytes) -> Path:
    """Write ``data`` (text as UTF-8, or bytes) to ``path`` atomically; return the path.

    The folder must exist. On any error the target is left as it was and the temporary file removed.
    """
    target = Path(path)
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(payload)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target


def write_json(path: str | Path, record: Any, indent: int | None = 1) -> Path:
    """Write ``record`` as JSON (with a final newline) to ``path`` atomically."""
    return atomic_write(path, json.dumps(record, indent=indent) + "\n")


def finite_or_none(value: float) -> float | None:
    """``value``, or None (JSON null) when it is NaN or infinite."""
    return None if not math.isfinite(value) else value


def jsonable(value: Any) -> Any:
    """``value`` as plain JSON types: NumPy scalars and arrays to Python ones, tuples to lists,
    dict keys to strings, and NaN or infinity to None (null)."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        return finite_or_none(float(value))
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def unknown_fields(cls: type, names: Iterable[str]) -> list[str]:
    """The ``names`` that are not fields of the dataclass ``cls``, sorted (empty when all are)."""
    known = {f.name for f in dataclasses.fields(cls)}
    return sorted(set(names) - known)


__all__ = ["atomic_write", "finite_or_none", "jsonable", "unknown_fields", "write_json"]
