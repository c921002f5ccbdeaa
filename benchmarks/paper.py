"""Reproduce every experiment of the paper's "Experimental Results" section (``hippomaze.paper``).

python -m benchmarks.paper --out benchmarks/results/paper     # the committed run (2 workers)
python -m benchmarks.paper --out /tmp/paper --quick           # every experiment, tiny (CI)
"""

from __future__ import annotations

from hippomaze.paper import PaperArgs, main, run_paper
from hippomaze.paper.statistics import pearson_with_ci, spearman

# PaperArgs and run_paper for hippo_agent.cli, the statistics for benchmarks.maze_suite and benchmarks.diagnose,
# until they import them from hippomaze.paper.
__all__ = ["PaperArgs", "main", "pearson_with_ci", "run_paper", "spearman"]

if __name__ == "__main__":
    main()
