"""The pymunk world: static walls and an iRobot Create 2 body with a differential drive.

Figures (the authors' reference robot; sources in ``docs/parameters.md``): the Create 2 is a disc of 0.17 m radius,
wheel axle 0.272 m, top speed 0.5 m/s, turning in place at about 105 deg/s. One control step
lasts ``CONTROL_DT = 0.3 s`` of simulated time, 0.15 m of travel at top speed: one place-cell
update of the reference robot (about 0.14 m).

A heading command turns the robot in place toward the heading (taking ``angle / TURN_RATE``
of simulated time; a disc turning in place touches nothing) and then drives it straight at top
speed for one control step. A wheel command drives both wheels for one control step.

Collisions are resolved by pymunk. Where the robot is further from every wall than it can
travel in a step, one physics step integrates the whole control step exactly; near a wall the
step is cut into substeps of ``SKIN`` travel (the margin of the collision disc: 15 substeps at
top speed, plus one that only shows the solver the new command) until the robot is clear of
every wall again, so that the robot never enters a wall, and a blocked robot slides along it or
stops. Steps near walls therefore cost more than free ones.
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from hippo_env import _pymunk_fast
from hippo_env.geometry import segments_clearance, wrap_angle
from hippo_env.maze import MazeSpec

ROBOT_RADIUS = 0.17  # m, Create 2 body
AXLE_LENGTH = 0.272  # m, between the wheels
MAX_SPEED = 0.5  # m/s at the wheel (16 rad/s x 0.031 m)
TURN_RATE = math.radians(105.0)  # rad/s, turning in place
CONTROL_DT = 0.3  # s of simulated time per env step
ROBOT_MASS = 3.6  # kg
SKIN = 0.01  # m: the collision disc's margin (a bumper), and a substep's travel near walls
# Counted as a collision when the robot ends a step this much short of where it was sent.
BLOCKED_TOLERANCE = 1e-4


class RobotWorld:
    """One pymunk space for the world's life: the maze's walls, added once, and the robot.

    Each :meth:`reset` replaces the robot with a new body and shape in the same space. A new body
    is needed for the same result on every reset: Chipmunk keeps solver state on a body that
    pymunk does not expose, so moving the old one would carry it over. Keeping the space (instead
    of building one per reset) leaves pymunk's objects to be freed only with the world.

    A copy (``copy.deepcopy``, ``pickle``) gets what pymunk can read (the robot's pose and
    velocities, the cached contacts) but not that solver state, so it is not always an exact
    continuation of the original: at a wall, most often when the robot was pressing on one as it
    was copied, the copy can end a step slightly elsewhere (micrometres, up to about a millimetre).

    The calls on the hot path go through :mod:`hippo_env._pymunk_fast`: pymunk's C bindings where
    they were checked, its public API elsewhere, with the same results. The world takes that
    module's non-owning handles again whenever it replaces the robot and when it is unpickled;
    it never keeps a handle past the pymunk object it came from.

    Args:
        maze: The maze whose walls the space holds.
        radius: The robot's radius in metres.
        pymunk_calls: ``"cffi"``, ``"public"``, or ``None``/``"auto"`` (the C path where checked, unless the
            environment variable ``HIPPO_ENV_PYMUNK=public``); see :func:`hippo_env._pymunk_fast.choose`.
    """

    def __init__(self, maze: MazeSpec, radius: float = ROBOT_RADIUS, pymunk_calls: str | None = None) -> None:
        self.maze = maze
        self.radius = float(radius)
        self.segments = maze.segments
        self._calls = _pymunk_fast.choose(pymunk_calls)
        self.pymunk_calls = self._calls.name
        """Which implementation of the pymunk calls this world uses: ``"cffi"`` or ``"public"``."""
        space = pymunk.Space()
        space.collision_slop = 1e-4
        space.iterations = 20
        self.space = space
        self.walls: list[pymunk.Segment] = []
        self._add_walls()
        self.body: pymunk.Body | None = None
        self.shape: pymunk.Circle | None = None
        self.sim_time = 0.0
        self.reset((0.0, 0.0), 0.0)

    def _add_walls(self) -> None:
        for x0, y0, x1, y1 in self.segments:
            wall = pymunk.Segment(self.space.static_body, (x0, y0), (x1, y1), 0.0)
            wall.friction = 0.0
            wall.elasticity = 0.0
            self.space.add(wall)
            self.walls.append(wall)

    def set_maze(self, maze: MazeSpec) -> None:
        """The walls of ``maze`` in place of the old ones, in the same space (call :meth:`reset`
        next: the robot may stand where a wall now is)."""
        self.space.remove(*self.walls)
        self.walls = []
        self.maze = maze
        self.segments = maze.segments
        self._add_walls()

    def reset(self, position: tuple[float, float] | np.ndarray, heading: float) -> None:
        """A new robot body and shape at a pose, in place of the old ones (nothing carried over)."""
        if self.body is not None and self.shape is not None:
            self.space.remove(self.shape, self.body)
        body = pymunk.Body(ROBOT_MASS, pymunk.moment_for_circle(ROBOT_MASS, 0.0, self.radius))
        body.position = (float(position[0]), float(position[1]))
        body.angle = float(heading)
        # A contact skin: pymunk finds a contact only once shapes overlap, by at most one
        # substep's travel near a wall, so the collision disc is that much larger than the robot.
        shape = pymunk.Circle(body, self.radius + SKIN)
        shape.friction = 0.0
        shape.elasticity = 0.0
        self.space.add(body, shape)
        _pymunk_fast.settle(self.space)  # pymunk lets go of the old robot now, not at its next public step
        self.body, self.shape = body, shape
        self._h_space, self._h_body = self._calls.handles(self.space, body)
        self._mass, self._moment = body.mass, body.moment
        self.sim_time = 0.0
        self._last_dt = math.inf

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        # The calls and handles are taken again on unpickling (in this process or another).
        del state["_calls"], state["_h_space"], state["_h_body"]
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        # A public world stays public; the C path only where this process can (and may) use it.
        self._calls = _pymunk_fast.choose("public" if self.pymunk_calls == "public" else None)
        self.pymunk_calls = self._calls.name
        assert self.body is not None  # every world has a robot from its first reset on
        self._h_space, self._h_body = self._calls.handles(self.space, self.body)

    @property
    def position(self) -> tuple[float, float]:
        p = self._calls.get_position(self._h_body)
        return (p.x, p.y)

    @property
    def heading(self) -> float:
        """Compass heading in [-pi, pi) (:func:`~hippo_env.geometry.wrap_angle`)."""
        return wrap_angle(self._calls.get_angle(self._h_body))

    @property
    def pose(self) -> tuple[float, float, float]:
        """:attr:`position` and :attr:`heading` as ``(x, y, heading)``, read in one call."""
        calls, body = self._calls, self._h_body
        p = calls.get_position(body)
        return (p.x, p.y, wrap_angle(calls.get_angle(body)))

    def clearance(self) -> float:
        """Distance from the robot's centre to the nearest wall."""
        p = self._calls.get_position(self._h_body)
        return segments_clearance(p.x, p.y, self.segments)

    def drive_heading(self, heading: float) -> bool:
        """Turn in place to ``heading`` (rad), then drive straight at top speed for one control step.

        Returns whether a wall blocked the robot.
        """
        calls, body = self._calls, self._h_body
        angle = wrap_angle(heading)
        turn = abs(wrap_angle(heading - calls.get_angle(body)))
        self.sim_time += turn / TURN_RATE
        calls.set_angle(body, angle)
        return self._drive(MAX_SPEED, 0.0, angle)  # both wheels at top speed; the body's angle is the one just set

    def drive_wheels(self, left: float, right: float) -> bool:
        """Drive the wheels at ``left``, ``right`` in [-1, 1] of top speed for one control step.

        Returns whether a wall blocked the robot.
        """
        speed = MAX_SPEED * (left + right) / 2.0
        spin = MAX_SPEED * (right - left) / AXLE_LENGTH
        return self._drive(speed, spin, self._calls.get_angle(self._h_body))

    def _drive(self, speed: float, spin: float, start_angle: float) -> bool:
        """One control step at ``speed`` (m/s) and ``spin`` (rad/s) from the body's angle ``start_angle``;
        whether a wall blocked the robot."""
        calls, body = self._calls, self._h_body
        start = calls.get_position(body)
        start_x, start_y = start.x, start.y
        gap = segments_clearance(start_x, start_y, self.segments) - self.radius
        velocity = _chord_velocity(speed, spin, start_angle, CONTROL_DT)
        if gap > abs(speed) * CONTROL_DT + SKIN:
            # No wall within reach: one physics step integrates the whole control step.
            calls.set_velocity(body, velocity)
            calls.set_angular_velocity(body, spin)
            calls.space_step(self._h_space, CONTROL_DT)
            self._last_dt = CONTROL_DT
        else:
            self._drive_near_walls(speed, spin, start_x, start_y, gap)
        calls.set_velocity(body, (0.0, 0.0))
        calls.set_angular_velocity(body, 0.0)
        self.sim_time += CONTROL_DT
        # Where the robot would have ended with no wall in the way.
        end_x, end_y = start_x + velocity[0] * CONTROL_DT, start_y + velocity[1] * CONTROL_DT
        p = calls.get_position(body)
        return math.hypot(p.x - end_x, p.y - end_y) > BLOCKED_TOLERANCE

    def _drive_near_walls(self, speed: float, spin: float, x: float, y: float, gap: float) -> None:
        """Substeps of ``SKIN`` travel, with the motors acting as forces, from ``(x, y)``, where the
        robot's edge is ``gap`` from the nearest wall.

        pymunk moves a body with its velocity before it solves contacts, so the motors are the
        force that brings the velocity to the commanded one, and the contact solver removes
        whatever would push into a wall before the next substep moves the robot. A first substep
        that does not move the robot shows the solver the new command. Substeps are all alike
        (pymunk scales its cached contact impulses by the ratio of successive time steps)
        until the robot is clear of every wall, when one step finishes the control step.

        Whether it is clear is a bound first: the distance to the walls is 1-Lipschitz, so since the
        last point where it was computed it has grown by no more than the distance moved. Only where
        that bound (with a margin far beyond rounding) could pass the test is the distance computed,
        so the test's outcome is exactly the one computing it every substep would give.
        """
        body, space, segments = self._h_body, self._h_space, self.segments
        mass, moment = self._mass, self._moment
        dt = CONTROL_DT if speed == 0 else min(CONTROL_DT, SKIN / abs(speed))
        substeps = round(CONTROL_DT / dt)
        if abs(substeps * dt - CONTROL_DT) > 1e-9:  # equal substeps: no sliver of a last one
            dt = CONTROL_DT / math.ceil(CONTROL_DT / dt)
        if dt > self._last_dt * (1 + 1e-9):
            # pymunk would scale the contact impulses it cached in the last, shorter step by
            # dt / last dt and kick the robot through the wall: forget them.
            assert self.shape is not None
            self.space.remove(self.shape)
            self.space.add(self.shape)
        calls = self._calls  # the calls, bound once: this loop is the simulator's hot path
        get_angle, get_velocity, get_spin, get_position = (
            calls.get_angle,
            calls.get_velocity,
            calls.get_angular_velocity,
            calls.get_position,
        )
        set_force, set_torque, space_step = calls.set_force, calls.set_torque, calls.space_step
        radius, travel, skin = self.radius, abs(speed), SKIN
        remaining = CONTROL_DT
        calls.set_velocity(body, (0.0, 0.0))
        priming = True
        angle = target_dt = None
        while remaining > 1e-12:
            a = get_angle(body)
            if a != angle or dt != target_dt:  # the same command as last substep: the same target
                angle, target_dt = a, dt
                target_x, target_y = _chord_velocity(speed, spin, a, dt)
            velocity = get_velocity(body)
            set_force(body, (mass * (target_x - velocity.x) / dt, mass * (target_y - velocity.y) / dt))
            set_torque(body, moment * (spin - get_spin(body)) / dt)
            space_step(space, dt)
            stepped = dt
            if priming:
                priming = False
            else:
                remaining -= dt
                if remaining <= 1e-12:
                    break
            p = get_position(body)
            if remaining < dt:
                dt = remaining
                continue
            reach = travel * remaining + skin
            if gap + math.hypot(p.x - x, p.y - y) > reach - 1e-9:
                x, y = p.x, p.y
                gap = segments_clearance(x, y, segments) - radius
                if gap > reach:
                    dt = remaining
        self._last_dt = stepped


def _chord_velocity(speed: float, spin: float, angle: float, dt: float) -> tuple[float, float]:
    """The straight-line velocity that ends a substep where the wheels' arc would."""
    half_turn = spin * dt / 2.0
    chord_speed = speed * (math.sin(half_turn) / half_turn if half_turn else 1.0)
    return (chord_speed * math.cos(angle + half_turn), chord_speed * math.sin(angle + half_turn))
