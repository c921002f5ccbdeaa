"""The positions of the current run, in bounded memory."""

from __future__ import annotations

import numpy as np

from hippo_env.checks import check_int

_FIRST_CAPACITY = 1024


class PathRecord:
    """Positions since the last reset, in a float array that keeps at most the latest ``limit``.

    Grows by doubling up to ``limit`` rows, then overwrites the oldest (a ring buffer), so a run
    of any length holds at most ``limit`` positions (16 bytes each). ``limit=None`` keeps all.

    Args:
        limit: The most positions kept, or None for no bound.
    """

    def __init__(self, limit: int | None) -> None:
        if limit is not None:
            check_int(limit, "path_limit", 1, "a positive integer (positions kept per run) or None (keep all)")
        self.limit = None if limit is None else int(limit)
        self._data = np.empty((0, 2))
        self._count = 0  # rows in use
        self._oldest = 0  # row of the oldest position once the ring is full
        self.total = 0  # positions appended since the last reset, kept or not

    def reset(self, start: tuple[float, float]) -> None:
        """Begin a new run at ``start``."""
        capacity = _FIRST_CAPACITY if self.limit is None else min(_FIRST_CAPACITY, self.limit)
        if len(self._data) != capacity:
            self._data = np.empty((capacity, 2))
        self._count = self._oldest = self.total = 0
        self.append(start)

    def append(self, point: tuple[float, float]) -> None:
        """Record the next position (dropping the oldest once ``limit`` are kept)."""
        self.total += 1
        x, y = point
        if self.limit is not None and self._count == self.limit:
            self._data[self._oldest, 0] = x
            self._data[self._oldest, 1] = y
            self._oldest = (self._oldest + 1) % self.limit
            return
        if self._count == len(self._data):
            grown = max(2 * len(self._data), _FIRST_CAPACITY)
            if self.limit is not None:
                grown = min(grown, self.limit)
            self._data = np.concatenate([self._data, np.empty((grown - len(self._data), 2))])
        self._data[self._count, 0] = x  # two scalar writes: cheaper than converting a tuple to a row
        self._data[self._count, 1] = y
        self._count += 1

    def __len__(self) -> int:
        return self._count

    def __getitem__(self, index: int) -> tuple[float, float]:
        """The ``index``-th kept position, oldest first (negative indices count from the latest)."""
        if not -self._count <= index < self._count:
            raise IndexError(f"path index {index} out of range for {self._count} positions")
        row = (self._oldest + index) % self._count
        return float(self._data[row, 0]), float(self._data[row, 1])

    def array(self) -> np.ndarray:
        """The kept positions, oldest first, as a new (n, 2) float array."""
        if self._oldest == 0:
            return self._data[: self._count].copy()
        return np.concatenate([self._data[self._oldest : self._count], self._data[: self._oldest]])
