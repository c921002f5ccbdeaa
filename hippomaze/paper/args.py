"""The paper run's arguments: one dataclass (CleanRL style), parsed from the command line."""

from __future__ import annotations

import argparse
import dataclasses
import shlex
from dataclasses import dataclass

from hippo_agent import AgentConfig

DESCRIPTION = 'Reproduce every experiment of the paper\'s "Experimental Results" section on ``HippoMaze-v0``.'


@dataclass
class PaperArgs:
    """Everything the benchmark takes (CleanRL style: one dataclass, parsed from the command line)."""

    out: str = "benchmarks/results/paper"
    """Output folder for REPORT.md, paper.json and the figures."""
    quick: bool = False
    """A smoke run of every experiment (3 trials of 2 runs, short dry run and runs, coarse maps; it overrides
    the sizes below)."""
    seed: int = 0
    """Base seed; every task's seed derives from it (see the package docstring)."""
    workers: int = 2
    """Processes for the independent tasks (1 = run in this process). Results do not depend on it."""
    trials: int = 20
    """Open-arena DMTP trials with random starts (experiments 4 and 5; paper: 20)."""
    runs: int = 4
    """Runs per trial, the first naive (paper: 4)."""
    same_start_trials: int = 3
    """Open-arena trials with every run from the same start (experiment 3; paper: 3)."""
    maze_trials: int = 10
    """DMTP trials with random starts in each obstacle maze (beyond the paper; 0 skips them)."""
    roam_steps: int = 4000
    """Steps of aimless roaming over which place fields and reward maps are sampled."""
    grid_spacing: float = 0.2
    """Metres between the grid positions used for field statistics and aliasing."""
    explore_steps: int = 5000
    """Goal-free exploration (W_pp learning) before the generalisation replays."""
    nav_runs: int = 5
    """Runs from random starts toward each generalisation goal, to test the inferred map."""
    nav_max_steps: int = 3000
    """Step limit of those runs."""
    model: str = "paper"
    """The agent: ``paper`` (``AgentConfig.paper()``, the model as the paper describes it) or
    ``default`` (``AgentConfig()``, with path integration)."""
    dry_run_steps: int | None = None
    """Override the agent's dry run (None: the config's default)."""
    max_episode_steps: int | None = None
    """Override the environment's 10,000-step limit per DMTP run (None: keep it)."""
    progress: bool = True
    """Show a progress bar."""

    def resolved(self) -> PaperArgs:
        """The arguments actually used: ``quick`` shrinks everything."""
        if not self.quick:
            return self
        return dataclasses.replace(
            self,
            trials=3,
            runs=2,
            same_start_trials=1,
            maze_trials=1,
            roam_steps=300,
            grid_spacing=0.5,
            explore_steps=300,
            nav_runs=1,
            nav_max_steps=200,
            dry_run_steps=300,
            max_episode_steps=400,
        )

    def agent_config(self) -> AgentConfig:
        if self.model not in ("paper", "default"):
            raise ValueError(f"--model {self.model!r} is unknown; allowed: paper, default")
        config = AgentConfig.paper() if self.model == "paper" else AgentConfig()
        return config if self.dry_run_steps is None else config.with_values({"model.dry_run_steps": int(self.dry_run_steps)})

    def command(self) -> str:
        """The command line that reproduces this run."""
        parts = ["python", "-m", "benchmarks.paper", "--out", self.out, "--seed", str(self.seed), "--workers", str(self.workers)]
        default = PaperArgs()
        for f in dataclasses.fields(self):
            if f.name in ("out", "seed", "workers", "progress"):
                continue
            value = getattr(self, f.name)
            if value != getattr(default, f.name):
                parts += [f"--{f.name.replace('_', '-')}"] if f.type in ("bool",) else [f"--{f.name.replace('_', '-')}", str(value)]
        return shlex.join(parts)

    def validate(self) -> None:
        """Raise ``ValueError`` for sizes the experiments cannot run with."""
        if self.workers < 1:
            raise ValueError(f"workers must be >= 1, got {self.workers}")
        for name in ("trials", "runs", "same_start_trials", "roam_steps"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.runs < 2:
            raise ValueError("runs must be >= 2: the paper's experiments compare run 1 with later runs")


def parse_args(argv: list[str] | None = None) -> PaperArgs:
    """Command-line flags, one per ``PaperArgs`` field (``--no-progress`` turns the bar off)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.paper", description=DESCRIPTION)
    for f in dataclasses.fields(PaperArgs):
        flag = "--" + f.name.replace("_", "-")
        if f.name == "progress":
            parser.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
        elif f.type == "bool":
            parser.add_argument(flag, action="store_true", help=f"(default: {f.default})")
        elif f.type == "int | None":
            parser.add_argument(flag, type=int, default=f.default, help=f"(default: {f.default})")
        else:
            kind = {"int": int, "float": float, "str": str}[str(f.type)]
            parser.add_argument(flag, type=kind, default=f.default, help=f"(default: {f.default})")
    return PaperArgs(**vars(parser.parse_args(argv)))
