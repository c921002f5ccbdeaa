"""``python -m benchmarks.sample_efficiency``: see the package docstring."""

from benchmarks.sample_efficiency.cli import main

if __name__ == "__main__":
    main()
