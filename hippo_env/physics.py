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

# pymunk's own C bindings: the very functions its properties and Space.step call, without the
# Python wrapping around each (Vec2d objects, checks for features this module does not use).
from pymunk._chipmunk_cffi import lib as _cp

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
    """A pymunk space holding the maze's walls and the robot; rebuilt by :meth:`reset`.

    Args:
        maze: The maze whose walls the space holds.
        radius: The robot's radius in metres.
    """

    def __init__(self, maze: MazeSpec, radius: float = ROBOT_RADIUS) -> None:
        self.maze = maze
        self.radius = float(radius)
        self.segments = maze.segments
        self.sim_time = 0.0
        self.reset((0.0, 0.0), 0.0)

    def reset(self, position: tuple[float, float] | np.ndarray, heading: float) -> None:
        """A new space (nothing carried over from earlier episodes) with the robot at a pose."""
        space = pymunk.Space()
        space.collision_slop = 1e-4
        space.iterations = 20
        for x0, y0, x1, y1 in self.segments:
            wall = pymunk.Segment(space.static_body, (x0, y0), (x1, y1), 0.0)
            wall.friction = 0.0
            wall.elasticity = 0.0
            space.add(wall)
        body = pymunk.Body(ROBOT_MASS, pymunk.moment_for_circle(ROBOT_MASS, 0.0, self.radius))
        body.position = (float(position[0]), float(position[1]))
        body.angle = float(heading)
        # A contact skin: pymunk finds a contact only once shapes overlap, by at most one
        # substep's travel near a wall, so the collision disc is that much larger than the robot.
        shape = pymunk.Circle(body, self.radius + SKIN)
        shape.friction = 0.0
        shape.elasticity = 0.0
        space.add(body, shape)
        self.space, self.body, self.shape = space, body, shape
        self._cp_space, self._cp_body = space._space, body._body
        self._mass, self._moment = body.mass, body.moment
        self.sim_time = 0.0
        self._last_dt = math.inf

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        del state["_cp_space"], state["_cp_body"]  # raw C pointers: taken again from the pymunk objects
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._cp_space, self._cp_body = self.space._space, self.body._body

    @property
    def position(self) -> tuple[float, float]:
        p = _cp.cpBodyGetPosition(self._cp_body)
        return (p.x, p.y)

    @property
    def heading(self) -> float:
        """Compass heading in (-pi, pi]."""
        return wrap_angle(_cp.cpBodyGetAngle(self._cp_body))

    def clearance(self) -> float:
        """Distance from the robot's centre to the nearest wall."""
        p = _cp.cpBodyGetPosition(self._cp_body)
        return segments_clearance(p.x, p.y, self.segments)

    def drive_heading(self, heading: float) -> bool:
        """Turn in place to ``heading`` (rad), then drive straight at top speed for one control step.

        Returns whether a wall blocked the robot.
        """
        turn = abs(wrap_angle(heading - _cp.cpBodyGetAngle(self._cp_body)))
        self.sim_time += turn / TURN_RATE
        _cp.cpBodySetAngle(self._cp_body, wrap_angle(heading))
        return self.drive_wheels(1.0, 1.0)

    def drive_wheels(self, left: float, right: float) -> bool:
        """Drive the wheels at ``left``, ``right`` in [-1, 1] of top speed for one control step.

        Returns whether a wall blocked the robot.
        """
        speed = MAX_SPEED * (left + right) / 2.0
        spin = MAX_SPEED * (right - left) / AXLE_LENGTH
        body = self._cp_body
        start = _cp.cpBodyGetPosition(body)
        start_x, start_y = start.x, start.y
        start_angle = _cp.cpBodyGetAngle(body)
        gap = segments_clearance(start_x, start_y, self.segments) - self.radius
        velocity = _chord_velocity(speed, spin, start_angle, CONTROL_DT)
        if gap > abs(speed) * CONTROL_DT + SKIN:
            # No wall within reach: one physics step integrates the whole control step.
            _cp.cpBodySetVelocity(body, velocity)
            _cp.cpBodySetAngularVelocity(body, spin)
            _cp.cpSpaceStep(self._cp_space, CONTROL_DT)
            self._last_dt = CONTROL_DT
        else:
            self._drive_near_walls(speed, spin)
        _cp.cpBodySetVelocity(body, (0.0, 0.0))
        _cp.cpBodySetAngularVelocity(body, 0.0)
        self.sim_time += CONTROL_DT
        # Where the robot would have ended with no wall in the way.
        end_x, end_y = start_x + velocity[0] * CONTROL_DT, start_y + velocity[1] * CONTROL_DT
        p = _cp.cpBodyGetPosition(body)
        return math.hypot(p.x - end_x, p.y - end_y) > BLOCKED_TOLERANCE

    def _drive_near_walls(self, speed: float, spin: float) -> None:
        """Substeps of ``SKIN`` travel, with the motors acting as forces.

        pymunk moves a body with its velocity before it solves contacts, so the motors are the
        force that brings the velocity to the commanded one, and the contact solver removes
        whatever would push into a wall before the next substep moves the robot. A first substep
        that does not move the robot shows the solver the new command. Substeps are all alike
        (pymunk scales its cached contact impulses by the ratio of successive time steps)
        until the robot is clear of every wall, when one step finishes the control step.
        """
        body, space, segments = self._cp_body, self._cp_space, self.segments
        mass, moment = self._mass, self._moment
        dt = CONTROL_DT if speed == 0 else min(CONTROL_DT, SKIN / abs(speed))
        substeps = round(CONTROL_DT / dt)
        if abs(substeps * dt - CONTROL_DT) > 1e-9:  # equal substeps: no sliver of a last one
            dt = CONTROL_DT / math.ceil(CONTROL_DT / dt)
        if dt > self._last_dt * (1 + 1e-9):
            # pymunk would scale the contact impulses it cached in the last, shorter step by
            # dt / last dt and kick the robot through the wall: forget them.
            self.space.remove(self.shape)
            self.space.add(self.shape)
        cp = _cp  # the C functions, bound once: this loop is the simulator's hot path
        get_angle, get_velocity, get_spin, get_position = (
            cp.cpBodyGetAngle,
            cp.cpBodyGetVelocity,
            cp.cpBodyGetAngularVelocity,
            cp.cpBodyGetPosition,
        )
        set_force, set_torque, space_step = cp.cpBodySetForce, cp.cpBodySetTorque, cp.cpSpaceStep
        radius, travel, skin = self.radius, abs(speed), SKIN
        remaining = CONTROL_DT
        cp.cpBodySetVelocity(body, (0.0, 0.0))
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
            if remaining < dt or segments_clearance(p.x, p.y, segments) - radius > travel * remaining + skin:
                dt = remaining
        self._last_dt = stepped


def _chord_velocity(speed: float, spin: float, angle: float, dt: float) -> tuple[float, float]:
    """The straight-line velocity that ends a substep where the wheels' arc would."""
    half_turn = spin * dt / 2.0
    chord_speed = speed * (math.sin(half_turn) / half_turn if half_turn else 1.0)
    return (chord_speed * math.cos(angle + half_turn), chord_speed * math.sin(angle + half_turn))
