"""A live table of the supervisors and their axes; --once prints one table and exits.

  mpi-ros status                 every supervisor, refreshed in place (Ctrl-C to leave)
  mpi-ros status --once          one table, for scripts
  mpi-ros status --supervisor 1  one supervisor and its axes

Per supervisor: state, axes, move id, motion type, pending moves, the last action and who
caused it. Per axis: state, command and actual position, command velocity and the status
bits DONE, AT_TARGET, IN_FINE_POSITION, SETTLED. Each supervisor's row and its axes come
from one MotionStatus, so they are from the same sample. On a terminal the table is
redrawn in place every 0.1 s; otherwise a new table is printed every second.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import threading
import time
from typing import Any, TextIO

from .console import OK, add_target_options, run_verb, twins_warning

STALE_AFTER = 2.0  # s without a newer sample before the header says so
FLAGS = (("DONE", "done"), ("AT_TARGET", "at_target"), ("IN_FINE_POSITION", "in_fine_position"),
         ("SETTLED", "settled"))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--once", action="store_true", help="print one table and exit")
    parser.add_argument("--interval", type=float, metavar="S",
                        help="seconds between tables (default 0.1 on a terminal, 1 otherwise)")
    add_target_options(parser, supervisor_default=None)


def run(args: argparse.Namespace) -> int:
    return run_verb(args, lambda session: _status(session, args))


def _status(session, args: argparse.Namespace) -> int:
    watcher = session.watcher()
    supervisors = [args.supervisor] if args.supervisor is not None else watcher.supervisors_on_graph()
    watcher.follow_status(supervisors, [])
    statuses, _ = watcher.wait_for_status(supervisors, [], args.timeout)
    extra: list[int] = []
    if args.supervisor is None:  # axes no supervisor has still get a row, from their own topic
        mapped = {k for status in statuses.values() for k in status.axis_numbers}
        extra = [k for k in watcher.axes_on_graph() if k not in mapped]
        watcher.follow_status([], extra)
        watcher.wait_for_status(supervisors, extra, args.timeout)
    if args.once:
        supervisor_statuses, axis_statuses = watcher.latest()
        print("\n".join(render(supervisor_statuses, axis_statuses, watcher.namespace, None, twins_warning(watcher))))
        return OK
    tty = sys.stdout.isatty()
    interval = args.interval if args.interval is not None else (0.1 if tty else 1.0)
    with contextlib.suppress(KeyboardInterrupt):  # Ctrl-C is how a live view ends
        _live(watcher, sys.stdout, tty, interval)
    return OK


def _live(watcher, out: TextIO, tty: bool, interval: float) -> None:
    drawn = 0
    last_sample, changed_at = -1, time.monotonic()
    tick = threading.Event()  # never set: an interruptible wait between tables
    if tty:
        out.write("\x1b[?25l")  # hide the cursor while redrawing
    try:
        while True:
            supervisors, axes = watcher.latest()
            sample = max((s.sample for s in [*supervisors.values(), *axes.values()]), default=-1)
            if sample != last_sample:
                last_sample, changed_at = sample, time.monotonic()
            stale = time.monotonic() - changed_at
            lines = render(supervisors, axes, watcher.namespace, stale if stale > STALE_AFTER else None,
                           twins_warning(watcher))
            if tty:
                up = f"\x1b[{drawn}F" if drawn else ""
                out.write(up + "".join(f"{line}\x1b[K\n" for line in lines) + "\x1b[J")
                drawn = len(lines)
            else:
                out.write("\n".join(lines) + "\n\n")
            out.flush()
            tick.wait(interval)
    finally:
        if tty:
            out.write("\x1b[?25h")
            out.flush()


def render(supervisors: dict[int, Any], axes: dict[int, Any], namespace: str,
           stale: float | None = None, warning: str | None = None) -> list[str]:
    """The table's lines: a header (and ``warning`` under it), one row per supervisor, one per axis."""
    sample = max((s.sample for s in [*supervisors.values(), *axes.values()]), default=0)
    header = f"{namespace}  sample {sample}"
    if stale is not None:
        header += f"  (no newer status for {stale:.0f} s: is the suite still running?)"
    lines = [header, *([warning] if warning else []),
             f"{'supervisor':<11} {'state':<15} {'axes':<10} {'move':>5}  {'type':<14} {'pending':>7}  last action"]
    rows: list[Any] = []
    for number in sorted(supervisors):
        ms = supervisors[number]
        axis_list = " ".join(str(k) for k in ms.axis_numbers)
        action = f"{ms.last_action} ({ms.action_source})" if ms.last_action not in ("", "NONE") else "-"
        lines.append(f"{'ms' + str(number):<11} {ms.state_name:<15} {axis_list:<10} {ms.move_id:>5}  "
                     f"{ms.motion_type:<14} {ms.moves_pending:>7}  {action}")
        rows.extend((number, axis) for axis in ms.axes)
    rows.extend((axis.supervisor, axis) for k, axis in sorted(axes.items()))
    flags = "  ".join(name for name, _ in FLAGS)
    lines += ["", f"{'axis':<5} {'ms':<3} {'state':<15} {'command':>12} {'actual':>12} {'velocity':>11}  {flags}"]
    for number, axis in rows:
        owner = "-" if number < 0 else str(number)
        bits = "  ".join(f"{'yes' if getattr(axis, field) else '-':<{len(name)}}" for name, field in FLAGS)
        lines.append(f"{axis.number:<5} {owner:<3} {axis.state_name:<15} {axis.command_position:>12.1f} "
                     f"{axis.actual_position:>12.1f} {axis.command_velocity:>11.1f}  {bits}".rstrip())
    return lines
