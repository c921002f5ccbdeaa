"""Seeded changes of a maze (hippo_env.changes): blocks added, a door (a shortcut), a barrier (a detour)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from hippo_env.changes import CHANGES, change_maze, main
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS

KEEP_CLEAR = 0.6  # m, hippo_env.changes.KEEP_CLEAR
MIN_EFFECT = 1.0  # m, hippo_env.changes.MIN_EFFECT
# A base maze each kind of change has something to change in.
BASES = {"blocks": "open", "door": "maze1", "barrier": "maze2"}


def _added(old: MazeSpec, new: MazeSpec) -> list:
    return [p for p in new.obstacles if p not in old.obstacles]


def _removed(old: MazeSpec, new: MazeSpec) -> list:
    return [p for p in old.obstacles if p not in new.obstacles]


def _segment_distance(p, a, b) -> float:
    p, a, b = (np.asarray(v, float) for v in (p, a, b))
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * (b - a))))


def _polygon_distance(p, polygon) -> float:
    return min(_segment_distance(p, a, b) for a, b in zip(polygon, polygon[1:] + polygon[:1]))


def _rectangle_axes(polygon):
    """The centre, the unit vector along the long side and across it, and the thickness of a rectangle."""
    corners = np.asarray(polygon, float)
    e1, e2 = corners[1] - corners[0], corners[3] - corners[0]
    if np.linalg.norm(e1) < np.linalg.norm(e2):
        e1, e2 = e2, e1
    return corners.mean(axis=0), e1 / np.linalg.norm(e1), e2 / np.linalg.norm(e2), float(np.linalg.norm(e2))


@pytest.mark.parametrize("kind", CHANGES)
def test_each_change_is_reproducible_from_its_seed(kind):
    first = change_maze(BASES[kind], kind, 3)
    assert change_maze(BASES[kind], kind, 3) == first
    assert first.name == f"{BASES[kind]}+{'blocks12' if kind == 'blocks' else kind}-3"
    assert first.obstacles != MazeSpec.load(BASES[kind]).obstacles


def test_other_seeds_place_other_blocks():
    assert change_maze("open", "blocks", 0).obstacles != change_maze("open", "blocks", 1).obstacles


@pytest.mark.parametrize("kind", CHANGES)
@pytest.mark.parametrize("seed", [0, 1])
def test_each_change_keeps_the_free_space_connected(kind, seed):
    change_maze(BASES[kind], kind, seed).check_connected(ROBOT_RADIUS)  # raises if split


def test_blocks_keep_clear_of_the_points_given():
    plain = change_maze("open", "blocks", 0, count=12)
    centres = [np.mean(block, axis=0) for block in plain.obstacles]
    inner = [c for c in centres if np.max(np.abs(c)) <= 3.5][:3]  # away from the arena's walls
    assert inner, "the test needs a block away from the walls"
    kept = change_maze("open", "blocks", 0, count=12, keep_clear=inner)
    assert len(kept.obstacles) == 12
    for point in inner:
        assert plain.inside_obstacle(tuple(point))  # the plain change covered it
        assert min(_polygon_distance(point, list(block)) for block in kept.obstacles) >= KEEP_CLEAR - 1e-9
        assert not kept.inside_obstacle(tuple(point))


def test_blocks_have_the_count_and_side_asked_for():
    changed = change_maze("open", "blocks", 2, count=5, side=2.0)
    assert len(changed.obstacles) == 5
    for block in changed.obstacles:
        xs, ys = zip(*block)
        assert max(xs) - min(xs) == pytest.approx(2.0) and max(ys) - min(ys) == pytest.approx(2.0)


def test_a_barrier_keeps_clear_of_the_points_given():
    base = MazeSpec.load("maze2")
    (bar,) = _added(base, change_maze(base, "barrier", 0))
    middle = tuple(np.mean(bar, axis=0))
    (other,) = _added(base, change_maze(base, "barrier", 0, keep_clear=[middle]))
    assert other != bar
    assert _polygon_distance(middle, list(other)) >= KEEP_CLEAR - 0.1 - 1e-6  # its centre line 0.6 m away; 0.1 m its half thickness


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_door_shortens_the_way_between_the_two_sides_of_its_wall(seed):
    base = MazeSpec.load("maze1")
    changed = change_maze(base, "door", seed)
    (wall,) = _removed(base, changed)
    centre, along, across, thickness = _rectangle_axes(wall)
    length = max(np.linalg.norm(np.subtract(wall[k], wall[0])) for k in (1, 3))
    line = [centre + along * s for s in np.linspace(-length / 2, length / 2, 401)]
    gap = [p for p in line if not changed.inside_obstacle(tuple(p))]
    assert gap, "the door's gap lies on the wall's centre line"
    door = np.mean(gap, axis=0)
    sides = [tuple(door + s * across * (thickness / 2 + 0.6)) for s in (1.0, -1.0)]
    before, after = base.geodesic(*sides, ROBOT_RADIUS), changed.geodesic(*sides, ROBOT_RADIUS)
    assert after <= before - MIN_EFFECT
    assert after == pytest.approx(math.dist(*sides), abs=0.05)  # straight through the door


@pytest.mark.parametrize(("maze", "seed"), [("maze2", 0), ("maze3", 0), ("maze4", 1)])
def test_a_barrier_lengthens_the_way_between_the_two_sides_of_its_gap(maze, seed):
    base = MazeSpec.load(maze)
    changed = change_maze(base, "barrier", seed)
    (bar,) = _added(base, changed)
    centre, _, across, _ = _rectangle_axes(bar)
    sides = [tuple(centre + s * across * 0.6) for s in (1.0, -1.0)]
    assert changed.geodesic(*sides, ROBOT_RADIUS) >= base.geodesic(*sides, ROBOT_RADIUS) + MIN_EFFECT


@pytest.mark.parametrize(
    ("maze", "kind", "kwargs", "message"),
    [
        ("maze4", "door", {}, "maze 'maze4' has no straight wall at least 1.45 m long to cut a door in"),
        ("open", "door", {}, "maze 'open' has no straight wall"),
        ("open", "barrier", {}, "maze 'open' has no obstacle: no gap to close"),
        ("open", "blocks", {"count": 200}, "maze 'open': only"),
        ("open", "blocks", {"count": 0}, "count >= 1 and side > 0"),
        ("open", "tunnel", {}, "change 'tunnel' is unknown; allowed: blocks, door, barrier"),
    ],
)
def test_nothing_to_change_is_a_clear_error(maze, kind, kwargs, message):
    with pytest.raises(ValueError) as err:
        change_maze(maze, kind, 0, **kwargs)
    assert message in str(err.value)


def test_the_command_line_prints_the_changed_maze(capsys):
    assert main(["open", "blocks", "--seed", "3", "--count", "4", "--keep-clear", "0", "0"]) == 0
    changed = MazeSpec.from_dict(json.loads(capsys.readouterr().out))
    assert changed == change_maze("open", "blocks", 3, count=4, keep_clear=[(0.0, 0.0)])
    assert main(["maze4", "door"]) == 2
    assert "error: maze 'maze4' has no straight wall" in capsys.readouterr().err
