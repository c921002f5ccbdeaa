"""What the measurements are made of: place-field shape and aliasing on a grid, how a sampled
reward map looks, and a DMTP result's summary. The thresholds are stated in the report."""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np

from hippo_env.dmtp import DMTPResult
from hippo_env.geometry import convex_hull_area
from hippomaze.stats import median_or_none, pearson_with_ci, spearman

from .geometry import Grid, distance_to_path, geodesic_to
from .results import DMTPSummary, FieldCell, FieldSummary, MapStats

FIELD_MIN_PEAK = 0.1  # a cell "has a field" if its peak rate on the grid reaches this
FIELD_LEVEL = 0.5  # the field is where the rate is at least this fraction of the peak
COMPONENT_MIN_MASS = 0.1  # a separate piece of a field counts if it holds this share of the field's rate
NEAR_PATH, FAR_PATH = 0.5, 2.0  # m: "explored" / "far from anything explored"
SIMILAR_PLACE = 1.0  # m: aliased pieces within this of each other in compartment coordinates
COMPARTMENT = 5.0  # m: maze4's quadrants (and maze3's halves) repeat every 5 m


# -------------------------------------------------------------------------------- reward maps
def map_stats(maze: str, positions: np.ndarray, values: np.ndarray, goal: Any, explored: np.ndarray, xi: float) -> MapStats:
    """How a sampled reward map looks: where it reaches, and whether it is graded toward the goal.

    ``coverage``: share of sampled positions whose value exceeds ``xi`` (the agent's exploit
    threshold); ``near``/``band``/``far``: the same among positions <= 0.5 m, 0.5-1.5 m and >= 2 m
    from the explored path; ``spearman``: rank correlation of value with the geodesic distance to
    the goal over the covered positions (negative = graded toward the goal); ``peak_offset``: the
    distance from the goal to the centre of the top 2 % of values; ``second_peak``: the largest
    value at least 3 m (geodesic) from the goal, as a share of the largest anywhere (high = the map
    also peaks somewhere else, e.g. at an aliased place).
    """
    values = np.asarray(values, float)
    ok = np.isfinite(values)
    positions, values = positions[ok], values[ok]
    covered = values > xi
    to_path = distance_to_path(positions, explored)
    dist = geodesic_to(maze, goal, positions)

    def share(mask: np.ndarray) -> float | None:
        return float(covered[mask].mean()) if mask.any() else None

    stats = MapStats(
        coverage=float(covered.mean()) if len(values) else 0.0,
        near=share(to_path <= NEAR_PATH),
        band=share((to_path > NEAR_PATH) & (to_path <= 1.5)),
        far=share(to_path >= FAR_PATH),
        spearman=spearman(values[covered], dist[covered]) if covered.sum() >= 5 else None,
        max_value=float(values.max()) if len(values) else 0.0,
    )
    far_from_goal = dist >= 3.0
    if covered.any() and far_from_goal.any() and values.max() > 0:
        stats.second_peak = float(values[far_from_goal].max() / values.max())
    if covered.any():
        top = values >= np.quantile(values, 0.98)
        stats.peak_offset = float(np.linalg.norm(positions[top].mean(axis=0) - np.asarray(goal, float)))
    return stats


# -------------------------------------------------------------------------------- place fields
def components(grid: Grid, members: np.ndarray) -> list[np.ndarray]:
    """4-connected pieces of a set of grid positions (indices into ``grid.positions``)."""
    rows, cols = grid.shape
    where = {int(grid.flat[i]): int(i) for i in members}
    seen: set[int] = set()
    pieces = []
    for cell in where:
        if cell in seen:
            continue
        seen.add(cell)
        queue, piece = deque([cell]), []
        while queue:
            cur = queue.popleft()
            piece.append(where[cur])
            r, c = divmod(cur, cols)
            for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
                nxt = rr * cols + cc
                if 0 <= rr < rows and 0 <= cc < cols and nxt in where and nxt not in seen:
                    seen.add(nxt)
                    queue.append(nxt)
        pieces.append(np.array(piece))
    return pieces


def _compartment_coords(points: np.ndarray) -> np.ndarray:
    """Positions folded into one 5 m compartment: maze4's quadrants (and maze3's halves) map onto
    each other by 5 m translations, so aliased places share these coordinates."""
    return np.where(points < 0, points + COMPARTMENT, points)


def analyse_fields(grid: Grid, rates: np.ndarray) -> list[FieldCell]:
    """Per cell with a field: peak, area, pieces, convexity of the main piece, and which quadrants /
    halves its substantial pieces lie in (for aliasing)."""
    out = []
    cell_area = grid.spacing**2
    corners = np.array([[-1, -1], [-1, 1], [1, -1], [1, 1]]) * grid.spacing / 2
    peaks = np.nanmax(np.nan_to_num(rates, nan=0.0), axis=0)
    for cell in np.flatnonzero(peaks >= FIELD_MIN_PEAK):
        r = rates[:, cell]
        members = np.flatnonzero(r >= FIELD_LEVEL * peaks[cell])
        pieces = components(grid, members)
        total = float(r[members].sum())
        info = []
        for piece in pieces:
            mass = float(r[piece].sum()) / total
            pts = grid.positions[piece]
            centre = (pts * r[piece, None]).sum(axis=0) / r[piece].sum()
            info.append((mass, piece, centre))
        info.sort(key=lambda t: -t[0])
        substantial = [t for t in info if t[0] >= COMPONENT_MIN_MASS]
        main = info[0][1]
        main_pts = grid.positions[main]
        hull = convex_hull_area((main_pts[:, None, :] + corners[None]).reshape(-1, 2))
        quadrants = {int(c[0] > 0) + 2 * int(c[1] > 0) for _, _, c in substantial}
        halves = {int(c[0] > 0) for _, _, c in substantial}
        folded = _compartment_coords(np.array([c for _, _, c in substantial]))
        spread = float(max(np.linalg.norm(a - b) for a in folded for b in folded)) if len(folded) > 1 else 0.0
        out.append(
            FieldCell(
                cell=int(cell),
                peak=float(peaks[cell]),
                area=float(len(members) * cell_area),
                pieces=len(substantial),
                solidity=float(len(main) * cell_area / hull) if hull > 0 else 1.0,
                centre=[float(v) for v in info[0][2]],
                quadrants=len(quadrants),
                halves=len(halves),
                folded_spread=spread,
                min_piece_mass=float(min(t[0] for t in substantial)),
            )
        )
    return out


def summarise_fields(cells: list[FieldCell], n_cells: int, arena_area: float) -> FieldSummary:
    if not cells:
        return FieldSummary(cells=n_cells, with_field=0)
    area = np.array([c.area for c in cells])
    single = np.array([c.pieces == 1 for c in cells])
    multi_q = np.array([c.quadrants >= 2 for c in cells])
    return FieldSummary(
        cells=n_cells,
        with_field=len(cells),
        single_piece=float(single.mean()),
        median_area_m2=float(np.median(area)),
        median_area_share=float(np.median(area) / arena_area),
        median_solidity_main_piece=float(np.median([c.solidity for c in cells])),
        quadrants_hist=[int(sum(c.quadrants == k for c in cells)) for k in (1, 2, 3, 4)],
        halves_hist=[int(sum(c.halves == k for c in cells)) for k in (1, 2)],
        multi_quadrant=float(multi_q.mean()),
        multi_quadrant_similar_place=float(np.mean([c.quadrants >= 2 and c.folded_spread <= SIMILAR_PLACE for c in cells])),
        multi_half=float(np.mean([c.halves == 2 for c in cells])),
        multi_half_similar_place=float(np.mean([c.halves == 2 and c.folded_spread <= SIMILAR_PLACE for c in cells])),
        median_folded_spread_multi_quadrant=float(np.median([c.folded_spread for c in cells if c.quadrants >= 2]))
        if multi_q.any()
        else None,
    )


def random_examples(cells: list[FieldCell], count: int, rng: np.random.Generator) -> list[int]:
    """``count`` cells drawn at random among those with a field: examples not picked for shape."""
    chosen: np.ndarray | list[int] = rng.choice(len(cells), size=min(count, len(cells)), replace=False) if cells else []
    return sorted(cells[i].cell for i in chosen)


def aliasing_examples(cells: list[FieldCell], count: int) -> list[int]:
    """The clearest aliased cells (pieces at similar places, the smallest piece as large as
    possible), taking cells with 3, 4 and 2 quadrants in turn so that every kind is shown."""
    ranked = {
        k: sorted((c for c in cells if c.quadrants == k), key=lambda c: (c.folded_spread > SIMILAR_PLACE, -c.min_piece_mass))
        for k in (2, 3, 4)
    }
    out: list[int] = []
    while len(out) < count and any(ranked.values()):
        for k in (3, 4, 2):
            if ranked[k] and len(out) < count:
                out.append(ranked[k].pop(0).cell)
    return out


# -------------------------------------------------------------------------------- DMTP
def dmtp_summary(result: DMTPResult, seed: int) -> DMTPSummary:
    """Medians, success, the Pearson r (with its interval) and the project's targets."""
    ind, ok = result.indirectness(), result.success()
    lengths = np.full((result.trials, result.runs), np.nan)
    for r in result.run_records:
        lengths[r.trial, r.run] = r.path_length
    later = ind[:, 1:]
    return DMTPSummary(
        protocol=result.summary(),
        median_runs_2_on=median_or_none(later.ravel()),
        later_runs_reached=int(ok[:, 1:].sum()),
        later_runs_total=int(ok[:, 1:].size),
        pearson=pearson_with_ci(lengths[:, 0], ind[:, 1], seed) if result.runs >= 2 else None,
    )
