"""Maze specifications: the arena, its obstacles, JSON loading and validation, free space.

A maze is a rectangle ``size = (width, height)`` in metres centred on the origin, holding zero or
more obstacles, each a simple polygon. A :class:`MazeSpec` answers what the environment asks of
a maze: the wall segments (for physics and the rangefinder), the clearance of a point from the
walls, sampling free positions, whether the free space is connected, and the shortest path
around the obstacles (computed by :mod:`hippo_env.geodesic`, on the primitives of
:mod:`hippo_env.geometry`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from hippo_env.geodesic import DistanceField, VisibilityGraph
from hippo_env.geometry import (
    CHUNK,
    Point,
    clear_of_segments,
    point_in_polygon,
    points_in_polygon,
    segments_clearance,
    segments_intersect,
    signed_area,
)

BUILTIN_MAZES = ("open", "maze1", "maze2", "maze3", "maze4")

#: The largest arena side, in metres. The connectivity check rasterises the free space at 5 cm,
#: so its cost grows with the arena's area; this bound keeps it under a second and ~100 MB.
MAX_SIZE = 100.0
#: The grid on which :meth:`MazeSpec.check_connected` finds the free space's parts (metres).
CONNECTIVITY_RESOLUTION = 0.05


def _builtin_names() -> str:
    return ", ".join(BUILTIN_MAZES)


@dataclass(frozen=True)
class MazeSpec:
    """An arena with obstacles, in metres, origin at the arena centre.

    Args:
        name: A short name, used in records and figures.
        size: ``(width, height)`` of the arena; its walls are at ``x = +-width/2``, ``y = +-height/2``.
        obstacles: Simple polygons, each a sequence of ``(x, y)`` vertices (either orientation,
            not repeating the first vertex at the end).
        goal: An optional default goal centre ``(x, y)``; without one the environment draws goals.
    """

    name: str
    size: tuple[float, float]
    obstacles: tuple[tuple[tuple[float, float], ...], ...] = ()
    goal: tuple[float, float] | None = None
    _segments: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise TypeError(f"maze 'name' must be a non-empty string, got {self.name!r}")
        if not self.name:
            raise ValueError(f"maze 'name' must be a non-empty string, got {self.name!r}")
        size = _as_point(self.size, f"maze {self.name!r}: 'size'")
        if size[0] <= 0 or size[1] <= 0:
            raise ValueError(f"maze {self.name!r}: 'size' must be two positive numbers [width, height], got {list(size)}")
        if max(size) > MAX_SIZE:
            raise ValueError(
                f"maze {self.name!r}: 'size' {list(size)} is too large; width and height may be at most {MAX_SIZE:g} m (hippo_env.maze.MAX_SIZE)"
            )
        object.__setattr__(self, "size", size)
        polygons = []
        if isinstance(self.obstacles, (str, bytes)) or not hasattr(self.obstacles, "__iter__"):
            raise TypeError(f"maze {self.name!r}: 'obstacles' must be a list of polygons, got {self.obstacles!r}")
        for n, polygon in enumerate(self.obstacles):
            where = f"maze {self.name!r}: obstacle {n}"
            if isinstance(polygon, (str, bytes)) or not hasattr(polygon, "__iter__"):
                raise TypeError(f"{where} must be a list of [x, y] vertices, got {polygon!r}")
            vertices = tuple(_as_point(p, f"{where}, vertex {k}") for k, p in enumerate(polygon))
            if len(vertices) < 3:
                raise ValueError(f"{where} has {len(vertices)} vertices; a polygon needs at least 3")
            _check_simple_polygon(vertices, where)
            half_w, half_h = size[0] / 2, size[1] / 2
            for k, (x, y) in enumerate(vertices):
                if abs(x) > half_w or abs(y) > half_h:
                    raise ValueError(
                        f"{where}, vertex {k} ({x}, {y}) lies outside the arena; vertices must satisfy |x| <= {half_w} and |y| <= {half_h}"
                    )
            polygons.append(vertices)
        object.__setattr__(self, "obstacles", tuple(polygons))
        if self.goal is not None:
            object.__setattr__(self, "goal", _as_point(self.goal, f"maze {self.name!r}: 'goal'"))
        object.__setattr__(self, "_segments", self._build_segments())

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_dict(cls, data: Any, source: str = "maze") -> MazeSpec:
        """Build a spec from the JSON structure ``{"name", "size", "obstacles", ["goal"]}``.

        A field of the wrong type raises ``TypeError`` (:meth:`load`, which reads a document,
        raises ``ValueError`` for anything wrong in it)."""
        if not isinstance(data, dict):
            raise TypeError(f"{source}: a maze must be a JSON object with keys name, size, obstacles, got {type(data).__name__}")
        allowed = {"name", "size", "obstacles", "goal"}
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ValueError(f"{source}: unknown key(s) {unknown}; allowed keys: {sorted(allowed)}")
        for key in ("name", "size", "obstacles"):
            if key not in data:
                raise ValueError(f"{source}: missing key {key!r}; a maze needs 'name', 'size' and 'obstacles' (and may give 'goal')")
        return cls(name=data["name"], size=data["size"], obstacles=data["obstacles"], goal=data.get("goal"))

    @classmethod
    def load(cls, maze: str | Path | MazeSpec) -> MazeSpec:
        """A built-in name (``open``, ``maze1`` ... ``maze4``), a path to a JSON file, or a spec."""
        if isinstance(maze, MazeSpec):
            return maze
        if not isinstance(maze, (str, Path)):
            raise TypeError(
                f"maze must be a built-in name ({_builtin_names()}), a path to a JSON file or a MazeSpec, got {type(maze).__name__}"
            )
        if isinstance(maze, str) and maze in BUILTIN_MAZES:
            text = resources.files("hippo_env.mazes").joinpath(f"{maze}.json").read_text()
            return cls._from_document(json.loads(text), source=f"built-in maze {maze!r}")
        path = Path(maze)
        if path.suffix.lower() != ".json" and not path.exists():
            raise ValueError(f"maze {str(maze)!r} is unknown; built-in mazes: {_builtin_names()}, or give a path to a JSON file")
        try:
            text = path.read_text()
        except OSError as err:
            raise ValueError(
                f"maze file {str(path)!r} cannot be read ({err.strerror or err}); give a readable JSON file or one of: {_builtin_names()}"
            ) from err
        try:
            data = json.loads(text)
        except json.JSONDecodeError as err:
            raise ValueError(f"maze file {str(path)!r} is not valid JSON: {err}") from err
        return cls._from_document(data, source=f"maze file {str(path)!r}")

    @classmethod
    def _from_document(cls, data: Any, source: str) -> MazeSpec:
        """:meth:`from_dict` for the content of a file: whatever is wrong in it is a ``ValueError``."""
        try:
            return cls.from_dict(data, source=source)
        except TypeError as err:
            raise ValueError(str(err)) from err

    def to_dict(self) -> dict[str, Any]:
        data: dict[str, Any] = {
            "name": self.name,
            "size": list(self.size),
            "obstacles": [[list(p) for p in poly] for poly in self.obstacles],
        }
        if self.goal is not None:
            data["goal"] = list(self.goal)
        return data

    # ------------------------------------------------------------------ geometry
    @property
    def half_extent(self) -> tuple[float, float]:
        return self.size[0] / 2, self.size[1] / 2

    @property
    def segments(self) -> np.ndarray:
        """Every wall as a segment ``(x0, y0, x1, y1)``: the four arena walls, then obstacle edges."""
        return self._segments

    def _build_segments(self) -> np.ndarray:
        hw, hh = self.half_extent
        rows = [(-hw, -hh, hw, -hh), (hw, -hh, hw, hh), (hw, hh, -hw, hh), (-hw, hh, -hw, -hh)]
        for poly in self.obstacles:
            for a, b in zip(poly, poly[1:] + poly[:1]):
                rows.append((a[0], a[1], b[0], b[1]))
        return np.asarray(rows, dtype=np.float64)

    def inside_obstacle(self, point: Point) -> bool:
        """Whether a point lies inside (or on the boundary of) any obstacle polygon."""
        x, y = float(point[0]), float(point[1])
        return any(point_in_polygon(x, y, poly) for poly in self.obstacles)

    def clearance(self, point: Point) -> float:
        """Distance from a point to the nearest wall; negative inside an obstacle or outside the arena."""
        return float(self.clearances([point])[0])

    def clearances(self, points: Any) -> np.ndarray:
        """:meth:`clearance` of each of ``points`` (``(k, 2)``), the inside tests vectorised over the points."""
        xy = np.asarray(points, float).reshape(-1, 2)
        distance = np.array([segments_clearance(float(x), float(y), self._segments) for x, y in xy], dtype=np.float64)
        hw, hh = self.half_extent
        outside = (np.abs(xy[:, 0]) > hw) | (np.abs(xy[:, 1]) > hh)
        for poly in self.obstacles:
            outside |= points_in_polygon(xy, poly)
        return np.where(outside, -distance, distance)

    def is_free(self, point: Point, radius: float) -> bool:
        """Whether a disc of ``radius`` centred at ``point`` fits without touching any wall."""
        return self.clearance(point) >= radius

    def free_mask(self, points: np.ndarray, radius: float) -> np.ndarray:
        """Whether a disc of ``radius`` fits at each of ``points`` (``(k, 2)``): :meth:`is_free` point by point."""
        return self.clearances(points) >= radius

    def sample_free(
        self,
        rng: np.random.Generator,
        clearance: float,
        away_from: Point | None = None,
        min_distance: float = 0.0,
        tries: int = 10_000,
    ) -> np.ndarray:
        """A uniform random point at least ``clearance`` from every wall (and ``min_distance`` from ``away_from``)."""
        hw, hh = self.half_extent
        for _ in range(tries):
            point = rng.uniform((-hw + clearance, -hh + clearance), (hw - clearance, hh - clearance))
            if away_from is not None and math.dist(point, away_from) < min_distance:
                continue
            if self.clearance(point) >= clearance:
                return point
        raise ValueError(
            f"maze {self.name!r}: found no free point with clearance {clearance} m (and {min_distance} m from {away_from}) in {tries} tries"
        )

    # ------------------------------------------------------------------ connectivity and geodesics
    def check_connected(self, radius: float, resolution: float = CONNECTIVITY_RESOLUTION) -> None:
        """Raise ValueError when the free space of a disc of ``radius`` falls into several parts.

        The free space is rasterised at ``resolution``; work and memory grow with the arena's
        area (at most ``MAX_SIZE`` squared), not with the number of walls times the area.
        """
        labels, n = self._free_components(radius, resolution)
        if n == 0:
            raise ValueError(f"maze {self.name!r} has no free space for a robot of radius {radius} m")
        if n > 1:
            areas = np.bincount(labels[labels > 0].ravel())[1:] * resolution**2
            raise ValueError(
                f"maze {self.name!r}: the free space is split into {n} parts that cannot reach each other "
                f"(areas {', '.join(f'{a:.2f}' for a in sorted(areas, reverse=True))} m^2) for a robot of radius {radius} m; "
                "leave gaps of at least the robot's diameter between obstacles"
            )

    def free_grid(self, radius: float, resolution: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cell centres ``xs``, ``ys`` over the arena and ``free[row, col]``: whether a disc of ``radius`` fits there.

        The same test as :meth:`free_mask`, point for point, but each wall only visits the cells
        within ``radius`` of it and each obstacle the cells of its bounding box, so the cost is the
        grid itself plus the walls' surroundings: fast enough for a ``MAX_SIZE`` arena.
        """
        hw, hh = self.half_extent
        xs = np.arange(-hw + resolution / 2, hw - 1e-9, resolution)
        ys = np.arange(-hh + resolution / 2, hh - 1e-9, resolution)
        free = np.ones((len(ys), len(xs)), dtype=bool)
        clear_of_segments(free, xs, ys, self._segments, float(radius))
        for poly in self.obstacles:
            pts = np.asarray(poly)
            cols = slice(np.searchsorted(xs, pts[:, 0].min()), np.searchsorted(xs, pts[:, 0].max(), side="right"))
            rows = slice(np.searchsorted(ys, pts[:, 1].min()), np.searchsorted(ys, pts[:, 1].max(), side="right"))
            for block_rows, points in _blocks(xs[cols], ys[rows], rows.start):
                free[block_rows, cols] &= ~points_in_polygon(points, poly).reshape(-1, len(xs[cols]))
        return xs, ys, free

    def distance_field(self, goal: np.ndarray, radius: float, resolution: float) -> DistanceField:
        """Geodesic distances to ``goal`` for a disc of ``radius`` over the :meth:`free_grid` at ``resolution``."""
        xs, ys, free = self.free_grid(radius, resolution)
        return DistanceField.from_grid(xs, ys, free, -np.asarray(self.half_extent, float), resolution, np.asarray(goal, float))

    def _free_components(self, radius: float, resolution: float) -> tuple[np.ndarray, int]:
        _, _, free = self.free_grid(radius, resolution)
        labels, n = _label(free)
        if n > 1:
            # Ignore specks smaller than the robot itself: rasterisation artefacts, not rooms.
            counts = np.bincount(labels.ravel())
            keep = [k for k in range(1, n + 1) if counts[k] * resolution**2 >= math.pi * radius**2]
            relabel = np.zeros(n + 1, dtype=labels.dtype)
            relabel[keep] = np.arange(1, len(keep) + 1)
            labels, n = relabel[labels], len(keep)
        return labels, n

    def geodesic(self, start: Point, goal: Point, radius: float) -> float:
        """Shortest path length for a disc of ``radius`` from ``start`` to ``goal`` around the obstacles.

        The obstacles are inflated by ``radius``; the path is found on a
        :class:`~hippo_env.geodesic.VisibilityGraph` (built once per radius). In an open arena it is
        the straight line.
        """
        return self._visibility_graph(radius).length(start, goal)

    def _visibility_graph(self, radius: float) -> VisibilityGraph:
        """The visibility graph for a disc of ``radius``, built once per radius."""
        cache = self.__dict__.setdefault("_graph_cache", {})
        if radius not in cache:
            cache[radius] = VisibilityGraph(self, radius)
        return cache[radius]


# ---------------------------------------------------------------------- helpers
def _as_point(value: Any, where: str) -> tuple[float, float]:
    try:
        x, y = value
        point = (float(x), float(y))
    except (TypeError, ValueError):
        raise ValueError(f"{where} must be a pair of numbers [x, y], got {value!r}") from None
    if isinstance(x, (bool, str)) or isinstance(y, (bool, str)) or not all(map(math.isfinite, point)):
        raise ValueError(f"{where} must be a pair of finite numbers [x, y], got {value!r}")
    return point


def _check_simple_polygon(vertices: tuple[tuple[float, float], ...], where: str) -> None:
    pts = np.asarray(vertices, float)
    n = len(pts)
    for i in range(n):  # before the crossing test, which would report a repeated vertex as crossing edges
        if np.allclose(pts[i], pts[(i + 1) % n]):
            raise ValueError(f"{where} repeats vertex {i}; list each vertex once (the polygon closes itself)")
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        for j in range(i + 1, n):
            if j == i or (j + 1) % n == i or j == (i + 1) % n:
                continue  # neighbouring edges share a vertex
            c, d = pts[j], pts[(j + 1) % n]
            if segments_intersect(a, b, c, d):
                raise ValueError(f"{where} is self-intersecting (edges {i} and {j} cross); obstacles must be simple polygons")
    if abs(signed_area(pts)) < 1e-9:
        raise ValueError(f"{where} has zero area; give the polygon's outline, at least 3 non-collinear vertices")


def _blocks(xs: np.ndarray, ys: np.ndarray, first_row: int) -> Iterator[tuple[slice, np.ndarray]]:
    """The grid points (xs x ys) in blocks of whole rows, at most ``CHUNK`` points each: (row slice, (k, 2) points)."""
    if len(xs) == 0 or len(ys) == 0:
        return
    step = max(1, CHUNK // len(xs))
    for start in range(0, len(ys), step):
        gx, gy = np.meshgrid(xs, ys[start : start + step])
        yield slice(first_row + start, first_row + start + gx.shape[0]), np.stack([gx.ravel(), gy.ravel()], axis=1)


def _label(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """4-connected component labelling of a boolean grid, numbered in row-major order of first cells."""
    return _label_compiled(np.ascontiguousarray(mask, dtype=np.bool_))


@njit(cache=True)
def _label_compiled(mask: np.ndarray) -> tuple[np.ndarray, int]:  # pragma: no cover - compiled
    rows, cols = mask.shape
    labels = np.zeros((rows, cols), dtype=np.int32)
    stack = np.empty(rows * cols, dtype=np.int32)
    n = 0
    for r0 in range(rows):
        for c0 in range(cols):
            if not mask[r0, c0] or labels[r0, c0] != 0:
                continue
            n += 1
            labels[r0, c0] = n
            stack[0] = r0 * cols + c0
            top = 1
            while top > 0:
                top -= 1
                r = stack[top] // cols
                c = stack[top] % cols
                for rr, cc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
                    if 0 <= rr < rows and 0 <= cc < cols and mask[rr, cc] and labels[rr, cc] == 0:
                        labels[rr, cc] = n
                        stack[top] = rr * cols + cc
                        top += 1
    return labels, n
