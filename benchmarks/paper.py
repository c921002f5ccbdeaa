"""Reproduce every experiment of the paper's "Experimental Results" section (``hippomaze.paper``).

python -m benchmarks.paper --out benchmarks/results/paper     # the committed run (2 workers)
python -m benchmarks.paper --out /tmp/paper --quick           # every experiment, tiny (CI)
"""

from hippomaze.paper import main

if __name__ == "__main__":
    main()
