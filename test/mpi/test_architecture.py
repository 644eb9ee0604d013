"""The controller's layout (docs/architecture.md): subpackages in layers, no import cycle, one
owner per concept. A supervisor and its collaborators reach the controller only through
SupervisorHost, the fault monitor through FaultHost; the ROS layer, the runner and the ruckig
cross-check use no supervisor collaborator."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "mpi_ros"
MPI = PACKAGE / "mpi"
COLLABORATORS = {"axis_list", "moves", "actions", "stepping", "state", "holds"}
# Each layer may import the layers before it, never one after it: a subpackage, or a module at
# the root (host.py: the interface the controller offers its parts, below the parts). The
# other root modules (control.py and what only it uses) are the top.
LAYERS = ["base", "planning", "axes", "host", "faults", "supervisor"]


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(path: Path) -> set[str]:
    """Every module ``path`` imports, absolute, TYPE_CHECKING imports included (a cycle of
    type names is still a cycle a reader has to untangle)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = module_name(path).split(".")
                anchor = anchor if path.name == "__init__.py" else anchor[:-1]
                base = ".".join(anchor[: len(anchor) - node.level + 1] + ([base] if base else []))
            found.add(base)
            found.update(f"{base}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return found


def mpi_graph() -> dict[str, set[str]]:
    """The import graph of mpi_ros.mpi's modules (package __init__ files left out: they only
    re-export)."""
    modules = {module_name(p): p for p in MPI.rglob("*.py") if p.name != "__init__.py"}
    return {name: imports_of(path) & modules.keys() for name, path in modules.items()}


def layer_of(module: str) -> int:
    part = module.split(".")[2]
    return LAYERS.index(part) if part in LAYERS else len(LAYERS)


def test_the_controller_has_no_import_cycle():
    graph = mpi_graph()
    done: set[str] = set()

    def visit(node: str, path: list[str]) -> None:
        if node in path:
            pytest.fail("import cycle: " + " -> ".join([*path[path.index(node):], node]))
        if node in done:
            return
        for child in sorted(graph[node]):
            visit(child, [*path, node])
        done.add(node)

    for module in sorted(graph):
        visit(module, [])


def test_each_layer_imports_only_the_layers_before_it():
    for module, imported in mpi_graph().items():
        for other in imported:
            assert layer_of(other) <= layer_of(module), f"{module} imports {other}"


def test_the_supervisor_and_the_fault_monitor_never_import_the_controller():
    for path in [*(MPI / "supervisor").glob("*.py"), *(MPI / "faults").glob("*.py")]:
        assert "mpi_ros.mpi.control" not in imports_of(path), path


def test_the_ros_layer_runner_and_crosscheck_use_no_supervisor_collaborator():
    forbidden = {f"mpi_ros.mpi.supervisor.{name}" for name in COLLABORATORS}
    users = [*(PACKAGE / "ros").glob("*.py"), PACKAGE / "runner.py", *(PACKAGE / "crosscheck").glob("*.py")]
    for path in users:
        assert not imports_of(path) & forbidden, path


def test_the_controller_never_imports_ros():
    for path in MPI.rglob("*.py"):
        assert not {name for name in imports_of(path) if name.split(".")[0] in {"rclpy", "rosidl_runtime_py"}}, path
