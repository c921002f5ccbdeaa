"""Environment throughput: steps per second with uniformly random discrete actions.

One process, through ``gym.make`` (all the registered wrappers), for every built-in maze at 64 and
720 rays; then ``gym.make_vec(..., vectorization_mode="async")`` at 720 rays (total env steps/s).
Episode resets are inside the timed loop, as in training. Each figure is the median of
``--repeats`` timed runs of ``--steps`` steps after a warm-up.

A peer is timed beside it: Gymnasium-Robotics' ``PointMaze_UMaze-v3`` (MuJoCo) with uniformly random
actions, its repeats interleaved with each maze's so that both see the same machine load; a maze's
``x_peer`` is the median over the repeats of its steps/s over the peer's (with the quartiles),
the figure the target in ``benchmarks/targets.toml`` is read against. It needs
the ``peers`` extra (``pip install -e .[peers]``); without it the benchmark says so and times
hippomaze alone.

``--scaling`` measures how the cost grows instead: steps/s and memory against the number of rays
(``--scaling-rays``, in the built-in 10 m mazes) and against the arena's side (``--scaling-sizes``:
the built-in geometry scaled up, walls and all, at 720 rays; the rangefinder keeps its 10 m
range), each point in a fresh process, with the time of a step split into ray casting
(``Rangefinder.scan``), physics (``RobotWorld.drive_heading``), resets (their share, amortised)
and the rest of ``step`` with its wrappers ("step_overhead"). It writes the table, the log-log
slopes, the part that dominates at each end, and a figure (``.png`` beside the JSON).

``--profile`` splits a step at 720 rays in each maze (``--mazes``, each in a fresh process) finer,
into :data:`PROFILE_TERMS`: ray casting, physics (free steps) and its substeps near walls, the
observation and info built around them, the geodesic and the rest of a reset, ``HippoMazeEnv.step``'s
own lines, and gymnasium's registered wrappers with the loop ("step_overhead"). The instrumented pass
is slower than a plain one (``instrumentation_us_per_step``): read the parts beside each other.

    python -m benchmarks.env_throughput                      # writes benchmarks/results/env_throughput.json
    python -m benchmarks.env_throughput --steps 2000 --repeats 1 --out /tmp/quick.json
    python -m benchmarks.env_throughput --scaling            # benchmarks/results/env_scaling.json and .png
    python -m benchmarks.env_throughput --profile            # benchmarks/results/env_profile.json
    python -m benchmarks.env_throughput --scaling --scaling-mazes open --scaling-rays 64 720 --scaling-sizes 10 20 \
        --steps 500 --warmup 100 --repeats 1 --out /tmp/env_scaling.json   # a quick look
"""

from __future__ import annotations

import dataclasses
import datetime
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numba
import numpy as np
import pymunk

import hippo_env
from benchmarks.common import (
    SplitTimer,
    command_line,
    cost_growth,
    in_fresh_process,
    load_average,
    machine_info,
    output_path,
    parse_dataclass_args,
    peak_resident_megabytes,
    resident_megabytes,
)
from benchmarks.records import env_peer
from benchmarks.targets import target, verdict
from hippo_env.maze import MazeSpec
from hippo_env.physics import RobotWorld
from hippomaze.runinfo import source_digest
from hippomaze.stats import median_and_quartiles


@dataclass
class Args:
    mazes: tuple[str, ...] = hippo_env.BUILTIN_MAZES
    """the mazes to time"""
    rays: tuple[int, ...] = (64, 720)
    """rangefinder resolutions to time through gym.make"""
    steps: int = 10_000
    """timed steps per repeat (per sub-environment for the vector env)"""
    warmup: int = 1_000
    """untimed steps first (numba and pymunk warm up; caches fill)"""
    repeats: int = 7
    """timed repeats, short and many so that the interleaved ratios see the same load; the median (and
    for the peer ratio the quartiles) is reported"""
    vec_envs: int = 2
    """sub-environments for the vector envs (0 skips them)"""
    vec_modes: tuple[str, ...] = ("async", "sync")
    """vectorization modes to time"""
    vec_steps: int = 5_000
    """timed vector steps per repeat (each steps every sub-environment)"""
    vec_rays: int = 720
    """rays for the vector envs"""
    seed: int = 0
    """seeds the environments and the random actions"""
    peer: str = "PointMaze_UMaze-v3"
    """the peer environment timed beside each maze ("" skips it)"""
    scaling: bool = False
    """measure how the cost grows instead (see above): each point in a fresh process"""
    profile: bool = False
    """split a step at 720 rays into finer parts instead (see above): each maze in a fresh process"""
    scaling_mazes: tuple[str, ...] = ("open", "maze2")
    """built-in mazes of the scaling table"""
    scaling_rays: tuple[int, ...] = (64, 128, 256, 360, 720)
    """rays of the scaling table (in the 10 m mazes)"""
    scaling_sizes: tuple[float, ...] = (10.0, 20.0, 40.0)
    """arena sides of the scaling table (m; the built-in geometry scaled up, at 720 rays)"""
    out: str = ""
    """where the JSON goes (relative to the repository root unless absolute); '' = benchmarks/results/
    env_throughput.json, with --scaling benchmarks/results/env_scaling.json (the figure beside it), with
    --profile benchmarks/results/env_profile.json"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    if args.scaling:
        scaling(args)
        return
    if args.profile:
        profile(args)
        return
    rng = np.random.default_rng(args.seed)
    load_at_start = load_average()
    print(f"hippomaze env throughput: {args.steps} steps x {args.repeats} repeats, random discrete actions")

    # ---------------------------------------------------------------------- one env through gym.make
    peer = _make_peer(args.peer)
    print(
        f"  peer: {args.peer} (interleaved with each maze at 720 rays)"
        if peer
        else f"  peer: not timed ({args.peer or 'none asked for'}: {_PEER_STATUS['why']})"
    )
    single = []
    for n_rays in args.rays:
        for maze in args.mazes:
            env = gym.make("HippoMaze-v0", maze=maze, n_rays=n_rays)
            env.reset(seed=args.seed)
            ours = _Timed(env, rng.integers(0, 8, args.warmup + args.repeats * args.steps).tolist(), args)
            theirs = None
            if peer is not None and n_rays == 720:
                peer.reset(seed=args.seed)
                theirs = _Timed(peer, list(rng.uniform(-1.0, 1.0, (args.warmup + args.repeats * args.steps, 2)).astype(np.float32)), args)
            for timed in (ours, theirs):
                if timed is not None:
                    timed.warm_up()
            for r in range(args.repeats):  # interleaved: both see the same load
                for timed in (ours, theirs):
                    if timed is not None:
                        timed.repeat(r)
            env.close()
            row = {
                "maze": maze,
                "n_rays": n_rays,
                "steps_per_second": round(statistics.median(ours.wall)),
                "steps_per_cpu_second": round(statistics.median(ours.cpu)),
                "repeats": [round(r) for r in ours.wall],
            }
            line = f"  gym.make   {maze:6s} {n_rays:4d} rays: {statistics.median(ours.wall):9,.0f} steps/s ({statistics.median(ours.cpu):,.0f} per CPU second)"
            if theirs is not None:
                row["peer_steps_per_second"] = round(statistics.median(theirs.wall))
                row["peer_repeats"] = [round(r) for r in theirs.wall]
                ratios = median_and_quartiles([a / b for a, b in zip(ours.wall, theirs.wall, strict=True)])
                row["x_peer"], row["x_peer_quartiles"] = ratios["median"], ratios["quartiles"]
                line += f"; {args.peer} {statistics.median(theirs.wall):,.0f} steps/s: {row['x_peer']:.2f}x"
            single.append(row)
            print(line)
    if peer is not None:
        peer.close()

    # ---------------------------------------------------------------------- vector envs
    vector = []
    for mode in args.vec_modes if args.vec_envs > 0 else ():
        for maze in args.mazes:
            envs = gym.make_vec("HippoMaze-v0", num_envs=args.vec_envs, vectorization_mode=mode, maze=maze, n_rays=args.vec_rays)
            envs.reset(seed=args.seed)
            actions = rng.integers(0, 8, (args.warmup + args.repeats * args.vec_steps, args.vec_envs))
            for k in range(args.warmup):
                envs.step(actions[k])  # the vector env resets finished episodes itself
            rates = []
            for r in range(args.repeats):
                began = time.perf_counter()
                for action in actions[args.warmup + r * args.vec_steps : args.warmup + (r + 1) * args.vec_steps]:
                    envs.step(action)
                rates.append(args.vec_steps * args.vec_envs / (time.perf_counter() - began))
            envs.close()
            vector.append(
                {
                    "mode": mode,
                    "maze": maze,
                    "n_rays": args.vec_rays,
                    "num_envs": args.vec_envs,
                    "env_steps_per_second": round(statistics.median(rates)),
                    "repeats": [round(r) for r in rates],
                }
            )
            print(
                f"  {mode:5s} x{args.vec_envs}   {maze:6s} {args.vec_rays:4d} rays: {statistics.median(rates):9,.0f} env steps/s (all sub-envs)"
            )

    # ---------------------------------------------------------------------- the record
    at_720_rays = [row["steps_per_second"] for row in single if row["n_rays"] == 720]
    at_720_rays_cpu = [row["steps_per_cpu_second"] for row in single if row["n_rays"] == 720]
    record = {
        **_header(args, load_at_start),
        "single_env": single,
        "vector_env": vector,
        "min_steps_per_second_720_rays": min(at_720_rays) if at_720_rays else None,
        "min_steps_per_cpu_second_720_rays": min(at_720_rays_cpu) if at_720_rays_cpu else None,
        "peer": {
            "name": args.peer,
            "timed": peer is not None,
            "why_not": None if peer is not None else _PEER_STATUS["why"],
            "versions": _peer_versions() if peer is not None else None,
            "min_x_peer_720_rays": min((row["x_peer"] for row in single if "x_peer" in row), default=None),
        },
    }
    out = output_path(args.out or "benchmarks/results/env_throughput.json")
    hippo_env.write_json(out, record)
    peer_ratio = env_peer(record)
    if peer_ratio is not None:
        goal = target("env_vs_pointmaze")
        print(
            f"  slowest maze at 720 rays: {peer_ratio['slowest']}x {args.peer} ({peer_ratio['slowest_maze']}); "
            f"target {goal.text(unit='x')}: {verdict(goal.met(peer_ratio['slowest']))}"
        )
    print(f"wrote {out}")


def _header(args: Args, load_at_start: list[float] | None) -> dict[str, Any]:
    return {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(
            numpy=np.__version__, pymunk=pymunk.version, numba=numba.__version__, gymnasium=gym.__version__, hippo_env=hippo_env.__version__
        )
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
        # hippo_env's pymunk calls: "cffi" (pymunk's C bindings, on the pymunk versions checked) or "public".
        "pymunk_calls": RobotWorld(MazeSpec.load("open")).pymunk_calls,
    }


_PEER_STATUS = {"why": ""}


def _make_peer(name: str) -> gym.Env | None:
    """The peer environment, or None (and why, in ``_PEER_STATUS``) if it cannot be made here."""
    if not name:
        _PEER_STATUS["why"] = "no peer asked for"
        return None
    try:
        import gymnasium_robotics

        gym.register_envs(gymnasium_robotics)
        return gym.make(name)
    except Exception as err:  # noqa: BLE001 (the extra is missing or MuJoCo cannot start: time hippomaze alone)
        _PEER_STATUS["why"] = f"{type(err).__name__}: {err}; install the peers extra: pip install -e .[peers]"
        return None


def _peer_versions() -> dict[str, str | None]:
    """The versions the peer's speed depends on (its ratio to hippomaze moves with them)."""
    from importlib import metadata

    versions: dict[str, str | None] = {}
    for package in ("gymnasium-robotics", "mujoco"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    return versions


class _Timed:
    """One env and its pre-drawn actions: a warm-up, then timed repeats of ``args.steps`` steps."""

    def __init__(self, env: gym.Env, actions: list, args: Args) -> None:
        self.env, self.actions, self.args = env, actions, args
        self.wall: list[float] = []
        self.cpu: list[float] = []
        self.collisions = 0  # steps that touched a wall (hippomaze's info["collision"])

    def _run(self, actions: list) -> None:
        for action in actions:
            _, _, terminated, truncated, info = self.env.step(action)
            self.collisions += bool(info.get("collision"))
            if terminated or truncated:
                self.env.reset()

    def warm_up(self) -> None:
        self._run(self.actions[: self.args.warmup])

    def repeat(self, r: int) -> None:
        """Times repeat ``r``: steps per wall-clock second and per CPU second of this process."""
        first = self.args.warmup + r * self.args.steps
        began, began_cpu = time.perf_counter(), time.process_time()
        self._run(self.actions[first : first + self.args.steps])
        self.wall.append(self.args.steps / (time.perf_counter() - began))
        self.cpu.append(self.args.steps / (time.process_time() - began_cpu))


# ============================================================================ scaling
# The parts of a step, as the methods (attribute path from the unwrapped env, method) whose
# exclusive time each part is; the rest of a step (``HippoMazeEnv.step`` itself, the observation
# and info dicts, gymnasium's wrappers) is "step_overhead".
ENV_TERMS: dict[str, tuple[tuple[str, str], ...]] = {
    "ray_cast": (("rangefinder", "scan"), ("rangefinder", "scan_float32")),
    "physics": (("world", "drive_heading"),),
    "reset": (("", "reset"),),
}

# The finer parts of ``--profile``; the rest of a step (gymnasium's wrappers, the loop) is "step_overhead".
PROFILE_TERMS: dict[str, tuple[tuple[str, str], ...]] = {
    "ray_cast": ENV_TERMS["ray_cast"],
    "physics": ENV_TERMS["physics"],  # turning, and a control step far from walls in one physics step
    "physics_near_walls": (("world", "_drive_near_walls"),),  # the substeps near walls
    "observation": (("", "_observe"),),  # less its ray cast
    "info": (("", "_info"),),
    "geodesic": (("", "_shortest_path"),),  # once per reset
    "reset": ENV_TERMS["reset"],  # less its geodesic, ray cast and observation
    "env_step": (("", "step"),),  # HippoMazeEnv.step's own lines
}


def scaled_maze(name: str, size: float) -> MazeSpec:
    """A built-in maze scaled up (or down) uniformly to a side of ``size`` metres: walls, obstacles,
    gaps and the goal (if any) alike. The built-in size itself gives the maze unchanged."""
    spec = MazeSpec.load(name)
    factor = size / max(spec.size)
    if factor == 1.0:
        return spec
    return MazeSpec(
        name=f"{spec.name}-{size:g}m",
        size=(spec.size[0] * factor, spec.size[1] * factor),
        obstacles=[[(x * factor, y * factor) for x, y in polygon] for polygon in spec.obstacles],
        goal=None if spec.goal is None else (spec.goal[0] * factor, spec.goal[1] * factor),
    )


def measure_point(
    maze: str, size: float, n_rays: int, args: Args, terms: dict[str, tuple[tuple[str, str], ...]] = ENV_TERMS, split_passes: int = 1
) -> dict[str, Any]:
    """One point of the scaling table: ``gym.make`` of the scaled maze, timed as the single-env table
    is (median of ``args.repeats``), then ``split_passes`` instrumented passes of ``args.steps`` steps
    split into ``terms`` (microseconds per step, each term's median over the passes; an instrumented
    pass is slower: read the shares); the process's memory (run it in a fresh process for its own peak)."""
    resident_at_start = resident_megabytes()
    began = time.perf_counter()
    env = gym.make("HippoMaze-v0", maze=scaled_maze(maze, size), n_rays=n_rays)
    env.reset(seed=args.seed)
    make_seconds = time.perf_counter() - began
    actions = np.random.default_rng(args.seed).integers(0, 8, args.warmup + (args.repeats + split_passes) * args.steps).tolist()
    timed = _Timed(env, actions, args)
    timed.warm_up()
    for r in range(args.repeats):
        timed.repeat(r)
    timer = SplitTimer()
    for term, methods in terms.items():
        for owner, name in methods:
            timer.wrap(getattr(env.unwrapped, owner) if owner else env.unwrapped, name, term)
    timed.collisions = 0
    passes: list[dict[str, float]] = []
    calls = dict.fromkeys(timer.calls, 0)
    reset_seconds = 0.0
    for k in range(split_passes):
        first = args.warmup + (args.repeats + k) * args.steps
        timer.reset()
        began = time.perf_counter()
        timed._run(actions[first : first + args.steps])
        total = time.perf_counter() - began
        passes.append({("step_overhead" if t == "other" else t): 1e6 * v / args.steps for t, v in timer.split(total).items()})
        passes[-1]["total"] = 1e6 * total / args.steps
        calls = {t: calls[t] + timer.calls[t] for t in calls}
        reset_seconds += timer.seconds.get("reset", 0.0)
    timer.unwrap()
    split: dict[str, Any] = {t: round(statistics.median(p[t] for p in passes), 3) for t in passes[0]}
    if timer.missing:
        split["methods_not_found"] = timer.missing
    env.close()
    steps = split_passes * args.steps
    return {
        "maze": maze,
        "size_m": size,
        "n_rays": n_rays,
        "n_segments": int(env.unwrapped.maze.segments.shape[0]),
        "max_range_m": env.unwrapped.rangefinder.max_range,
        "steps_per_second": round(statistics.median(timed.wall)),
        "steps_per_cpu_second": round(statistics.median(timed.cpu)),
        "repeats": [round(r) for r in timed.wall],
        "split_us_per_step": split,
        "split_passes": split_passes,
        "calls_per_step": {term: round(n / steps, 4) for term, n in calls.items()},
        "wall_contact_share": round(timed.collisions / steps, 3),
        "resets_in_split_passes": calls.get("reset", 0),
        "ms_per_reset": round(1e3 * reset_seconds / calls["reset"], 3) if calls.get("reset") else None,
        "make_and_reset_seconds": round(make_seconds, 3),
        "peak_rss_mb": round(peak_resident_megabytes(), 1),
        "peak_rss_above_start_mb": round(peak_resident_megabytes() - resident_at_start, 1),
    }


def scaling_table(args: Args, fresh_process: bool = True) -> dict[str, Any]:
    """Rows against rays (10 m mazes) and against the arena's side (720 rays), per maze, with
    :func:`cost_growth` along each axis."""
    rows, growth = [], {}
    for maze in args.scaling_mazes:
        side = max(MazeSpec.load(maze).size)
        points = [("rays", side, n) for n in sorted(args.scaling_rays)] + [("size", s, 720) for s in sorted(args.scaling_sizes)]
        for axis, size, n_rays in points:
            done = next((r for r in rows if (r["maze"], r["size_m"], r["n_rays"]) == (maze, size, n_rays)), None)
            row = dict(done) if done else (in_fresh_process if fresh_process else _call)(measure_point, maze, size, n_rays, args)
            rows.append(row | {"axis": axis})
            if not done:
                print(
                    f"  {maze:6s} {size:4g} m {n_rays:4d} rays: {row['steps_per_second']:9,} steps/s; peak RSS {row['peak_rss_mb']:.0f} MB "
                    f"({row['peak_rss_above_start_mb']:.0f} above the imports); parts (us/step) "
                    + ", ".join(f"{t} {v:.1f}" for t, v in row["split_us_per_step"].items() if isinstance(v, float | int)),
                    flush=True,
                )
        for axis, key in (("rays", "n_rays"), ("size", "size_m")):
            mine = [r for r in rows if r["maze"] == maze and r["axis"] == axis]
            growth[f"{maze}_{axis}"] = cost_growth(
                [r[key] for r in mine], [1.0 / r["steps_per_second"] for r in mine], [r["split_us_per_step"] for r in mine]
            )
    return {"rows": rows, "growth": growth}


def _call(function: Any, *args: Any) -> Any:
    return function(*args)


def scaling(args: Args) -> None:
    load_at_start = load_average()
    print(
        f"hippomaze env scaling: {args.steps} steps x {args.repeats} repeats (median) after {args.warmup}, random discrete actions; "
        "each point in a fresh process"
    )
    table = scaling_table(args)
    record = {**_header(args, load_at_start), **table}
    out = output_path(args.out or "benchmarks/results/env_scaling.json")
    hippo_env.write_json(out, record)
    figure = out.with_suffix(".png")
    plot_scaling(table, figure)
    for name, g in table["growth"].items():
        print(f"  {name}: cost per step {g['verdict']}; largest part {g['dominant_at_smallest']} -> {g['dominant_at_largest']}")
    print(f"wrote {out} and {figure}")


def plot_scaling(table: dict[str, Any], path: Path) -> None:
    """Log-log against rays (left) and arena side (right): steps/s, the parts of a step (with a
    cost-proportional reference line for ray casting against rays), and peak memory."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = table["rows"]
    fig, axes = plt.subplots(3, 2, figsize=(11, 11), sharex="col")
    for col, (axis, key, label) in enumerate((("rays", "n_rays", "rays"), ("size", "size_m", "arena side (m)"))):
        for maze in dict.fromkeys(r["maze"] for r in rows):
            mine = [r for r in rows if r["maze"] == maze and r["axis"] == axis]
            x = np.array([r[key] for r in mine], dtype=float)
            axes[0, col].plot(x, [r["steps_per_second"] for r in mine], "o-", label=maze)
            for n, term in enumerate(t for t in mine[0]["split_us_per_step"] if t not in ("total", "methods_not_found")):
                values = [r["split_us_per_step"].get(term, 0.0) for r in mine]
                if max(values) <= 0.0:
                    continue  # e.g. no reset in the timed steps
                values = [v if v > 0.0 else np.nan for v in values]
                axes[1, col].plot(x, values, marker="os^vD"[n % 5], ls="-" if maze == rows[0]["maze"] else "--", label=f"{maze}: {term}")
            axes[2, col].plot(x, [r["peak_rss_mb"] for r in mine], "o-", label=f"{maze}: peak resident (process)")
            axes[2, col].plot(x, [r["peak_rss_above_start_mb"] for r in mine], "s--", label=f"{maze}: above the imports")
            if axis == "rays" and maze == rows[0]["maze"]:
                ray = mine[-1]["split_us_per_step"]["ray_cast"]
                axes[1, col].plot(x, ray * x / x[-1], "k:", label="proportional to rays")
        axes[0, col].set(ylabel="steps / s (median)", title=f"environment against {label}")
        axes[1, col].set(ylabel="microseconds per step", title="parts of a step")
        axes[2, col].set(ylabel="MB", xlabel=label, title="memory")
        for ax in axes[:, col]:
            ax.set(xscale="log", yscale="log")
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ============================================================================ profile
def profile(args: Args) -> None:
    """:func:`measure_point` at 720 rays with :data:`PROFILE_TERMS` for each of ``args.mazes``, each in
    a fresh process; the record names the source of the ``hippo_env`` that ran."""
    load_at_start = load_average()
    print(
        f"hippomaze env profile: {args.steps} steps x {args.repeats} repeats (median) after {args.warmup}, then {args.repeats} "
        "instrumented passes (median per part); 720 rays, each maze in a fresh process"
    )
    rows = []
    for maze in args.mazes:
        row = in_fresh_process(measure_point, maze, max(MazeSpec.load(maze).size), 720, args, PROFILE_TERMS, args.repeats)
        plain = 1e6 / row["steps_per_second"]
        row["plain_us_per_step"] = round(plain, 3)
        row["instrumentation_us_per_step"] = round(row["split_us_per_step"]["total"] - plain, 3)
        rows.append(row)
        parts = ", ".join(f"{t} {v:.2f}" for t, v in row["split_us_per_step"].items() if isinstance(v, float | int) and t != "total")
        print(f"  {maze:6s} {plain:6.2f} us/step plain; instrumented {row['split_us_per_step']['total']:.2f}: {parts}", flush=True)
    record = {
        **_header(args, load_at_start),
        "hippo_env_source_sha256": source_digest(("hippo_env",)).get("hippo_env"),
        "terms": {term: [".".join(filter(None, m)) for m in methods] for term, methods in PROFILE_TERMS.items()},
        "rows": rows,
    }
    out = output_path(args.out or "benchmarks/results/env_profile.json")
    hippo_env.write_json(out, record)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
