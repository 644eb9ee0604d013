"""Print the version of mpi_ros (with -v: where it is installed and what it found)."""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "-v", "--verbose", action="store_true",
        help="also print the Python, the package location and the generated interfaces found",
    )


def run(args: argparse.Namespace) -> int:
    import mpi_ros

    print(f"mpi_ros {mpi_ros.__version__}")
    if args.verbose:
        print(f"python: {sys.executable} ({sys.version.split()[0]})")
        print(f"package: {os.path.dirname(mpi_ros.__file__)}")
        for sub in ("msg", "srv", "action"):
            found = importlib.util.find_spec(f"mpi_ros.{sub}") is not None
            print(f"interfaces mpi_ros.{sub}: {'found' if found else 'MISSING (not built/installed)'}")
    return 0
