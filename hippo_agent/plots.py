"""Figures in the paper's style: place fields, reward maps, trajectories.

Every function returns ``(fig, ax)`` and draws into ``ax=`` when given one. Maps are hexagonal-bin
plots over the positions actually visited: unvisited bins stay empty, with the grey arena
underneath visible (paper, Fig. "place fields"). matplotlib is imported lazily.

Typical use, recording positions from ``info`` while the agent runs (analysis only; the agent
never sees them)::

    positions, rates = [], []
    ...  # each step: positions.append(info["position"]); rates.append(agent.place_rates)
    plot_place_field(positions, np.array(rates)[:, cell], maze=env.unwrapped.maze)
"""

from __future__ import annotations

from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any

import numpy as np

__all__ = ["grid_positions", "plot_place_field", "plot_reward_map", "plot_trajectories"]


def _axes(ax: Any = None, figsize: tuple[float, float] = (5.0, 5.0)) -> tuple[Any, Any]:
    if ax is not None:
        return ax.figure, ax
    try:
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - matplotlib is a dependency
        raise ImportError("hippo_agent.plots needs matplotlib: pip install matplotlib") from exc
    fig, ax = plt.subplots(figsize=figsize)
    return fig, ax


def grid_positions(size: tuple[float, float], spacing: float = 0.2, margin: float = 0.2) -> np.ndarray:
    """Grid of ``(x, y)`` positions over an arena of ``size`` centred on the origin, ``margin``
    metres from its walls (for :meth:`HippocampalAgent.place_field_map` / ``reward_map``)."""
    if spacing <= 0:
        raise ValueError(f"spacing={spacing} is invalid; allowed: a value > 0")
    half_w, half_h = size[0] / 2 - margin, size[1] / 2 - margin
    if half_w <= 0 or half_h <= 0:
        raise ValueError(f"margin={margin} leaves no room in an arena of size {tuple(size)}")
    xs = np.arange(-half_w, half_w + 1e-9, spacing)
    ys = np.arange(-half_h, half_h + 1e-9, spacing)
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx.ravel(), gy.ravel()])


def _draw_arena(ax: Any, maze: Any = None, size: tuple[float, float] | None = None) -> None:
    """The arena under a map: ``maze`` (a ``MazeSpec``-like object with ``size`` and ``obstacles``)
    or a bare floor of ``size``, drawn by :func:`hippo_env.render.draw_maze` in its plot style."""
    from hippo_env.render import PLOT_STYLE, draw_maze

    if maze is None:
        if size is None:
            return
        maze = SimpleNamespace(size=tuple(size), obstacles=())
    draw_maze(maze, ax, style=PLOT_STYLE)


def _draw_goal(ax: Any, goal: Any, goal_radius: float) -> None:
    from matplotlib.patches import Circle

    if goal is None:
        return
    goal = np.asarray(goal, dtype=float)
    if goal.shape == (2,) and np.all(np.isfinite(goal)):
        ax.add_patch(Circle(tuple(goal), goal_radius, facecolor="none", edgecolor="red", lw=2, zorder=4))


def _hexmap(
    positions: Any,
    values: Any,
    ax: Any,
    gridsize: int,
    maze: Any,
    size: Any,
    goal: Any,
    goal_radius: float,
    cmap: str,
    label: str,
    title: str | None,
    colorbar: bool,
) -> tuple[Any, Any]:
    positions = np.asarray(positions, dtype=float).reshape(-1, 2)
    values = np.asarray(values, dtype=float).ravel()
    if len(values) != len(positions):
        raise ValueError(f"{len(positions)} positions but {len(values)} values; give one value per position")
    keep = np.isfinite(values) & np.all(np.isfinite(positions), axis=1)
    fig, ax = _axes(ax)
    _draw_arena(ax, maze, size)
    extent = None
    if maze is not None or size is not None:
        w, h = tuple(maze.size) if maze is not None else size
        extent = (-w / 2, w / 2, -h / 2, h / 2)
    hb = ax.hexbin(
        positions[keep, 0],
        positions[keep, 1],
        C=values[keep],
        reduce_C_function=np.mean,
        gridsize=gridsize,
        mincnt=1,
        cmap=cmap,
        extent=extent,
        zorder=1,
    )  # mincnt=1: unvisited bins stay empty
    _draw_goal(ax, goal, goal_radius)
    ax.set_aspect("equal")
    if title:
        ax.set_title(title)
    if colorbar:
        fig.colorbar(hb, ax=ax, label=label)
    return fig, ax


def plot_place_field(
    positions: Any,
    rates: Any,
    ax: Any = None,
    *,
    gridsize: int = 30,
    maze: Any = None,
    size: tuple[float, float] | None = None,
    goal: Any = None,
    goal_radius: float = 0.3,
    cmap: str = "viridis",
    title: str | None = None,
    colorbar: bool = True,
) -> tuple[Any, Any]:
    """One place cell's rate as a hexbin over visited positions (mean rate per bin).

    Args:
        positions: ``(T, 2)`` positions visited.
        rates: ``(T,)`` the cell's rate at each.
        ax: axes to draw into (a new figure if ``None``).
        gridsize: hexagons across.
        maze: a ``MazeSpec``-like object to draw underneath (``size``, ``obstacles``).
        size: arena ``(width, height)`` when no ``maze`` is given.
        goal, goal_radius: a goal disk to outline in red.
        cmap, title, colorbar: appearance.
    """
    return _hexmap(positions, rates, ax, gridsize, maze, size, goal, goal_radius, cmap, "rate", title, colorbar)


def plot_reward_map(
    positions: Any,
    values: Any,
    ax: Any = None,
    *,
    gridsize: int = 30,
    maze: Any = None,
    size: tuple[float, float] | None = None,
    goal: Any = None,
    goal_radius: float = 0.3,
    cmap: str = "magma",
    title: str | None = None,
    colorbar: bool = True,
) -> tuple[Any, Any]:
    """The reward cell's value (eq. 9) as a hexbin over positions (visited, or a grid from
    :func:`grid_positions`; NaN values are left out). Arguments as :func:`plot_place_field`."""
    return _hexmap(positions, values, ax, gridsize, maze, size, goal, goal_radius, cmap, "value", title, colorbar)


def plot_trajectories(
    paths: Sequence[Any],
    ax: Any = None,
    *,
    maze: Any = None,
    size: tuple[float, float] | None = None,
    goal: Any = None,
    goal_radius: float = 0.3,
    labels: Sequence[str] | None = None,
    title: str | None = None,
) -> tuple[Any, Any]:
    """Trajectories (each ``(T, 2)`` positions), start marked with a dot, over the arena.

    Args:
        paths: one array of positions per run.
        ax: axes to draw into (a new figure if ``None``).
        maze, size: the arena to draw underneath (see :func:`hippo_env.render.draw_maze`).
        goal, goal_radius: a goal disk to outline in red.
        labels: one legend label per path.
        title: axes title.
    """
    fig, ax = _axes(ax)
    _draw_arena(ax, maze, size)
    if labels is not None and len(labels) != len(paths):
        raise ValueError(f"{len(paths)} paths but {len(labels)} labels; give one label per path")
    for n, path in enumerate(paths):
        path = np.asarray(path, dtype=float).reshape(-1, 2)
        (line,) = ax.plot(path[:, 0], path[:, 1], lw=1.2, zorder=2, label=None if labels is None else labels[n])
        if len(path):
            ax.plot(path[0, 0], path[0, 1], "o", color=line.get_color(), zorder=5)
    _draw_goal(ax, goal, goal_radius)
    ax.set_aspect("equal")
    if labels is not None:
        ax.legend(loc="best", fontsize="small")
    if title:
        ax.set_title(title)
    return fig, ax
