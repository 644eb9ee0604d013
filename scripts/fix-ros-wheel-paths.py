#!/usr/bin/env python3
"""Point the ROS wheels' exported CMake files at this environment's Python.

The ROS 2 Jazzy wheels on PyPI were built in a manylinux container whose Python lives in
/opt/python/cp311-cp311; their exported CMake targets (share/<pkg>/cmake/*.cmake) name its
include directory and site-packages (numpy's headers), and CMake refuses imported targets with
missing include directories. This rewrites those paths to the include directory and
site-packages of the interpreter running this script (run it with the venv's python).

Idempotent: a second run finds nothing to change. Only CMake files are touched.
Usage: python fix-ros-wheel-paths.py [--prefix PREFIX] [--quiet]   (PREFIX defaults to sys.prefix)
"""

from __future__ import annotations

import argparse
import os
import sys
import sysconfig
import tempfile

WHEEL_PYTHON = "/opt/python/cp311-cp311"


def replacements() -> list[tuple[str, str]]:
    paths = sysconfig.get_paths()
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    return [
        (f"{WHEEL_PYTHON}/include/{version}", paths["include"]),
        (f"{WHEEL_PYTHON}/lib/{version}/site-packages", paths["purelib"]),
    ]


def cmake_files(prefix: str):
    roots = [os.path.join(prefix, "share"), os.path.join(prefix, "lib", "cmake")]
    for root in roots:
        if not os.path.isdir(root):
            continue
        for dirpath, _dirnames, filenames in os.walk(root):
            for name in filenames:
                if name.endswith(".cmake"):
                    yield os.path.join(dirpath, name)


def fix(prefix: str, quiet: bool = False) -> int:
    """Rewrite the files under prefix; returns the number of files changed."""
    if sys.version_info[:2] != (3, 11):
        print(f"warning: the ROS wheels are cp311, this is Python {sys.version.split()[0]}",
              file=sys.stderr)
    subs = replacements()
    include_dir = subs[0][1]
    if not os.path.exists(os.path.join(include_dir, "Python.h")):
        print(f"warning: no Python.h in {include_dir}: building interfaces will fail",
              file=sys.stderr)
    changed = 0
    leftovers = []
    for path in cmake_files(prefix):
        with open(path, "rb") as f:
            data = f.read()
        if WHEEL_PYTHON.encode() not in data:
            continue
        text = data.decode("utf-8")
        new = text
        for old, repl in subs:
            new = new.replace(old, repl)
        if WHEEL_PYTHON in new:
            leftovers.append(path)
        if new != text:
            mode = os.stat(path).st_mode
            fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".fix-")
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(new)
            os.chmod(tmp, mode & 0o7777)
            os.replace(tmp, path)
            changed += 1
    for path in leftovers:
        print(f"warning: {path} still names {WHEEL_PYTHON}", file=sys.stderr)
    if not quiet:
        print(f"fix-ros-wheel-paths: {changed} CMake file(s) rewritten under {prefix}")
    return changed


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--prefix", default=sys.prefix)
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args(argv)
    fix(args.prefix, args.quiet)
    return 0


if __name__ == "__main__":
    sys.exit(main())
