"""A live table of the supervisors and their axes; --once prints one table and exits.

  mpi-ros status                 every supervisor, refreshed in place (Ctrl-C to leave)
  mpi-ros status --once          one table, for scripts
  mpi-ros status --supervisor 1  one supervisor and its axes

Per supervisor: state, axes, move id, motion type, pending moves, the last action and who
caused it. Per axis: state, command and actual position, following error, command velocity
and the status bits DONE, AT_TARGET, IN_FINE_POSITION, SETTLED (D T F S below 128 columns;
from 128 on also the actual velocity and the faults). Each supervisor's row and its axes
come from one MotionStatus, so they are from the same sample. Above the table, a warning when
two suites run under one namespace, and (live) when the suite's /diagnostics entry is WARN: its
controller behind the wall clock (docs/reliability.md). On a terminal the table fits
its width (80 columns and up) and is redrawn in place every 0.1 s on the alternate screen,
the last one left on yours when you leave; otherwise a new table is printed every second.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import sys
import textwrap
import threading
import time
from collections.abc import Callable
from typing import Any, TextIO

from .console import OK, add_target_options, run_verb, twins_warning, view_warnings

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
        width = shutil.get_terminal_size().columns if sys.stdout.isatty() else PIPE_WIDTH
        print("\n".join(render(supervisor_statuses, axis_statuses, watcher.namespace, width=width,
                               warning=twins_warning(watcher))))
        return OK
    watcher.follow_suite()  # a suite behind real time says so above the table
    tty = sys.stdout.isatty()
    interval = args.interval if args.interval is not None else (0.1 if tty else 1.0)
    with contextlib.suppress(KeyboardInterrupt):  # Ctrl-C is how a live view ends
        _live(watcher, sys.stdout, tty, interval)
    return OK


# The alternate screen (as top and less use): each table is drawn from the top-left corner
# over the last, so nothing stacks whatever the terminal's width, height or resizing; the
# operator's screen comes back on exit, with the last table printed on it.
ENTER = "\x1b[?1049h\x1b[?25l"  # alternate screen, cursor hidden
LEAVE = "\x1b[?25h\x1b[?1049l"  # cursor shown, the operator's screen back
PIPE_WIDTH = 1000  # off a terminal nothing wraps: every column


def _live(watcher, out: TextIO, tty: bool, interval: float,
          size: Callable[[], os.terminal_size] = shutil.get_terminal_size) -> None:
    last_sample, changed_at = -1, time.monotonic()
    tick = threading.Event()  # never set: an interruptible wait between tables
    lines: list[str] = []
    if tty:
        out.write(ENTER)
    try:
        while True:
            supervisors, axes = watcher.latest()
            sample = max((s.sample for s in [*supervisors.values(), *axes.values()]), default=-1)
            if sample != last_sample:
                last_sample, changed_at = sample, time.monotonic()
            stale = time.monotonic() - changed_at
            columns, rows = size() if tty else (PIPE_WIDTH, 0)
            lines = render(supervisors, axes, watcher.namespace, stale if stale > STALE_AFTER else None, columns,
                           view_warnings(watcher))
            if tty:
                out.write("\x1b[H" + "\x1b[K\n".join(_fit(lines, rows)) + "\x1b[K\x1b[J")
            else:
                out.write("\n".join(lines) + "\n\n")
            out.flush()
            tick.wait(interval)
    finally:
        if tty:
            out.write(LEAVE + "".join(f"{line}\n" for line in lines))
            out.flush()


def _fit(lines: list[str], rows: int) -> list[str]:
    """At most ``rows`` lines (the last one unended: nothing scrolls), the cut said in the last."""
    if len(lines) <= rows:
        return lines
    return [*lines[:rows - 1], f"... {len(lines) - rows + 1} more lines: a taller terminal shows them"]


WIDE = 128  # columns from which the axis rows add the actual velocity, full flag names and faults
NARROW_FLAGS = (("D", "done"), ("T", "at_target"), ("F", "in_fine_position"), ("S", "settled"))
AXIS_TITLES = f"{'axis':<4} {'ms':<2} {'state':<14} {'command':>12} {'actual':>12} {'error':>9}"
LEGEND = "D done  T at target  F in fine position  S settled  (y set, - not)"


def render(supervisors: dict[int, Any], axes: dict[int, Any], namespace: str,
           stale: float | None = None, width: int = WIDE, warning: str | None = None) -> list[str]:
    """The table's lines, none longer than ``width`` - 1 (a terminal wraps a line that fills
    its last column on some terminals): a header (and ``warning`` under it), one row per
    supervisor, one per axis. From WIDE columns on, the axis rows carry more (actual velocity,
    full flag names, faults); narrower, a legend names the flags and faults get a line of their own."""
    sample = max((s.sample for s in [*supervisors.values(), *axes.values()]), default=0)
    header = f"{namespace}  sample {sample}"
    if stale is not None:
        header += f"  (no newer status for {stale:.0f} s: is the suite still running?)"
    said = [line for text in (warning or "").splitlines() for line in textwrap.wrap(text, max(width - 1, 20))]
    lines = [header, *said,
             f"{'ms':<4} {'state':<14} {'axes':<8} {'move':>5}  {'type':<12} {'pending':>7}  last action"]
    rows: list[Any] = []
    for number in sorted(supervisors):
        ms = supervisors[number]
        axis_list = " ".join(str(k) for k in ms.axis_numbers)
        action = f"{ms.last_action} ({ms.action_source})" if ms.last_action not in ("", "NONE") else "-"
        lines.append(f"{'ms' + str(number):<4} {ms.state_name:<14} {axis_list:<8} {ms.move_id:>5}  "
                     f"{ms.motion_type:<12} {ms.moves_pending:>7}  {action}")
        rows.extend((number, axis) for axis in ms.axes)
    rows.extend((axis.supervisor, axis) for k, axis in sorted(axes.items()))
    lines += ["", *(_wide_axes(rows, width) if width >= WIDE else _narrow_axes(rows))]
    return [line[:max(width - 1, 1)].rstrip() for line in lines]


def _axis_start(owner: int, axis: Any) -> str:
    """The axis' columns common to both layouts: number, supervisor, state, positions, following error."""
    return (f"{axis.number:<4} {'-' if owner < 0 else str(owner):<2} {axis.state_name:<14} "
            f"{axis.command_position:>12.1f} {axis.actual_position:>12.1f} {axis.position_error:>9.1f}")


def _narrow_axes(rows: list[Any]) -> list[str]:
    flags = " ".join(letter for letter, _ in NARROW_FLAGS)
    lines = [f"{AXIS_TITLES} {'velocity':>10}  {flags}"]
    for owner, axis in rows:
        bits = " ".join("y" if getattr(axis, field) else "-" for _, field in NARROW_FLAGS)
        lines.append(f"{_axis_start(owner, axis)} {axis.command_velocity:>10.1f}  {bits}")
        if getattr(axis, "faults", None):
            lines.append(_faults_line(axis))
    return [*lines, LEGEND]


def _wide_axes(rows: list[Any], width: int) -> list[str]:
    flags = "  ".join(name for name, _ in FLAGS)
    lines = [f"{AXIS_TITLES} {'velocity':>10} {'actual vel':>10}  {flags}  faults"]
    for owner, axis in rows:
        bits = "  ".join(f"{'yes' if getattr(axis, field) else '-':<{len(name)}}" for name, field in FLAGS)
        row = f"{_axis_start(owner, axis)} {axis.command_velocity:>10.1f} {axis.actual_velocity:>10.1f}  {bits}  "
        faults = ", ".join(getattr(axis, "faults", ())) or "-"
        if len(row) + len(faults) < width:
            lines.append(row + faults)
        else:  # too many faults for the column: a line of their own, as in the narrow layout
            lines += [row + "(below)", _faults_line(axis)]
    return lines


def _faults_line(axis: Any) -> str:
    return f"     axis {axis.number} faults: {', '.join(axis.faults)}"
