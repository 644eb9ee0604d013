"""Start a move (MotionStart) on a supervisor and follow it to its end.

  mpi-ros move --type S_CURVE --position 1000 0 --velocity 500 --acceleration 5000 --deceleration 5000 --jerk-percent 50
  mpi-ros move --position -200 0 -v 500 -a 5000 -d 5000 --attribute RELATIVE --supervisor 1
  mpi-ros move --type VELOCITY --velocity 300 --acceleration 2000 --no-wait
  mpi-ros move --goal "{type: S_CURVE, position: [1000.0, 0.0], trajectory: [{velocity: 500.0, acceleration: 5000.0,
                        deceleration: 5000.0, jerk_percent: 50.0}]}"

One --position per axis of the supervisor (ms0 has axes 0 and 1 by default, so two).
--goal takes the same YAML as `ros2 action send_goal /mpi/ms0/motion_start
mpi_ros/action/MotionStart`; flags override its fields. Feedback shows as a progress bar
(plain lines when stdout is not a terminal); the result shows the controller's message,
its code, the state and the positions. Ctrl-C cancels the goal, which is a STOP.

Exit status: 0 MPIMessageOK; 1 refused or ended early by the controller (its message is
printed, e.g. MPIMotionMessageMOVING); 2 usage or connection problem.
"""

from __future__ import annotations

import argparse

from .goals import add_goal_arguments, send


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_goal_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return send(args, modify=False)
