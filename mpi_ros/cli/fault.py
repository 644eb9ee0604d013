"""Inject a fault on an axis, or clear one, to rehearse what goes wrong (docs/faults.md).

  mpi-ros fault AMP_FAULT --axis 1           the drive of axis 1 faults: the motor coasts, ms0 ABORTs
  mpi-ros fault AMP_FAULT --axis 1 --clear   the drive is healthy again; `mpi-ros reset` then recovers
  mpi-ros fault ENCODER_FAULT --axis 3       motor 3's encoder faults: every axis watching it aborts
  mpi-ros fault LIMIT_ERROR --axis 0         a one-off trip of a fault the controller detects itself

Faults: LIMIT_ERROR, LIMIT_SW_POSITIVE, LIMIT_SW_NEGATIVE, AMP_FAULT, ENCODER_FAULT and
FRAME_UNDERFLOW; each takes the action configured for the axis (axes.*.faults in the YAML).
A refused injection prints why (exit status 1).
"""

from __future__ import annotations

import argparse

from .console import OK, REFUSED, add_target_options, run_verb


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("fault", help="the fault: LIMIT_ERROR, LIMIT_SW_POSITIVE, LIMIT_SW_NEGATIVE, AMP_FAULT, "
                                      "ENCODER_FAULT or FRAME_UNDERFLOW")
    parser.add_argument("--axis", "-x", type=int, required=True, metavar="K", help="the axis")
    parser.add_argument("--clear", action="store_true",
                        help="the condition is gone (AMP_FAULT, ENCODER_FAULT); RESET then clears the fault")
    add_target_options(parser)


def run(args: argparse.Namespace) -> int:
    def body(session) -> int:
        reply = session.client(args.supervisor).fault_inject(args.axis, args.fault, active=not args.clear)
        detail = f": {reply.detail}" if reply.detail else ""
        print(f"{args.fault.upper()} on axis {args.axis}: {reply.message} (code {reply.code}), "
              f"faults [{', '.join(reply.faults)}]{detail}")
        return OK if reply.ok else REFUSED

    return run_verb(args, body)
