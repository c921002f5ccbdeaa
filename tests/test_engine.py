"""The execution engine: results in the items' order on every engine, each result handed over as it
finishes, the workers' environment, and an unknown engine refused. (Ray: see test_sample_efficiency.py.)"""

from __future__ import annotations

import operator
import os

import pytest

from hippomaze import engine


@pytest.mark.parametrize("name", ["serial", "local"])
def test_map_returns_the_results_in_the_items_order(name):
    seen = []
    results = engine.map_tasks(operator.neg, [3, 1, 2], engine=name, workers=2, on_result=lambda item, result: seen.append((item, result)))
    assert results == [-3, -1, -2]
    assert sorted(seen) == [(1, -1), (2, -2), (3, -3)]


def test_nothing_to_do():
    assert engine.map_tasks(operator.neg, [], engine="local") == []


def test_local_workers_start_with_worker_env():
    name = "HIPPOMAZE_ENGINE_TEST"
    assert name not in os.environ
    assert engine.map_tasks(os.getenv, [name], engine="local", workers=1, worker_env={name: "1"}) == ["1"]
    assert name not in os.environ  # the driver's environment is restored


def test_unknown_engine_is_refused():
    with pytest.raises(ValueError, match="engines: local, ray, serial"):
        engine.map_tasks(operator.neg, [1], engine="dask")


def test_a_ray_cluster_does_not_share_the_driver_files():
    assert engine.shares_filesystem("local") and engine.shares_filesystem("ray")
    assert not engine.shares_filesystem("ray", address="auto")
