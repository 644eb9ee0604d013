"""Inject a fault on an axis, or clear one, to rehearse what goes wrong (docs/faults.md).

  mpi-ros fault AMP_FAULT --axis 1           the drive of axis 1 faults: the motor coasts, ms0 ABORTs
  mpi-ros fault AMP_FAULT --axis 1 --clear   the drive is healthy again; the fault stays latched
                                             (ms0 in ERROR) until `mpi-ros reset`
  mpi-ros fault ENCODER_FAULT --axis 3       motor 3's encoder faults: every axis watching it aborts
  mpi-ros fault LIMIT_ERROR --axis 0         a one-off trip of a fault the controller detects itself

Faults: LIMIT_ERROR, LIMIT_SW_POSITIVE, LIMIT_SW_NEGATIVE, AMP_FAULT, ENCODER_FAULT and
FRAME_UNDERFLOW; each takes the action configured for the axis (axes.*.faults in the YAML).
A refused injection prints why (exit status 1).
"""

from __future__ import annotations

import argparse
import sys

from .console import OK, REFUSED, add_target_options, run_verb

OWNER_WAIT = 3.0  # s for the supervisor's status that says whether it has the axis (a first status may wait
# for discovery: up to 3 s, Fast DDS's default announcement period, where the suite has no profile of ours)


def _reset_command(client, axis: int) -> str:
    """The RESET that clears the axis' latched faults: of this command's supervisor when its
    status lists the axis, else of the axis' supervisor, which `mpi-ros status` shows."""
    from mpi_ros.errors import NoResponse

    try:
        mine = axis in client.status(OWNER_WAIT).axis_numbers
    except NoResponse:  # no status in time: say which supervisor without naming it
        mine = False
    if not mine:
        return "`mpi-ros reset --supervisor N`, N the supervisor of the axis (`mpi-ros status` shows it)"
    return "`mpi-ros reset`" if client.supervisor == 0 else f"`mpi-ros reset --supervisor {client.supervisor}`"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("fault", help="the fault: LIMIT_ERROR, LIMIT_SW_POSITIVE, LIMIT_SW_NEGATIVE, AMP_FAULT, "
                                      "ENCODER_FAULT or FRAME_UNDERFLOW")
    parser.add_argument("--axis", "-x", type=int, required=True, metavar="K", help="the axis")
    parser.add_argument("--clear", action="store_true",
                        help="the condition is gone (AMP_FAULT, ENCODER_FAULT); RESET then clears the fault")
    add_target_options(parser)


def run(args: argparse.Namespace) -> int:
    def body(session) -> int:
        client = session.client(args.supervisor)
        reply = client.fault_inject(args.axis, args.fault, active=not args.clear)
        detail = f": {reply.detail}" if reply.detail else ""
        fault = args.fault.upper()
        print(f"{fault} on axis {args.axis}{' cleared' if args.clear else ''}: {reply.message} (code {reply.code}), "
              f"faults [{', '.join(reply.faults)}]{detail}")
        if reply.ok and args.clear and fault in reply.faults:
            print(f"hint: the condition is gone, but {fault} stays latched on axis {args.axis} (and its supervisor "
                  f"in ERROR) until a RESET: {_reset_command(client, args.axis)}", file=sys.stderr)
        return OK if reply.ok else REFUSED

    return run_verb(args, body)
