"""One owner per concept (docs/architecture.md): a supervisor and its collaborators reach the
controller only through SupervisorHost, the fault monitor through FaultHost; the ROS layer,
the runner and the ruckig cross-check import no supervisor collaborator."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "mpi_ros"
SUPERVISOR = ["motion.py", "axis_list.py", "moves.py", "supervisor_actions.py", "supervisor_stepping.py",
              "supervisor_state.py", "faults.py"]
COLLABORATORS = {"axis_list", "moves", "supervisor_actions", "supervisor_stepping", "supervisor_state"}


def imported(path: Path) -> set[str]:
    """The modules ``path`` imports, as written (relative ones without their dots)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            names.add((node.module or "").split(".")[-1])
        elif isinstance(node, ast.Import):
            names.update(alias.name.split(".")[-1] for alias in node.names)
    return names


def test_the_supervisor_and_the_fault_monitor_never_import_the_controller():
    for name in SUPERVISOR:
        assert "control" not in imported(PACKAGE / "mpi" / name), name


def test_the_ros_layer_runner_and_crosscheck_use_no_supervisor_collaborator():
    users = [*(PACKAGE / "ros").glob("*.py"), PACKAGE / "runner.py", *(PACKAGE / "crosscheck").glob("*.py")]
    for path in users:
        assert not imported(path) & COLLABORATORS, path
