"""The launch files, read as source: launch and launch_ros are not on PyPI, so they cannot
run here. Each compiles; machine.launch.py declares its arguments, starts the suite with
options `mpi-ros run` has, and starts robot_state_publisher and RViz only where installed."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from mpi_ros.cli import build_parser

LAUNCH = Path(__file__).resolve().parents[1] / "launch"


def _tree(name: str) -> ast.Module:
    source = (LAUNCH / name).read_text(encoding="utf-8")
    compile(source, name, "exec")  # a syntax error fails here
    return ast.parse(source)


def _calls(tree: ast.Module, name: str) -> list[ast.Call]:
    return [node for node in ast.walk(tree) if isinstance(node, ast.Call)
            and getattr(node.func, "id", getattr(node.func, "attr", None)) == name]


def _keyword(call: ast.Call, name: str):
    """A keyword argument's value if it is a literal, else its source text."""
    value = next(k.value for k in call.keywords if k.arg == name)
    return ast.literal_eval(value) if isinstance(value, ast.Constant) else ast.unparse(value)


@pytest.mark.parametrize("name", ["mpi_ros.launch.py", "machine.launch.py"])
def test_every_launch_file_compiles_and_has_generate_launch_description(name):
    tree = _tree(name)
    assert "generate_launch_description" in {f.name for f in tree.body if isinstance(f, ast.FunctionDef)}


def test_the_machine_launch_declares_config_namespace_record_and_rviz():
    declared = {ast.literal_eval(call.args[0]): _keyword(call, "default_value")
                for call in _calls(_tree("machine.launch.py"), "DeclareLaunchArgument")}
    assert set(declared) == {"config", "namespace", "record", "rviz"}
    assert declared == {"config": "default_config", "namespace": "", "record": "", "rviz": "false"}


def test_the_machine_launch_starts_the_suite_with_options_of_mpi_ros_run_and_the_optional_nodes():
    tree = _tree("machine.launch.py")
    packages = {_keyword(call, "package"): _keyword(call, "executable") for call in _calls(tree, "Node")}
    assert packages == {"mpi_ros": "suite", "robot_state_publisher": "robot_state_publisher", "rviz2": "rviz2"}
    installed = {ast.literal_eval(call.args[0]) for call in _calls(tree, "_installed")}
    assert installed == {"robot_state_publisher", "rviz2"}  # each optional node asks first
    options = {node.value for node in ast.walk(tree) if isinstance(node, ast.Constant)
               and isinstance(node.value, str) and node.value.startswith("--")}
    run = build_parser()._subparsers._group_actions[0].choices["run"]  # type: ignore[union-attr]
    known = {option for action in run._actions for option in action.option_strings}
    assert options == {"--config", "--namespace", "--record"}
    assert options <= known
    # its default configuration is one the package installs (config/ is installed whole)
    assert "gantry.yaml" in {node.value for node in ast.walk(tree) if isinstance(node, ast.Constant)}
    assert (LAUNCH.parent / "config" / "gantry.yaml").is_file()
