"""A full-screen console that stays connected: live status, events, keys for the actions.

  mpi-ros console                    every supervisor; keys act on the selected one (ms0 first)
  mpi-ros console --jog-speed 2000   counts/s of the arrow keys' jog

Keys (shown at the bottom): space STOP, e E_STOP, r RESET, u RESUME the selected supervisor;
up/down select an axis (its supervisor with it), Tab the next supervisor; left/right arrows jog
the selected axis alone (mpi_ros/cli/jog.py: a VELOCITY move at --jog-speed, the other axes at
0; a terminal reports no key release, so the jog STOPs once the key stops repeating, and when
the console exits); ctrl+e is E_STOP wherever the focus is, the command
line included; : or / opens the command line, which takes the one-shot verbs: move ...,
modify ..., stop, e-stop, abort, reset, resume, with their own options (--supervisor N among
them). q quits.

Why Textual: one library gives the layout, the table, the log, key bindings shown on screen
and a headless test driver (its pilot); prompt_toolkit with rich would need the three put
together by hand. The ROS side is the Python client: one node per supervisor plus a watcher,
spun in their own threads; an action key is one service call on an already matched client.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import shlex
import threading
import time
from typing import Any, ClassVar

from .console import OK, UsageError, add_target_options, fail, suite_warning
from .jog import Jogger, JogTarget

REFRESH = 0.1  # s between table refreshes
VERBS = ("move", "modify", "stop", "e-stop", "abort", "reset", "resume")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--jog-speed", type=float, default=1000.0, metavar="V",
                        help="counts/s of the arrow keys' jog (default 1000)")
    parser.add_argument("--jog-acceleration", type=float, default=10000.0, metavar="A",
                        help="counts/s² of the jog's start and stop (default 10000)")
    add_target_options(parser, supervisor_default=None)


def run(args: argparse.Namespace) -> int:
    from mpi_ros.errors import NoResponse, NoSuchSupervisor

    if args.jog_speed <= 0 or args.jog_acceleration <= 0:
        return fail(args, "--jog-speed and --jog-acceleration must be > 0")
    try:
        link = Link(args)
    except (UsageError, NoResponse, NoSuchSupervisor) as exc:
        return fail(args, str(exc))
    try:
        make_app(link, args).run()
    finally:
        link.close()
    return OK


class Link:
    """The console's ROS side: a Watcher of the suite and a MotionClient per supervisor."""

    def __init__(self, args: argparse.Namespace, context: Any = None):
        import rclpy

        from mpi_ros.client import MotionClient, Watcher

        self.own_context = context is None
        self.context = context or rclpy.Context()
        if self.own_context:
            from mpi_ros import dds_profile

            dds_profile.use(os.environ, dds_profile.CLIENT)  # as a one-shot verb's Session does
            rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])], context=self.context)
        self.watcher = Watcher(args.namespace, context=self.context, timeout=args.timeout,
                               node_name="mpi_ros_console_watch")
        self.clients: dict[int, Any] = {}
        try:
            numbers = self.watcher.wait_for_suite(args.timeout, args.supervisor)
            self.numbers = [args.supervisor] if args.supervisor is not None else numbers
            for n in self.numbers:
                self.clients[n] = MotionClient(n, args.namespace, context=self.context, timeout=args.timeout,
                                               node_name=f"mpi_ros_console_ms{n}")
                if not self.clients[n].wait_for_server(args.timeout):
                    raise UsageError(f"ms{n} did not answer within {args.timeout:g} s")
            self.watcher.follow_status(self.numbers, [])
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        for client in self.clients.values():
            client.close()
        self.watcher.close()
        if self.own_context:
            self.context.try_shutdown()


def make_app(link: Link, args: argparse.Namespace):  # noqa: C901 - the App class inside: textual loads lazily
    """The Textual application (a function: textual is imported only when the console runs)."""
    from textual.app import App, ComposeResult
    from textual.binding import Binding
    from textual.widgets import DataTable, Footer, Input, RichLog, Static

    JOG, AXIS = Binding.Group("jog"), Binding.Group("axis")

    class Console(App):
        TITLE = "mpi-ros console"
        ENABLE_COMMAND_PALETTE = False  # its ^p would take room in the footer for nothing an operator needs
        CSS = """
        #table { height: 1fr; }
        #events { height: 8; border-top: solid $accent; }
        #command { dock: bottom; display: none; }
        #command.open { display: block; }
        """
        BINDINGS: ClassVar[list[Binding | tuple[str, str] | tuple[str, str, str]]] = [
            Binding("space", "act('STOP')", "STOP"),
            Binding("e", "act('E_STOP')", "E_STOP"),
            Binding("ctrl+e", "act('E_STOP')", "E_STOP (anywhere)", priority=True, show=False),
            Binding("r", "act('RESET')", "RESET"),
            Binding("u", "act('RESUME')", "RESUME"),
            # priority: the event log would take the arrows to scroll; the command line gets them back
            Binding("left", "jog(-1)", "jog -", priority=True, group=JOG),
            Binding("right", "jog(1)", "jog +", priority=True, group=JOG),
            Binding("up", "select_axis(-1)", "axis", priority=True, group=AXIS),
            Binding("down", "select_axis(1)", "axis", priority=True, group=AXIS),
            # priority: the screen's own Tab moves the focus; not shown: ↑↓ reach every axis, 80 columns are few
            Binding("tab", "next_supervisor", "next ms", priority=True, show=False),
            Binding("colon,slash", "command", "command"),
            Binding("escape", "close_command", "close", show=False),
            Binding("q", "quit", "quit"),
        ]

        def __init__(self) -> None:
            super().__init__()
            self.selected = link.numbers[0]
            self.axis = 0  # index in the selected supervisor's axes: the one the arrows jog
            self.jogger = Jogger(link.clients, args.jog_speed, args.jog_acceleration, args.timeout)
            self.events: Any = None

        def compose(self) -> ComposeResult:
            # kept, not queried: a refresh may come while the screen is being rebuilt
            self.heading = Static(id="selected")
            self.table: DataTable[str] = DataTable(id="table", cursor_type="none", zebra_stripes=True)
            self.log_view = RichLog(id="events", max_lines=500, wrap=False)
            hint = "move --position 1000 0 -v 500 -a 5000 -d 5000   (Enter runs it, Esc closes)"
            self.command_line = Input(placeholder=hint, id="command")
            yield from (self.heading, self.table, self.log_view, self.command_line, Footer())

        def on_ready(self) -> None:  # the screen and its widgets are there (on_mount may come first)
            table = self.table
            table.can_focus = False  # the arrows are the jog's, not the table's scrolling
            table.add_columns("row", "state", "command", "actual", "error", "velocity", "bits", "faults")
            self.events = link.watcher.follow_events(self._from_ros)
            link.watcher.follow_suite()  # a suite behind real time: said under the heading
            self.set_interval(REFRESH, self._refresh)
            self._refresh()

        # -- views ---------------------------------------------------------------------------------
        def _refresh(self) -> None:
            supervisors, _ = link.watcher.latest()
            table = self.table
            table.clear()
            for n in sorted(supervisors):
                ms = supervisors[n]
                table.add_row(f"ms{n}" + (" *" if n == self.selected else ""), ms.state_name, "", "", "", "",
                              f"move {ms.move_id}", f"{ms.last_action} ({ms.action_source})")
                for index, axis in enumerate(ms.axes):
                    bits = "".join(letter if getattr(axis, name) else "-" for letter, name in
                                   (("D", "done"), ("T", "at_target"), ("F", "in_fine_position"), ("S", "settled")))
                    mark = " *" if (n, index) == (self.selected, self.axis) else ""
                    table.add_row(f"  axis{axis.number}{mark}", axis.state_name, f"{axis.command_position:.1f}",
                                  f"{axis.actual_position:.1f}", f"{axis.position_error:.1f}",
                                  f"{axis.command_velocity:.1f}", bits, ", ".join(axis.faults) or "-")
            warning = suite_warning(link.watcher)
            self.heading.update(f"selected ms{self.selected} axis{self._axis_number(supervisors)}  "
                                f"jog {args.jog_speed:g}/s  D done T at target F fine S settled"
                                + (f"\n{warning}" if warning else ""))
            self.jogger.expire(time.monotonic())
            while self.jogger.said:
                self.say(self.jogger.said.popleft())

        def _axis_number(self, supervisors: dict[int, Any]) -> str:
            axes = supervisors[self.selected].axes if self.selected in supervisors else []
            return str(axes[self.axis].number) if self.axis < len(axes) else "?"

        def _from_ros(self, msg: Any) -> None:
            if self.is_running:  # the ROS thread may deliver one more as the console closes
                self.call_from_thread(self._event, msg)

        def _event(self, msg: Any) -> None:
            where = f"ms{msg.supervisor}" + (f" axis{msg.axis}" if msg.axis >= 0 else "")
            self.log_view.write(f"{msg.sample:>10}  {msg.type:<20} {where}  move {msg.move_id}")

        def say(self, text: str) -> None:
            self.log_view.write(text)

        # -- actions ---------------------------------------------------------------------------------
        def action_act(self, name: str) -> None:
            self._act(name, self.selected)

        def _act(self, name: str, supervisor: int) -> None:
            threading.Thread(target=self._call, args=(name, supervisor), daemon=True).start()

        def _call(self, name: str, supervisor: int) -> None:
            reply = link.clients[supervisor].action(name, raise_on_error=False)
            detail = f": {reply.detail}" if reply.detail and not reply.ok else ""
            self.call_from_thread(self.say, f"{name} ms{supervisor}: {reply.message}, state {reply.state_name}, "
                                            f"sample {reply.sample}{detail}")

        def action_next_supervisor(self) -> None:
            numbers = link.numbers
            self.selected = numbers[(numbers.index(self.selected) + 1) % len(numbers)]
            self.axis = 0

        def action_select_axis(self, step: int) -> None:
            """The next (previous) axis row of the table; past a supervisor's last axis, the next one's first."""
            if self.command_line.has_focus:
                return
            supervisors, _ = link.watcher.latest()
            rows = [(n, index) for n in sorted(supervisors) for index in range(len(supervisors[n].axes))]
            if (self.selected, self.axis) in rows:
                self.selected, self.axis = rows[(rows.index((self.selected, self.axis)) + step) % len(rows)]
            self._refresh()

        def action_jog(self, sign: int) -> None:
            box = self.command_line
            if box.has_focus:  # editing a command: the arrows move the cursor
                (box.action_cursor_right if sign > 0 else box.action_cursor_left)()
                return
            supervisors, _ = link.watcher.latest()
            axes = supervisors[self.selected].axes if self.selected in supervisors else []
            if self.axis >= len(axes):
                self.say(f"jog: no status of ms{self.selected} yet")
                return
            target = JogTarget(self.selected, self.axis, axes[self.axis].number, sign)
            self.jogger.press(target, len(axes), time.monotonic())

        def action_command(self) -> None:
            box = self.command_line
            box.add_class("open")
            box.focus()

        def action_close_command(self) -> None:
            self.command_line.remove_class("open")
            self.set_focus(None)

        def on_input_submitted(self, event: Input.Submitted) -> None:
            event.input.value = ""
            self.action_close_command()
            if event.value.strip():
                self.say(f"> {event.value}")
                self.say(run_command(link, event.value, self.selected))

        def on_unmount(self) -> None:
            link.watcher.node.destroy_subscription(self.events)
            self.jogger.close()  # a held jog stops with the console

    return Console()


def run_command(link: Link, line: str, selected: int) -> str:
    """One command line (a one-shot verb and its options) on the console's clients; what to show."""
    from mpi_ros.cli import build_parser

    try:
        words = shlex.split(line)
    except ValueError as exc:
        return f"cannot read the line: {exc}"
    if not words or words[0] not in VERBS:
        return f"unknown command {words[0] if words else ''!r}: the console takes {', '.join(VERBS)}"
    parser = build_parser(words[0])
    said = io.StringIO()
    try:
        with contextlib.redirect_stderr(said), contextlib.redirect_stdout(said):  # not over the screen
            args = parser.parse_args(words)
    except SystemExit:
        lines = said.getvalue().strip().splitlines()
        return lines[-1] if lines else f"{words[0]}: --help is for the shell (mpi-ros {words[0]} --help)"
    supervisor = selected if "--supervisor" not in words and "-s" not in words else args.supervisor
    if supervisor not in link.clients:
        return f"no supervisor ms{supervisor} in this console ({', '.join(f'ms{n}' for n in link.clients)})"
    client = link.clients[supervisor]
    if words[0] in ("move", "modify"):
        from .goals import goal_from_args

        try:
            goal = goal_from_args(args)
        except UsageError as exc:
            return str(exc)
        (client.modify if words[0] == "modify" else client.start)(goal)
        return f"{words[0]} sent to ms{supervisor}"
    reply = client.action(words[0].upper().replace("-", "_"), raise_on_error=False)
    return f"{words[0].upper()} ms{supervisor}: {reply.message}, state {reply.state_name}, sample {reply.sample}"
