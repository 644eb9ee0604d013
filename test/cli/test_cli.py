"""The `mpi-ros` command front end (mpi_ros.cli) and the package's import hygiene."""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from mpi_ros import __version__
from mpi_ros.cli import COMMANDS, build_parser, main, split_ros_args

REPO = Path(__file__).resolve().parents[2]


def test_version_subcommand(capsys):
    assert main(["version"]) == 0
    assert capsys.readouterr().out.strip() == f"mpi_ros {__version__}"


def test_version_verbose_finds_generated_interfaces(capsys):
    assert main(["version", "-v"]) == 0
    out = capsys.readouterr().out
    for sub in ("msg", "srv", "action"):
        assert f"interfaces mpi_ros.{sub}: found" in out


def test_version_matches_package_xml():
    text = (REPO / "package.xml").read_text()
    assert re.search(r"<version>([^<]+)</version>", text).group(1) == __version__


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_registered_subcommands_follow_the_contract(name):
    module = importlib.import_module(COMMANDS[name])
    assert (module.__doc__ or "").strip(), f"{COMMANDS[name]} needs a docstring (its help)"
    assert callable(module.add_arguments)
    assert callable(module.run)


def test_parser_lists_every_subcommand():
    help_text = build_parser().format_help()
    for name in COMMANDS:
        assert name in help_text


def test_no_subcommand_is_an_error(capsys):
    with pytest.raises(SystemExit) as exc:
        main([])
    assert exc.value.code == 2


@pytest.mark.parametrize(("argv", "own", "ros"), [
    (["run", "--config", "a.yaml"], ["run", "--config", "a.yaml"], []),
    (["--config", "a.yaml", "--ros-args", "-r", "__ns:=/x"],
     ["--config", "a.yaml"], ["--ros-args", "-r", "__ns:=/x"]),
    (["--ros-args", "-p", "a:=1", "--", "--time-scale", "2"],
     ["--time-scale", "2"], ["--ros-args", "-p", "a:=1"]),
    (["--ros-args", "--log-level", "debug", "--", "x", "--ros-args", "-r", "a:=b"],
     ["x"], ["--ros-args", "--log-level", "debug", "--ros-args", "-r", "a:=b"]),
])
def test_split_ros_args(argv, own, ros):
    assert split_ros_args(argv) == (own, ros)


def test_ros_args_do_not_reach_the_parser(capsys):
    assert main(["version", "--ros-args", "-r", "__node:=x"]) == 0


def _run_python(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-P", "-c", code], check=False, capture_output=True, text=True,
                          env=dict(os.environ), timeout=60, cwd=REPO)


def test_importing_the_package_and_cli_does_not_import_rclpy():
    proc = _run_python(
        "import sys, mpi_ros, mpi_ros.cli; mpi_ros.cli.build_parser();"
        "print(sorted(m for m in sys.modules if m.split('.')[0] == 'rclpy'))")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_console_script_is_installed():
    script = Path(sys.prefix) / "bin" / "mpi-ros"
    assert script.is_file(), f"{script} missing: run scripts/setup.sh"
    proc = subprocess.run([str(script), "version"], check=False, capture_output=True, text=True,
                          env=dict(os.environ), timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"mpi_ros {__version__}"


def test_started_as_the_suite_executable_messages_name_it(monkeypatch, capsys):
    # `ros2 run mpi_ros suite` and the launch file run scripts/ros/suite, which calls main(["run", ...])
    monkeypatch.setattr(sys, "argv", ["/ws/install/lib/mpi_ros/suite", "--time-scale", "-1"])
    assert main(["run", "--time-scale", "-1"]) == 2
    assert capsys.readouterr().err.strip() == "mpi_ros suite: --time-scale must be >= 0"
    with pytest.raises(SystemExit):
        main(["run", "--bogus"])
    assert capsys.readouterr().err.startswith("usage: mpi_ros suite ")
    monkeypatch.setattr(sys, "argv", ["mpi-ros"])
    assert main(["run", "--time-scale", "-1"]) == 2
    assert capsys.readouterr().err.strip() == "mpi-ros run: --time-scale must be >= 0"


def test_help_says_where_to_start_and_what_exit_statuses_mean():
    text = build_parser().format_help()
    assert "mpi-ros run " in text
    assert "mpi-ros status" in text
    assert "mpi-ros demo" in text
    assert "Exit status: 0 OK; 1 refused by the controller" in text
