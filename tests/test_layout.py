"""The package layout: what the wheel installs, which way imports point, and that importing runs nothing."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

# Imports point one way: a module may import its own layer and the layers before it.
LAYERS = ("hippo_env", "hippo_agent", "baselines", "hippomaze", "benchmarks")
# Where each layer's modules live, and the name they are imported by.
SOURCES = {
    "hippo_env": "hippo_env",
    "hippo_agent": "hippo_agent",
    "baselines": "hippomaze.baselines",
    "hippomaze": "hippomaze",
    "benchmarks": "benchmarks",
}


def _layer(module: str) -> str | None:
    """The layer a module name belongs to (``None`` for anything outside the project)."""
    if module == "hippomaze.baselines" or module.startswith("hippomaze.baselines.") or module.split(".")[0] == "baselines":
        return "baselines"
    top = module.split(".")[0]
    return top if top in LAYERS else None


def _modules() -> list[tuple[str, Path]]:
    found = []
    for folder, name in SOURCES.items():
        for path in sorted((REPO / folder).rglob("*.py")):
            parts = path.relative_to(REPO / folder).with_suffix("").parts
            parts = parts[:-1] if parts[-1] == "__init__" else parts
            found.append((".".join((name, *parts)), path))
    return found


def _imports(module: str, path: Path) -> set[str]:
    """Every module ``path`` imports, lazy imports inside functions included, relative ones resolved."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join([*anchor, base] if base else anchor)
            names.add(base)
    return names


def test_imports_point_one_way():
    """hippo_env <- hippo_agent <- baselines <- hippomaze <- benchmarks: no arrow against that order, so no cycle."""
    against = []
    for module, path in _modules():
        mine = LAYERS.index(_layer(module))
        for imported in _imports(module, path):
            layer = _layer(imported)
            if layer is not None and LAYERS.index(layer) > mine:
                against.append(f"{module} imports {imported} ({_layer(module)} -> {layer})")
    assert not against, "imports against the layer order:\n" + "\n".join(against)


def _module_level_imports(module: str, path: Path, known: set[str]) -> set[str]:
    """The project modules ``path`` imports outside any function or class body (``if TYPE_CHECKING``
    and ``try`` blocks included): ``from a import b`` names ``a.b`` where that is a module, else ``a``."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()

    def visit(nodes: list[ast.stmt]) -> None:
        for node in nodes:
            if isinstance(node, ast.Import):
                found.update(alias.name for alias in node.names if alias.name in known)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                    base = ".".join([*anchor, base] if base else anchor)
                for alias in node.names:
                    name = f"{base}.{alias.name}"
                    found.update({name} if name in known else {base} & known)
            elif not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                for field in ("body", "orelse", "finalbody", "handlers"):
                    visit([n for n in getattr(node, field, []) if isinstance(n, (ast.stmt, ast.ExceptHandler))])

    visit(ast.parse(path.read_text(), str(path)).body)
    return found - {module}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected parts of ``graph`` with more than one module (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                found.append(sorted(part))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_module_imports_in_a_circle():
    """No project module imports, at module level (type-checking imports included), a module that
    imports it back, directly or through others: each layer's modules form a tree, not a knot."""
    modules = dict(_modules())
    graph = {module: _module_level_imports(module, path, set(modules)) for module, path in modules.items()}
    assert graph["hippo_env.maze"] >= {"hippo_env.geodesic", "hippo_env.geometry"}  # the graph sees imports
    assert not _cycles(graph), "modules that import each other in a circle: " + "; ".join(" <-> ".join(c) for c in _cycles(graph))


def test_the_circle_test_sees_a_circle(tmp_path):
    """A circle made only of ``if TYPE_CHECKING`` imports is still a circle."""
    (tmp_path / "a.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.b import B\n")
    (tmp_path / "b.py").write_text("from pkg import a\n\ndef f():\n    from pkg import c\n")
    (tmp_path / "c.py").write_text("import pkg.b\n")
    known = {"pkg.a", "pkg.b", "pkg.c"}
    graph = {f"pkg.{n}": _module_level_imports(f"pkg.{n}", tmp_path / f"{n}.py", known) for n in "abc"}
    assert graph == {"pkg.a": {"pkg.b"}, "pkg.b": {"pkg.a"}, "pkg.c": {"pkg.b"}}  # b's import inside f is not at module level
    assert _cycles(graph) == [["pkg.a", "pkg.b"]]


def test_importing_runs_nothing():
    """Importing any module parses no arguments, prints nothing and starts no experiment."""
    modules = [m for m, _ in _modules() if not m.endswith("__main__")]
    code = f"import importlib, sys\nsys.argv = ['x', '--no-such-flag']\nfor m in {modules!r}:\n    importlib.import_module(m)\n"
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout == "", done.stdout[-2000:]


def test_wheel_installs_only_project_named_packages(tmp_path):
    pytest.importorskip("setuptools")
    source = tmp_path / "source"  # a copy: building in the checkout would leave build/ behind
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, source / name)
    for name in ("hippo_env", "hippo_agent", "hippomaze", "baselines"):
        shutil.copytree(REPO / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "--no-build-isolation", "-q", "-w", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert built.returncode == 0, built.stderr[-2000:]
    (wheel,) = tmp_path.glob("hippomaze-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names if ".dist-info/" not in n}
    assert top == {"hippo_env", "hippo_agent", "hippomaze"}
    assert "hippomaze/baselines/sb3_agents.py" in names  # --agent dqn works from the wheel
    assert "hippo_env/mazes/open.json" in names
    assert "hippomaze/bench/reference_results/hippo.json" in names  # hippomaze bench compares with shipped results
