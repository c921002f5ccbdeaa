"""Drawing the maze, the robot, its path and rays: ``rgb_array`` frames and a ``human`` window.

The figure is built once per environment; each frame only moves the robot, path and rays. The
renderer draws from a :class:`Frame`, a snapshot the environment hands it, never from the
environment's own attributes. :func:`draw_maze` is the one drawing of an arena, used by the
renderer, :func:`plot_maze` and the agent's figures (``hippo_agent.plots``, in :data:`PLOT_STYLE`).
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from hippo_env import physics
from hippo_env.maze import MazeSpec

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

WALL_COLOUR = "#4a4a4a"
FLOOR_COLOUR = "#f4f1ea"
GOAL_COLOUR = "#d62728"
ROBOT_COLOUR = "#1f77b4"
MAX_DRAWN_RAYS = 90
#: matplotlib's built-in backends that draw only to files or buffers, never to a window.
NON_INTERACTIVE_BACKENDS = ("agg", "cairo", "pdf", "pgf", "ps", "svg", "template")


@dataclass(frozen=True)
class MazeStyle:
    """How :func:`draw_maze` draws an arena: colours, the wall's width, the margin around it."""

    floor: str
    wall: str
    wall_width: float
    obstacle: str
    obstacle_edge: str | None  # None: matplotlib's default for a filled patch (no edge)
    obstacle_zorder: float
    margin: float  # the axes reach this share of the larger half-side beyond the walls
    axis_labels: bool


#: The environment's frames and :func:`plot_maze`.
ENV_STYLE = MazeStyle(FLOOR_COLOUR, WALL_COLOUR, 3, WALL_COLOUR, WALL_COLOUR, 1, 0.1, True)
#: The agent's maps and trajectories: a grey floor, black obstacles above the data.
PLOT_STYLE = MazeStyle("0.85", "black", 2, "black", None, 3, 0.0, False)


@dataclass(frozen=True)
class Frame:
    """What one rendered frame shows: a snapshot the environment hands the renderer.

    ``ranges`` are the noise-free rays to draw (``None``: no rays), ``ranges[i]`` along
    ``heading + 2*pi*i/len(ranges)``; ``goal`` is ``None`` in a goal-free run.
    """

    position: tuple[float, float]
    heading: float
    path: np.ndarray
    goal: np.ndarray | None
    goal_radius: float
    ranges: np.ndarray | None
    fps: float


def draw_maze(
    maze: Any, ax: Axes, goal: tuple[float, float] | np.ndarray | None = None, goal_radius: float = 0.3, style: MazeStyle = ENV_STYLE
) -> Axes:
    """Draw the arena, its obstacles and (optionally) a goal disk on ``ax``; returns ``ax``.

    ``maze`` is a :class:`MazeSpec` or any object with its ``size`` and ``obstacles``.
    """
    from matplotlib.patches import Circle, Polygon, Rectangle

    hw, hh = maze.size[0] / 2, maze.size[1] / 2
    ax.add_patch(Rectangle((-hw, -hh), 2 * hw, 2 * hh, facecolor=style.floor, edgecolor=style.wall, linewidth=style.wall_width, zorder=0))
    for poly in maze.obstacles:
        ax.add_patch(
            Polygon(np.asarray(poly), closed=True, facecolor=style.obstacle, edgecolor=style.obstacle_edge, zorder=style.obstacle_zorder)
        )
    if goal is not None and np.all(np.isfinite(goal)):
        ax.add_patch(Circle(tuple(goal), goal_radius, facecolor="none", edgecolor=GOAL_COLOUR, linewidth=2, zorder=3))
    margin = style.margin * max(hw, hh)
    ax.set_xlim(-hw - margin, hw + margin)
    ax.set_ylim(-hh - margin, hh + margin)
    ax.set_aspect("equal")
    if style.axis_labels:
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    return ax


def plot_maze(
    maze: MazeSpec | str, ax: Axes | None = None, goal: tuple[float, float] | None = None, title: str | None = None
) -> tuple[Figure | SubFigure, Axes]:
    """A figure of a maze (a spec, a built-in name or a JSON path); returns ``(fig, ax)``."""
    import matplotlib.pyplot as plt

    spec = MazeSpec.load(maze)
    fig: Figure | SubFigure
    if ax is None:
        fig, ax = plt.subplots(figsize=(4, 4))
    else:
        fig = ax.figure
    draw_maze(spec, ax, goal=goal if goal is not None else spec.goal)
    ax.set_title(title if title is not None else spec.name)
    return fig, ax


def check_human_display() -> None:
    """Raise ``RuntimeError`` if ``render_mode="human"`` could show no window here.

    Without a display, matplotlib quietly falls back to a backend that draws off-screen: the
    environment would then pause at every step and show nothing. Two causes are named: no display
    on Linux (neither ``DISPLAY`` nor ``WAYLAND_DISPLAY`` set), or a matplotlib backend that cannot
    open windows.
    """
    alternative = (
        'use render_mode="rgb_array" instead: render() then returns each frame as an array (gymnasium.wrappers.RecordVideo saves them)'
    )
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise RuntimeError(
            f'render_mode="human" needs a display to open a window in, and there is none (neither DISPLAY nor WAYLAND_DISPLAY is set); {alternative}'
        )
    import matplotlib

    backend = matplotlib.get_backend()
    if backend.lower() in NON_INTERACTIVE_BACKENDS:
        raise RuntimeError(
            f'render_mode="human" needs an interactive matplotlib backend, but matplotlib uses {backend!r}, which cannot open a window '
            f"(no GUI toolkit such as tkinter or PyQt found, or MPLBACKEND / matplotlib.use chose it); {alternative}"
        )


class Renderer:
    """Keeps one matplotlib figure per environment and redraws only what moves."""

    def __init__(self, maze: MazeSpec, human: bool = False, size_px: int = 480) -> None:
        import matplotlib

        self.human = human
        if human:
            import matplotlib.pyplot as plt

            plt.ion()
            self.fig = plt.figure(figsize=(5, 5))
        else:
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from matplotlib.figure import Figure

            self.fig = Figure(figsize=(size_px / 100, size_px / 100), dpi=100)
            self.canvas = FigureCanvasAgg(self.fig)
        from matplotlib.collections import LineCollection
        from matplotlib.patches import Circle

        self.ax = self.fig.add_axes((0.02, 0.02, 0.96, 0.96))
        draw_maze(maze, self.ax)
        self.ax.set_axis_off()
        self.goal = Circle((0, 0), 0.3, facecolor="none", edgecolor=GOAL_COLOUR, linewidth=2, zorder=3, visible=False)
        self.ax.add_patch(self.goal)
        (self.path,) = self.ax.plot([], [], color=ROBOT_COLOUR, linewidth=1, alpha=0.7, zorder=2)
        self.rays = LineCollection([], colors="#ff7f0e", linewidths=0.5, alpha=0.5, zorder=2)
        self.ax.add_collection(self.rays)
        self.body = Circle((0, 0), physics.ROBOT_RADIUS, facecolor=ROBOT_COLOUR, edgecolor="black", zorder=4)
        self.ax.add_patch(self.body)
        (self.nose,) = self.ax.plot([], [], color="white", linewidth=2, zorder=5)
        self._matplotlib = matplotlib

    def draw(self, frame: Frame) -> np.ndarray | None:
        x, y = frame.position
        heading = frame.heading
        self.body.center = (x, y)
        r = physics.ROBOT_RADIUS
        self.nose.set_data([x, x + r * math.cos(heading)], [y, y + r * math.sin(heading)])
        self.path.set_data(frame.path[:, 0], frame.path[:, 1])
        if frame.goal is not None:
            self.goal.center = tuple(frame.goal)
            self.goal.radius = frame.goal_radius
            self.goal.set_visible(True)
        else:
            self.goal.set_visible(False)
        if frame.ranges is not None:
            n = len(frame.ranges)
            every = max(1, n // MAX_DRAWN_RAYS)
            index = np.arange(0, n, every)
            angles = heading + 2 * math.pi * index / n
            ends = np.stack([x + frame.ranges[index] * np.cos(angles), y + frame.ranges[index] * np.sin(angles)], axis=1)
            self.rays.set_segments([[(x, y), tuple(end)] for end in ends])
        if self.human:
            import matplotlib.pyplot as plt

            self.fig.canvas.draw_idle()
            plt.pause(1.0 / frame.fps)
            return None
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()

    def close(self) -> None:
        if self.human:
            import matplotlib.pyplot as plt

            plt.close(self.fig)
