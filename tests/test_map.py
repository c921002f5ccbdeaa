"""The map and its planner (:mod:`hippo_agent.faculties.map`): what a scan writes, the fit of a scan
to the map, the searches (breadth-first, into a disk, squeezing through narrow doorways), the
straight line in sight, and the map's own saved state."""

from __future__ import annotations

import math

import numpy as np
import pytest
from agent_helpers import ring_scan, same_state

from hippo_agent import MapConfig
from hippo_agent.faculties.map import ExplorationMap


def test_scan_marks_free_ground_and_walls():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.observe(np.zeros(2), 0.0, ring_scan(), max_range=10.0)
    free = m.known_free
    for x, y in [(0.0, 0.0), (1.0, 0.0), (0.0, -1.5), (-1.0, 1.0)]:
        assert free[m.index(x, y)], (x, y)
    for x, y in [(2.0, 0.0), (0.0, 2.0), (-2.0, 0.0), (0.0, -2.0)]:
        i, j = m.index(x, y)
        assert m.hits[i, j] > 0 and not free[i, j], (x, y)
    assert not free[m.index(3.0, 0.0)]  # behind the wall: unknown
    assert 8.0 < m.explored_area() < math.pi * 2.0**2


def test_a_bump_is_expected_within_a_cell_of_a_wall_the_map_holds():
    """``wall_near``: the ring's wall 0.3 m ahead of a robot at its foot, in any direction; none
    ahead in the middle of the room, nor beyond the map's edge (no error there)."""
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.observe(np.zeros(2), 0.0, ring_scan(), max_range=10.0)
    for angle in np.linspace(-math.pi, math.pi, 16, endpoint=False):
        at_the_foot = 1.8 * np.array([math.cos(angle), math.sin(angle)])
        assert m.wall_near(at_the_foot, angle, 0.3), angle
        assert not m.wall_near(np.zeros(2), angle, 0.3), angle
    assert not m.wall_near(np.array([-4.9, -4.9]), -2.4, 0.3)


def test_planner_goes_to_unvisited_ground_until_none_is_left():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.observe(np.zeros(2), 0.0, ring_scan(), max_range=10.0)
    assert m.heading_to_unvisited(np.zeros(2)) is not None
    # stand everywhere in the room: nothing unvisited is left
    for x in np.arange(-1.6, 1.7, 0.2):
        for y in np.arange(-1.6, 1.7, 0.2):
            if math.hypot(x, y) < 1.6:
                m.observe(np.array([x, y]), 0.0, ring_scan(radius=2.0 - math.hypot(x, y)), max_range=10.0)
    assert m.heading_to_unvisited(np.zeros(2)) is None
    # a new run has searched nothing yet
    m.new_run()
    assert m.heading_to_unvisited(np.zeros(2), this_run=True) is not None


def test_walkable_points_lie_on_known_ground_clear_of_walls():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    assert m.walkable_points().shape == (0, 2)  # nothing known yet
    m.observe(np.zeros(2), 0.0, ring_scan(radius=2.0), max_range=10.0)
    points = m.walkable_points()
    assert len(points) > 10
    distance = np.hypot(points[:, 0], points[:, 1])
    assert distance.max() < 2.0 - m.cell  # a cell clear of the round wall
    assert np.all([m.known_free[m.index(x, y)] for x, y in points])
    assert len(m.walkable_points(stride=1)) > 3 * len(points)


def test_a_scan_entered_unknown_only_leaves_what_the_map_knows():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=2.0), max_range=10.0)
    free, hits = m.free.copy(), m.hits.copy()
    # the same room seen from a place 1 m off (a misplaced estimate): its walls would land on known ground
    m.observe(np.array([1.0, 0.0]), 0.0, ring_scan(radius=2.0), max_range=10.0, unknown_only=True)
    known = (free > 0) | (hits > 0)
    assert np.array_equal(m.free[known], free[known]) and np.array_equal(m.hits[known], hits[known])
    assert m.known_free[m.index(2.5, 0.0)]  # beyond the old wall: new ground entered
    m.observe(np.array([1.0, 0.0]), 0.0, ring_scan(radius=2.0), max_range=10.0)
    assert not np.array_equal(m.free[known], free[known])  # (entered everywhere, it would change)


def test_path_goes_around_a_wall():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.free[:] = 1  # all free ...
    i0, i1 = m.index(0.0, -3.0)[1], m.index(0.0, 2.0)[1]
    m.hits[m.index(0.0, 0.0)[0], i0:i1] = 5  # ... but a wall along x = 0 from y = -3 to y = 2
    target = m.flat_index(2.0, 0.0)
    path = m.path(np.array([-2.0, 0.0]), target)
    assert path.size > 0 and path[-1] == target
    centres = np.array([m.centre(c) for c in path])
    assert centres[:, 1].max() > 2.0  # it went round the wall's open end
    assert not any(m.hits[divmod(int(c), m.n)] for c in path)


def test_the_planner_heads_straight_for_a_point_in_sight_not_along_the_search_grid():
    """The breadth-first search's 8-connected path to a place about 20 degrees off the grid's axes
    zig-zags; across open ground the planner heads straight at the path's farthest point in sight
    instead. Behind a wall, the point in sight is round the wall's end."""
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.free[:] = 1
    start, target = np.array([0.0, 0.0]), np.array([1.5, 0.5])
    heading = m.heading_to(start, m.flat_index(*target))
    assert heading is not None
    cx, cy = m.centre(m.flat_index(*target))
    assert abs(heading - math.atan2(cy - start[1], cx - start[0])) < math.radians(5), math.degrees(heading)
    wall_row = m.index(0.75, 0.0)[0]
    m.hits[wall_row, m.index(0.0, -3.0)[1] : m.index(0.0, 0.5)[1]] = 5  # a wall along x = 0.75 up to y = 0.5
    m.grids_replaced()  # (written by hand, so announced)
    heading = m.heading_to(start, m.flat_index(*target))
    assert heading is not None and 0.75 * math.tan(heading) > 0.5, math.degrees(heading)  # passes the wall's end


def test_a_search_squeezes_through_a_doorway_the_map_holds_too_narrow():
    """A doorway one free cell wide has walls in every 3 x 3 block along it, so no walkable path
    leads through: the plain search finds nothing left, the squeezing one plans through it."""
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.free[:] = 1
    wall_row, door = m.index(0.0, 0.0)
    m.hits[wall_row, :] = 5  # a wall along x = 0 ...
    m.hits[wall_row, door] = 0  # ... with a one-cell gap at y = 0
    m.searched[: wall_row + 1, :] = True  # this side searched
    m.grids_replaced()
    assert m.heading_to_unvisited(np.array([-2.0, 0.0]), this_run=True) is None
    heading = m.heading_to_unvisited(np.array([-2.0, 0.0]), this_run=True, squeeze=True)
    assert heading is not None and abs(heading) < math.pi / 4, heading  # toward the gap, at +x
    path = m.path(np.array([-2.0, 0.0]), -1, m.searched, squeeze=True)
    assert wall_row * m.n + door in path.tolist()  # through the gap


def test_local_search_heads_for_unsearched_ground_near_a_place_until_none_is_left():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=3.0), max_range=10.0)
    m.new_run()
    centre = np.array([1.0, 0.0])
    # searched only around the robot at the origin: the nearest unsearched ground near (1, 0) lies toward +x
    m.observe(np.zeros(2), 0.0, ring_scan(radius=3.0), max_range=10.0)
    heading = m.heading_to_unsearched_near(np.zeros(2), centre, 0.8)
    assert heading is not None and math.cos(heading) > 0.5
    for x in np.arange(0.1, 1.95, 0.1):
        for y in np.arange(-0.9, 0.95, 0.1):
            m.observe(np.array([x, y]), 0.0, ring_scan(radius=3.0 - math.hypot(x, y)), max_range=10.0, unknown_only=True)
    assert m.heading_to_unsearched_near(np.zeros(2), centre, 0.8) is None  # all of the disk searched
    assert m.heading_to_unvisited(np.zeros(2), this_run=True) is not None  # (ground farther away is not)


def test_planning_near_a_place_by_a_wall_ends_on_walkable_ground_beside_it():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.3))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=2.0), max_range=10.0)
    by_the_wall = np.array([1.95, 0.0])
    assert m.heading_to(np.zeros(2), m.flat_index(*by_the_wall)) is None  # the place itself is not walkable
    heading = m.heading_to_near(np.array([-1.0, 0.0]), by_the_wall, 0.6)
    assert heading is not None and math.cos(heading) > 0.5  # (an 8-connected path: up to 45 degrees off)


def test_homing_reuses_its_search_only_from_the_same_cell_on_the_same_grids():
    """Homing plans at every step, and the robot stays in one cell for several: from the same cell
    to the same place on unchanged grids the search is reused, and the heading still comes from the
    robot's exact position. A bump, a scan with new ground, or grids written by hand (announced
    with ``grids_replaced``) make it search again."""
    m = ExplorationMap(MapConfig(extent=5.0))
    m.free[:] = 1
    place = np.array([2.0, 0.0])
    first = m.heading_to_near(np.array([-2.0, 0.0]), place, 0.3)
    searches = int(m._search_id[0])
    nudged = m.heading_to_near(np.array([-2.0, 0.05]), place, 0.3)  # the same cell
    assert int(m._search_id[0]) == searches and first is not None and nudged is not None
    assert nudged != first and abs(nudged - first) < math.radians(5)
    wall_row = m.index(0.0, 0.0)[0]
    m.hits[wall_row, m.index(0.0, -3.0)[1] : m.index(0.0, 2.0)[1]] = 5  # a wall across the way ...
    m.grids_replaced()  # ... written by hand, so announced
    around = m.heading_to_near(np.array([-2.0, 0.0]), place, 0.3)
    assert around is not None and math.sin(around) > 0.3, math.degrees(around)  # round the wall's open end, at +y
    revision = m.revision
    m.mark_bump(np.array([-2.0, 0.0]), around, 0.3)
    assert m.revision == revision + 1
    m.heading_to_near(np.array([-2.0, 0.0]), place, 0.3)
    assert int(m._search_id[0]) > searches + 1  # searched again after the bump
    m.observe(np.array([-2.0, 0.0]), 0.0, ring_scan(radius=1.0), max_range=10.0, unknown_only=True)
    assert m.revision == revision + 1  # (a scan of ground the map knows changes nothing)


def test_a_line_is_in_sight_over_walkable_ground_only_and_the_walkability_follows_the_grids():
    """``in_sight``: the straight line homing takes when it can. Across open ground it is in sight;
    with a wall across it, written by hand and announced, it is not, though the open ground was
    worked out walkable before (walkability is remembered per state of the grids); nor is a line
    with less than a cell of walkable ground beside it."""
    m = ExplorationMap(MapConfig(extent=5.0))
    m.free[:] = 1
    start, end = np.array([-2.0, 0.3]), np.array([2.0, -0.4])
    assert m.in_sight(start, end) and m.in_sight(end, start)
    m.hits[m.index(0.0, 0.0)[0], m.index(0.0, -1.0)[1] : m.index(0.0, 1.0)[1]] = 5  # a wall 2 m long across it
    m.grids_replaced()
    assert not m.in_sight(start, end) and not m.in_sight(end, start)
    assert m.in_sight(np.array([-2.0, 3.0]), np.array([2.0, 3.0]))  # (well beyond the wall's end)
    by_the_end = np.array([-2.0, 1.3]), np.array([2.0, 1.3])  # 0.3 m past the wall's end: on walkable cells ...
    assert m.in_sight(*by_the_end, margin=0) and not m.in_sight(*by_the_end)  # ... but not with a cell to spare


def test_the_fit_around_a_place_is_the_fit_at_it_and_at_the_offsets_from_it():
    m = ExplorationMap(MapConfig(extent=8.0))
    m.observe(np.zeros(2), 0.2, ring_scan(radius=4.0), max_range=10.0)
    rng = np.random.default_rng(2)
    here, offsets, ranges = rng.uniform(-1.0, 1.0, 2), rng.uniform(-3.0, 3.0, (9, 2)), rng.uniform(0.5, 6.0, 720)
    around = m.scan_agreement(offsets, 0.4, ranges, 10.0, around=here)
    np.testing.assert_array_equal(around, m.scan_agreement(np.vstack((here, here + offsets)), 0.4, ranges, 10.0))
    assert around.shape == (10,) and np.count_nonzero(around) > 5


def test_the_judged_fit_from_the_same_ray_march_equals_its_own_call():
    """``judged``: the first place's fit with short readings and unknown ends left out, written by
    the march of a fit with other weights, is the number a call of its own gives, bit for bit
    (walls, short readings, rays through walls, rays ending on unknown ground and a new wall)."""
    m = ExplorationMap(MapConfig(extent=8.0))
    m.observe(np.zeros(2), 0.2, ring_scan(radius=4.0), max_range=10.0)
    m.mark_bump(np.array([1.0, 0.0]), 0.0, 0.3, new=True)
    rng = np.random.default_rng(3)
    seen = set()
    for _ in range(20):
        here, offsets, ranges = rng.uniform(-2.0, 2.0, 2), rng.uniform(-3.0, 3.0, (8, 2)), rng.uniform(0.3, 9.0, 720)
        judged = np.empty(1)
        fits = m.scan_agreement(offsets, 0.4, ranges, 10.0, around=here, short_weight=0.25, judged=judged)
        alone = m.scan_agreement(here[None, :], 0.4, ranges, 10.0, short_weight=0.0, judged_only=True)
        assert judged[0] == alone[0]
        np.testing.assert_array_equal(fits, m.scan_agreement(offsets, 0.4, ranges, 10.0, around=here, short_weight=0.25))
        seen.add(float(judged[0]))
    assert len(seen) > 10  # (fits that differ: the comparison means something)


def test_grid_indices_by_multiplication_equal_those_by_division():
    """A power-of-two cell (the default 0.25 m) lets the ray marches multiply by 1 / cell instead of
    dividing: the scan's fit from many places is the same either way. Any other cell divides."""
    from hippo_agent.faculties._fit_kernel import scan_agreement

    m = ExplorationMap(MapConfig(extent=8.0))
    for x in (-1.0, 0.0, 1.0):
        m.observe(np.array([x, 0.5 * x]), 0.2, ring_scan(radius=4.0), max_range=10.0)  # a round room of 4 m
    assert m._inv_cell == 1.0 / m.cell == 4.0
    assert ExplorationMap(MapConfig(cell=0.3))._inv_cell == 0.0
    rng = np.random.default_rng(0)
    points = rng.uniform(-6.0, 6.0, (200, 2))
    ranges = rng.uniform(0.2, 9.0, 720).astype(np.float32)
    fits = []
    for inv_cell in (m._inv_cell, 0.0):
        out = np.empty(len(points))
        scan_agreement(
            m.free,
            m.hits,
            m._walls(),
            0.0,
            0.0,
            False,
            points,
            0.3,
            ranges,
            20,
            10.0,
            m.extent,
            m.cell,
            inv_cell,
            m.hit_range,
            1.0,
            False,
            out,
            np.empty(0),
            1.0,
        )
        fits.append(out)
    np.testing.assert_array_equal(fits[0], fits[1])
    assert np.count_nonzero(fits[0]) > 100  # (most places judged)


def test_a_local_search_marks_a_narrower_path_and_starts_afresh_round_the_place():
    m = ExplorationMap(MapConfig(extent=5.0, visit_radius=0.5, search_radius=0.6))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=3.0), max_range=10.0)
    assert m.searched[m.index(0.4, 0.0)]  # the run's search marks 0.6 m round the robot
    m.new_run()
    m.observe(np.zeros(2), 0.0, ring_scan(radius=3.0), max_range=10.0, search_radius=0.25)
    assert m.searched[m.index(0.0, 0.0)] and not m.searched[m.index(0.4, 0.0)]
    m.observe(np.array([1.0, 0.0]), 0.0, ring_scan(radius=2.0), max_range=10.0)
    m.forget_searched_near(np.array([1.0, 0.0]), 0.5)
    assert not m.searched[m.index(1.0, 0.0)] and not m.searched[m.index(1.3, 0.0)]
    assert m.searched[m.index(0.0, 0.0)] and m.searched[m.index(1.3, 0.3)]  # outside the disk: kept


def test_long_rays_through_a_wall_the_map_holds_count_against_a_place():
    """Rays longer than ``hit_range`` (out through a door, down a corridor) count against a place
    from which they would pass through a wall the map holds, and are left out otherwise, so two
    places alike up close differ."""
    m = ExplorationMap(MapConfig(extent=12.0, visit_radius=0.5, search_radius=0.3))
    for y in np.arange(-1.0, 1.01, m.cell / 2):  # a wall 2 m long at x = 3
        m.hits[m.index(3.0, y)] = 3
    ranges = np.full(72, 8.0, dtype=np.float32)  # nothing nearer than 8 m in any direction
    near, far = m.scan_agreement(np.array([[5.0, 0.0], [5.0, 10.0]]), 0.0, ranges, max_range=10.0)
    assert near == -1.0  # its westward rays would have stopped at the wall
    assert far == 0.0  # no ray passes the wall, and none ends near enough to judge: no evidence


def _disk_as_known(m: ExplorationMap, done: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    """``done`` inside the disk, everything outside it known: what the breadth-first search needs
    to look for the same cells as the search into the disk."""
    inside = np.zeros_like(done)
    for flat in range(m.n * m.n):
        x, y = m.centre(flat)
        inside[divmod(flat, m.n)] = math.hypot(x - centre[0], y - centre[1]) <= radius + 1e-9
    return np.where(inside, done, True)


def test_the_search_into_a_disk_finds_paths_as_short_as_the_breadth_first_search():
    """Homing's A* search (``path(..., disk=...)``) against the breadth-first search over the same
    cells, on random maps with walls, holes and searched ground: the same cells found or not, paths
    of the same number of steps, each a chain of neighbouring cells ending on a goal cell."""
    rng = np.random.default_rng(3)
    compared = 0
    for _ in range(60):
        m = ExplorationMap(MapConfig(extent=4.0))
        m.free[:] = 1
        for _ in range(rng.integers(0, 25)):
            i, j = rng.integers(1, m.n - 1, 2)
            length = int(rng.integers(1, 12))
            if rng.random() < 0.5:
                m.hits[i, j : j + length] = 5
            else:
                m.hits[i : i + length, j] = 5
        m.free[rng.random(m.free.shape) < 0.05] = 0
        done = rng.random(m.free.shape) < 0.3
        position, centre, radius = rng.uniform(-3.5, 3.5, 2), rng.uniform(-3.5, 3.5, 2), float(rng.uniform(0.3, 1.2))
        known = _disk_as_known(m, done, centre, radius)
        for squeeze in (False, True):
            fast = m.path(position, -1, done, squeeze, disk=(centre, radius))
            breadth_first = m.path(position, -1, known, squeeze)
            assert fast.size == breadth_first.size
            if fast.size:
                compared += 1
                assert not known[divmod(int(fast[-1]), m.n)]
                steps = np.abs(np.diff(np.column_stack(np.divmod(fast, m.n)), axis=0)).max(axis=1)
                assert np.all(steps == 1)
    assert compared > 30  # (most maps have a path)


# ------------------------------------------------------------------ save / load
def test_the_state_of_the_map_loads_into_a_fresh_one_that_plans_the_same():
    m = ExplorationMap(MapConfig(extent=5.0))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=3.0), max_range=10.0)
    m.observe(np.array([1.0, 0.5]), 0.3, ring_scan(radius=2.0), max_range=10.0)
    m.mark_bump(np.array([1.0, 0.5]), 0.0, 0.3)
    m.new_run()
    m.observe(np.array([-0.5, 0.0]), 0.0, ring_scan(radius=2.5), max_range=10.0, search_radius=0.25)
    here, place = np.array([-1.0, -0.5]), np.array([1.5, 1.0])
    before = (m.heading_to_near(here, place, 0.6), m.heading_to_unvisited(here, this_run=True))  # (searches cached by the map)
    fresh = ExplorationMap(MapConfig(extent=5.0))
    revision = fresh.revision
    fresh.load_state(*m.state())
    same_state(fresh.state(), m.state())
    assert fresh.revision > revision  # (new grids: nothing worked out on the old ones is reused)
    assert (fresh.heading_to_near(here, place, 0.6), fresh.heading_to_unvisited(here, this_run=True)) == before
    ranges = ring_scan(n_rays=72, radius=2.2)
    points = np.random.default_rng(0).uniform(-2.0, 2.0, (20, 2))
    np.testing.assert_array_equal(fresh.scan_agreement(points, 0.1, ranges, 10.0), m.scan_agreement(points, 0.1, ranges, 10.0))


def test_the_scans_fit_reads_the_walls_as_the_grids_hold_them_after_every_change():
    """The fit reads a grid of wall kinds worked out once per revision: after each change to the
    walls (a scan entered, a bump, a revised scan, walls forgotten) it is that of a fresh map
    loaded with the same grids, which works the kinds out anew."""
    m = ExplorationMap(MapConfig(extent=5.0))
    ranges = ring_scan(n_rays=72, radius=2.2)
    points = np.random.default_rng(1).uniform(-2.0, 2.0, (20, 2))

    def as_fresh() -> None:
        fresh = ExplorationMap(MapConfig(extent=5.0))
        fresh.load_state(*m.state())
        np.testing.assert_array_equal(m.scan_agreement(points, 0.1, ranges, 10.0), fresh.scan_agreement(points, 0.1, ranges, 10.0))

    m.observe(np.zeros(2), 0.0, ring_scan(radius=3.0), max_range=10.0)
    as_fresh()
    before = m.scan_agreement(points, 0.1, ranges, 10.0)
    for k in range(4):  # bumps write walls round the origin, where the ring's rays end
        m.mark_bump(np.zeros(2), k * math.pi / 2, 2.2, new=True)
        as_fresh()
    assert not np.array_equal(before, m.scan_agreement(points, 0.1, ranges, 10.0))
    m.revise(np.zeros(2), 0.0, ring_scan(radius=1.5), 10.0)
    as_fresh()
    m.forget_new_walls()
    as_fresh()


@pytest.mark.parametrize("spoil", ["missing", "shape"])
def test_a_malformed_map_state_raises_value_error(spoil):
    m = ExplorationMap(MapConfig(extent=5.0))
    m.observe(np.zeros(2), 0.0, ring_scan(), max_range=10.0)
    state, arrays = m.state()
    if spoil == "missing":
        arrays = {name: value for name, value in arrays.items() if name != "hits"}
    else:  # the grids of a map of another extent
        arrays = ExplorationMap(MapConfig(extent=4.0)).state()[1]
    with pytest.raises(ValueError, match="the map's array"):
        ExplorationMap(MapConfig(extent=5.0)).load_state(state, arrays)


# ------------------------------------------------------------------ a world that changes
def _ring(radius: float, n: int = 720) -> np.ndarray:
    return np.full(n, radius)


def _wall(m: ExplorationMap, cell: tuple[int, int]) -> bool:
    return bool(m.hits[cell] > 0 and m.hits[cell] >= m.free[cell])


def test_a_boundary_seen_on_free_ground_becomes_a_new_wall_after_new_wall_evidence_scans():
    m = ExplorationMap(MapConfig(extent=5.0, new_wall_evidence=5))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)  # a round room of 3 m
    scan = _ring(3.0)
    scan[:5] = 1.0  # something 1 m east, where the map knows free ground
    cell = m.index(1.0, 0.0)
    for k in range(5):
        assert not _wall(m, cell), k  # not yet
        m.revise(np.zeros(2), 0.0, scan, max_range=10.0)
    assert _wall(m, cell) and m.new_walls[cell]
    # a ray through a wall written in a run is no evidence against the place: the fit there stays
    gone = _ring(3.0)
    assert m.scan_agreement(np.zeros((1, 2)), 0.0, gone, 10.0)[0] == pytest.approx(1.0)


def _pacing(k: int) -> np.ndarray:
    """The robot's place at its ``k``-th scan: back and forth between two neighbouring cells."""
    return np.array([-0.25 * (k % 2), 0.0])


def test_a_wall_the_rays_cross_is_cleared_after_gone_wall_evidence_scans_unless_a_ray_ends_by_it():
    config = MapConfig(extent=6.0, gone_wall_evidence=15)
    m = ExplorationMap(config)
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    east = m.index(3.0, 0.0)
    assert _wall(m, east)
    farther = _ring(5.0)  # the wall gone: every ray goes on to 5 m
    for k in range(14):
        m.revise(_pacing(k), 0.0, farther, max_range=10.0)
    assert _wall(m, east)  # 14 scans: still held
    m.revise(_pacing(14), 0.0, farther, max_range=10.0)
    assert m.hits[east] == 0 and m.known_free[east]
    held = ExplorationMap(config)  # rays that end by the wall (it is there, only grazed) keep it
    held.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    grazed = _ring(3.0)
    grazed[::20] = 5.0  # every other ray the map reads (one in 10, 5 degrees apart) passes, its neighbours end on the wall
    for k in range(30):
        held.revise(_pacing(k), 0.0, grazed, max_range=10.0)
    assert _wall(held, east)


def test_with_gone_paired_a_wall_is_cleared_only_where_rays_beside_each_other_see_through_it():
    """One ray through a wall, its neighbours ending short of it (at a small error in the estimate,
    a ray grazing a thin wall), is no evidence with ``gone_paired``; an opening seen over three rays is."""

    def after(scan: np.ndarray, paired: bool) -> ExplorationMap:
        m = ExplorationMap(MapConfig(extent=6.0, gone_wall_evidence=3, gone_paired=paired))
        m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
        for k in range(6):
            m.revise(_pacing(k), 0.0, scan, max_range=10.0)
        return m

    alone = _ring(3.0)
    alone[[710, 10]] = 2.0  # the map's rays beside the east one (5 degrees off) end 2 m out
    alone[0] = 5.0  # the east ray passes the wall
    opening = alone.copy()
    opening[[710, 10]] = 5.0  # three of the map's rays pass: an opening about 0.5 m wide
    for scan, paired, cleared in ((alone, False, True), (alone, True, False), (opening, True, True)):
        m = after(scan, paired)
        assert _wall(m, m.index(3.0, 0.0)) is not cleared, (paired, cleared)


def test_a_robot_standing_still_counts_a_crossing_once():
    """The same crossing seen again from the cell the robot stood in at the last count is no new
    evidence (a robot turning on the spot, say, scans the same rays again)."""
    m = ExplorationMap(MapConfig(extent=6.0, gone_wall_evidence=3))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    east = m.index(3.0, 0.0)
    for _ in range(10):
        m.revise(np.zeros(2), 0.0, _ring(5.0), max_range=10.0)
    assert _wall(m, east) and m.change[east] == 1
    m.revise(_pacing(1), 0.0, _ring(5.0), max_range=10.0)
    m.revise(_pacing(2), 0.0, _ring(5.0), max_range=10.0)
    assert m.hits[east] == 0


def test_gone_range_lets_farther_rays_clear_a_wall_without_entering_farther_cells():
    def after(gone_range: float) -> ExplorationMap:
        m = ExplorationMap(MapConfig(extent=8.0, gone_wall_evidence=3, gone_range=gone_range))
        m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)  # the wall at 3 m, seen from the centre
        for k in range(3):  # then from 2 m west of it: the wall 5 m off, the scan reading 7 m
            m.revise(np.array([-2.0 - 0.25 * (k % 2), 0.0]), 0.0, _ring(7.0), max_range=10.0)
        return m

    east = (3.0, 0.0)
    assert _wall(after(4.0), after(4.0).index(*east))  # beyond free_range (4 m): no evidence
    cleared = after(6.0)
    assert not _wall(cleared, cleared.index(*east))
    assert cleared.free[cleared.index(4.0, 0.0)] == 0  # 6 m from the robot: entered by no ray


def test_without_evidence_settings_a_run_only_fills_in_the_unknown():
    m = ExplorationMap(MapConfig(extent=5.0, new_wall_evidence=None, gone_wall_evidence=None))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    before = (m.free.copy(), m.hits.copy())
    scan = _ring(3.0)
    scan[:5] = 1.0
    for _ in range(20):
        m.revise(np.zeros(2), 0.0, scan, max_range=10.0)
    assert np.array_equal(m.hits, before[1]) and not m.new_walls.any()


def test_known_ground_is_free_ground_the_map_holds():
    m = ExplorationMap(MapConfig(extent=5.0))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    assert m.known_ground(np.array([1.0, 1.0])) and not m.known_ground(np.array([4.5, 4.5]))


def test_the_beam_models_short_readings_weigh_short_weight():
    """A boundary where the map knows free ground costs a place ``short_weight`` of a ray through a wall."""
    m = ExplorationMap(MapConfig(extent=5.0))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    scan = _ring(3.0)
    scan[: len(scan) // 2] = 1.5  # half the scan ends short, on free ground
    full, half, none = (m.scan_agreement(np.zeros((1, 2)), 0.0, scan, 10.0, short_weight=w)[0] for w in (1.0, 0.5, 0.0))
    assert full == pytest.approx(0.0, abs=0.05) and none == pytest.approx(1.0) and full < half < none


def test_flat_indices_and_centres_are_flat_index_and_centre_for_many():
    m = ExplorationMap(MapConfig(extent=5.0))
    points = np.random.default_rng(4).uniform(-4.99, 4.99, (500, 2))
    flat = m.flat_indices(points)
    assert flat.tolist() == [m.flat_index(*p) for p in points]
    assert m.centres(flat).tolist() == [list(m.centre(int(f))) for f in flat]


def test_the_revision_counts_changes_to_what_the_map_says_of_a_cell_not_its_counts():
    """An open scan again adds to the free counts but makes no cell free or a wall that was not:
    the revision (the searches' cache key) stays; a scan that ends on that free ground moves it."""
    m = ExplorationMap(MapConfig(extent=5.0))
    open_scan = np.full(720, 10.0, dtype=np.float32)  # nothing within range: free ground only
    m.observe(np.zeros(2), 0.0, open_scan, max_range=10.0)
    before, free = m.revision, m.free.copy()
    m.observe(np.zeros(2), 0.0, open_scan, max_range=10.0)
    assert m.revision == before and (m.free > free).any()
    for _ in range(5):  # boundaries on that ground, until the map holds them as walls
        m.observe(np.zeros(2), 0.0, ring_scan(radius=1.0), max_range=10.0)
    assert m.revision > before and m.wall_near(np.zeros(2), 0.0, 1.0)


def test_a_reading_ending_by_a_wall_written_in_a_run_weighs_new_wall_weight():
    """Walls written in runs come and go: a ray ending by one counts ``new_wall_weight`` of a ray
    ending by a wall of the dry run, for the place and in the judged fit alike."""
    m = ExplorationMap(MapConfig(extent=5.0, new_wall_evidence=5))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)  # a round room of 3 m
    scan = _ring(3.0)
    scan[: len(scan) // 4] = 1.0  # a quarter of the scan ends 1 m out: a new obstacle
    for _ in range(5):
        m.revise(np.zeros(2), 0.0, scan, max_range=10.0)
    assert m.new_walls.any()
    here = np.zeros((1, 2))
    full, half, none = (m.scan_agreement(here, 0.0, scan, 10.0, new_wall_weight=w)[0] for w in (1.0, 0.5, 0.0))
    assert full == half == none == pytest.approx(1.0)  # every judged ray a hit: the weight moves nothing
    shifted = np.array([[0.4, 0.0]])  # from here some readings miss: the new wall's hits weigh less against them
    fits = [m.scan_agreement(shifted, 0.0, scan, 10.0, new_wall_weight=w)[0] for w in (1.0, 0.5, 0.0)]
    assert fits[0] > fits[1] > fits[2]
    judged = np.empty(1)
    m.scan_agreement(shifted, 0.0, scan, 10.0, judged=judged, new_wall_weight=0.5)
    alone = m.scan_agreement(shifted, 0.0, scan, 10.0, short_weight=0.0, judged_only=True, new_wall_weight=0.5)[0]
    assert judged[0] == alone


def test_a_revision_that_may_not_write_walls_still_clears_them():
    """``write_new=False`` (a scan that crosses a wall the map holds): boundaries on free ground stay
    free however often they are seen, and walls the rays cross are still cleared."""
    m = ExplorationMap(MapConfig(extent=6.0, new_wall_evidence=5, gone_wall_evidence=15))
    m.observe(np.zeros(2), 0.0, _ring(3.0), max_range=10.0)
    scan = _ring(5.0)  # the round wall gone ...
    scan[:5] = 1.0  # ... and something new 1 m east
    new, east = m.index(1.0, 0.0), m.index(-3.0, 0.0)
    for k in range(20):
        m.revise(_pacing(k), 0.0, scan, max_range=10.0, write_new=False)
    assert not _wall(m, new) and not m.new_walls.any()
    assert m.hits[east] == 0 and m.known_free[east]


def test_forgetting_the_walls_runs_wrote_keeps_the_dry_runs():
    """``forget_new_walls``: a wall bumped into in a run goes; the walls the dry run mapped stay, and
    searches made on the old grids are not reused (the revision moves on)."""
    m = ExplorationMap(MapConfig(extent=8.0))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=4.0), max_range=10.0)
    dry_walls = (m.hits > 0) & (m.hits >= m.free)
    m.mark_bump(np.array([1.0, 0.0]), 0.0, 0.3, new=True)
    assert m.new_walls.sum() == 1 and m.wall_near(np.array([1.0, 0.0]), 0.0, 0.3)
    revision = m.revision
    m.forget_new_walls()
    assert not m.new_walls.any() and m.revision > revision
    assert not m.wall_near(np.array([1.0, 0.0]), 0.0, 0.3)
    np.testing.assert_array_equal((m.hits > 0) & (m.hits >= m.free), dry_walls)


def test_a_search_is_reused_only_while_the_ground_it_looks_for_is_unchanged():
    """The nearest ground not yet visited (or searched) is searched again only when the start cell,
    the grids or that ground changed: at every step of a walk that marks ground, forgets what was
    searched and starts runs, the answer is the one a map with no earlier search gives."""

    def afresh(m: ExplorationMap, here: np.ndarray, this_run: bool) -> float | None:
        twin = ExplorationMap(m.config)
        twin.load_state(*m.state())
        return twin.heading_to_unvisited(here, this_run=this_run)

    m = ExplorationMap(MapConfig(extent=8.0))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=4.0), max_range=10.0)
    rng = np.random.default_rng(5)
    here = np.zeros(2)
    for step in range(120):
        this_run = step % 3 == 0
        heading = m.heading_to_unvisited(here, this_run=this_run)
        assert heading == afresh(m, here, this_run)
        if heading is not None and rng.random() < 0.7:  # (sometimes it stays where it is)
            here = here + 0.15 * np.array([math.cos(heading), math.sin(heading)])
        m.mark(here)
        if step % 40 == 39:
            m.new_run()
        elif step % 25 == 24:
            m.forget_searched_near(here, 1.0)


def test_a_path_after_the_search_everywhere_is_the_one_a_search_to_its_cell_finds():
    """After ``reachable_visited`` (a transit's choice of destination), the path to a cell it reached
    is read from that search where it is the same (the robot not by a wall), not searched again: from
    starts in the open and beside walls, the path is the one a map with no earlier search gives."""
    m = ExplorationMap(MapConfig(extent=8.0))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=4.0), max_range=10.0)
    for x in np.arange(-1.0, 1.0, 0.1):  # a wall across the middle, so that paths bend
        m.mark_bump(np.array([x, 0.5]), math.pi / 2, 0.3)
    for y in np.arange(-3.0, 3.0, 0.5):
        m.mark(np.array([0.0, y]))
    reused = 0
    for start in ([0.0, -1.0], [2.0, 0.5], [0.0, -3.3], [-1.3, 0.8], [3.2, 0.0]):  # in the open, by walls
        cells, _ = m.reachable_visited(np.array(start))
        twin = ExplorationMap(m.config)
        twin.load_state(*m.state())
        for target in cells[:: max(1, len(cells) // 5)]:
            before = int(m._search_id[0])
            np.testing.assert_array_equal(m.path(np.array(start), int(target)), twin.path(np.array(start), int(target)))
            reused += int(m._search_id[0]) == before
            m.reachable_visited(np.array(start))  # (the tree back for the next target)
    assert reused > 0


@pytest.mark.parametrize(("wall_from", "middle"), [(-2.0, True), (0.0, False)])
def test_a_ray_through_a_walls_middle_is_told_from_one_clipping_its_end(wall_from, middle):
    """Localisation's evidence of a wrong place where the world changed (``scan_agreement`` with a
    three-element ``judged``): one ray, east, passes through a wall 1 m away that runs north from
    ``wall_from``. Through its middle (wall on both sides of the ray's line) it counts; at the
    wall's end (wall on one side only: a door's jamb, a thin wall's corner) it does not. Either
    way the ray passes through a wall the map holds, and the other rays, ending 0.3 m away on free
    ground, are short readings."""
    m = ExplorationMap(MapConfig(extent=5.0))
    here = np.array(m.centre(m.flat_index(0.0, 0.0)))  # (a cell's centre: the ray runs along its cells' centres)
    for y in np.arange(wall_from, 2.0, m.cell / 2):
        m.hits[m.index(here[0] + 1.0, here[1] + y)] = 3
    for a in range(m.n):
        for b in range(m.n):
            if m.hits[a, b] == 0 and math.dist(m.centre(a * m.n + b), here) < 0.6:
                m.free[a, b] = 1
    m.grids_replaced()
    ranges = np.full(720, 0.3)
    ranges[0] = 2.0
    judged = np.empty(3)
    m.scan_agreement(here[None, :], 0.0, ranges, 10.0, judged=judged)
    n_rays = 720 // round(720 * m.agreement_stride_deg / 360.0)
    assert judged[0] == -1.0  # the one judged ray passed through a wall the map holds
    assert judged[1] == pytest.approx((n_rays - 1) / n_rays)  # the others: short readings
    assert judged[2] == (1 if middle else 0)


def _walkable_afresh(m: ExplorationMap) -> np.ndarray:
    """Each cell's walkability worked out in NumPy from the grids: known free ground off the border
    with no wall in the 3 x 3 block round it (flat, as the searches index cells)."""
    wall = (m.hits > 0) & (m.hits >= m.free)
    blocked = np.zeros_like(wall)
    padded = np.pad(wall, 1)
    for di in range(3):
        for dj in range(3):
            blocked |= padded[di : di + m.n, dj : dj + m.n]
    walkable = (m.free > 0) & ~blocked
    walkable[[0, -1], :] = walkable[:, [0, -1]] = False
    return walkable.reshape(-1)


def test_the_walkability_the_searches_remember_is_that_of_the_grids_after_every_step_of_a_dry_run():
    """A scan that changes cells forgets the walkability remembered round them only, and the rest is
    kept for the next search: after every step of a dry run in maze1, each remembered walkability
    that the current grids' id marks as valid equals the one worked out afresh from the grids."""
    from agent_helpers import SMALL, make_env

    from hippo_agent import HippocampalAgent

    env = make_env("maze1", seed=3)
    agent = HippocampalAgent(env.observation_space, env.action_space, SMALL, seed=3)
    observe, kept = agent.observe, []

    def observe_and_check(*args: object) -> None:
        observe(*args)
        m = agent.map
        valid = (m._walk_cache >> 1) == m._walk_id()
        assert np.array_equal((m._walk_cache[valid] & 1) == 1, _walkable_afresh(m)[valid])
        kept.append(int(valid.sum()))

    agent.observe = observe_and_check  # type: ignore[method-assign]
    agent.dry_run(env)
    assert len(kept) > 500 and np.median(kept) > 1_000  # (the scans kept most of what the searches worked out)


def _open_east(radius: float) -> np.ndarray:
    """A round room of ``radius`` open east: the rays within 30 degrees of east meet nothing (max range)."""
    scan = _ring(radius)
    east = np.cos(np.arange(720) * 2 * math.pi / 720) > math.cos(math.radians(30))
    scan[east] = 10.0
    return scan


@pytest.mark.parametrize("dry_reachable_only", [False, True])
def test_with_dry_reachable_only_a_run_maps_new_ground_only_where_the_dry_runs_ground_can_be_walked_to(dry_reachable_only):
    """The dry run found a round room of 2 m open east (to 4 m, how far rays enter cells). Cells a
    misplaced scan entered 4 m west, beyond the room's wall, are known ground that walkable ground
    does not join to the room: with ``dry_reachable_only`` a run's scan from there enters none of
    the unknown cells round it. Farther east than the dry run saw, on ground a run's scan entered,
    joined to the room, a scan maps new ground either way."""
    m = ExplorationMap(MapConfig(extent=8.0, dry_reachable_only=dry_reachable_only))
    m.observe(np.zeros(2), 0.0, _open_east(2.0), max_range=10.0)
    m.end_dry_run()
    assert (m.dry_ground is not None) == dry_reachable_only
    ghost = np.array([-4.0, 0.0])
    i, j = m.index(*ghost)
    m.free[i - 1 : i + 2, j - 1 : j + 2] = 1
    m.grids_replaced()
    assert m.known_ground(ghost)
    assert m.reaches_dry_ground(np.zeros(2))
    assert m.reaches_dry_ground(ghost) != dry_reachable_only
    m.revise(ghost, 0.0, _ring(1.0), max_range=10.0)
    assert bool(m.known_free[m.index(-4.5, 0.0)]) != dry_reachable_only
    m.revise(np.array([3.5, 0.0]), 0.0, _open_east(1.0), max_range=10.0)  # (on the dry run's ground)
    far_east = np.array([5.5, 0.0])
    assert m.known_ground(far_east)
    if dry_reachable_only:
        assert not m.known_ground(far_east, m.dry_ground)
    assert m.reaches_dry_ground(far_east)
    before = np.count_nonzero(m.known_free)
    m.revise(far_east, 0.0, _open_east(1.0), max_range=10.0)
    assert np.count_nonzero(m.known_free) > before


def test_the_dry_runs_ground_is_saved_with_the_map_and_absent_from_saves_without_it():
    m = ExplorationMap(MapConfig(extent=5.0, dry_reachable_only=True))
    m.observe(np.zeros(2), 0.0, ring_scan(radius=2.0), max_range=10.0)
    fresh = ExplorationMap(MapConfig(extent=5.0, dry_reachable_only=True))
    fresh.load_state(*m.state())
    assert fresh.dry_ground is None and fresh.reaches_dry_ground(np.array([4.0, 4.0]))  # (no dry run ended yet)
    m.end_dry_run()
    fresh.load_state(*m.state())
    np.testing.assert_array_equal(fresh.dry_ground, m.dry_ground)
    assert not fresh.reaches_dry_ground(np.array([4.0, 4.0]))
    arrays = dict(m.state()[1])
    arrays["dry_ground"] = np.zeros((3, 3), dtype=bool)
    with pytest.raises(ValueError, match="dry_ground"):
        fresh.load_state({}, arrays)
