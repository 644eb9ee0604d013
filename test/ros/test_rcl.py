"""The private rclpy bindings have one owner (mpi_ros/ros/rcl.py), which refuses an rclpy it
was not written for, naming the version (docs/reliability.md, "Two action servers, one
protocol")."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from mpi_ros.ros import rcl

PACKAGE = Path(__file__).resolve().parents[2] / "mpi_ros"
PRIVATE = ("rclpy.impl", "rclpy._rclpy_pybind11")


def test_only_rcl_imports_rclpys_private_bindings():
    users = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([node.module or ""] if isinstance(node, ast.ImportFrom)
                     else [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            if any(name.startswith(PRIVATE) for name in names):
                users.append(path.relative_to(PACKAGE).as_posix())
    assert users == ["ros/rcl.py"]


def test_the_installed_rclpy_is_the_one_the_bindings_were_written_for():
    rcl.check_version()  # Jazzy's rclpy, from requirements/runtime.txt


@pytest.mark.parametrize("version", ["8.0.1", "7.2.0", "27.0", "rolling"])
def test_another_rclpy_is_refused_naming_its_version(version):
    with pytest.raises(rcl.UnsupportedRclpy, match=f"rclpy {version} is installed.*ros.action_server: rclpy"):
        rcl.check_version(version)


def test_a_bad_action_server_setting_names_its_key():
    from mpi_ros import config

    with pytest.raises(config.ConfigError, match=r"ros\.action_server: one of batched, rclpy, got 'stock'"):
        config.load(overrides={"ros": {"action_server": "stock"}})
    with pytest.raises(config.ConfigError, match=r"ros\.goal_process: the goal front serves the batched"):
        config.load(overrides={"ros": {"action_server": "rclpy", "goal_process": True}})
