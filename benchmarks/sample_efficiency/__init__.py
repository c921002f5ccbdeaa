"""Sample efficiency, the research benchmark: every agent of the study, and the shipped references.

A thin caller of :mod:`hippomaze.bench` (the protocol, the measures and the statistics are
described there): it lists the study's jobs (hippo, hippo-paper, random, DQN, PPO, the
privileged Dyna-Q, DQN and PPO with the dense reward; or the hyperparameter sweep), runs them
(resumable: each job's record is kept in ``<out>/sample_efficiency/``), and writes
``<out>/sample_efficiency.json``, its figure and, with ``--write-references``, the reference
files that ``hippomaze bench`` ships (``hippomaze/bench/reference_results/``).

    python -m benchmarks.sample_efficiency --out benchmarks/results --write-references   # the committed results
    python -m benchmarks.sample_efficiency --quick --out /tmp/se                         # a tiny smoke run
    python -m benchmarks.sample_efficiency --sweep --out benchmarks/results              # the hyperparameter sweep
    python -m benchmarks.sample_efficiency --engine ray --address auto

Nothing is written into ``benchmarks/results`` or the package unless ``--out`` and
``--write-references`` say so.
"""
