"""How numbers are shown in the claims table, the figures' titles and the report."""

from __future__ import annotations

import math
from typing import Any


def fmt(x: Any, digits: int = 2, pct: bool = False) -> str:
    """``x`` with ``digits`` decimals, or as a whole percentage; ``n/a`` for None and non-finite values."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{100 * x:.0f} %" if pct else f"{x:.{digits}f}"
