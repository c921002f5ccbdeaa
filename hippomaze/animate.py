"""``hippomaze animate``: one DMTP trial as an animation (a GIF, or an MP4 with the ``video`` extra).

The trial is the first of ``hippomaze dmtp --maze M --seed S --agent A``: the same goal and
starts. Each frame shows, left, the arena: the robot, its rangefinder's rays, its path in the
current run (the earlier runs faint) and the goal. For an agent with place cells (the
hippocampal agent) two more panels follow: the place cells' activity, each cell drawn at the
centre of its field (where it fired, rate-weighted, over the whole trial: an analysis that reads
the true position, which the agent never does), and the reward map, each cell coloured by its
weight onto the current goal's reward cell (``W_rp``). At the end of a successful run the map is
revealed as replay writes it: cells in order of their new weight, the largest (reached first,
near the goal) first.

A trial has thousands of steps; frames are a subsample (the dry run and the long exploring run
sped up, the short direct runs nearly step by step), a few held at each run's end.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import gymnasium as gym
import numpy as np

#: The file types ``--out`` may have.
FORMATS = (".gif", ".mp4")
#: Rays drawn (every k-th of the rangefinder's).
DRAWN_RAYS = 48
#: Frames per phase, as shares of ``--frames``: the dry run, the first run, each later run, the replay, the holds.
DRY_SHARE, FIRST_RUN_SHARE, LATER_RUN_SHARE = 0.22, 0.25, 0.1
REPLAY_FRAMES, HOLD_FRAMES, END_FRAMES = 8, 4, 10


@dataclass
class Step:
    """What one environment step showed (the true position is for drawing only)."""

    phase: int  # 0: the dry run, k: run k
    position: tuple[float, float]
    heading: float
    ranges: np.ndarray
    rates: np.ndarray | None  # the place cells' rates after the step (None: an agent without place cells)
    decision: str


@dataclass
class Recording:
    """A trial, step by step, and the reward weights around each run."""

    goal: tuple[float, float] | None = None
    steps: list[Step] = field(default_factory=list)
    weights_before: dict[int, np.ndarray | None] = field(default_factory=dict)  # run -> W_rp of the goal when it began (None: none)
    weights_after: dict[int, np.ndarray | None] = field(default_factory=dict)  # run -> after it (replay included)
    success: dict[int, bool] = field(default_factory=dict)
    runs: int = 0


class _RecordingEnv(gym.Wrapper):
    """The dry run's environment: records each step it takes."""

    def __init__(self, env: gym.Env, recorder: _Recorder) -> None:
        super().__init__(env)
        self.recorder = recorder

    def step(self, action: Any) -> Any:
        result = self.env.step(action)
        self.recorder.record(result[0], result[4])
        return result


class _Recorder:
    """Wraps the agent for the runner and records every step: the runs' through ``observe``, the
    dry run's through the environment it is handed."""

    def __init__(self, agent: Any, recording: Recording) -> None:
        self.agent = agent
        self.recording = recording
        self.phase = 0

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.phase = len(self.recording.weights_before) + 1
        self.recording.goal = (float(info["goal"][0]), float(info["goal"][1]))
        self.recording.weights_before[self.phase] = _weights(self.agent)
        self.agent.reset(observation, info)
        self.record(observation, info)

    def act(self, observation: Any) -> Any:
        return self.agent.act(observation)

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        self.agent.observe(action, observation, reward, terminated, truncated, info)
        self.record(observation, info)
        if terminated or truncated:
            self.recording.weights_after[self.phase] = _weights(self.agent)
            self.recording.success[self.phase] = bool(info.get("is_success", False))

    def record(self, observation: Any, info: dict[str, Any]) -> None:
        rates = getattr(self.agent, "place_rates", None)
        self.recording.steps.append(
            Step(
                phase=self.phase,
                position=(float(info["position"][0]), float(info["position"][1])),
                heading=float(info["heading"]),
                ranges=np.asarray(observation["ranges"], dtype=np.float32),
                rates=None if rates is None else np.asarray(rates, dtype=np.float32),
                decision=str(getattr(self.agent, "last_decision", "")),
            )
        )

    def __getattr__(self, name: str) -> Any:
        if name == "dry_run" and callable(getattr(self.agent, "dry_run", None)):

            def dry_run(env: gym.Env) -> None:
                self.phase = 0
                self.agent.dry_run(_RecordingEnv(env, self))

            return dry_run
        if name == "start_trial" and callable(getattr(self.agent, "start_trial", None)):
            return self.agent.start_trial
        raise AttributeError(name)


def _weights(agent: Any) -> np.ndarray | None:
    """The current goal's reward weights (``W_rp``), if the agent has reward cells."""
    reward = getattr(agent, "reward", None)
    W = getattr(reward, "W_rp", None)
    if W is None or len(W) == 0:
        return None if W is None else np.zeros(W.shape[1])
    return np.asarray(W[-1], dtype=np.float64).copy()


def record_trial(maze: str, seed: int, agent: str = "hippo", runs: int = 4) -> tuple[Recording, Any]:
    """Run the first DMTP trial of ``hippomaze dmtp --maze maze --seed seed --agent agent`` with
    ``runs`` runs, recording every step; returns the recording and the maze spec."""
    import hippo_env  # noqa: F401  (registers the environment)
    from hippo_env.dmtp import run_dmtp
    from hippo_env.maze import MazeSpec
    from hippomaze.registry import agent_factory

    spec = MazeSpec.load(maze)
    try:
        base = agent_factory(agent)
    except ImportError as err:  # a missing optional extra (dqn, ppo)
        raise ValueError(str(err)) from err
    recording = Recording(runs=runs)

    def make(observation_space: Any, action_space: Any, *, seed: int) -> _Recorder:
        return _Recorder(base(observation_space, action_space, seed=seed), recording)

    make.env_kwargs = getattr(base, "env_kwargs", {})  # type: ignore[attr-defined]
    run_dmtp(make, spec, trials=1, runs=runs, seed=seed, agent_name=agent, progress=False)
    return recording, spec


def frame_plan(recording: Recording, frames: int) -> list[tuple[int, str, float]]:
    """Which recorded step each frame shows: ``(step, kind, reveal)``; kind ``"step"``, ``"replay"``
    (``reveal``: the share of the replay's new weights shown) or ``"hold"``."""
    phases = np.array([s.phase for s in recording.steps])
    plan: list[tuple[int, str, float]] = []
    for phase in range(int(phases.max(initial=0)) + 1):
        where = np.flatnonzero(phases == phase)
        if where.size == 0:
            continue
        share = DRY_SHARE if phase == 0 else FIRST_RUN_SHARE if phase == 1 else LATER_RUN_SHARE
        count = max(2, min(where.size, round(share * frames)))
        picks = where[np.unique(np.linspace(0, where.size - 1, count).round().astype(int))]
        plan += [(int(i), "step", 1.0) for i in picks]
        last = int(where[-1])
        before, after = recording.weights_before.get(phase), recording.weights_after.get(phase)
        if phase > 0 and before is not None and after is not None and np.any(after - before[: after.size] > 0):
            plan += [(last, "replay", (k + 1) / REPLAY_FRAMES) for k in range(REPLAY_FRAMES)]
        plan += [(last, "hold", 1.0)] * (END_FRAMES if phase == recording.runs else HOLD_FRAMES)
    return plan


def _centres(recording: Recording) -> tuple[np.ndarray, np.ndarray]:
    """Each place cell's field centre (rate-weighted mean true position over the trial), and which cells ever fired."""
    n = max(s.rates.size for s in recording.steps if s.rates is not None)
    total = np.zeros(n)
    weighted = np.zeros((n, 2))
    for s in recording.steps:
        if s.rates is None:
            continue
        total[: s.rates.size] += s.rates
        weighted[: s.rates.size] += s.rates[:, None] * np.asarray(s.position)
    fired = total > 0
    centres = np.zeros((n, 2))
    centres[fired] = weighted[fired] / total[fired, None]
    return centres, fired


def _padded(values: np.ndarray | None, n: int) -> np.ndarray:
    out = np.zeros(n)
    if values is not None:
        out[: min(n, values.size)] = values[:n]
    return out


def render_frames(recording: Recording, spec: Any, frames: int, dpi: int = 80) -> Iterator[np.ndarray]:
    """The animation's frames as RGB arrays (height, width, 3), each drawn by updating one figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle

    from hippo_env.physics import ROBOT_RADIUS
    from hippo_env.render import PLOT_STYLE, draw_maze

    cells = recording.steps[0].rates is not None and any(s.rates is not None and s.rates.size for s in recording.steps)
    panels = 3 if cells else 1
    fig, axes = plt.subplots(1, panels, figsize=(4.0 * panels, 4.35), squeeze=False, dpi=dpi)
    axes = axes[0]
    goal = recording.goal
    for ax in axes:
        draw_maze(spec, ax, goal=goal, style=PLOT_STYLE)
        ax.set_xticks([])
        ax.set_yticks([])
    arena = axes[0]
    earlier = LineCollection([], colors="0.6", linewidths=0.8, alpha=0.7, zorder=4)
    arena.add_collection(earlier)
    rays = LineCollection([], colors="#ff7f0e", linewidths=0.5, alpha=0.4, zorder=5)
    arena.add_collection(rays)
    (path,) = arena.plot([], [], color="#1f77b4", lw=1.4, zorder=6)
    robot = Circle((0, 0), ROBOT_RADIUS, facecolor="#1f77b4", edgecolor="k", lw=0.8, zorder=7)
    arena.add_patch(robot)
    (nose,) = arena.plot([], [], color="w", lw=1.6, zorder=8)
    arena.set_title("the robot, its rays and path", fontsize=10)
    status = fig.text(0.5, 0.015, "", ha="center", va="bottom", fontsize=10)

    if cells:
        from matplotlib.colors import PowerNorm

        centres, fired = _centres(recording)
        shown = np.flatnonzero(fired)
        # colour scales: the rates the cells reach when active (a few spikes would wash out the rest), the final weights
        active = np.concatenate([s.rates[s.rates > 0] for s in recording.steps if s.rates is not None] or [np.ones(1)])
        top_rate = float(np.percentile(active, 95)) or 1.0
        finals = [w for w in recording.weights_after.values() if w is not None]
        top_weight = max((float(w.max(initial=0.0)) for w in finals), default=0.0) or 1.0
        for ax in axes[1:]:  # every cell that ever fired, at its field centre, as a faint dot
            ax.scatter(centres[shown, 0], centres[shown, 1], s=3, color="0.55", zorder=4, linewidths=0)
        activity = axes[1].scatter([], [], c=[], s=[], cmap="viridis", vmin=0, vmax=top_rate, zorder=5, linewidths=0)
        (here,) = axes[1].plot([], [], "+", color="#d62728", ms=9, mew=1.6, zorder=6)
        axes[1].set_title("place cells firing (at their field centres)", fontsize=10)
        reward = axes[2].scatter([], [], c=[], s=[], cmap="plasma", norm=PowerNorm(0.5, vmin=0, vmax=top_weight), zorder=5, linewidths=0)
        axes[2].set_title("reward map: weights onto the reward cell", fontsize=10)
    fig.tight_layout(rect=(0, 0.06, 1, 0.97))
    canvas = fig.canvas
    assert isinstance(canvas, FigureCanvasAgg)  # the Agg backend, chosen above

    steps = recording.steps
    phases = np.array([s.phase for s in steps])
    starts = {p: int(np.flatnonzero(phases == p)[0]) for p in np.unique(phases)}
    n_runs = recording.runs
    for index, kind, reveal in frame_plan(recording, frames):
        s = steps[index]
        first = starts[s.phase]
        xy = np.array([steps[i].position for i in range(first, index + 1)])
        path.set_data(xy[:, 0], xy[:, 1])
        earlier.set_segments([np.array([steps[i].position for i in np.flatnonzero(phases == p)]) for p in range(1, s.phase)])
        robot.center = s.position
        nose.set_data([s.position[0], s.position[0] + ROBOT_RADIUS * math.cos(s.heading)],
                      [s.position[1], s.position[1] + ROBOT_RADIUS * math.sin(s.heading)])  # fmt: skip
        k = max(1, s.ranges.size // DRAWN_RAYS)
        angles = s.heading + 2 * math.pi * np.arange(0, s.ranges.size, k) / s.ranges.size
        r = s.ranges[::k]
        ends = np.column_stack([s.position[0] + r * np.cos(angles), s.position[1] + r * np.sin(angles)])
        rays.set_segments([[s.position, tuple(e)] for e in ends] if kind == "step" else [])
        run_steps = index - first
        if s.phase == 0:
            text = f"dry run: exploring, no goal yet (step {run_steps:,})"
        else:
            text = f"run {s.phase} of {n_runs}: {s.decision or 'moving'} (step {run_steps:,})"
            if kind != "step":
                outcome = "reached the goal" if recording.success.get(s.phase) else "stopped at the step limit"
                text = f"run {s.phase} of {n_runs} {outcome} in {run_steps:,} steps"
                if kind == "replay":
                    text += ": replay writes the reward map"
        status.set_text(text)
        if cells:
            rates = _padded(s.rates, centres.shape[0])
            on = shown[rates[shown] > 0]
            activity.set_offsets(centres[on] if on.size else np.zeros((0, 2)))
            activity.set_array(rates[on])
            activity.set_sizes(8 + 50 * np.minimum(rates[on] / top_rate, 1.0))
            here.set_data([s.position[0]], [s.position[1]])
            weights = _padded(_weights_at(recording, s.phase, index, starts, kind, reveal), centres.shape[0])
            on = shown[weights[shown] > 0]
            reward.set_offsets(centres[on] if on.size else np.zeros((0, 2)))
            reward.set_array(weights[on])
            reward.set_sizes(8 + 40 * np.sqrt(np.minimum(weights[on] / top_weight, 1.0)))
        canvas.draw()
        yield np.asarray(canvas.buffer_rgba())[..., :3].copy()
    plt.close(fig)


def _weights_at(recording: Recording, phase: int, index: int, starts: dict[int, int], kind: str, reveal: float) -> np.ndarray | None:
    """The reward weights a frame shows: the run's starting weights, or during the replay frames
    the new weights revealed largest first (``reveal``: the share of the replay's cells shown)."""
    before = recording.weights_before.get(phase)
    after = recording.weights_after.get(phase)
    if phase == 0 or before is None:
        return None
    if kind == "step" or after is None:
        return before
    if kind == "hold":
        return after
    added = after - _padded(before, after.size)
    written = np.flatnonzero(added > 0)
    order = written[np.argsort(-added[written])]
    shown = order[: max(1, math.ceil(reveal * order.size))]
    out = _padded(before, after.size)
    out[shown] = after[shown]
    return out


def _imageio_ffmpeg() -> ModuleType:
    """imageio-ffmpeg, which writes an .mp4, or an ImportError saying how to install it."""
    try:
        import imageio_ffmpeg
    except ImportError as err:
        raise ImportError(
            f"an .mp4 needs imageio-ffmpeg (the 'video' extra): pip install 'hippomaze[video]', or write a .gif ({err})"
        ) from err
    return imageio_ffmpeg


def write_animation(frames: Iterator[np.ndarray], out: Path, fps: int) -> int:
    """Write the frames to ``out`` (.gif with Pillow, .mp4 with imageio-ffmpeg); returns how many."""
    if out.suffix.lower() == ".mp4":
        imageio_ffmpeg = _imageio_ffmpeg()
        writer = None
        count = 0
        for frame in frames:
            frame = frame[: frame.shape[0] // 2 * 2, : frame.shape[1] // 2 * 2]  # H.264 wants even sides
            if writer is None:
                writer = imageio_ffmpeg.write_frames(str(out), (frame.shape[1], frame.shape[0]), fps=fps, macro_block_size=2,
                                                     quality=7, pix_fmt_out="yuv420p")  # fmt: skip
                writer.send(None)
            writer.send(np.ascontiguousarray(frame))
            count += 1
        if writer is not None:
            writer.close()
        return count
    from PIL import Image

    images = [Image.fromarray(frame).quantize(colors=128, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE) for frame in frames]
    images[0].save(out, save_all=True, append_images=images[1:], duration=round(1000 / fps), loop=0, optimize=True)
    return len(images)


def animate(maze: str, seed: int, out: str | Path, agent: str = "hippo", runs: int = 4, frames: int = 240, fps: int = 12,
            dpi: int = 80) -> Path:  # fmt: skip
    """Animate the first DMTP trial of ``agent`` in ``maze`` with ``seed`` into ``out`` (.gif or .mp4).

    Args:
        maze: a built-in maze name or a JSON path.
        seed: the runner's seed (the goal, the starts, the agent's seed), as ``hippomaze dmtp --seed``.
        out: the file to write; its suffix (.gif or .mp4) picks the format.
        agent: any agent ``hippomaze dmtp --agent`` takes; the place-cell and reward-map panels need one with place cells.
        runs: runs in the trial.
        frames: about this many frames in all (the dry run and long runs subsampled), plus the replay's and the holds.
        fps: frames per second.
        dpi: the frames' resolution (a 3-panel frame is 12 x 4.35 inches).

    Raises:
        ValueError: an unknown maze or agent, a bad number, or an ``out`` that is not .gif or .mp4.
        ImportError: an .mp4 without imageio-ffmpeg.
    """
    out = Path(out)
    if out.suffix.lower() not in FORMATS:
        raise ValueError(f"--out {str(out)!r} must end in .gif or .mp4 (.mp4 needs the 'video' extra: pip install 'hippomaze[video]')")
    if out.suffix.lower() == ".mp4":
        _imageio_ffmpeg()  # before any work: a missing extra is said at once
    for name, value, least in (("seed", seed, 0), ("runs", runs, 1), ("frames", frames, 10), ("fps", fps, 1), ("dpi", dpi, 20)):
        if not isinstance(value, int) or value < least:
            raise ValueError(f"--{name} must be an integer >= {least}, got {value!r}")
    if not out.parent.exists():
        raise ValueError(f"--out {str(out)!r}: folder {str(out.parent)!r} does not exist")
    recording, spec = record_trial(maze, seed, agent, runs)
    write_animation(render_frames(recording, spec, frames, dpi), out, fps)
    return out


def add_parser(commands: Any) -> argparse.ArgumentParser:
    """Add ``animate`` to the ``hippomaze`` subcommands."""
    p = commands.add_parser(
        "animate", help="animate one DMTP trial into a .gif or .mp4", description=__doc__.split("\n\n")[0].replace("``", "")
    )
    p.add_argument("--maze", default="open", help="built-in maze (open, maze1 ... maze4) or a path to a maze JSON file (default: open)")
    p.add_argument(
        "--seed", type=int, default=0, help="the runner's seed: the goal, the starts and the agent's, as hippomaze dmtp (default: 0)"
    )
    p.add_argument(
        "--agent",
        default="hippo",
        help="hippo, hippo-paper, random, dqn, ppo or module:Class; the place-cell and reward-map panels need an agent with "
        "place cells (default: hippo)",
    )
    p.add_argument("--runs", type=int, default=4, help="runs in the trial (default: 4)")
    p.add_argument("--out", required=True, help="the file to write: .gif, or .mp4 with the 'video' extra (imageio-ffmpeg)")
    p.add_argument("--frames", type=int, default=240, help="about this many frames; the dry run and long runs are sped up (default: 240)")
    p.add_argument("--fps", type=int, default=12, help="frames per second (default: 12)")
    p.add_argument("--dpi", type=int, default=80, help="resolution: a three-panel frame is 12 x 4.35 inches (default: 80)")
    return p


def animate_command(args: argparse.Namespace) -> int:
    """Run ``hippomaze animate`` from parsed arguments."""
    import os

    if ":" in args.agent and "" not in sys.path and os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())  # --agent mymodule:MyAgent finds ./mymodule.py
    began = time.perf_counter()
    path = animate(args.maze, args.seed, args.out, args.agent, args.runs, args.frames, args.fps, args.dpi)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB) in {time.perf_counter() - began:.0f} s")
    return 0
