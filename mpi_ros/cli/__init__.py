"""The ``mpi-ros`` command: ``mpi-ros <subcommand> [options]``.

Subcommands are modules registered in :data:`COMMANDS` (name -> module path). A subcommand
module provides:

* a docstring whose first line is the subcommand's one-line help,
* ``add_arguments(parser)``: adds its options to an ``argparse.ArgumentParser``,
* ``run(args) -> int``: does the work and returns the exit status (None counts as 0).

Every subcommand module is imported to build the parser, so keep heavy imports (rclpy,
numpy, matplotlib, ...) inside ``run``: ``mpi-ros version`` and ``mpi-ros --help`` must stay fast.

ROS arguments (``--ros-args ... [--]``, as ``ros2 run`` and launch files append them) are taken
out of the command line before parsing and handed to the subcommand as ``args.ros_args``
(the full list, ``--ros-args`` included, ready for ``rclpy.init(args=...)``).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence
from pathlib import Path

# name -> module (absolute path). Add a subcommand by writing the module and adding it here.
# The order is the order of `mpi-ros --help`: the suite, then the operator's console, then tools.
COMMANDS: dict[str, str] = {
    "run": "mpi_ros.cli.run",
    "demo": "mpi_ros.cli.demo",
    "console": "mpi_ros.cli.tui",
    "move": "mpi_ros.cli.move",
    "modify": "mpi_ros.cli.modify",
    "stop": "mpi_ros.cli.stop",
    "e-stop": "mpi_ros.cli.e_stop",
    "abort": "mpi_ros.cli.abort",
    "reset": "mpi_ros.cli.reset",
    "resume": "mpi_ros.cli.resume",
    "fault": "mpi_ros.cli.fault",
    "status": "mpi_ros.cli.status",
    "events": "mpi_ros.cli.events",
    "echo": "mpi_ros.cli.echo",
    "record": "mpi_ros.cli.record",
    "replay": "mpi_ros.cli.replay",
    "play": "mpi_ros.cli.play",
    "crosscheck": "mpi_ros.cli.crosscheck",
    "plot": "mpi_ros.cli.plot",
    "urdf": "mpi_ros.cli.urdf",
    "fit": "mpi_ros.cli.fit",
    "compare": "mpi_ros.cli.compare",
    "version": "mpi_ros.cli.version",
}

PROG = "mpi-ros"
EPILOG = """\
start here:
  mpi-ros run                      the suite (leave it running), then from another shell:
  mpi-ros console                  a full-screen console: live table, events, keys for STOP/E_STOP/...
  mpi-ros status                   a live table of the supervisors and axes
  mpi-ros move --position 1000 0 --velocity 500 --acceleration 5000 --deceleration 5000 --jerk-percent 50
  mpi-ros demo                     or instead: a narrated, recorded tour on a suite of its own

The console verbs (move ... echo) take --namespace (default /mpi) and --supervisor N
(default 0). Exit status: 0 OK; 1 refused by the controller (its message is printed);
2 usage or connection problem. `mpi-ros COMMAND --help` explains each, with examples.
"""
# `ros2 run mpi_ros suite` (and the launch file) run scripts/ros/suite, which calls
# main(["run", ...]): its messages and usage must name what the user started.
SUITE_EXECUTABLE = "suite"
SUITE_PROG = "mpi_ros suite"


def split_ros_args(argv: Sequence[str]) -> tuple[list[str], list[str]]:
    """Split ``argv`` into (own arguments, ROS arguments).

    ROS arguments run from each ``--ros-args`` to the next ``--`` (dropped) or the end, as in
    rcl. The ROS list keeps every ``--ros-args`` token; it is empty if there were none.
    """
    own: list[str] = []
    ros: list[str] = []
    in_ros = False
    for arg in argv:
        if arg == "--ros-args":
            in_ros = True
            ros.append(arg)
        elif in_ros and arg == "--":
            in_ros = False
        elif in_ros:
            ros.append(arg)
        else:
            own.append(arg)
    return own, ros


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand, or with subcommand ``only``:
    a one-shot verb imports its own module, not all of them (a tenth of a second)."""
    from mpi_ros import __version__

    parser = argparse.ArgumentParser(
        prog=PROG,
        description="mpi_ros: ROS 2 node suite for MPI/XMP-style motion controllers.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"mpi_ros {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name, module_name in COMMANDS.items():
        if only is not None and name != only:
            continue
        module = importlib.import_module(module_name)
        doc = (module.__doc__ or "").strip()
        summary = doc.splitlines()[0] if doc else ""
        sub_parser = sub.add_parser(
            name,
            help=summary,
            description=doc or None,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        module.add_arguments(sub_parser)
        sub_parser.set_defaults(_run=module.run, _prog=sub_parser.prog)
    return parser


def build_suite_parser(prog: str = SUITE_PROG) -> argparse.ArgumentParser:
    """The parser of the ``suite`` executable: ``mpi-ros run``'s options under its own name."""
    from mpi_ros.cli import run as run_suite

    parser = argparse.ArgumentParser(prog=prog, description=run_suite.__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    run_suite.add_arguments(parser)
    parser.set_defaults(_run=run_suite.run, _prog=prog)
    return parser


def started_as_suite() -> bool:
    """Whether this process is the ``suite`` executable (ros2 run / launch), not ``mpi-ros``."""
    return Path(sys.argv[0]).name == SUITE_EXECUTABLE


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``mpi-ros`` command; returns the exit status."""
    if argv is None:
        argv = sys.argv[1:]
    own, ros_args = split_ros_args(list(argv))
    if own[:1] == ["run"] and started_as_suite():
        parser, own = build_suite_parser(), own[1:]
    else:
        parser = build_parser(own[0] if own[:1] and own[0] in COMMANDS else None)
    args = parser.parse_args(own)
    args.ros_args = ros_args
    try:
        status = args._run(args)
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # stdout's reader left (`mpi-ros echo events | head -3`): it had what it wanted.
        # Point stdout at /dev/null so the interpreter's final flush does not fail again.
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)
        except (OSError, ValueError):  # stdout is not a file (captured): nothing to flush into a pipe
            pass
        return 0
    return 0 if status is None else int(status)
