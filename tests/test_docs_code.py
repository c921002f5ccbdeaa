"""The documentation's code runs: the ```python blocks of README.md and docs/*.md, as printed.

Each file's blocks run in order in one namespace (a later block may use an earlier one's names), in
a fresh folder. A block fenced ```py is shown as Python but not run: keep those few (a block that
needs a display, or writes videos). Where a printed budget is too long for the test suite, SHORTER
swaps it for a small one; each swap must still match the text, so the docs cannot drift from it.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```", re.DOTALL | re.MULTILINE)

# file -> (as printed, as run): training budgets cut to a few hundred steps.
SHORTER: dict[str, list[tuple[str, str]]] = {
    "sb3.md": [
        ("total_timesteps=200_000", "total_timesteps=256"),
        ("eval_freq=10_000", "eval_freq=128"),
        ("max_episode_steps=500", "max_episode_steps=40"),
        (
            'PPO("MultiInputPolicy", train_env, seed=0, verbose=0)',
            'PPO("MultiInputPolicy", train_env, seed=0, verbose=0, n_steps=128, batch_size=64, n_epochs=1)',
        ),
    ],
    "cleanrl.md": [("total_timesteps: int = 200_000", "total_timesteps: int = 512")],
}


def blocks(path: Path) -> list[str]:
    return BLOCK.findall(path.read_text())


def test_the_docs_have_code_to_run():
    assert blocks(ROOT / "README.md"), "README.md has no ```python block"
    assert sum(len(blocks(path)) for path in FILES) >= 10
    for name in SHORTER:
        assert (ROOT / "docs" / name).exists(), f"SHORTER names docs/{name}, which does not exist"


@pytest.mark.parametrize("path", [path for path in FILES if blocks(path)], ids=lambda path: path.name)
def test_code_blocks_run(path, tmp_path, monkeypatch):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    code = "\n".join(blocks(path))
    for printed, run in SHORTER.get(path.name, []):
        assert printed in code, f"{path.name} no longer prints {printed!r}: update SHORTER in {Path(__file__).name}"
        code = code.replace(printed, run)
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__main__"}
    try:
        exec(compile(code, str(path), "exec"), namespace)  # noqa: S102 (the documentation's own examples)
    finally:
        plt.close("all")
        for value in list(namespace.values()):
            close = getattr(value, "close", None)
            if callable(close) and not isinstance(value, type) and hasattr(value, "step") and hasattr(value, "reset"):
                close()
