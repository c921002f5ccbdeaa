"""Benchmarks: runnable scripts that write JSON + figures (see ``benchmarks/results/``)."""
