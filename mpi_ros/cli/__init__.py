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
import sys
from typing import Sequence

# name -> module (absolute path). Add a subcommand by writing the module and adding it here.
COMMANDS: dict[str, str] = {
    "run": "mpi_ros.cli.run",
    "record": "mpi_ros.cli.record",
    "replay": "mpi_ros.cli.replay",
    "play": "mpi_ros.cli.play",
    "crosscheck": "mpi_ros.cli.crosscheck",
    "plot": "mpi_ros.cli.plot",
    "version": "mpi_ros.cli.version",
}

PROG = "mpi-ros"


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


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand."""
    from mpi_ros import __version__

    parser = argparse.ArgumentParser(
        prog=PROG,
        description="mpi_ros: ROS 2 node suite for MPI/XMP-style motion controllers.",
    )
    parser.add_argument("--version", action="version", version=f"mpi_ros {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name, module_name in COMMANDS.items():
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
        sub_parser.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``mpi-ros`` command; returns the exit status."""
    if argv is None:
        argv = sys.argv[1:]
    own, ros_args = split_ros_args(list(argv))
    parser = build_parser()
    args = parser.parse_args(own)
    args.ros_args = ros_args
    try:
        status = args._run(args)
    except KeyboardInterrupt:
        return 130
    return 0 if status is None else int(status)
