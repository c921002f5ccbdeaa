"""The paper's claims, each beside the measurement and the criterion that decide its verdict.

Every function below makes the rows of one claim (or a group of alike claims); ``assess`` lists
them in the order of the table.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

from hippomaze.stats import median_or_none

from .analysis import FAR_PATH, NEAR_PATH, SIMILAR_PLACE
from .args import PaperArgs
from .design import MAZES
from .formatting import fmt
from .results import Claim, GoalResult, PaperData

T = TypeVar("T")

FIG_REWARD_MAPS = "fig2a_reward_maps_open.png, fig2b_reward_maps_mazes.png"
FIG_MAZES = "fig3b_same_start_mazes.png, fig8_mazes_indirectness.png"


def verdict(ok: bool | np.bool_, partly: bool | np.bool_) -> str:
    return "reproduced" if ok else ("partly" if partly else "not reproduced")


def known(value: T | None) -> T:
    """A summary's statistic that is present: every one is, once the maze has a cell with a field."""
    assert value is not None
    return value


# ------------------------------------------------------------------------------- 1. place fields
def place_fields_claim(data: PaperData) -> Claim:
    fields = data.place_fields
    plain = [m for m in ("open", "maze1", "maze2") if m in fields and fields[m].with_field]
    single = [known(fields[m].single_piece) for m in plain]
    solid = [known(fields[m].median_solidity_main_piece) for m in plain]
    share = [known(fields[m].median_area_share) for m in plain]
    measured = "; ".join(
        f"{m}: {fields[m].with_field} of {fields[m].cells} cells have a field, {fmt(fields[m].single_piece, pct=True)} in one piece, "
        f"median {fields[m].median_area_m2:.2f} m^2, solidity {fields[m].median_solidity_main_piece:.2f}"
        for m in MAZES
        if m in fields and fields[m].with_field
    )
    return Claim(
        id="P1",
        experiment="1 place fields",
        paper="Place fields are localised and convex (Fig. 2), in the open arena and the mazes.",
        measured=measured,
        verdict=verdict(
            bool(single) and min(single) >= 0.8 and min(solid) >= 0.8 and max(share) <= 0.05, bool(single) and min(single) >= 0.5
        ),
        criterion="reproduced if in open, maze1 and maze2 >= 80 % of fields are one piece, median solidity >= 0.8 and median area <= 5 % "
        "of the arena; partly if >= 50 % are one piece",
        figure="fig1_place_fields.png",
    )


# ------------------------------------------------------------------------------- 2. reward maps after run 1
def reward_map_graded_claim(data: PaperData) -> Claim:
    maps = data.reward_maps_after_run1
    rhos = [v.stats.spearman for v in maps.values() if v.found_goal]
    good = [r is not None and r <= -0.5 for r in rhos]
    fair = [r is not None and r <= -0.3 for r in rhos]
    measured = "Spearman(value, geodesic distance to goal): " + ", ".join(f"{k} {fmt(v.stats.spearman)}" for k, v in maps.items())
    return Claim(
        id="R1",
        experiment="2 reward maps",
        paper="The reward map after run 1 is graded toward the goal (Figs. 3, 8).",
        measured=measured,
        verdict=verdict(bool(good) and np.mean(good) >= 0.8, bool(fair) and np.mean(fair) >= 0.5),
        criterion="reproduced if rho <= -0.5 in >= 80 % of the maps whose run 1 found the goal; partly if rho <= -0.3 in half",
        figure=FIG_REWARD_MAPS,
    )


def reward_map_spread_claim(data: PaperData) -> Claim:
    found = [v for v in data.reward_maps_after_run1.values() if v.found_goal]
    near = median_or_none(v.stats.near for v in found)
    far = median_or_none(v.stats.far for v in found)
    cover = median_or_none(v.stats.coverage for v in found)
    return Claim(
        id="R2",
        experiment="2 reward maps",
        paper="The map spreads over the regions run 1 explored and depends on how extensive that run was (Figs. 3, 8).",
        measured=f"median share of sampled places with value > xi: within {NEAR_PATH} m of run 1's path {fmt(near, pct=True)}, >= "
        f"{FAR_PATH} m from it {fmt(far, pct=True)}, "
        f"whole arena {fmt(cover, pct=True)}",
        verdict=verdict(
            near is not None and far is not None and near >= 0.5 and far <= 0.5 * near, near is not None and far is not None and near > far
        ),
        criterion="reproduced if the median coverage near the path is >= 50 % and far from it at most half that; partly if near > far",
        figure=FIG_REWARD_MAPS,
    )


# ------------------------------------------------------------------------------- 3. same start
def same_start_claim(data: PaperData) -> Claim:
    open_trials = data.same_start.open
    better = [all(x < t.indirectness[0] for x in t.indirectness[1:]) for t in open_trials]
    direct = [(median_or_none(t.indirectness[1:]) or math.inf) <= 1.0 for t in open_trials]
    measured = "; ".join(f"trial {k + 1}: " + " / ".join(fmt(x) for x in t.indirectness) for k, t in enumerate(open_trials))
    return Claim(
        id="S1",
        experiment="3 same start",
        paper="Open arena, same start: random search on run 1, then progressively more direct paths (Fig. 4).",
        measured="indirectness by run, " + measured,
        verdict=verdict(bool(better) and all(better) and all(direct), bool(better) and np.mean(better) >= 0.5),
        criterion="reproduced if in every trial each later run beats run 1 and the later runs' median is <= 1; partly if later runs beat "
        "run 1 in half the trials",
        figure="fig3a_same_start_open.png",
    )


# ------------------------------------------------------------------------------- 4-5. open arena DMTP
def indirectness_falls_claim(args: PaperArgs, data: PaperData) -> Claim:
    d = data.open_dmtp.summary
    med = d.median_indirectness
    r1 = med[0]
    later_ok = r1 is not None and all(m is not None and m <= r1 / 3 for m in med[1:])
    later_lower = r1 is not None and all(m is not None and m < r1 for m in med[1:])
    return Claim(
        id="D1",
        experiment="4 indirectness",
        paper="Indirectness falls sharply after one rewarded run: runs 2-4 much lower than run 1 (Fig. 5).",
        measured=f"{args.trials} trials, median by run "
        + " / ".join(fmt(m) for m in med)
        + f"; runs 2-{args.runs} reached the goal {d.later_runs_reached}/{d.later_runs_total}",
        verdict=verdict(later_ok, later_lower),
        criterion="reproduced if every later run's median is <= a third of run 1's; partly if lower",
        figure="fig4_indirectness.png",
    )


def correlation_claim(data: PaperData) -> Claim:
    p = data.open_dmtp.summary.pearson or {}
    r, ci = p.get("r"), p.get("ci95")
    return Claim(
        id="D2",
        experiment="5 correlation",
        paper="Pearson r = -0.53 between run 1's path length and run 2's indirectness (Fig. 6).",
        measured=f"r = {fmt(r)} (95 % bootstrap CI {fmt(ci[0]) if ci else 'n/a'} to {fmt(ci[1]) if ci else 'n/a'}), Spearman "
        f"{fmt(p.get('spearman'))}, n = {p.get('n')}",
        verdict=verdict(r is not None and r <= -0.3 and ci is not None and ci[1] < 0, r is not None and r < 0),
        criterion="reproduced if r <= -0.3 and the interval excludes 0; partly if r < 0",
        figure="fig5_length_vs_indirectness.png",
    )


def project_target_claims(args: PaperArgs, data: PaperData) -> list[Claim]:
    """The project's targets (open arena, 20 trials, 4 runs, seed 0): the target's text is its criterion."""
    d = data.open_dmtp.summary
    med = d.median_indirectness
    r1 = med[0]
    targets = [
        ("T1", "run-2 median indirectness <= 1.0", med[1] if len(med) > 1 else None, lambda v: v <= 1.0),
        ("T2", "run-4 median indirectness <= 0.5", med[3] if len(med) > 3 else None, lambda v: v <= 0.5),
        ("T3", ">= 95 % of runs 2-4 reach the goal", d.later_runs_success_rate, lambda v: v >= 0.95),
        (
            "T4",
            "run-1 median >= 3x run-4 median",
            (r1 / med[3]) if len(med) > 3 and r1 is not None and med[3] else None,
            lambda v: v >= 3.0,
        ),
    ]
    official = args.trials == 20 and args.runs == 4 and args.seed == 0
    rows = []
    for rid, text, value, test in targets:
        shown = fmt(value, pct=True) if rid == "T3" else (f"{fmt(value)}x" if rid == "T4" else fmt(value))
        met = value is not None and test(value)
        rows.append(
            Claim(
                id=rid,
                experiment="project target",
                paper=f"(project issue, open arena, 20 trials, 4 runs, seed 0) {text}",
                measured=shown + ("" if official else " (not the official setting)"),
                verdict="met" if met else "not met",
                criterion=text,
                figure="fig4_indirectness.png",
            )
        )
    return rows


# ------------------------------------------------------------------------------- 3/4. mazes
class MazeOutcomes:
    """The later runs in each obstacle maze: over its random-start trials if there are any
    (beyond the paper), else over its same-start trial (as in the paper)."""

    def __init__(self, args: PaperArgs, data: PaperData) -> None:
        self.runs, self.random_starts, self.same_start = args.runs, data.maze_dmtp, data.same_start.mazes
        self.source = "the random-start trials" if self.random_starts else "the same-start trial"

    def later(self, m: str) -> float | None:
        """Median indirectness of runs 2 on."""
        if m in self.random_starts:
            return self.random_starts[m].summary.median_runs_2_on
        return median_or_none(self.same_start[m].indirectness[1:]) if m in self.same_start else None

    def rate(self, m: str) -> float | None:
        """Share of runs 2 on that reached the goal."""
        if m in self.random_starts:
            return self.random_starts[m].summary.later_runs_success_rate
        return float(np.mean(self.same_start[m].success[1:])) if m in self.same_start else None

    def measured(self, m: str) -> str:
        same = self.same_start.get(m)
        text = "same start: " + " / ".join(fmt(x) for x in same.indirectness) if same else ""
        if m in self.random_starts:
            outcome = self.random_starts[m]
            text += (
                f"; {outcome.result.trials} trials with random starts: median by run "
                + " / ".join(fmt(x) for x in outcome.summary.median_indirectness)
                + f", runs 2-{self.runs} median {fmt(self.later(m))}, {fmt(self.rate(m), pct=True)} reached the goal"
            )
        return text


def maze_claim(mazes: MazeOutcomes, rid: str, maze: str, name: str) -> Claim:
    v = mazes.later(maze)
    return Claim(
        id=rid,
        experiment="3/4 mazes",
        paper=f"{name} ({maze}): a useful value map after one run; efficient, generalised paths on runs 2-4 (Fig. 7).",
        measured=mazes.measured(maze),
        verdict=verdict(v is not None and v <= 1.0, v is not None and v <= 3.0),
        criterion=f"over {mazes.source}: reproduced if the median indirectness of runs 2-{mazes.runs} is <= 1; partly if <= 3",
        figure=FIG_MAZES,
    )


def alike_compartments_claim(mazes: MazeOutcomes) -> Claim:
    easy = [mazes.later(m) for m in ("maze1", "maze2")]
    hard, easy_max = mazes.later("maze4"), max((v for v in easy if v is not None), default=None)
    worse = hard is not None and easy_max is not None and hard > easy_max
    rates = [r_ for r_ in (mazes.rate(m) for m in ("maze1", "maze2")) if r_ is not None]
    rate4 = mazes.rate("maze4")
    fails = rate4 is not None and len(rates) == 2 and rate4 < min(rates)
    return Claim(
        id="M3",
        experiment="3/4 mazes",
        paper="The four alike compartments (the paper's Maze 3; our maze4) defeat it: the robot meanders, mistakes one compartment "
        "for another (Fig. 7).",
        measured=mazes.measured("maze4") + f"; worst of maze1/maze2: runs 2-{mazes.runs} median {fmt(easy_max)}",
        verdict=verdict(worse and fails, worse or fails),
        criterion=f"over {mazes.source}: reproduced if maze4's later-run median is above maze1's and maze2's and fewer of its later runs "
        "reach the goal; partly if one holds",
        figure=FIG_MAZES,
    )


# ------------------------------------------------------------------------------- 6. generalisation
def _goal_text(g: GoalResult) -> str:
    return (
        f"goal {tuple(g.goal)}: covers {fmt(g.stats.near, pct=True)} of the explored area, rho {fmt(g.stats.spearman)}, "
        f"value >= 3 m from the goal up to {fmt(g.stats.second_peak, pct=True)} of the peak, "
        f"{sum(n.success for n in g.nav)}/{len(g.nav)} runs reached it (median ind. {fmt(median_or_none(n.indirectness for n in g.nav))})"
    )


def extensive_exploration_claim(data: PaperData, rid: str, name: str, fig: str) -> Claim:
    gen = data.generalisation[name]
    visited = [g for g in gen.goals if g.visited]
    ok = [g.stats.near is not None and g.stats.near >= 0.5 and g.stats.spearman is not None and g.stats.spearman <= -0.5 for g in visited]
    return Claim(
        id=rid,
        experiment="6 generalisation",
        paper=f"After extensive goal-free exploration ({gen.maze}), replay alone at a new reward place gives a map over the known "
        f"environment (Fig. {fig}).",
        measured="; ".join(_goal_text(g) for g in gen.goals),
        verdict=verdict(bool(ok) and all(ok), bool(ok) and float(np.mean(ok)) >= 0.5),
        criterion="reproduced if for every visited goal the map covers >= 50 % of the explored area and is graded (rho <= -0.5); partly "
        "for half of them",
        figure="fig6_generalisation.png",
    )


def unexplored_goal_claim(data: PaperData) -> Claim:
    goals = data.generalisation["open_limited"].goals
    on_path = [g for g in goals if g.visited]
    unvisited = [g for g in goals if g.distance_to_explored > 2.0]
    on_cov = median_or_none(g.stats.coverage for g in on_path)
    un_cov = median_or_none(g.stats.coverage for g in unvisited)
    on_nav = median_or_none(n.indirectness for g in on_path for n in g.nav)
    un_nav = median_or_none(n.indirectness for g in unvisited for n in g.nav)
    return Claim(
        id="G3",
        experiment="6 generalisation",
        paper="After exploring along one path, a reward placed where nothing was explored gives no useful map (Fig. 10b, last map).",
        measured=f"share of the arena covered: goals on the path {fmt(on_cov, pct=True)}, never-visited goal {fmt(un_cov, pct=True)}; "
        f"median indirectness from random starts {fmt(on_nav)} vs {fmt(un_nav)}",
        verdict=verdict(
            on_cov is not None and un_cov is not None and un_cov <= 0.25 * on_cov and (un_nav or 0) > (on_nav or 0),
            on_cov is not None and un_cov is not None and un_cov < on_cov,
        ),
        criterion="reproduced if the unvisited goal's map covers at most a quarter of what the on-path goals' maps cover and navigation "
        "to it is worse; partly if it covers less",
        figure="fig6_generalisation.png",
    )


def field_effect_claim(data: PaperData) -> Claim:
    on_path = [g for g in data.generalisation["open_limited"].goals if g.visited]
    band = median_or_none(g.stats.band for g in on_path)
    return Claim(
        id="G4",
        experiment="6 generalisation",
        paper="The inferred map is not confined to the exploratory path: place fields have width (the 'field effect', Fig. 10b).",
        measured=f"goals on the path: share of places 0.5-1.5 m from the path with value > xi {fmt(band, pct=True)}",
        verdict=verdict(band is not None and band >= 0.5, band is not None and band >= 0.2),
        criterion="reproduced if >= 50 %; partly if >= 20 %",
        figure="fig6_generalisation.png",
    )


# ------------------------------------------------------------------------------- 7. aliasing
def aliasing_claim(data: PaperData) -> Claim | None:
    a4, a0 = data.place_fields["maze4"], data.place_fields["open"]
    if not (a4.with_field and a0.with_field):
        return None
    hist = known(a4.quadrants_hist)
    frac, control, similar = known(a4.multi_quadrant), known(a0.multi_quadrant), known(a4.multi_quadrant_similar_place)
    return Claim(
        id="A1",
        experiment="7 aliasing",
        paper="In the four-compartment maze place cells fire at perceptually similar places of several compartments "
        "(Fig. 9: three of four).",
        measured=f"maze4: of {a4.with_field} cells with a field, {hist[1]} have separate pieces in 2 quadrants, {hist[2]} in 3, {hist[3]} "
        f"in 4 ({fmt(frac, pct=True)}; "
        f"{fmt(similar, pct=True)} at places within {SIMILAR_PLACE} m of each other once folded into one compartment); "
        f"open-arena control {fmt(control, pct=True)}",
        verdict=verdict(frac >= 0.05 and frac >= 3 * control and similar >= 0.5 * frac and hist[2] + hist[3] > 0, frac > control),
        criterion="reproduced if >= 5 % of maze4's fields span >= 2 quadrants, >= 3x the open arena, mostly at similar places, and some "
        "span 3-4; partly if more than the control",
        figure="fig7_aliasing_maze4.png",
    )


def alike_cups_claim(data: PaperData) -> Claim | None:
    a3, a0 = data.place_fields["maze3"], data.place_fields["open"]
    if not (a3.with_field and a0.with_field):
        return None
    both, control = known(a3.multi_half), known(a0.multi_half)
    return Claim(
        id="A2",
        experiment="7 aliasing",
        paper="(beyond the paper) maze3's two alike cups: cells with fields in both halves.",
        measured=f"maze3 {fmt(both, pct=True)} of fields in both halves "
        f"({fmt(a3.multi_half_similar_place, pct=True)} at similar places); "
        f"open-arena control {fmt(control, pct=True)}",
        verdict=verdict(both >= 0.05 and both >= 3 * control, both > control),
        criterion="reproduced if >= 5 % and >= 3x the open arena; partly if more than the control",
        figure="fig1_place_fields.png",
    )


def assess(args: PaperArgs, data: PaperData) -> list[Claim]:
    """The claims table: what the paper says, what we measured, and a verdict by a stated criterion."""
    mazes = MazeOutcomes(args, data)
    claims = [
        place_fields_claim(data),
        reward_map_graded_claim(data),
        reward_map_spread_claim(data),
        same_start_claim(data),
        indirectness_falls_claim(args, data),
        correlation_claim(data),
        *project_target_claims(args, data),
        maze_claim(mazes, "M1", "maze1", "Maze 1"),
        maze_claim(mazes, "M2", "maze2", "Maze 2"),
        alike_compartments_claim(mazes),
        extensive_exploration_claim(data, "G1", "open_extensive", "10a"),
        extensive_exploration_claim(data, "G2", "maze2_extensive", "10c"),
        unexplored_goal_claim(data),
        field_effect_claim(data),
        aliasing_claim(data),
        alike_cups_claim(data),
    ]
    return [c for c in claims if c is not None]
