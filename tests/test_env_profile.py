"""``python -m benchmarks.env_throughput --profile`` at a tiny size: every part it names is a method
the environment still has, and the parts with a call every step are called every step."""

from __future__ import annotations

from benchmarks import env_throughput


def test_the_profile_finds_every_part():
    args = env_throughput.Args(steps=30, warmup=5, repeats=2, peer="")
    row = env_throughput.measure_point("maze2", 10.0, 720, args, env_throughput.PROFILE_TERMS, split_passes=2)
    split = row["split_us_per_step"]
    assert "methods_not_found" not in split
    assert set(env_throughput.PROFILE_TERMS) | {"step_overhead", "total"} == set(split)
    assert row["split_passes"] == 2
    for term in ("ray_cast", "physics", "observation", "info", "env_step"):
        assert row["calls_per_step"][term] >= 1.0, term
        assert split[term] > 0, term
