"""Maze specifications: the arena, its obstacles, JSON loading and validation, free space, geodesics.

A maze is a rectangle ``size = (width, height)`` in metres centred on the origin, holding zero or
more obstacles, each a simple polygon. Everything the environment needs to know about geometry
lives here: the wall segments (for physics and the rangefinder), the clearance of a point from
the walls, sampling free positions, and the shortest path around obstacles inflated by the robot's
radius (a visibility graph over points placed around every convex corner, then Dijkstra).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from hippo_env.geometry import DistanceField, clear_of_segments, segments_clearance

BUILTIN_MAZES = ("open", "maze1", "maze2", "maze3", "maze4")

# Points placed around each convex corner of an inflated obstacle: an arc every 15 degrees
# keeps the polygonal path within 2 mm of the true rounded one for a 0.17 m robot.
_ARC_STEP = math.radians(15.0)
# Visibility segments may graze an inflated obstacle by this much (chords of those arcs).
_GRAZE = 3e-3
#: The largest arena side, in metres. The connectivity check rasterises the free space at 5 cm,
#: so its cost grows with the arena's area; this bound keeps it under a second and ~100 MB.
MAX_SIZE = 100.0
#: The grid on which :meth:`MazeSpec.check_connected` finds the free space's parts (metres).
CONNECTIVITY_RESOLUTION = 0.05
# Work on at most this many (point, segment) or (pair, wall) combinations at once.
_CHUNK = 1 << 18


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
        if not isinstance(self.name, str) or not self.name:
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
            raise ValueError(f"maze {self.name!r}: 'obstacles' must be a list of polygons, got {self.obstacles!r}")
        for n, polygon in enumerate(self.obstacles):
            where = f"maze {self.name!r}: obstacle {n}"
            if isinstance(polygon, (str, bytes)) or not hasattr(polygon, "__iter__"):
                raise ValueError(f"{where} must be a list of [x, y] vertices, got {polygon!r}")
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
        """Build a spec from the JSON structure ``{"name", "size", "obstacles", ["goal"]}``."""
        if not isinstance(data, dict):
            raise ValueError(f"{source}: a maze must be a JSON object with keys name, size, obstacles, got {type(data).__name__}")
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
            raise ValueError(
                f"maze must be a built-in name ({_builtin_names()}), a path to a JSON file or a MazeSpec, got {type(maze).__name__}"
            )
        if isinstance(maze, str) and maze in BUILTIN_MAZES:
            text = resources.files("hippo_env.mazes").joinpath(f"{maze}.json").read_text()
            return cls.from_dict(json.loads(text), source=f"built-in maze {maze!r}")
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
        return cls.from_dict(data, source=f"maze file {str(path)!r}")

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

    def inside_obstacle(self, point: tuple[float, float] | np.ndarray) -> bool:
        """Whether a point lies inside (or on the boundary of) any obstacle polygon."""
        x, y = float(point[0]), float(point[1])
        return any(_point_in_polygon(x, y, poly) for poly in self.obstacles)

    def clearance(self, point: tuple[float, float] | np.ndarray) -> float:
        """Distance from a point to the nearest wall; negative inside an obstacle or outside the arena."""
        return float(self.clearances([point])[0])

    def clearances(self, points: Any) -> np.ndarray:
        """:meth:`clearance` of each of ``points`` (``(k, 2)``), the inside tests vectorised over the points."""
        xy = np.asarray(points, float).reshape(-1, 2)
        distance = np.array([segments_clearance(float(x), float(y), self._segments) for x, y in xy], dtype=np.float64)
        hw, hh = self.half_extent
        outside = (np.abs(xy[:, 0]) > hw) | (np.abs(xy[:, 1]) > hh)
        for poly in self.obstacles:
            outside |= _points_in_polygon(xy, poly)
        return np.where(outside, -distance, distance)

    def is_free(self, point: tuple[float, float] | np.ndarray, radius: float) -> bool:
        """Whether a disc of ``radius`` centred at ``point`` fits without touching any wall."""
        return self.clearance(point) >= radius

    def free_mask(self, points: np.ndarray, radius: float) -> np.ndarray:
        """Whether a disc of ``radius`` fits at each of ``points`` (``(k, 2)``): :meth:`is_free` point by point."""
        return self.clearances(points) >= radius

    def sample_free(
        self,
        rng: np.random.Generator,
        clearance: float,
        away_from: tuple[float, float] | None = None,
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
                free[block_rows, cols] &= ~_points_in_polygon(points, poly).reshape(-1, len(xs[cols]))
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

    def geodesic(self, start: tuple[float, float], goal: tuple[float, float], radius: float) -> float:
        """Shortest path length for a disc of ``radius`` from ``start`` to ``goal`` around the obstacles.

        The obstacles are inflated by ``radius``; the path is found on a visibility graph over
        points placed around every convex obstacle corner (built once per radius), then Dijkstra.
        In an open arena it is the straight line.
        """
        nodes, between = self._corner_graph(radius)
        ends = np.asarray([start, goal], dtype=float)
        points = np.concatenate([ends, nodes])
        n = len(points)
        lengths = np.full((n, n), np.inf)
        lengths[2:, 2:] = between
        # Edges from the two end points to everything else.
        pairs_a = np.repeat(ends, n, axis=0)
        pairs_b = np.tile(points, (2, 1))
        seen = _visible_many(pairs_a, pairs_b, self._segments[4:], radius - _GRAZE).reshape(2, n)
        direct = np.linalg.norm(pairs_a - pairs_b, axis=1).reshape(2, n)
        lengths[:2] = np.where(seen, direct, np.inf)
        lengths[:, :2] = lengths[:2].T
        return _dijkstra(lengths, 0, 1)

    def _corner_graph(self, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Nodes around the inflated obstacles' corners and the lengths of the visible edges between them."""
        cache = self.__dict__.setdefault("_graph_cache", {})
        if radius not in cache:
            nodes = np.asarray(self._corner_nodes(radius)).reshape(-1, 2)
            k = len(nodes)
            a = np.repeat(nodes, k, axis=0)
            b = np.tile(nodes, (k, 1))
            seen = _visible_many(a, b, self._segments[4:], radius - _GRAZE).reshape(k, k)
            between = np.where(seen, np.linalg.norm(a - b, axis=1).reshape(k, k), np.inf)
            cache[radius] = (nodes, between)
        return cache[radius]

    def _corner_nodes(self, radius: float) -> list[np.ndarray]:
        """Points on an arc of ``radius`` around every convex corner, those clear of every wall (by 3 mm grace)."""
        candidates = []
        margin = radius * (1 + 1e-6)
        for poly in self.obstacles:
            pts = np.asarray(poly, float)
            orientation = 1.0 if _signed_area(pts) > 0 else -1.0
            for k in range(len(pts)):
                prev_pt, corner, next_pt = pts[k - 1], pts[k], pts[(k + 1) % len(pts)]
                d_in, d_out = corner - prev_pt, next_pt - corner
                turn = orientation * (d_in[0] * d_out[1] - d_in[1] * d_out[0])
                if turn <= 0:  # a reflex (concave) corner: shortest paths never bend there
                    continue
                # Outward normals of the two edges meeting at the corner; place points on the arc between them.
                n_in = orientation * np.array([d_in[1], -d_in[0]]) / np.linalg.norm(d_in)
                n_out = orientation * np.array([d_out[1], -d_out[0]]) / np.linalg.norm(d_out)
                # The arc turns the way the polygon turns at a convex corner: counter-clockwise for a
                # counter-clockwise polygon, clockwise for a clockwise one, the short way round in
                # both cases. (A counter-clockwise sweep modulo 2*pi for every polygon went the long
                # way round a clockwise polygon's corners and left them uncovered.)
                a0 = math.atan2(n_in[1], n_in[0])
                sweep = orientation * ((orientation * (math.atan2(n_out[1], n_out[0]) - a0)) % (2 * math.pi))
                steps = max(1, math.ceil(abs(sweep) / _ARC_STEP))
                for s in range(steps + 1):
                    angle = a0 + sweep * s / steps
                    candidates.append(corner + margin * np.array([math.cos(angle), math.sin(angle)]))
        return [p for p, c in zip(candidates, self.clearances(candidates)) if c >= radius - _GRAZE]


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


def _signed_area(pts: np.ndarray) -> float:
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


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
            if _segments_intersect(a, b, c, d):
                raise ValueError(f"{where} is self-intersecting (edges {i} and {j} cross); obstacles must be simple polygons")
    if abs(_signed_area(pts)) < 1e-9:
        raise ValueError(f"{where} has zero area; give the polygon's outline, at least 3 non-collinear vertices")


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _segments_intersect(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    d1, d2, d3, d4 = _cross(c, d, a), _cross(c, d, b), _cross(a, b, c), _cross(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and d1 != 0 and d2 != 0 and d3 != 0 and d4 != 0:
        return True
    eps = 1e-12

    def on_segment(p, q, r):  # r collinear with p-q and between them
        return min(p[0], q[0]) - eps <= r[0] <= max(p[0], q[0]) + eps and min(p[1], q[1]) - eps <= r[1] <= max(p[1], q[1]) + eps

    return (
        (abs(d1) < eps and on_segment(c, d, a))
        or (abs(d2) < eps and on_segment(c, d, b))
        or (abs(d3) < eps and on_segment(a, b, c))
        or (abs(d4) < eps and on_segment(a, b, d))
    )


def _point_in_polygon(x: float, y: float, poly: tuple[tuple[float, float], ...]) -> bool:
    return bool(_points_in_polygon(np.array([[x, y]]), poly)[0])


def _points_in_polygon(points: np.ndarray, poly: tuple[tuple[float, float], ...]) -> np.ndarray:
    """Even-odd rule, vectorised over points."""
    px, py = points[:, 0], points[:, 1]
    inside = np.zeros(len(points), dtype=bool)
    pts = np.asarray(poly, float)
    for (x0, y0), (x1, y1) in zip(pts, np.roll(pts, -1, axis=0)):
        crosses = (y0 > py) != (y1 > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_at = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (px < x_at)
    return inside


def _segments_distance(p0: np.ndarray, p1: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """Distance between each segment p0[k]-p1[k] and each wall (0 where they cross): shape (K, M)."""
    return _pair_distance(p0[:, None, :], p1[:, None, :], walls[None, :, :2], walls[None, :, 2:])


def _pair_distance(p: np.ndarray, q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance between segments p-q and a-b (0 where they cross), broadcasting over leading axes."""

    def cross(o, u, v):
        return (u[..., 0] - o[..., 0]) * (v[..., 1] - o[..., 1]) - (u[..., 1] - o[..., 1]) * (v[..., 0] - o[..., 0])

    crossing = (np.sign(cross(a, b, p)) * np.sign(cross(a, b, q)) < 0) & (np.sign(cross(p, q, a)) * np.sign(cross(p, q, b)) < 0)
    distance = np.minimum.reduce(
        [_point_to_segments(p, a, b), _point_to_segments(q, a, b), _point_to_segments(a, p, q), _point_to_segments(b, p, q)]
    )
    return np.where(crossing, 0.0, distance)


def _point_to_segments(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points to segments a-b, broadcasting over leading axes."""
    ab = b - a
    t = np.clip(((points - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-18), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[..., None] * ab), axis=-1)


def _visible_many(p0: np.ndarray, p1: np.ndarray, walls: np.ndarray, radius: float) -> np.ndarray:
    """Whether each segment p0[k]-p1[k] keeps at least ``radius`` from every wall.

    Only walls whose bounding box comes within ``radius`` of a segment's bounding box can be
    nearer than ``radius``; the exact distance is computed for those pairs only, in bounded chunks.
    """
    seen = np.ones(len(p0), dtype=bool)
    if len(walls) == 0:
        return seen
    low, high = np.minimum(p0, p1) - radius, np.maximum(p0, p1) + radius
    wall_low, wall_high = np.minimum(walls[:, :2], walls[:, 2:]), np.maximum(walls[:, :2], walls[:, 2:])
    step = max(1, _CHUNK // len(walls))
    for start in range(0, len(p0), step):
        part = slice(start, start + step)
        near = np.all(low[part, None] <= wall_high[None], axis=-1) & np.all(wall_low[None] <= high[part, None], axis=-1)
        pair, wall = np.nonzero(near)
        close = _pair_distance(p0[part][pair], p1[part][pair], walls[wall, :2], walls[wall, 2:]) < radius
        seen[start + pair[close]] = False
    return seen


def _dijkstra(lengths: np.ndarray, source: int, target: int) -> float:
    """Shortest path on a small dense graph (inf = no edge)."""
    n = len(lengths)
    best = np.full(n, np.inf)
    best[source] = 0.0
    done = np.zeros(n, dtype=bool)
    for _ in range(n):
        u = int(np.argmin(np.where(done, np.inf, best)))
        if done[u] or not np.isfinite(best[u]):
            break
        if u == target:
            break
        done[u] = True
        best = np.minimum(best, best[u] + lengths[u])
    return float(best[target])


def _blocks(xs: np.ndarray, ys: np.ndarray, first_row: int):
    """The grid points (xs x ys) in blocks of whole rows, at most ``_CHUNK`` points each: (row slice, (k, 2) points)."""
    if len(xs) == 0 or len(ys) == 0:
        return
    step = max(1, _CHUNK // len(xs))
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
