"""``mpi-ros move`` and ``modify``: a goal from flags or YAML, sent and followed to its end.

The goal is the fields of MotionStart/MotionModify: ``--goal`` takes the same YAML (or flow
text) as ``ros2 action send_goal``; flags set or override single fields. Feedback drives a
progress bar on a terminal and plain lines otherwise; the result ends it (see console).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any, TextIO

from .console import OK, USAGE, UsageError, add_target_options, print_result, run_verb

TRAJECTORY_FLAGS = ("velocity", "acceleration", "deceleration", "jerk_percent")
GOAL_FLAGS = frozenset({"position", *TRAJECTORY_FLAGS})  # the goal fields a flag sets
BAR_WIDTH = 30
CANCEL_WAIT = 30.0  # s: how long a cancelled goal may take to stop before the command gives up


def add_goal_arguments(parser: argparse.ArgumentParser) -> None:
    goal = parser.add_argument_group("the goal (flags set single fields and override --goal)")
    goal.add_argument("--goal", metavar="YAML",
                      help="the whole goal as YAML, as `ros2 action send_goal` takes it")
    goal.add_argument("--type", "-t", metavar="TYPE",
                      help="motion type: S_CURVE (default), TRAPEZOIDAL, VELOCITY, S_CURVE_JERK, ...")
    goal.add_argument("--position", "-p", type=float, nargs="+", metavar="P",
                      help="target of each axis of the supervisor, in counts")
    goal.add_argument("--velocity", "-v", type=float, metavar="V", help="counts/s")
    goal.add_argument("--acceleration", "-a", type=float, metavar="A", help="counts/s²")
    goal.add_argument("--deceleration", "-d", type=float, metavar="D",
                      help="counts/s² (TRAPEZOIDAL, S_CURVE and S_CURVE_JERK need it; VELOCITY ignores it)")
    goal.add_argument("--jerk-percent", "-j", type=float, metavar="J",
                      help="0..100: share of each ramp with non-zero jerk (S_CURVE, VELOCITY; default 0)")
    goal.add_argument("--attribute", action="append", default=[], metavar="NAME",
                      help="an attribute (APPEND, RELATIVE, SYNC_START, ...); repeatable")
    goal.add_argument("--id", type=int, metavar="N", help="the move's id (adds the ID attribute)")
    goal.add_argument("--delay", type=float, nargs="+", metavar="S", help="seconds per axis (adds DELAY)")
    goal.add_argument("--final-velocity", type=float, nargs="+", metavar="V",
                      help="counts/s per axis at the target (adds FINAL_VEL)")
    parser.add_argument("--no-wait", action="store_true",
                        help="return once the move runs (or was refused) instead of following it to its end")
    add_target_options(parser)


def parse_goal_text(text: str) -> dict[str, Any]:
    """The --goal YAML as a mapping (usage errors say what is wrong)."""
    import yaml

    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise UsageError(f"--goal: not valid YAML: {exc}") from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise UsageError(f"--goal: expected a mapping of goal fields, e.g. \"{{type: S_CURVE, position: [1000, 0]}}\", "
                         f"got {text!r}")
    return data


def goal_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """The goal's fields from --goal and the flags (flags win)."""
    goal = parse_goal_text(args.goal) if args.goal else {}
    if args.type:
        goal["type"] = args.type.upper()
    goal.setdefault("type", "S_CURVE")
    if args.position is not None:
        goal["position"] = args.position
    limits = {k: getattr(args, k) for k in TRAJECTORY_FLAGS if getattr(args, k) is not None}
    if limits:
        trajectory = goal.get("trajectory") or [{}]
        if not isinstance(trajectory, list) or not all(isinstance(t, dict) for t in trajectory):
            raise UsageError("--goal: trajectory must be a list of mappings")
        # every axis' limits, if SYNC_START/SYNC_END gives one per axis; no deceleration is
        # made up: a point-to-point profile needs one (docs/decisions.md, "Deceleration")
        goal["trajectory"] = [{**t, **limits} for t in trajectory]
    attributes = [str(a).upper() for a in goal.get("attributes") or []] + [a.upper() for a in args.attribute]
    for flag, field, attribute in (("id", "id", "ID"), ("delay", "delay", "DELAY"),
                                   ("final_velocity", "final_velocity", "FINAL_VEL")):
        value = getattr(args, flag)
        if value is not None:
            goal[field] = value
            attributes.append(attribute)
    if attributes:
        goal["attributes"] = list(dict.fromkeys(attributes))  # once each, in order
    if not args.goal:
        _check_complete(goal)
    return goal


def _check_complete(goal: dict[str, Any]) -> None:
    """Flags alone must make a whole move: say which field is missing rather than let it be
    refused. What each type needs is its family record's (mpi_ros/mpi/planning/families.py:
    MPI 000, MPIMotionTrapezoidal and MPIMotionSCurve need velocity, acceleration and
    deceleration, MPIMotionVelocity velocity and acceleration, a path its points and times).
    A type without a record is left to the controller, which answers TYPE_INVALID."""
    from mpi_ros.mpi.base.types import MPIMotionType  # (the core, only for a goal made of flags)
    from mpi_ros.mpi.planning.families import family_of

    motion_type = MPIMotionType.__members__.get(str(goal["type"]))
    family = family_of(motion_type) if motion_type is not None else None
    if family is None:
        return
    have = set(goal) | set((goal.get("trajectory") or [{}])[0])
    missing = [name for name in (*family.fields, *family.trajectory) if name not in have]
    if missing:
        named = [f"--{name.replace('_', '-')}" if name in GOAL_FLAGS else name for name in missing]
        raise UsageError(f"{' and '.join(named)} needed for a {goal['type']} move "
                         "(or give the whole goal with --goal YAML)")


# -- following a goal --------------------------------------------------------------------------------------
class ProgressView:
    """Feedback as a redrawn bar on a terminal, as a line per tenth of the move otherwise
    (or nothing, with ``plain=False``)."""

    def __init__(self, out: TextIO, tty: bool, plain: bool = True):
        self.out = out
        self.tty = tty
        self.plain = plain
        self._last: tuple[int, str] | None = None
        self._drawn = False

    def show(self, feedback: Any) -> None:
        tenth = min(10, int(feedback.progress * 10))
        state = feedback.state_name
        if self.tty:
            filled = round(feedback.progress * BAR_WIDTH)
            bar = "#" * filled + "-" * (BAR_WIDTH - filled)
            line = (f"[{bar}] {feedback.progress * 100:5.1f}%  {state:<14} "
                    f"command {_fmt(feedback.command_position)}")
            self.out.write(f"\r{line}\x1b[K")
            self.out.flush()
            self._drawn = True
        elif self.plain and (tenth, state) != self._last:
            print(f"progress {tenth * 10:3d}%  {state:<14} command {_fmt(feedback.command_position)}  "
                  f"actual {_fmt(feedback.actual_position)}", file=self.out, flush=True)
        self._last = (tenth, state)

    def end(self) -> None:
        """Leave the bar's line (once)."""
        if self._drawn:
            self.out.write("\n")
            self.out.flush()
            self._drawn = False


def _fmt(values) -> str:
    return "[" + ", ".join(f"{v:.1f}" for v in values) + "]"


def follow(goal: Any, view: ProgressView, poll: float = 0.05) -> Any:
    """Show the goal's feedback until its result arrives; Ctrl-C cancels it (a STOP) first."""
    seen = None
    try:
        while not goal.result_ready(poll):
            if goal.feedback is not None and goal.feedback is not seen:
                seen = goal.feedback
                view.show(seen)
    except KeyboardInterrupt:
        view.end()
        print("interrupted: cancelling the goal (a STOP); Ctrl-C again leaves the move running", file=sys.stderr)
        goal.cancel()
        goal.result_ready(CANCEL_WAIT)
        raise
    finally:
        view.end()
    return goal.wait(raise_on_error=False)


def send(args: argparse.Namespace, modify: bool) -> int:
    """Build the goal, send it, follow it; the exit status."""
    try:
        goal = goal_from_args(args)
    except UsageError as exc:
        print(f"{args._prog}: {exc}", file=sys.stderr)
        return USAGE
    return run_verb(args, lambda session: _send(session, args, goal, modify))


def _send(session, args: argparse.Namespace, fields: dict[str, Any], modify: bool) -> int:
    client = session.client(args.supervisor)
    try:
        goal = client.modify(fields) if modify else client.start(fields)
    except ValueError as exc:  # a field name or type the goal does not have
        raise UsageError(f"bad goal: {exc}") from exc
    if args.no_wait:
        if goal.wait_started(args.timeout):
            print(f"{'modified' if modify else 'started'}: ms{args.supervisor} {goal.feedback.state_name}, "
                  f"move {goal.feedback.move_id}")
            return OK
        return print_result(goal.wait(raise_on_error=False), args.supervisor)
    view = ProgressView(sys.stdout, sys.stdout.isatty())
    try:
        result = follow(goal, view)
    except KeyboardInterrupt:
        if goal.done:
            print_result(goal.wait(raise_on_error=False), args.supervisor)
        return 130
    return print_result(result, args.supervisor)
