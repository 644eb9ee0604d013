"""The linter and the type checker run clean (issue 10): ``ruff check`` over the Python of the
repository and ``mypy`` over mpi_ros/, both configured in pyproject.toml.

Each runs as a module of this interpreter (the venv's: requirements/test.txt installs both, and
mypy then checks against the annotations of the libraries installed there), from the repository
root. A tool that is not installed skips its test, saying so; anything it reports fails it, with
its output.
"""

from __future__ import annotations

import ast
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LINTED = ("mpi_ros", "test", "bench", "examples", "scripts")  # what ruff checks


def _run_clean(module: str, *args: str, timeout: float) -> None:
    if importlib.util.find_spec(module) is None:
        pytest.skip(f"{module} is not installed in {sys.prefix} (requirements/test.txt pins it: "
                    "scripts/setup.sh installs it)")
    command = [sys.executable, "-P", "-m", module, *args]
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, (f"`{' '.join([module, *args])}` exited with {done.returncode}:\n"
                                  f"{done.stdout}{done.stderr}")


def test_ruff_check_is_clean():
    _run_clean("ruff", "check", *LINTED, timeout=120)


def test_mypy_is_clean():
    # the packages, options and per-module overrides are pyproject.toml's; its cache is .mypy_cache
    _run_clean("mypy", timeout=240)


def test_every_test_marked_slow_by_name_exists():
    # test/conftest.py marks slow tests by function name: a renamed test would silently lose its mark
    tree = ast.parse((ROOT / "test" / "conftest.py").read_text())
    slow = next(ast.literal_eval(node.value) for node in tree.body
                if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "_SLOW_TESTS")
    defined = {line.split("def ", 1)[1].split("(", 1)[0]
               for path in (ROOT / "test").rglob("test_*.py")
               for line in path.read_text().splitlines() if line.lstrip().startswith("def test_")}
    assert slow <= defined, f"no such test: {sorted(slow - defined)}"
