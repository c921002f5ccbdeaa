"""Environment throughput: steps per second with uniformly random discrete actions.

One process, through ``gym.make`` (all the registered wrappers), for every built-in maze at 64 and
720 rays; then ``gym.make_vec(..., vectorization_mode="async")`` at 720 rays (total env steps/s).
Episode resets are inside the timed loop, as in training. Each figure is the median of
``--repeats`` timed runs of ``--steps`` steps after a warm-up.

A peer is timed beside it: Gymnasium-Robotics' ``PointMaze_UMaze-v3`` (MuJoCo) with uniformly random
actions, its repeats interleaved with each maze's so that both see the same machine load. It needs
the ``peers`` extra (``pip install -e .[peers]``); without it the benchmark says so and times
hippomaze alone.

    python -m benchmarks.env_throughput                      # writes benchmarks/results/env_throughput.json
    python -m benchmarks.env_throughput --steps 2000 --repeats 1 --out /tmp/quick.json
"""

from __future__ import annotations

import dataclasses
import datetime
import statistics
import time
from dataclasses import dataclass

import gymnasium as gym
import numba
import numpy as np
import pymunk

import hippo_env
from benchmarks.common import command_line, load_average, machine_info, output_path, parse_dataclass_args


@dataclass
class Args:
    mazes: tuple[str, ...] = hippo_env.BUILTIN_MAZES
    """the mazes to time"""
    rays: tuple[int, ...] = (64, 720)
    """rangefinder resolutions to time through gym.make"""
    steps: int = 20_000
    """timed steps per repeat (per sub-environment for the vector env)"""
    warmup: int = 1_000
    """untimed steps first (numba and pymunk warm up; caches fill)"""
    repeats: int = 3
    """timed repeats; the median is reported"""
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
    target: float = 20_000.0
    """steps/s aimed for at 720 rays on one core"""
    peer: str = "PointMaze_UMaze-v3"
    """the peer environment timed beside each maze ("" skips it)"""
    out: str = "benchmarks/results/env_throughput.json"
    """where the JSON goes (relative to the repository root unless absolute)"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
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
                row["x_peer"] = round(statistics.median(ours.wall) / statistics.median(theirs.wall), 3)
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
    at_target_rays = [row["steps_per_second"] for row in single if row["n_rays"] == 720]
    at_target_rays_cpu = [row["steps_per_cpu_second"] for row in single if row["n_rays"] == 720]
    record = {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(
            numpy=np.__version__, pymunk=pymunk.version, numba=numba.__version__, gymnasium=gym.__version__, hippo_env=hippo_env.__version__
        )
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
        "single_env": single,
        "vector_env": vector,
        "target_steps_per_second_720_rays": args.target,
        "min_steps_per_second_720_rays": min(at_target_rays) if at_target_rays else None,
        "min_steps_per_cpu_second_720_rays": min(at_target_rays_cpu) if at_target_rays_cpu else None,
        "meets_target": bool(at_target_rays) and min(at_target_rays) >= args.target,
        "peer": {
            "name": args.peer,
            "timed": peer is not None,
            "why_not": None if peer is not None else _PEER_STATUS["why"],
            "min_x_peer_720_rays": min((row["x_peer"] for row in single if "x_peer" in row), default=None),
        },
    }
    out = output_path(args.out)
    hippo_env.write_json(out, record)
    slowest = record["min_steps_per_second_720_rays"]
    print(f"wrote {out}" + (f"; slowest maze at 720 rays: {slowest:,} steps/s (target {args.target:,.0f})" if slowest else ""))


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


class _Timed:
    """One env and its pre-drawn actions: a warm-up, then timed repeats of ``args.steps`` steps."""

    def __init__(self, env: gym.Env, actions: list, args: Args) -> None:
        self.env, self.actions, self.args = env, actions, args
        self.wall: list[float] = []
        self.cpu: list[float] = []

    def _run(self, actions: list) -> None:
        for action in actions:
            _, _, terminated, truncated, _ = self.env.step(action)
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


if __name__ == "__main__":
    main()
