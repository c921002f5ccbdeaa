"""What a recorded run says about itself: its command line from a dataclass (CleanRL style), the
command that ran it, the machine it ran on (a shared machine skews wall-clock rates), and which
code ran (digests of the packages' source)."""

from __future__ import annotations

import argparse
import dataclasses
import functools
import hashlib
import importlib.util
import itertools
import json
import os
import platform
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

ArgsT = TypeVar("ArgsT", bound="DataclassInstance")


def cpu_model() -> str:
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor()


# The vector extensions NumPy picks its kernels by at run time: exp, tanh and BLAS round differently
# with and without them, so two machines with the same "model name" can differ in the last bits.
_VECTOR_FLAGS = ("avx2", "fma", "avx512f")


def cpu_vector_flags() -> list[str] | None:
    """Which of :data:`_VECTOR_FLAGS` the CPU reports (None where ``/proc/cpuinfo`` is missing)."""
    cpuinfo = Path("/proc/cpuinfo")
    if not cpuinfo.exists():
        return None
    flags = next((line.split(":", 1)[1].split() for line in cpuinfo.read_text().splitlines() if line.startswith("flags")), [])
    return [f for f in _VECTOR_FLAGS if f in flags]


#: The packages whose code decides what a simulated run does: the environment, the model and the
#: baselines (the repository's ``baselines/``, installed as ``hippomaze.baselines``).
SIMULATION_PACKAGES = ("hippo_env", "hippo_agent", "hippomaze.baselines")


def source_digest(packages: tuple[str, ...] = ("hippo_agent", "hippo_env"), suffixes: tuple[str, ...] = (".py",)) -> dict[str, str]:
    """SHA-256 of each package's files ending in ``suffixes`` (paths and contents, in path order), by
    package name: which code ran, whatever its version number says. A package that is not
    installed is left out."""
    digests = {}
    for package in packages:
        spec = importlib.util.find_spec(package)
        if spec is None or not spec.submodule_search_locations:
            continue
        root = Path(next(iter(spec.submodule_search_locations)))
        h = hashlib.sha256()
        for path in sorted(p for p in root.rglob("*") if p.suffix in suffixes and "__pycache__" not in p.parts):
            h.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
        digests[package] = h.hexdigest()
    return digests


@functools.cache
def code_fingerprint() -> str:
    """One digest of the code and data of :data:`SIMULATION_PACKAGES` (their ``.py`` and ``.json``
    files, the built-in mazes among them), computed once per process: records made with another
    fingerprint were made by other code."""
    digests = source_digest(SIMULATION_PACKAGES, (".py", ".json"))
    return hashlib.sha256(json.dumps(digests, sort_keys=True).encode()).hexdigest()[:16]


def load_average() -> list[float] | None:
    return [round(x, 2) for x in os.getloadavg()] if hasattr(os, "getloadavg") else None


def machine_info(**versions: str) -> dict[str, Any]:
    """CPU, platform and Python, plus the given package versions."""
    return {
        "cpu_count": os.cpu_count(),
        "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "cpu": cpu_model(),
        "cpu_vector_flags": cpu_vector_flags(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        **versions,
    }


def command_line(root: str | Path = ".") -> str:
    """The command that ran this script, as one runs it from ``root``: ``python -m package.module``
    for a module of a package there (run as a file, its imports of the package would fail), else
    ``python`` and the script's path relative to ``root``."""
    script = Path(sys.argv[0])
    shown = os.path.relpath(script, root) if script.is_absolute() else sys.argv[0]
    relative = Path(shown)
    if (
        relative.suffix == ".py"
        and not relative.is_absolute()
        and ".." not in relative.parts
        and (Path(root) / relative.parent / "__init__.py").exists()
    ):
        return shlex.join(["python", "-m", ".".join(relative.with_suffix("").parts), *sys.argv[1:]])
    return shlex.join(["python", shown, *sys.argv[1:]])


def field_docs(cls: type) -> dict[str, str]:
    """The docstring under each field of the dataclass ``cls`` (CleanRL style: a string literal on the
    line after the field), by field name; empty where the source cannot be read."""
    import ast
    import inspect
    import textwrap

    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    except (OSError, TypeError, SyntaxError):
        return {}
    body = tree.body[0].body if tree.body and isinstance(tree.body[0], ast.ClassDef) else []
    docs = {}
    for node, after in itertools.pairwise(body):
        if (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and isinstance(after, ast.Expr)
            and isinstance(after.value, ast.Constant)
            and isinstance(after.value.value, str)
        ):
            docs[node.target.id] = " ".join(after.value.value.split())
    return docs


def _int_at_least(text: str, least: int, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = least - 1
    if value < least:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
    return value


def positive_int(text: str) -> int:
    """An argparse type: an integer >= 1 (argparse names the option in its error)."""
    return _int_at_least(text, 1, "a positive integer")


def non_negative_int(text: str) -> int:
    """An argparse type: an integer >= 0, e.g. a seed (argparse names the option in its error)."""
    return _int_at_least(text, 0, "a non-negative integer")


def parse_dataclass_args(cls: type[ArgsT], description: str, argv: list[str] | None = None, prog: str | None = None) -> ArgsT:
    """A command line with one ``--flag`` per field of the dataclass ``cls`` (CleanRL style).

    Tuples take several values; booleans get ``--flag/--no-flag``. Each field's docstring
    (:func:`field_docs`) is its help text, with its default. ``prog``: the command as the usage line
    shows it (default: the script's file name).
    """
    parser = argparse.ArgumentParser(prog=prog, description=description)
    docs = field_docs(cls)
    for f in dataclasses.fields(cls):
        default, flag = f.default, f"--{f.name.replace('_', '-')}"
        shown = " ".join(map(str, default)) if isinstance(default, tuple) else default
        text = f"{docs[f.name]} (default: {shown})" if f.name in docs else f"(default: {shown})"
        text = text.replace("%", "%%")  # argparse formats help with %
        if isinstance(default, bool):
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=default, help=docs.get(f.name, "").replace("%", "%%"))
        elif isinstance(default, tuple):
            parser.add_argument(flag, nargs="+", type=type(default[0]) if default else str, default=default, help=text)
        else:
            parser.add_argument(flag, type=type(default), default=default, help=text)
    values = vars(parser.parse_args(argv))
    return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in values.items()})
