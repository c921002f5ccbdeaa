"""Sample efficiency: success and indirectness against environment steps, and a goal switch.

Every agent goes through :func:`hippo_env.dmtp.run_dmtp`, on the same goals and starts for the
same seed. A job is one (agent, maze, seed, reward type):

1. **learn.** The hippocampal agent: ``--hippo-days`` DMTP trials of ``--hippo-runs`` runs, a fresh
   agent (and its dry run, counted) each trial, so each trial is one replicate of "an agent from birth".
   The learners (DQN, PPO, random, and the privileged Dyna-Q): one long trial, the goal held, random
   starts, ``step_budget`` steps in all (``run_dmtp(..., trials=1, runs=<many>, step_budget=budget,
   fresh_agent_per_trial=False)``).
2. **switch.** If that agent became direct on its goal (the criterion below, within its life), it
   gets a new DMTP trial: the goal moves (at least 2 m, a seed of the runner chosen for that) and the
   agent is told (``start_trial``), as the hippocampal agent always is. At most ``--switch-budget``
   steps. An agent that never became direct has nothing to become direct *again* on: no switch trial.

Measuring. Steps are counted from the agent's creation, the dry run included; every agent is
measured by runs alike (a wandering run of thousands of steps counts once). A replicate (hippo:
a trial; learners: their one trial) is *direct* from x on when the ``--window`` runs from its
run in progress at x on have >= 90 % successes and median indirectness <= 1.0, the one in
progress being a direct success itself; its *steps to criterion* are the first run start from
which it is, and a seed's are the median over its replicates (hippo: its 10 trials). The curves show,
at x, each replicate's ``--window`` latest runs (the one in progress and those before it: no
looking past the run under way), pooled over the seed's replicates; no point once fewer than half
of them are still running (the trials left late are the slow ones). The headline is the median over
seeds ("> budget" when fewer than half the seeds got there); the curves, the IQM over seeds with
95 % bootstrap intervals (stratified over mazes for the "all mazes" panel),
``scipy.stats.bootstrap``, percentile method. Goal switch: the runs and steps of the new trial
before the first run that starts a direct window.

Jobs run on a local process pool (``--engine local``, default) or on Ray (``--engine ray``, local
``ray.init()`` or ``--address`` of a cluster). Each job's record is written to
``<out>/sample_efficiency/<job>.json.gz`` as soon as it finishes; finished jobs are skipped when the
command is run again (resumable). Then the summary ``<out>/sample_efficiency.json`` and the figures.

    python -m benchmarks.sample_efficiency                           # the committed results
    python -m benchmarks.sample_efficiency --quick --out /tmp/se     # a tiny smoke run
    python -m benchmarks.sample_efficiency --sweep                   # the hyperparameter sweep
    python -m benchmarks.sample_efficiency --engine ray --address auto

Modules, in the order the data flows: ``cli`` (the arguments and ``main``), ``jobs`` (a job, the
benchmark's list of them, running one, its :class:`~benchmarks.sample_efficiency.jobs.JobRecord` on
disk), ``ledger`` (the agent wrapper that counts a job's steps), ``runner`` (the jobs not yet on disk,
on :mod:`hippomaze.engine`), ``metrics`` (replicates, steps to criterion, curve points, IQM
intervals), ``summary`` (the summary document: curves, per-seed figures, headline), ``report``
(its Markdown tables) and ``figures``.
"""
