"""How far the twin's following error is from a recording's, per axis (docs/calibration.md).

  mpi-ros compare RECORDING --config FILE [--axis K ...] [--rate HZ]

RECORDING as for `mpi-ros fit` (a bag or a CSV). The twin's plant of each axis, as FILE
configures it, is run on the recorded command; printed per axis: the recorded following
error, the twin's, and their difference (RMS, maximum and the time of the maximum, in
counts and seconds from the recording's start). Exit status 0, or 2 for bad input.
"""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recording", metavar="RECORDING", help="bag directory, .mcap file or .csv file")
    parser.add_argument("--config", metavar="FILE", required=True, help="the configuration to compare")
    parser.add_argument("--axis", type=int, nargs="+", action="extend", metavar="K",
                        help="only these axes (default: every axis whose command moves)")
    parser.add_argument("--rate", type=float, metavar="HZ", help="the controller's sample rate")


def run(args) -> int:
    from mpi_ros.cli.fit import gathered

    inputs = gathered(args, "compare")
    if inputs is None:
        return 2
    # scipy is imported here, when a comparison runs (never by the suite).
    from mpi_ros.calibration import report
    from mpi_ros.calibration.fit import compare

    for axis in inputs.axes:
        plant = inputs.plants[axis.number]
        print(report.compare_text(axis, inputs.rate, plant, *compare(axis, plant, inputs.rate)))
    return 0
