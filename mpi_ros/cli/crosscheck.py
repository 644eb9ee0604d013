"""Cross-check TRAPEZOIDAL, S_CURVE and VELOCITY profiles against ruckig and print a table.

  mpi-ros crosscheck [REQUEST ...] [--file FILE] [--random N [--seed S]]

A REQUEST is a YAML flow mapping or key=value pairs, e.g.
  "{type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, jerk_percent: 50}"
  type=TRAPEZOIDAL,distance=-200,velocity=500,acceleration=5000,deceleration=2000,start_velocity=300
keys: type, distance or target, velocity, acceleration, deceleration (default: the
acceleration), jerk_percent, start_velocity / start_acceleration / start_position (a modify
from motion), final_velocity. FILE is YAML: a list of such mappings (or {requests: [...]}).
Without requests a built-in set covering every case is checked. --random N checks N random
requests per category and prints agreement statistics instead of the table.

Verdicts: AGREE (the models coincide and agree), DIFFER_EXPLAINED (they legitimately differ,
the reason is given; the controller respects every limit and is never faster than ruckig),
DISAGREE (a problem is listed). Exit status 1 if any request DISAGREEs, 2 on bad input.
"""

from __future__ import annotations

import argparse
import sys

EXAMPLES = [
    "{type: TRAPEZOIDAL, distance: 1000, velocity: 500, acceleration: 5000}",
    "{type: TRAPEZOIDAL, distance: -1000, velocity: 500, acceleration: 5000, deceleration: 2000}",
    "{type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, jerk_percent: 50}",
    "{type: S_CURVE, distance: 10, velocity: 500, acceleration: 5000, jerk_percent: 50}",
    "{type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, deceleration: 2000, jerk_percent: 50}",
    "{type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, jerk_percent: 100, start_velocity: 200}",
    "{type: TRAPEZOIDAL, distance: 100, velocity: 500, acceleration: 5000, deceleration: 2000, start_velocity: -300}",
    ("{type: TRAPEZOIDAL, distance: 1000, velocity: 500, acceleration: 5000, start_velocity: 200,"
     " start_acceleration: 3000}"),
    "{type: VELOCITY, velocity: -300, acceleration: 5000, jerk_percent: 40, start_velocity: 100}",
]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("requests", nargs="*", metavar="REQUEST", help="a request (YAML mapping or key=value,...)")
    parser.add_argument("-f", "--file", help="YAML file with a list of requests")
    parser.add_argument("--random", type=int, metavar="N",
                        help="check N random requests per category and print statistics")
    parser.add_argument("--seed", type=int, default=0, help="seed of --random (default 0)")


def _load_file(path: str) -> list[dict]:
    import yaml

    with open(path, encoding="utf-8") as stream:
        data = yaml.safe_load(stream)
    if isinstance(data, dict) and "requests" in data:
        data = data["requests"]
    if not isinstance(data, list) or not all(isinstance(item, dict) for item in data):
        raise ValueError(f"{path}: expected a list of request mappings (or {{requests: [...]}})")
    return data


def run(args) -> int:
    from mpi_ros.crosscheck import ProfileRequest, RequestInvalid, Verdict, check_plan

    if args.random is not None:
        from mpi_ros.crosscheck.survey import format_summary, survey

        if args.random <= 0:
            print("mpi-ros crosscheck: --random needs N > 0", file=sys.stderr)
            return 2
        stats = survey(args.random, args.seed)
        print(format_summary(stats))
        for name, entry in stats.items():
            for request, result in entry.disagreements:
                print(f"DISAGREE {name}: {request} -> {result.detail}")
        return 1 if any(entry.disagreements for entry in stats.values()) else 0

    try:
        requests = [ProfileRequest.parse(text) for text in args.requests]
        if args.file:
            requests += [ProfileRequest.from_mapping(item) for item in _load_file(args.file)]
        if not requests:
            requests = [ProfileRequest.parse(text) for text in EXAMPLES]
    except (OSError, ValueError) as exc:  # RequestInvalid is a ValueError
        print(f"mpi-ros crosscheck: {exc}", file=sys.stderr)
        return 2

    from mpi_ros.crosscheck.result import CrossCheck
    from mpi_ros.crosscheck.table import format_table

    entries: list[tuple[ProfileRequest, CrossCheck | str]] = []
    for request in requests:
        try:
            entries.append((request, check_plan(request.plan(), request.type)))
        except RequestInvalid as exc:
            entries.append((request, str(exc)))
    print(format_table(entries))
    return 1 if any(not isinstance(r, str) and r.verdict is Verdict.DISAGREE for _, r in entries) else 0
