"""The one implementation of each geometric idea (hippo_env.geometry, MazeSpec) and the shared record helpers."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np
import pytest

from hippo_env.files import finite_or_none, jsonable, unknown_fields
from hippo_env.geometry import clearance, wrap_angle
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS


@pytest.mark.parametrize("angle", [0.0, math.pi, -math.pi, 3 * math.pi, -7.5, 1e3, 2 * math.pi - 1e-12])
def test_wrap_angle_lands_in_the_half_open_circle_and_keeps_the_direction(angle):
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped < math.pi
    assert math.cos(wrapped) == pytest.approx(math.cos(angle), abs=1e-9)
    assert math.sin(wrapped) == pytest.approx(math.sin(angle), abs=1e-9)


def test_clearance_of_many_points_is_that_of_each_point():
    spec = MazeSpec.load("maze2")
    points = np.random.default_rng(0).uniform(-5.5, 5.5, (500, 2))  # some outside the arena, some inside obstacles
    many = spec.clearances(points)
    assert np.array_equal(many, [spec.clearance(p) for p in points])
    assert np.array_equal(np.abs(many), [clearance(p, spec.segments) for p in points])
    assert np.array_equal(spec.free_mask(points, ROBOT_RADIUS), [spec.is_free(p, ROBOT_RADIUS) for p in points])


def test_distance_field_is_zero_at_the_goal_and_grows_around_an_obstacle():
    spec = MazeSpec.load("maze1")
    goal = spec.sample_free(np.random.default_rng(0), 0.5)
    field = spec.distance_field(goal, ROBOT_RADIUS, 0.1)
    rows, cols = field.cell(goal)
    assert field.distances[rows[0], cols[0]] == 0.0
    _, _, free = spec.free_grid(ROBOT_RADIUS, 0.1)
    assert np.all(np.isfinite(field.distances[free])) and np.all(np.isinf(field.distances[~free]))
    assert field.at(goal)[0] == 0.0 and field.distances.max(initial=0.0, where=free) > 0


def test_jsonable_writes_nan_and_infinity_as_null_and_numpy_as_python():
    record = {"a": math.nan, "b": np.float32(1.5), "c": [np.inf, 2], "d": np.arange(2), "e": (np.bool_(True),), 3: np.int64(4)}
    assert jsonable(record) == {"a": None, "b": 1.5, "c": [None, 2], "d": [0, 1], "e": [True], "3": 4}
    json.dumps(jsonable(record), allow_nan=False)
    assert finite_or_none(-math.inf) is None and finite_or_none(0.25) == 0.25


def test_unknown_fields_lists_the_names_that_are_no_field():
    @dataclass
    class Params:
        alpha: float = 1.0
        beta: int = 2

    assert unknown_fields(Params, ["beta", "zeta", "gamma"]) == ["gamma", "zeta"]
    assert unknown_fields(Params, {"alpha": 1}) == []


def test_one_draw_maze_serves_the_env_and_the_agent_figures():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_trajectories
    from hippo_env.render import PLOT_STYLE, draw_maze

    fig, axes = plt.subplots(1, 2)
    draw_maze(MazeSpec.load("maze1"), axes[0], goal=(1.0, 1.0))
    assert axes[0].get_xlabel() == "x (m)"
    draw_maze(MazeSpec.load("maze1"), axes[1], style=PLOT_STYLE)
    assert axes[1].get_xlim() == (-5.0, 5.0)
    plot_trajectories([np.zeros((3, 2))], axes[1], size=(4.0, 2.0))  # a bare floor of a size
    plt.close(fig)


def test_a_goal_on_a_cell_border_starts_the_field_at_one_nearest_free_cell():
    spec = MazeSpec.load("maze2")
    goal = np.array([3.2, 3.2])  # on the corner of four 0.1 m cells
    field = spec.distance_field(goal, ROBOT_RADIUS, 0.1)
    (row, col), *others = np.argwhere(field.distances == 0.0)
    assert not others
    _, _, free = spec.free_grid(ROBOT_RADIUS, 0.1)
    gx, gy = np.meshgrid(field.xs, field.ys)
    nearest = np.hypot(gx - goal[0], gy - goal[1])[free].min()
    assert np.hypot(field.xs[col] - goal[0], field.ys[row] - goal[1]) == nearest
