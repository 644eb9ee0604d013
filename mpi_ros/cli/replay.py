"""Replay a recorded bag into a fresh controller and compare it, sample for sample.

  mpi-ros replay BAG [--set KEY=VALUE ...] [--tolerance X] [--namespace NS]

BAG is a bag of `mpi-ros record` / `mpi-ros run --record`, or of any recorder of the graph
(`ros2 bag record -a`): the suite publishes its commands (/mpi/commands) and configuration
(/mpi/configuration, latched) for that. Exit status 0 when the replay reproduces every
recorded status, event and answer, 1 when it diverges (the first divergence is printed:
where, which field, by how much), 2 when the bag cannot be replayed (the message says what
it lacks: the configuration, the commands, the statuses). A bag its recorder did not finish
(killed) is replayed up to its last complete record, and said to be truncated.
--set changes the recorded configuration, e.g. --set axes.defaults.plant.bandwidth_hz=20.
--namespace chooses one suite of a bag that recorded a cell of several (/cell_a, /cell_b).
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", help="bag directory or .mcap file")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a configuration value (dotted key, YAML value)")
    parser.add_argument("--tolerance", type=float, default=0.0, help="allowed difference of numbers (default 0)")
    parser.add_argument("--namespace", metavar="NS", help="the suite to replay, in a bag of several (a cell)")


def overrides(pairs: list[str]) -> dict:
    """['a.b=1', ...] -> {'a': {'b': 1}}"""
    import yaml

    out: dict = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise ValueError(f"--set {pair!r}: expected KEY=VALUE")
        node = out
        parts = key.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = yaml.safe_load(value)
    return out


def run(args) -> int:
    from mpi_ros.bag.replay import replay
    from mpi_ros.config import ConfigError

    try:
        report = replay(args.bag, overrides(args.set), args.tolerance, namespace=args.namespace)
    except (OSError, ValueError, ConfigError) as exc:
        print(f"mpi-ros replay: {exc}", file=sys.stderr)
        return 2
    if report.truncated:
        print(f"mpi-ros replay: truncated bag: {report.truncated}", file=sys.stderr)
    print(report.summary())
    return 0 if report.identical else 1
