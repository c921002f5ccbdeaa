"""Hippocampal agent throughput: act + observe steps per second, learning on, on one core.

For each population size the agent does a short dry run, finds a fixed goal (so the reward map
exists and every later step exploits with 8-way preplay), then is timed alone on a recorded
random walk of real observations: once exploiting, once exploring. One replay is timed too, and
the memory of the place->place tensor is read off the agent. RatInABox (the ``peers`` extra) is timed
beside it at the same cell counts: its agent moving and its place cells and BVCs updating.

    python -m benchmarks.agent_throughput            # writes benchmarks/results/agent_throughput.json
    python -m benchmarks.agent_throughput --cells 250 --steps 500 --out /tmp/quick.json
"""

from __future__ import annotations

import dataclasses
import datetime
import resource
import time
from dataclasses import dataclass

import gymnasium as gym
import numpy as np

import hippo_env
from benchmarks.common import command_line, load_average, machine_info, output_path, parse_dataclass_args
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_env.dmtp import rollout


@dataclass
class Args:
    cells: tuple[int, ...] = (250, 1000, 4000)
    """place-cell counts to time"""
    steps: int = 3_000
    """recorded steps each timing replays"""
    repeats: int = 3
    """timed repeats; the best is reported (other load only slows a run down)"""
    dry_run_steps: int = 3_000
    """the agent's goal-free dry run before timing"""
    n_rays: int = 720
    """rangefinder rays (the paper's 720)"""
    seed: int = 0
    """seeds the environment, the agent and the recorded walk"""
    model: str = "default"
    """default (AgentConfig(), with path integration) or paper (AgentConfig.paper())"""
    target: float = 2_000.0
    """steps/s aimed for at 1000 place cells"""
    peer_steps: int = 500
    """steps of RatInABox (an agent moving, its place cells and 400 BVCs updating, no learning) timed
    per repeat at each cell count, beside the agent; 0 skips it. Needs the ``peers`` extra."""
    out: str = "benchmarks/results/agent_throughput.json"
    """where the JSON goes (relative to the repository root unless absolute)"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    load_at_start = load_average()
    print(f"hippomaze agent throughput: {args.steps} recorded steps x {args.repeats} repeats, {args.n_rays} rays")

    def timed(agent: HippocampalAgent, recorded: list, exploit: bool) -> tuple[float, float, dict]:
        """Best steps/s (wall and CPU) of act + observe over the recorded walk."""
        agent.goal_rewarded = exploit  # exploring ignores the reward map; exploiting preplays every step
        best_wall = best_cpu = 0.0
        for _ in range(args.repeats):
            agent.reset(recorded[0][1], recorded[0][2])
            began, began_cpu = time.perf_counter(), time.process_time()
            for action, observation, info in recorded:
                agent.act(observation)
                agent.observe(action, observation, 0.0, False, False, info)
            best_wall = max(best_wall, len(recorded) / (time.perf_counter() - began))
            best_cpu = max(best_cpu, len(recorded) / max(time.process_time() - began_cpu, 1e-9))
        return best_wall, best_cpu, dict(agent.episode_stats)

    rows = []
    for n_place in args.cells:
        env = gym.make("HippoMaze-v0", maze="open", n_rays=args.n_rays, odometry=True)
        env.reset(seed=args.seed)
        agent = HippocampalAgent(
            env.observation_space,
            env.action_space,
            (AgentConfig.paper if args.model == "paper" else AgentConfig)(n_place=n_place, dry_run_steps=args.dry_run_steps),
            seed=args.seed,
        )
        agent.prepare(env)
        agent.start_trial(0)
        observation, info = env.reset(options={"goal": [0.0, 0.0]})
        agent.reset(observation, info)
        rollout(env, agent, observation)  # run 1: explore until the goal, which triggers the replay
        began = time.perf_counter()
        agent.learn_reward()
        replay_ms = 1e3 * (time.perf_counter() - began)

        walk = np.random.default_rng(args.seed).integers(0, 8, args.steps)
        recorded = []
        observation, info = env.reset(options={"goal": None})
        for action in walk.tolist():
            observation, _, _, _, info = env.step(action)
            recorded.append((action, observation, info))
        exploit_wall, exploit_cpu, exploit_stats = timed(agent, recorded, exploit=True)
        explore_wall, explore_cpu, _ = timed(agent, recorded, exploit=False)
        w_pp_bytes = int(sum(a.nbytes for a in vars(agent.place).values() if isinstance(a, np.ndarray) and a.ndim == 3))
        peer = _ratinabox_steps_per_second(n_place, agent.bvc.n, args) if args.peer_steps > 0 else None
        rows.append(
            {
                "n_place": n_place,
                "n_bvc": agent.bvc.n,
                "exploiting_steps_per_second": round(exploit_wall),
                "exploiting_steps_per_cpu_second": round(exploit_cpu),
                "exploit_decisions": exploit_stats,
                "exploring_steps_per_second": round(explore_wall),
                "exploring_steps_per_cpu_second": round(explore_cpu),
                "replay_ms": round(replay_ms, 2),
                "W_pp_megabytes": round(w_pp_bytes / 2**20, 1),
                "max_rss_megabytes": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
                "ratinabox_steps_per_second": None if peer is None else round(peer),
                "exploiting_x_ratinabox": None if peer is None else round(exploit_wall / peer, 2),
            }
        )
        print(
            f"  {n_place:5d} place cells: exploiting {exploit_wall:7,.0f} steps/s ({exploit_cpu:,.0f} per CPU second), "
            f"exploring {explore_wall:7,.0f}; one replay {replay_ms:.1f} ms; W_pp {w_pp_bytes / 2**20:.1f} MB"
            + ("" if peer is None else f"; RatInABox {peer:,.0f} steps/s ({exploit_wall / peer:.1f}x)")
        )
        env.close()

    paper_scale = [r for r in rows if r["n_place"] == 1000]
    record = {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(numpy=np.__version__, gymnasium=gym.__version__, hippo_env=hippo_env.__version__)
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
        "rows": rows,
        "target_steps_per_second_1000_cells": args.target,
        "meets_target": bool(paper_scale)
        and min(paper_scale[0]["exploiting_steps_per_second"], paper_scale[0]["exploring_steps_per_second"]) >= args.target,
    }
    out = output_path(args.out)
    hippo_env.write_json(out, record)
    print(f"wrote {out}")


def _ratinabox_steps_per_second(n_place: int, n_bvc: int, args: Args) -> float | None:
    """Best steps/s of RatInABox updating an agent, ``n_place`` place cells and ``n_bvc`` BVCs in a
    10 m arena (its defaults otherwise; it does not learn), or None if it is not installed."""
    try:
        from ratinabox.Agent import Agent
        from ratinabox.Environment import Environment
        from ratinabox.Neurons import BoundaryVectorCells, PlaceCells
    except ImportError:
        print("  RatInABox is not installed (pip install -e .[peers]): not timed")
        return None
    environment = Environment(params={"scale": 10.0, "dimensionality": "2D"})
    rat = Agent(environment)  # its default time step: a longer one makes its random motion diverge
    cells = [BoundaryVectorCells(rat, params={"n": n_bvc}), PlaceCells(rat, params={"n": n_place})]
    best = 0.0
    for _ in range(args.repeats):
        began = time.perf_counter()
        for _ in range(args.peer_steps):
            rat.update()
            for population in cells:
                population.update()
        best = max(best, args.peer_steps / (time.perf_counter() - began))
    return best


if __name__ == "__main__":
    main()
