"""The workbench: any agent measured on the sample-efficiency protocol, beside shipped references.

``hippomaze bench --agent module:Class --out DIR`` (:mod:`hippomaze.bench.cli`) runs the agent
through :func:`hippo_env.dmtp.run_dmtp`, on the same goals and starts for the same seed as the
references, and measures:

- **steps to direct**: environment steps, counted from the agent's creation (its dry run
  included), until it is direct: its run under way is a direct success, and so are >= 90 % of the
  10 runs from there, with median indirectness <= 1.0 (:mod:`hippomaze.bench.metrics`);
- **after a goal switch**: an agent that became direct gets a new DMTP trial, the goal at least
  2 m away and the agent told (``start_trial``); the steps until it is direct again;
- **learning curves**: success rate and median indirectness of each replicate's 10 latest runs
  against steps.

A learner lives one long trial per seed within a step budget; a one-shot agent (the hippocampal
model) gets fresh-agent trials, each a replicate, a seed's figure the median over them
(:mod:`hippomaze.bench.jobs`). Over seeds: IQM with stratified-bootstrap intervals, probability of
improvement and performance profiles, by rliable (:mod:`hippomaze.stats`). The references
(hippo, hippo-paper, DQN, PPO, random) are shipped results (:mod:`hippomaze.bench.references`),
so neither torch nor stable-baselines3 is needed to compare with them.

Modules, in the order the data flows: ``jobs`` (a job, running it, its record on disk),
``ledger`` (the agent wrapper counting a job's steps), ``runner`` (the jobs not yet on disk, on
:mod:`hippomaze.engine`), ``metrics`` (replicates, criterion, curve points), ``stats`` (rliable),
``summary`` (variant results and their comparison), ``references``, ``report`` (Markdown),
``figures``, ``run`` (the command top to bottom) and ``cli``.
"""

from hippomaze.bench.run import BenchArgs, run_bench

__all__ = ["BenchArgs", "run_bench"]
