"""Property tests draw the same examples on every run (``make test`` and CI are reproducible).

To search new examples, as hypothesis does by default: ``HYPOTHESIS_PROFILE=explore make test``.

Also the ``small_maze`` fixture the agent's tests share.
"""

import json
import os

import pytest
from hypothesis import settings

settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


@pytest.fixture
def small_maze(tmp_path):
    """A bare 4 m x 4 m arena (a maze file), for the agent's tests."""
    path = tmp_path / "small.json"
    path.write_text(json.dumps({"name": "small", "size": [4.0, 4.0], "obstacles": []}))
    return str(path)
