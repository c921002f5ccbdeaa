"""The experiments' design: which mazes, which generalisation scenarios, how many example cells,
and how every DMTP trial's seed follows from the base seed."""

from __future__ import annotations

from dataclasses import dataclass

MAZES = ("open", "maze1", "maze2", "maze3", "maze4")
OBSTACLE_MAZES = MAZES[1:]
# Which of our mazes plays which of the paper's (see REPORT.md, "Mazes").
PAPER_NAME = {"open": "open maze", "maze1": "Maze 1", "maze2": "Maze 2", "maze3": "(not in the paper)", "maze4": "Maze 3 / Fig. 9's maze 4"}
EXAMPLE_CELLS = 4
TRIAL_SEED_STRIDE = 1000


@dataclass(frozen=True)
class Scenario:
    """A generalisation scenario (experiment 6): goal-free exploration of ``maze`` by the agent itself
    (``explore="agent"``) or along ``LIMITED_PATH`` (``"scripted"``), then the reward put at each goal."""

    maze: str
    explore: str
    goals: tuple[tuple[float, float], ...]
    title: str


LIMITED_PATH = ((-4.0, -3.0), (3.0, -3.0), (3.0, 3.0))  # an L driven once, by script
SCENARIOS: dict[str, Scenario] = {
    "open_extensive": Scenario("open", "agent", ((2.5, 2.5), (-3.0, -1.0), (0.5, -3.5)), "(a) open, extensive"),
    "open_limited": Scenario("open", "scripted", ((-1.5, -3.0), (3.0, 2.0), (2.0, 0.5), (-3.0, 3.0)), "(b) open, one path"),
    "maze2_extensive": Scenario("maze2", "agent", ((-3.5, -3.5), (-0.8, -0.8), (3.2, 3.2)), "(c) maze2, extensive"),
}


def trial_seed(seed: int, trial: int) -> int:
    """The ``hippomaze dmtp --seed`` of DMTP trial ``trial`` (random starts, any maze)."""
    return TRIAL_SEED_STRIDE * seed + trial
