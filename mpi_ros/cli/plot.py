"""Plot a profile (controller vs ruckig) or a recorded bag to a PNG.

  mpi-ros plot --type S_CURVE --distance 1000 --velocity 500 --acceleration 5000 --jerk-percent 50 [-o FILE]
  mpi-ros plot --request "{type: VELOCITY, velocity: -300, acceleration: 5000, start_velocity: 100}"
  mpi-ros plot BAG [-o FILE] [--axis N ...] [--from S] [--to S]

Without BAG: the profile's position, velocity, acceleration and jerk as the controller plans
it, with ruckig's profile for the same request overlaid (see mpi-ros crosscheck for the
verdict). With BAG (a bag directory or an .mcap file): the recorded axes and supervisor
states over time, the events labelled where they have room; --from/--to plot a window (s
since the first message, as the x axis), where every event gets its label sooner.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", nargs="?", metavar="BAG", help="bag directory or .mcap file (plots the recording)")
    parser.add_argument("-o", "--output", help="PNG to write (default: profile.png, or <bag name>.png)")
    bag = parser.add_argument_group("bag options")
    bag.add_argument("--axis", type=int, action="append", metavar="N", help="only these axes (repeatable)")
    bag.add_argument("--from", dest="start", type=float, metavar="S", help="start of the window, s (default 0)")
    bag.add_argument("--to", dest="end", type=float, metavar="S", help="end of the window, s (default: the end)")
    profile = parser.add_argument_group("profile options (without BAG)")
    profile.add_argument("--request", help="the whole request as YAML or key=value,... (as mpi-ros crosscheck)")
    profile.add_argument("--type", default="S_CURVE", help="TRAPEZOIDAL, S_CURVE or VELOCITY (default S_CURVE)")
    profile.add_argument("--distance", type=float, default=1000.0, help="counts (default 1000)")
    profile.add_argument("--velocity", type=float, default=500.0,
                         help="counts/s: the limit, or VELOCITY's velocity (default 500)")
    profile.add_argument("--acceleration", type=float, default=5000.0, help="counts/s² (default 5000)")
    profile.add_argument("--deceleration", type=float, help="counts/s² (default: the acceleration)")
    profile.add_argument("--jerk-percent", type=float, default=50.0, help="S_CURVE/VELOCITY jerk percent (default 50)")
    profile.add_argument("--start-velocity", type=float, default=0.0, help="a modify from motion (default 0)")
    profile.add_argument("--start-acceleration", type=float, default=0.0, help="acceleration at the modify")
    profile.add_argument("--final-velocity", type=float, default=0.0, help="FINAL_VEL (default 0)")


def is_bag(path: str) -> bool:
    """A bag is an existing directory or .mcap file."""
    p = Path(path)
    return p.is_dir() or (p.is_file() and p.suffix == ".mcap")


def run(args) -> int:
    if args.bag is not None:
        return _plot_bag(args)
    from mpi_ros.crosscheck.request import ProfileRequest, RequestInvalid

    try:
        if args.request:
            request = ProfileRequest.parse(args.request)
        else:
            request = ProfileRequest.from_mapping({
                "type": args.type, "distance": args.distance, "velocity": args.velocity,
                "acceleration": args.acceleration, "deceleration": args.deceleration,
                "jerk_percent": args.jerk_percent, "start_velocity": args.start_velocity,
                "start_acceleration": args.start_acceleration, "final_velocity": args.final_velocity})
        from mpi_ros.plot.profile import plot_profile

        path, result = plot_profile(request, args.output or "profile.png")
    except (RequestInvalid, OSError) as exc:
        print(f"mpi-ros plot: {exc}", file=sys.stderr)
        return 2
    print(f"{path}: {result.detail}")
    return 0


def _plot_bag(args) -> int:
    if not is_bag(args.bag):
        print(f"mpi-ros plot: {args.bag}: not a bag (an existing directory or .mcap file)", file=sys.stderr)
        return 2
    try:
        from mpi_ros.plot.bag import plot_bag
    except ModuleNotFoundError as exc:
        if exc.name not in ("mpi_ros.plot.bag", "mpi_ros.plot"):
            raise
        print("mpi-ros plot: plotting bags is not available in this installation (mpi_ros.plot.bag is missing)",
              file=sys.stderr)
        return 2
    output = args.output or f"{Path(args.bag.rstrip('/')).stem or 'bag'}.png"
    try:
        path = plot_bag(args.bag, output, args.axis, args.start, args.end)
    except (OSError, ValueError) as exc:
        print(f"mpi-ros plot: {exc}", file=sys.stderr)
        return 2
    print(path)
    return 0
