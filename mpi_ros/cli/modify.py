"""Modify the running move (MotionModify): a new target or new limits, in flight.

  mpi-ros modify --position 500 0 --velocity 1000 --acceleration 10000 --deceleration 10000
  mpi-ros modify --type VELOCITY --velocity -200 --acceleration 5000
  mpi-ros modify --goal "{type: S_CURVE, position: [500.0, 0.0],
                          trajectory: [{velocity: 1000.0, acceleration: 10000.0}]}"

The same flags and --goal YAML as `mpi-ros move` (MotionModify has the same fields). The
supervisor must be MOVING: while IDLE it answers MPIMotionMessageIDLE (unless the goal has
AUTO_START). The command follows the modified move to its end, like move.

Exit status: 0 MPIMessageOK; 1 refused or ended early by the controller (its message is
printed); 2 usage or connection problem.
"""

from __future__ import annotations

import argparse

from .goals import add_goal_arguments, send


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_goal_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return send(args, modify=True)
