"""HippoMaze-v0: a Morris water maze for a simulated iRobot Create 2 with a rangefinder."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from hippo_env import physics
from hippo_env.checks import check_int, check_number
from hippo_env.geodesic import DistanceField
from hippo_env.geometry import Point
from hippo_env.maze import MazeSpec
from hippo_env.path_record import PathRecord
from hippo_env.sensors import Rangefinder

if TYPE_CHECKING:
    from hippo_env.render import Frame, Renderer

ACTION_TYPES = ("discrete", "heading", "heading_normalized", "wheels")
REWARD_TYPES = ("sparse", "dense")
RESET_OPTIONS = ("maze", "goal", "new_goal", "start", "heading")
GOAL_CLEARANCE = 0.5  # m from every wall, for goals the environment draws
START_CLEARANCE = physics.ROBOT_RADIUS + 0.05  # m from every wall, for random starts
DENSE_GRID = 0.1  # m, cell of the distance field behind reward_type="dense"
ODOMETRY_BOUND = 2 * physics.MAX_SPEED * physics.CONTROL_DT  # m, twice a full step: room for noise
PATH_LIMIT = 100_000  # positions env.path keeps per run (the latest), by default: 1.6 MB


class HippoMazeEnv(gym.Env):
    """A Morris water maze with the delayed-match-to-place (DMTP) protocol.

    ## Description
    A simulated iRobot Create 2 (a disc of 0.17 m radius, pymunk physics) in a walled arena,
    possibly with obstacles, searches for a hidden goal disk. It senses its surroundings only
    through an omnidirectional rangefinder and a compass, as in Alabi, Vanderelst and Minai's
    model of hippocampal navigation. Following DMTP, the goal stays in place across
    :meth:`reset` calls (one trial of runs) until moved with ``options``.

    ## Action Space
    - ``action_type="discrete"`` (default): ``Discrete(8)``; action ``k`` turns the robot in place
      to the allocentric heading ``k * pi / 4`` (0 = +x, counter-clockwise) and drives it
      straight at 0.5 m/s for one control step of 0.3 s (0.15 m, less if a wall is in the way).
    - ``"heading"``: ``Box(-pi, pi, (1,))``, the allocentric heading to turn to, then one step as above.
    - ``"heading_normalized"``: ``Box(-1, 1, (1,))``, the same heading in units of pi radians (one
      unit = pi rad = 180 degrees: 0 = +x, 0.5 = +y, +-1 = -x), the symmetric normalised Box that
      RL libraries expect; otherwise as ``"heading"``.
    - ``"wheels"``: ``Box(-1, 1, (2,))``, left and right wheel speeds as fractions of 0.5 m/s,
      held for one control step.
    An action outside the space raises ``ValueError``.

    ## Observation Space
    ``Dict(ranges=Box(0, max_range, (n_rays,), float32), heading=Box(-1, 1, (2,), float32))``.
    ``ranges[i]`` is the distance to the nearest wall along ``heading + 2*pi*i/n_rays``
    (egocentric, counter-clockwise), capped at ``max_range``, plus Gaussian noise of standard
    deviation ``range_noise``. ``heading`` is ``(cos, sin)`` of the compass heading. The goal is
    invisible.

    ## Rewards
    ``reward_type="sparse"`` (default): 1.0 on the step the robot's centre enters the goal disk,
    else 0.0. ``"dense"`` (for baselines): the sparse reward plus ``0.1 x`` the progress made this
    step along the shortest path to the goal, in units of one full step (0.15 m).

    ## Starting State
    The goal is drawn uniformly from the free space at least 0.5 m from every wall (or taken from
    the ``goal`` or ``goal_seed`` argument, the maze file or ``options``). The start is drawn
    uniformly from the free space at least 1 m from the goal, facing a uniform random heading,
    unless ``options`` give it.

    ## Episode End
    Terminated when the robot reaches the goal. Truncated after ``max_episode_steps`` steps
    (10,000 as registered: an honest exploring first run can take 8,000 steps), by the
    ``TimeLimit`` wrapper that ``gym.make`` adds (and ``EpisodeEndInfo`` then adds ``indirectness``).

    ## Info
    Every step: ``position`` and ``goal``, each a float array ``[x, y]`` of shape (2,) (so vector
    environments stack them as (n, 2) floats), ``heading`` (rad), ``is_success``,
    ``path_length`` (m since reset), ``shortest_path_length`` (m, geodesic from the run's
    start to the goal disk's edge around obstacles inflated by the robot's radius),
    ``collision`` (a wall blocked the robot this step) and ``sim_time`` (simulated seconds since
    reset, turns included). On the step that ends a run, ``indirectness`` =
    (path_length - shortest) / shortest. After a goal-free reset the goal and path figures are NaN.

    ## Arguments
    - ``maze``: a built-in name (``"open"``, ``"maze1"`` ... ``"maze4"``), a path to a maze JSON
      file, or a :class:`~hippo_env.maze.MazeSpec`.
    - ``n_rays`` (720), ``max_range`` (10.0 m), ``range_noise`` (0.0 m): the rangefinder.
    - ``heading_noise`` (0.0 rad): the compass.
    - ``odometry`` (False): add the wheel-odometry observation; ``odometry_noise`` (0.0, a fraction
      of the distance moved).
    - ``action_type``: ``"discrete"``, ``"heading"``, ``"heading_normalized"`` or ``"wheels"``.
    - ``reward_type``: ``"sparse"`` or ``"dense"``.
    - ``goal_radius`` (0.3 m), ``min_start_distance`` (1.0 m from the goal centre).
    - ``goal``: ``[x, y]``, the first trial's goal; or ``goal_seed``: an integer from which the first
      trial's goal is drawn, whatever the reset seed. Two environments made with the same ``goal``
      or ``goal_seed`` share their goal (e.g. a training and an evaluation env). Without either,
      the maze's ``"goal"`` is used, else the first ``reset`` draws one with its seed.
    - ``render_mode``: ``None``, ``"rgb_array"`` or ``"human"``; ``render_rays`` draws the rays.
    - ``path_limit`` (100,000): the most positions :attr:`path` keeps per run (the latest ones),
      so that a goal-free run of any length uses bounded memory; ``None`` keeps them all.

    ``reset(options=...)`` takes ``{"goal": [x, y]}`` (move the goal: a new trial),
    ``{"goal": None}`` (no goal: exploration only), ``{"new_goal": True}`` (draw a new goal),
    ``{"start": [x, y], "heading": rad}`` (the start pose; each may be given alone),
    ``{"maze": name | path | MazeSpec}`` (a changed world: the layout from this run on, the goal kept
    unless moved too; a goal inside the new layout's walls is an error).
    Random starts keep 1 m from the current goal, so ``reset(seed=s)`` on an environment whose
    goal was moved earlier in the trial may start elsewhere than on a fresh one: the trial's goal is
    part of the state, as DMTP requires.

    ## Version History
    - v0: first version. Since then, info ``position`` and ``goal`` are float arrays (were tuples:
      compare them with ``np.array_equal``), and added: ``action_type="heading_normalized"``, the
      ``goal``, ``goal_seed`` and ``path_limit`` arguments. Also added: the opt-in ``odometry`` observation
      (with ``odometry_noise``) and ``heading_noise`` (the default observation is unchanged), and the
      reset option ``maze``.
    """

    # gymnasium.Env declares metadata as an attribute, so a ClassVar here would contradict it.
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 10}  # noqa: RUF012

    def __init__(
        self,
        maze: str | Path | MazeSpec = "open",
        n_rays: int = 720,
        max_range: float = 10.0,
        range_noise: float = 0.0,
        action_type: str = "discrete",
        reward_type: str = "sparse",
        goal_radius: float = 0.3,
        min_start_distance: float = 1.0,
        render_mode: str | None = None,
        render_rays: bool = False,
        odometry: bool = False,
        odometry_noise: float = 0.0,
        heading_noise: float = 0.0,
        goal: Any = None,
        goal_seed: int | None = None,
        path_limit: int | None = PATH_LIMIT,
    ) -> None:
        if action_type not in ACTION_TYPES:
            raise ValueError(f"action_type {action_type!r} is unknown; choose one of {', '.join(ACTION_TYPES)}")
        if reward_type not in REWARD_TYPES:
            raise ValueError(f"reward_type {reward_type!r} is unknown; choose one of {', '.join(REWARD_TYPES)}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode {render_mode!r} is unknown; choose None or one of {', '.join(self.metadata['render_modes'])}")
        if render_mode == "human":
            from hippo_env.render import check_human_display

            check_human_display()  # now, not as a silent blank window at the first step
        if not isinstance(odometry, bool):
            raise TypeError(f"odometry must be True or False, got {odometry!r}")
        noises = (("range_noise", range_noise), ("odometry_noise", odometry_noise), ("heading_noise", heading_noise))
        for name, value in (*noises, ("goal_radius", goal_radius), ("min_start_distance", min_start_distance)):
            check_number(value, name, "a finite number >= 0", 0.0)
        if goal_radius <= 0:
            raise ValueError(f"goal_radius must be positive, got {goal_radius!r}")
        self.maze = self._load_maze(maze, "maze")
        self.rangefinder = Rangefinder(self.maze.segments, n_rays, max_range)
        self.world = physics.RobotWorld(self.maze)
        self.range_noise = float(range_noise)
        self.odometry = odometry
        self.odometry_noise = float(odometry_noise)
        self.heading_noise = float(heading_noise)
        self.action_type = action_type
        self.reward_type = reward_type
        self.goal_radius = float(goal_radius)
        self.min_start_distance = float(min_start_distance)
        self.render_mode = render_mode
        self.render_rays = bool(render_rays)

        observation_spaces: dict[str, spaces.Space] = {
            "ranges": spaces.Box(0.0, self.rangefinder.max_range, (self.rangefinder.n_rays,), np.float32),
            "heading": spaces.Box(-1.0, 1.0, (2,), np.float32),
        }
        if odometry:
            observation_spaces["odometry"] = spaces.Box(-ODOMETRY_BOUND, ODOMETRY_BOUND, (2,), np.float32)
        self.observation_space = spaces.Dict(observation_spaces)
        if action_type == "discrete":
            self.action_space: spaces.Space = spaces.Discrete(8)
        elif action_type == "heading":
            self.action_space = spaces.Box(-math.pi, math.pi, (1,), np.float32)
        elif action_type == "heading_normalized":
            self.action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)
        else:
            self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)

        if self.maze.goal is not None:
            self._check_goal(self.maze.goal, "the maze's goal")
        self._first_goal = self._choose_first_goal(goal, goal_seed)
        self.goal: np.ndarray | None = None
        self._goal_set = False  # no goal chosen yet (the first reset chooses one)
        self._distance_field: tuple[DistanceField, float] | None = None
        self._ranges = np.zeros(self.rangefinder.n_rays)
        self._path = PathRecord(path_limit)
        self._path_length = 0.0
        self._shortest = math.nan
        self._elapsed = 0
        self._renderer: Renderer | None = None
        self._reset_done = False  # the robot has no pose until the first reset places it

    # ------------------------------------------------------------------ gymnasium API
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = sorted(set(options) - set(RESET_OPTIONS))
        if unknown:
            raise ValueError(f"reset options {unknown} are unknown; allowed: {', '.join(RESET_OPTIONS)}")
        if "maze" in options:
            self._change_maze(options["maze"], keep_goal="goal" not in options and not options.get("new_goal"))
        # Always draw a candidate goal, so that reset(seed=s) consumes the same random numbers
        # whether or not the goal moves: the same seed then gives the same start.
        candidate = self.maze.sample_free(self.np_random, GOAL_CLEARANCE)
        if "goal" in options:
            goal = None if options["goal"] is None else self._check_goal(options["goal"], "reset option 'goal'")
            if goal is None or self.goal is None or not np.array_equal(goal, self.goal):
                self._distance_field = None  # the same goal again (the DMTP runner's every run) keeps it
            self.goal = goal
            self._goal_set = True
        elif options.get("new_goal") or not self._goal_set:
            self.goal = candidate if (options.get("new_goal") or self._first_goal is None) else self._first_goal.copy()
            self._goal_set = True
            self._distance_field = None

        if "start" in options:
            start = self._check_start(options["start"])
        else:
            start = self.maze.sample_free(self.np_random, START_CLEARANCE, away_from=self.goal, min_distance=self.min_start_distance)
        heading = self.np_random.uniform(-math.pi, math.pi)
        if "heading" in options:
            heading = check_number(options["heading"], "reset option 'heading'", "a finite angle in radians")
        self.world.reset(start, float(heading))
        self._reset_done = True
        self._path.reset(self.world.position)
        self._path_length = 0.0
        self._elapsed = 0
        self._shortest = self._shortest_path(start)
        position, heading = self.world.position, self.world.heading
        observation = self._observe(position, heading, moved=(0.0, 0.0))
        if self.render_mode == "human":
            self.render()
        return observation, self._info(position, heading, collision=False, success=False)

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        if not self._reset_done:
            raise gym.error.ResetNeeded("call reset() before step(): the robot has no start pose until the first reset places it")
        world = self.world
        before = world.position
        if self.action_type == "discrete":
            collision = world.drive_heading(self._discrete_action(action) * math.pi / 4)
        elif self.action_type == "heading":
            collision = world.drive_heading(float(self._box_action(action)[0]))
        elif self.action_type == "heading_normalized":
            collision = world.drive_heading(math.pi * float(self._box_action(action)[0]))
        else:
            left, right = self._box_action(action)
            collision = world.drive_wheels(float(left), float(right))
        x, y, heading = world.pose
        after = (x, y)
        moved = (x - before[0], y - before[1])
        self._path.append(after)
        self._path_length += math.hypot(*moved)
        self._elapsed += 1

        goal = self.goal
        if goal is None:
            success = False
        else:
            goal_x, goal_y = goal.tolist()  # floats: cheaper arithmetic than numpy's scalars
            success = math.hypot(x - goal_x, y - goal_y) < self.goal_radius
        reward = 1.0 if success else 0.0
        if self.reward_type == "dense" and goal is not None:
            progress = self._distance_to_goal(before) - self._distance_to_goal(after)
            reward += 0.1 * progress / (physics.MAX_SPEED * physics.CONTROL_DT)
        observation = self._observe(after, heading, moved)
        info = self._info(after, heading, collision, success)
        if success:
            add_indirectness(info)
        if self.render_mode == "human":
            self.render()
        return observation, reward, success, False, info

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn('render() was called without a render_mode; make the env with render_mode="rgb_array" or "human"')
            return None
        if self._renderer is None:
            from hippo_env.render import Renderer

            self._renderer = Renderer(self.maze, human=self.render_mode == "human")
        return self._renderer.draw(self._frame())

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # ------------------------------------------------------------------ analysis helpers
    def observation_at(self, position: tuple[float, float] | np.ndarray, heading: float = 0.0) -> dict[str, np.ndarray]:
        """The noise-free observation the robot would get at a pose (does not move it)."""
        ranges = self.rangefinder.scan(position, heading)
        return {"ranges": ranges.astype(np.float32), "heading": np.array([math.cos(heading), math.sin(heading)], np.float32)}

    @property
    def path(self) -> np.ndarray:
        """Positions since the last reset, one row per step (the start first), as a new array.

        At most ``path_limit`` rows: a longer run keeps its latest positions.
        """
        return self._path.array()

    # ------------------------------------------------------------------ internals
    def _frame(self) -> Frame:
        """The snapshot the renderer draws."""
        from hippo_env.render import Frame

        return Frame(
            position=self.world.position,
            heading=self.world.heading,
            path=self.path,
            goal=None if self.goal is None else self.goal.copy(),
            goal_radius=self.goal_radius,
            ranges=self._ranges.copy() if self.render_rays else None,
            fps=self.metadata["render_fps"],
        )

    def _observe(self, position: tuple[float, float], heading: float, moved: tuple[float, float]) -> dict[str, np.ndarray]:
        """The observation at the robot's pose; ``moved`` is its allocentric displacement this step."""
        if self.range_noise > 0:
            self._ranges = self.rangefinder.scan(position, heading)
            noisy = self._ranges + self.np_random.normal(0.0, self.range_noise, self._ranges.shape)
            ranges = np.clip(noisy, 0.0, self.rangefinder.max_range).astype(np.float32)
        else:
            ranges = self.rangefinder.scan_float32(position[0], position[1], heading)
            self._ranges = self.rangefinder.last_ranges  # overwritten by the next scan; _frame copies it
        compass = heading + self.np_random.normal(0.0, self.heading_noise) if self.heading_noise > 0 else heading
        observation = {"ranges": ranges, "heading": np.array((math.cos(compass), math.sin(compass)), np.float32)}
        if self.odometry:
            c, s = math.cos(heading), math.sin(heading)
            step = np.array([c * moved[0] + s * moved[1], -s * moved[0] + c * moved[1]])  # (forward, left)
            if self.odometry_noise > 0:
                step += self.np_random.normal(0.0, self.odometry_noise * math.hypot(*moved), 2)
            observation["odometry"] = np.clip(step, -ODOMETRY_BOUND, ODOMETRY_BOUND).astype(np.float32)
        return observation

    def _info(self, position: tuple[float, float], heading: float, collision: bool, success: bool) -> dict[str, Any]:
        goal = np.full(2, math.nan) if self.goal is None else self.goal.copy()  # the goal is a float array (2,)
        return {
            "position": np.array(position),  # floats: a float64 array
            "heading": heading,
            "goal": goal,
            "is_success": success,
            "path_length": self._path_length,
            "shortest_path_length": self._shortest,
            "collision": collision,
            "sim_time": self.world.sim_time,
        }

    def _discrete_action(self, action: Any) -> int:
        if type(action) is int and 0 <= action < 8:  # the common case first (a bool is not an int here)
            return action
        if isinstance(action, np.ndarray) and action.shape == (1,):
            action = action[0]  # what a vectorised policy hands a single env
        if isinstance(action, (int, np.integer)) and not isinstance(action, (bool, np.bool_)) and 0 <= action < 8:
            return int(action)
        if isinstance(action, np.ndarray) and action.shape == () and np.issubdtype(action.dtype, np.integer) and 0 <= action < 8:
            return int(action)
        raise ValueError(f"action {action!r} is outside the action space Discrete(8); give an integer 0..7 (k means heading k*pi/4)")

    def _box_action(self, action: Any) -> np.ndarray:
        space = self.action_space
        assert isinstance(space, spaces.Box)  # every action type but "discrete" has a Box
        try:
            values: np.ndarray | None = np.asarray(action, dtype=np.float64).reshape(space.shape)
        except (TypeError, ValueError):
            values = None
        if values is None or not (
            bool(np.all(np.isfinite(values))) and bool(np.all(values >= space.low - 1e-6)) and bool(np.all(values <= space.high + 1e-6))
        ):
            meaning = {"heading": "[heading in radians]", "heading_normalized": "[heading in units of pi radians]"}.get(
                self.action_type, "[left, right] wheel speeds"
            )
            raise ValueError(
                f"action {action!r} is outside the action space {space}; give {meaning} with values in [{space.low[0]:.4g}, {space.high[0]:.4g}]"
            )
        return values

    def _check_goal(self, goal: Any, where: str, maze: MazeSpec | None = None) -> np.ndarray:
        point = _as_xy(goal, where)
        maze = self.maze if maze is None else maze
        if maze.clearance(point) < physics.ROBOT_RADIUS:
            raise ValueError(
                f"{where} ({point[0]:g}, {point[1]:g}) is inside a wall or obstacle, or too close to one for the robot to reach: "
                f"a goal's centre needs clearance of at least {physics.ROBOT_RADIUS} m (the robot's radius) inside the "
                f"{maze.size[0]:g} x {maze.size[1]:g} m arena"
            )
        return point

    def _choose_first_goal(self, goal: Any, goal_seed: Any) -> np.ndarray | None:
        """The goal of the first trial: the ``goal`` argument, one drawn with ``goal_seed``, the maze's, or None (drawn at reset)."""
        if goal is not None and goal_seed is not None:
            raise ValueError("give either goal=[x, y] or goal_seed=int, not both")
        if goal is not None:
            return self._check_goal(goal, "argument 'goal'")
        if goal_seed is not None:
            check_int(goal_seed, "goal_seed", 0, "a non-negative integer")
            return self.maze.sample_free(np.random.default_rng(int(goal_seed)), GOAL_CLEARANCE)
        return None if self.maze.goal is None else np.asarray(self.maze.goal, float)

    @staticmethod
    def _load_maze(maze: Any, where: str) -> MazeSpec:
        """The maze a name, a path or a spec stands for, checked: one connected free space."""
        if not isinstance(maze, (str, Path, MazeSpec)):
            raise TypeError(f"{where} must be a built-in maze name, a path to a maze JSON file or a MazeSpec, got {type(maze).__name__}")
        spec = MazeSpec.load(maze)
        spec.check_connected(physics.ROBOT_RADIUS)
        return spec

    def _change_maze(self, maze: Any, keep_goal: bool) -> None:
        """The world changes: ``maze``'s walls from this reset on (the goal too is checked against
        them if it stays). Nothing changes if the maze is refused."""
        spec = self._load_maze(maze, "reset option 'maze'")
        if keep_goal and self.goal is not None:
            self._check_goal(self.goal, f"the goal kept in maze {spec.name!r}", spec)
        self.maze = spec
        self.world.set_maze(spec)
        self.rangefinder = Rangefinder(spec.segments, self.rangefinder.n_rays, self.rangefinder.max_range)
        self._distance_field = None
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def _check_start(self, start: Any) -> np.ndarray:
        point = _as_xy(start, "reset option 'start'")
        needed = physics.ROBOT_RADIUS + physics.SKIN  # the robot and its bumper
        if self.maze.clearance(point) < needed:
            raise ValueError(
                f"reset option 'start' ({point[0]:g}, {point[1]:g}) puts the robot inside or against a wall: "
                f"its centre needs clearance of at least {needed:g} m from every wall"
            )
        # On the disk's edge the shortest path would be 0 m and a successful run's indirectness undefined.
        if self.goal is not None and np.linalg.norm(point - self.goal) <= self.goal_radius:
            raise ValueError(
                f"reset option 'start' ({point[0]:g}, {point[1]:g}) lies inside the goal disk or on its edge; "
                f"start more than {self.goal_radius} m from the goal ({self.goal[0]:g}, {self.goal[1]:g})"
            )
        return point

    def _shortest_path(self, start: np.ndarray) -> float:
        """The geodesic from ``start`` to the goal disk's edge; a clear error if there is none.

        Every start and goal the environment accepts lies in one connected free space, so an
        infinite geodesic is a defect: it is raised here rather than recorded as a missing value.
        """
        if self.goal is None:
            return math.nan
        length = self.maze.geodesic(start, self.goal, physics.ROBOT_RADIUS)
        if not math.isfinite(length):
            raise ValueError(
                f"maze {self.maze.name!r}: no shortest path could be computed from the start ({start[0]:g}, {start[1]:g}) "
                f"to the goal ({self.goal[0]:g}, {self.goal[1]:g}) for a robot of radius {physics.ROBOT_RADIUS} m; "
                "please report this maze, or move the start or goal away from narrow gaps"
            )
        return max(length - self.goal_radius, 0.0)

    def _distance_to_goal(self, position: Point) -> float:
        """Geodesic distance to the goal: the distance of the grid cell holding ``position`` in a field
        built once per goal. Cells the robot cannot occupy count as the farthest reachable one, so
        pushing against a wall never pays."""
        assert self.goal is not None  # (the dense reward needs a goal)
        if self._distance_field is None:
            field = self.maze.distance_field(self.goal, physics.ROBOT_RADIUS, DENSE_GRID)
            reachable = field.distances[np.isfinite(field.distances)]
            self._distance_field = (field, float(reachable.max()) if reachable.size else 0.0)
        field, farthest = self._distance_field
        rows, cols = field.cell(position)
        distance = float(field.distances[rows[0], cols[0]])
        return distance if math.isfinite(distance) else farthest


def maze_env(env: gym.Env) -> HippoMazeEnv:
    """The :class:`HippoMazeEnv` inside ``gym.make``'s wrappers (``TypeError`` if there is none)."""
    inner = env.unwrapped
    if not isinstance(inner, HippoMazeEnv):
        raise TypeError(f"expected a HippoMaze-v0 environment, got {inner!r}")
    return inner


def add_indirectness(info: dict[str, Any]) -> None:
    """Put ``indirectness`` = (path_length - shortest) / shortest in a run's last info."""
    shortest = info["shortest_path_length"]
    if math.isfinite(shortest) and shortest > 0:
        info["indirectness"] = (info["path_length"] - shortest) / shortest


class EpisodeEndInfo(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Adds ``indirectness`` to the info of a run cut off by the time limit (applied by ``gym.make``).

    The environment adds it itself when the goal is reached; only a wrapper outside
    :class:`gymnasium.wrappers.TimeLimit` knows that a step was the last.
    """

    def __init__(self, env: gym.Env) -> None:
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.Wrapper.__init__(self, env)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        result = self.env.step(action)  # (observation, reward, terminated, truncated, info), passed on as it came
        if result[3] and not result[2]:
            add_indirectness(result[4])
        return result


def _as_xy(value: Any, where: str) -> np.ndarray:
    """``value`` as a new float64 point ``[x, y]`` (a copy: the caller's array may change later)."""
    try:
        point = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        point = None
    if point is None or point.shape != (2,) or not np.all(np.isfinite(point)):
        raise ValueError(f"{where} must be a point [x, y] of two finite numbers in metres, got {value!r}")
    return point
