"""Fit each axis' servo plant to a recording of a real controller (docs/calibration.md).

  mpi-ros fit RECORDING [--axis K ...] [--output FILE] [--plot FILE] [--config FILE] [--rate HZ]

RECORDING is a bag of this suite's topics (a bag directory or .mcap file: the AxisStatus
topics' command_position and actual_position) or a CSV file with a header row: time (s) and,
per axis k, axis<k>_command_position and axis<k>_actual_position (one axis may use
command_position and actual_position). The twin's own plant is run on the recorded command
and bandwidth_hz, damping, velocity_feedforward and acceleration_feedforward (and
encoder_resolution, where the positions show the encoder's step) fitted to the recorded
actual position. Printed: per axis the residual with the configured plant and with the fit,
and whether the fitted twin matches within the recording's noise; then the fitted YAML
block, ready to paste into a configuration (--output also writes it to FILE).
--config: the configured plants (default: the one recorded in the bag, else the default).
--rate: the controller's sample rate the twin runs at (default: the recording's, else the
configuration's). Exit status 0 (a fit was made, matching or not), 2 bad input.
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recording", metavar="RECORDING", help="bag directory, .mcap file or .csv file")
    parser.add_argument("--axis", type=int, nargs="+", action="extend", metavar="K",
                        help="only these axes (default: every axis whose command moves)")
    parser.add_argument("--output", metavar="FILE", help="also write the fitted YAML block to FILE")
    parser.add_argument("--plot", metavar="FILE", help="a PNG of recorded and twin actual position and error")
    parser.add_argument("--config", metavar="FILE", help="the configuration whose plants are compared")
    parser.add_argument("--rate", type=float, metavar="HZ", help="the controller's sample rate")


def gathered(args, verb: str):
    """The recording, the configured plants and the rate of `mpi-ros fit` or `compare` (said
    on standard output), or None when the input is bad (said on standard error: exit 2)."""
    from mpi_ros.calibration.inputs import gather
    from mpi_ros.calibration.recording import RecordingError
    from mpi_ros.config import ConfigError

    try:
        inputs = gather(args.recording, args.axis, args.config, args.rate)
    except (RecordingError, ConfigError) as exc:
        print(f"mpi-ros {verb}: {exc}", file=sys.stderr)
        return None
    print(f"configured plants: {inputs.config_source}")
    for number in inputs.skipped:
        print(f"axis {number}: left out, its command never moves")
    return inputs


def run(args) -> int:
    inputs = gathered(args, "fit")
    if inputs is None:
        return 2
    # scipy is imported here, when a fit runs (never by the suite).
    from mpi_ros.calibration import report
    from mpi_ros.calibration.fit import fit_axis

    fits = []
    for axis in inputs.axes:
        fit = fit_axis(axis, inputs.rate, inputs.plants[axis.number])
        fits.append(fit)
        print(report.fit_text(fit))
    block = report.yaml_block(fits, args.recording)
    print()
    print(block, end="")
    try:
        if args.output:
            with open(args.output, "w", encoding="utf-8") as stream:
                stream.write(block)
            print(f"# written to {args.output}")
        if args.plot:
            chosen = [(axis, fit.configured, fit.fitted) for axis, fit in zip(inputs.axes, fits, strict=True)]
            print(f"# plot: {report.plot(args.plot, inputs.rate, chosen)}")
    except OSError as exc:
        print(f"mpi-ros fit: {exc}", file=sys.stderr)
        return 2
    return 0
