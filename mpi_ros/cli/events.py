"""Print the suite's events as they happen (MOTION_DONE, SETTLED, E_STOP, ...), filtered.

  mpi-ros events                                  every event, until Ctrl-C
  mpi-ros events --type MOTION_DONE --count 1     wait for the next MOTION_DONE, then exit
  mpi-ros events --supervisor 1 --axis 2 --type SETTLED --type AT_TARGET

One line per event: sample, type, supervisor, axis, move and element id, detail. "-" is an
event not tied to a supervisor or axis. --supervisor/--axis/--type keep only matching
events (--type and --axis are repeatable). Events are live: what happened before the
command started is not shown (the line "listening on ..." on stderr says when it is).
The subscription is reliable and deep, so a burst at the end of a move arrives whole.
"""

from __future__ import annotations

import argparse
import queue
import sys
from typing import Any

from .console import OK, UsageError, add_target_options, fail, run_verb


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--type", action="append", default=[], metavar="TYPE",
                        help="only this event type (MOTION_DONE, SETTLED, E_STOP, ...); repeatable")
    parser.add_argument("--axis", type=int, action="append", default=[], metavar="K",
                        help="only events of this axis; repeatable")
    parser.add_argument("--count", type=int, metavar="N", help="exit after N matching events")
    add_target_options(parser, supervisor_default=None)


def run(args: argparse.Namespace) -> int:
    try:
        types = event_types(args.type)
    except UsageError as exc:
        return fail(args, str(exc))
    if args.count is not None and args.count < 1:
        return fail(args, "--count must be at least 1")
    return run_verb(args, lambda session: _events(session, args, types))


def event_types(names: list[str]) -> set[str]:
    """The --type filter as a set of MotionEvent type names (upper case, known ones only)."""
    from mpi_ros.client import EventType

    wanted = {name.upper() for name in names}
    unknown = sorted(wanted - set(EventType))
    if unknown:
        raise UsageError(f"unknown event type {', '.join(unknown)} (known: {', '.join(EventType)})")
    return wanted


def matches(event: Any, args: argparse.Namespace, types: set[str]) -> bool:
    return ((not types or event.type in types)
            and (args.supervisor is None or event.supervisor == args.supervisor)
            and (not args.axis or event.axis in args.axis))


def line(event: Any) -> str:
    """One event as a line."""
    ms = "-" if event.supervisor < 0 else f"ms{event.supervisor}"
    axis = "-" if event.axis < 0 else f"axis{event.axis}"
    detail = f"  {event.detail}" if event.detail else ""
    return (f"sample {event.sample:<10} {event.type:<20} {ms:<5} {axis:<7} "
            f"move {event.move_id:<4} element {event.element_id}{detail}")


def _events(session, args: argparse.Namespace, types: set[str]) -> int:
    watcher = session.watcher()
    received: queue.Queue = queue.Queue()
    subscription = watcher.follow_events(received.put)
    watcher.wait_matched(subscription, args.timeout)
    print(f"listening on {watcher.namespace}/events (Ctrl-C to stop)", file=sys.stderr, flush=True)
    shown = 0
    try:
        while args.count is None or shown < args.count:
            event = received.get()  # blocks; Ctrl-C interrupts it
            if matches(event, args, types):
                print(line(event), flush=True)
                shown += 1
    except KeyboardInterrupt:
        pass  # Ctrl-C is how a live view ends
    return OK
