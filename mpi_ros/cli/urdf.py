"""Print the robot description (URDF) the suite publishes for a configuration.

Generated from the configured joints (axes.defaults|overrides.<n>.joint): a chain
base_link -> <joint>_link, limits from the software limits and max_velocity (docs/joints.md).
With ros.robot_description in the configuration, that file is printed instead, once checked
against the joints (--generated: the generated one all the same).

  mpi-ros urdf --config config/gantry.yaml > gantry.urdf
  mpi-ros urdf --config config/gantry.yaml --namespace /cell_a   # names prefixed cell_a/
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", help="the suite's YAML configuration (default: config/default.yaml's values)")
    parser.add_argument("--namespace", help="the suite's namespace, if not the configuration's ros.namespace "
                                            "(it prefixes the joint and link names, docs/cell.md)")
    parser.add_argument("--generated", action="store_true",
                        help="print the generated description even where ros.robot_description names a file")


def run(args: argparse.Namespace) -> int:
    from mpi_ros import config as suite_config
    from mpi_ros import description

    try:
        cfg = description.load(args.config, args.namespace)
        text = description.generate(cfg) if args.generated else description.robot_description(cfg)
    except suite_config.ConfigError as exc:
        print(f"mpi-ros urdf: invalid configuration: {exc}", file=sys.stderr)
        return 2
    sys.stdout.write(text)
    return 0
