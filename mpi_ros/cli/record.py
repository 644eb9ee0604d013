"""Record a run to a rosbag2-compatible bag (metadata.yaml + .mcap).

  mpi-ros record OUTPUT [--config FILE] [--time-scale X]   the node suite, recorded until Ctrl-C
  mpi-ros record OUTPUT --scenario FILE                    a scripted run, headless, as fast as possible

The bag holds statuses, events, joint states and every command with the sample at which
it took effect, plus the configuration: `mpi-ros replay OUTPUT` reproduces the run.
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("output", help="bag directory to create (must not exist or be empty)")
    parser.add_argument("--scenario", help="YAML scenario: commands at samples (see mpi_ros/bag/scenario.py)")
    parser.add_argument("--config", help="suite configuration (YAML); default: config/default.yaml")
    parser.add_argument("--time-scale", type=float, default=1.0, help="1 real time, larger faster, 0 fastest")


def run(args) -> int:
    if args.scenario:
        from mpi_ros.bag import scenario

        try:
            plan = scenario.load(args.scenario)
            path = scenario.record(plan, args.output)
        except (OSError, ValueError) as exc:
            print(f"mpi-ros record: {exc}", file=sys.stderr)
            return 2
        print(f"recorded scenario {plan.name} ({plan.samples} samples) to {path}")
        return 0
    from mpi_ros.cli import run as run_suite

    args.record = args.output
    return run_suite.run(args)
