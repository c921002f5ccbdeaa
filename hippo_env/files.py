"""Writing result files safely: a reader (or a crash, or Ctrl-C) never sees half a file.

Every JSON record the package and its benchmarks write (``dmtp.json``, ``summary.json``, the
sample-efficiency and paper records) goes through :func:`atomic_write`: the bytes go to a
temporary file in the same folder, which then replaces the target in one ``os.replace``.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any


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


__all__ = ["atomic_write", "write_json"]
