"""Reproduce every experiment of the paper's "Experimental Results" section on ``HippoMaze-v0``.

    python -m benchmarks.paper --out benchmarks/results/paper     # the committed run (2 workers)
    python -m benchmarks.paper --out /tmp/paper --quick           # every experiment, tiny (CI)
    hippomaze paper --out DIR [--quick] [--seed S] [--workers W]  # the same from the console script

Writes the figures, ``REPORT.md`` (every figure, and a table putting each of the paper's claims
beside our measurement with a plain verdict) and ``paper.json`` (every number) into ``--out``:

1. Place fields after the dry run, open arena and every maze (paper Fig. 2).
2. The reward map implied after run 1, sampled by roaming with learning off (Figs. 3 and 8).
3. Same start, four runs: three trials in the open arena, one in each maze (Figs. 4 and 7).
4. 20 trials with random starts in the open arena: indirectness per run (Fig. 5); beyond the
   paper, the same in every obstacle maze.
5. Run 1's path length against run 2's indirectness, with the Pearson r (Fig. 6; paper -0.53).
6. Generalisation: explore with no goal (extensively, or along one scripted path), put the reward
   at chosen places, replay only, and sample the inferred reward maps (Fig. 10).
7. Perceptual aliasing in maze4: place cells with fields in several compartments (Fig. 9).

Every trial or experiment is one task with its own seed, run in a ``ProcessPoolExecutor``;
results are gathered by task name, so nothing depends on ``--workers``. DMTP trials go through
``hippo_env.dmtp.run_dmtp``, one call per trial: trial ``t`` (from 0) in maze ``M`` is exactly
``hippomaze dmtp --maze M --trials 1 --runs 4 --seed <1000 * seed + t>``.

Maps are sampled the paper's way: the robot roams aimlessly (a separate environment; no agent is
stepped, so nothing learns) and at every position visited we read the place cells' steady-state
rates for the observation there (``agent.place_field_map`` / ``agent.reward_map``). Statistics
about field shape and aliasing use a regular grid of positions instead, so that every compartment
is sampled.

The modules, in the order a run uses them:

- ``args``: ``PaperArgs``, the run's arguments, and their command line;
- ``design``: the mazes, the generalisation scenarios and the seeds;
- ``experiments``: the tasks (built from ``procedures``: roaming, scripted drives, replay,
  navigation; on the ``geometry`` of the mazes), run by ``pool``;
- ``results``: the typed records the tasks return and the modules pass on;
- ``analysis``: field shape and aliasing, reward-map statistics, correlations (on :mod:`hippomaze.stats`);
- ``claims``: each of the paper's claims with the criterion that decides its verdict;
- ``figures`` and ``report``: the figures and REPORT.md; ``run``: the whole run and paper.json.
"""

from __future__ import annotations

from .args import PaperArgs, parse_args
from .run import main, run_paper

__all__ = ["PaperArgs", "main", "parse_args", "run_paper"]
