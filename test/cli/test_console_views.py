"""How the console draws, without a suite: the status table redrawn in place on a terminal
(printed anew otherwise), the progress bar of a move, goals built from flags and YAML."""

from __future__ import annotations

import argparse
import io
import os
import re
from types import SimpleNamespace

import pytest

from mpi_ros.cli import build_parser
from mpi_ros.cli.console import UsageError
from mpi_ros.cli.goals import ProgressView, goal_from_args
from mpi_ros.cli.status import _live, render


def _axis(number: int, supervisor: int, position: float = 0.0, faults: tuple[str, ...] = (), **bits) -> SimpleNamespace:
    flags = {"done": True, "at_target": True, "in_fine_position": True, "settled": True, **bits}
    return SimpleNamespace(number=number, supervisor=supervisor, state_name="IDLE", command_position=position,
                           actual_position=position, position_error=0.0, command_velocity=0.0, actual_velocity=0.0,
                           sample=100, faults=faults, **flags)


def _supervisor(number: int, axes: list, state: str = "IDLE", last_action: str = "NONE") -> SimpleNamespace:
    return SimpleNamespace(number=number, state_name=state, axis_numbers=[a.number for a in axes], axes=axes,
                           move_id=3, motion_type="S_CURVE", moves_pending=0, last_action=last_action,
                           action_source="USER", sample=100)


def _axis_rows(lines: list[str]) -> list[list[str]]:
    first = next(i for i, line in enumerate(lines) if line.startswith("axis"))
    return [line.split() for line in lines[first + 1:] if line[:1].isdigit()]


def test_render_has_a_row_per_supervisor_and_axis_with_the_status_bits():
    ms0 = _supervisor(0, [_axis(0, 0, 1000.0), _axis(1, 0, settled=False)], "MOVING", last_action="START")
    for width in (80, 200):
        lines = render({0: ms0}, {4: _axis(4, -1)}, "/mpi", width=width)
        assert lines[0] == "/mpi  sample 100"
        assert lines[2].split() == ["ms0", "MOVING", "0", "1", "3", "S_CURVE", "0", "START", "(USER)"]
        rows = _axis_rows(lines)
        assert rows[0][:6] == ["0", "0", "IDLE", "1000.0", "1000.0", "0.0"]
        assert rows[1][rows[1].index("-") if width == 80 else -2] == "-"  # not SETTLED
        assert rows[2][:2] == ["4", "-"]  # an axis no supervisor has
    assert _axis_rows(render({0: ms0}, {}, "/mpi", width=80))[0][-4:] == ["y", "y", "y", "y"]
    assert _axis_rows(render({0: ms0}, {}, "/mpi", width=200))[0][-5:] == ["yes", "yes", "yes", "yes", "-"]
    idle = render({0: _supervisor(0, [])}, {}, "/mpi")
    assert idle[2].split()[-1] == "-"  # no action yet


def test_render_says_when_the_status_is_stale():
    assert "(no newer status for 3 s: is the suite still running?)" in render({}, {}, "/mpi", stale=3.0)[0]


def _cell(axes: int = 4) -> tuple[dict, dict]:
    """Two supervisors, their axes far from zero (the widest numbers), one axis faulted."""
    numbers = list(range(axes))
    ms = {n: _supervisor(n, [_axis(k, n, -1234567.8, faults=("AMP_FAULT",) if k == 3 else ())
                             for k in numbers[2 * n:2 * n + 2]], "STOPPING_ERROR", "E_STOP") for n in (0, 1)}
    return ms, {}


@pytest.mark.parametrize("width", [80, 100, 127, 128, 200])
def test_no_line_of_the_table_reaches_the_last_column(width):
    lines = render(*_cell(), "/mpi", stale=12.0, width=width)
    assert max(len(line) for line in lines) <= width - 1
    text = "\n".join(lines)
    assert "AMP_FAULT" in text  # a column of its own from 128 on, a line of its own below
    assert ("D T F S" in text) == (width < 128)
    assert ("IN_FINE_POSITION" in text) == (width >= 128)


class Terminal:
    """A terminal of ``columns`` x ``rows``, as far as the live view drives one: text wraps
    at the last column, a newline at the bottom scrolls a line into the scrollback (the main
    screen only), ESC[H homes the cursor, ESC[nF goes up n lines, ESC[K and ESC[J clear to
    the end of the line and of the screen, ESC[?1049h/l switch to the alternate screen and
    back (the main screen as it was), other sequences change nothing seen here."""

    def __init__(self, columns: int, rows: int):
        self.columns, self.rows = columns, rows
        self.scrollback: list[str] = []
        self.main = self._blank()
        self.screen, self.row, self.col = self.main, 0, 0
        self.saved = (0, 0)

    def _blank(self) -> list[list[str]]:
        return [[" "] * self.columns for _ in range(self.rows)]

    def feed(self, text: str) -> None:
        for token in re.split(r"(\x1b\[[?0-9;]*[A-Za-z]|\n)", text):
            if token == "\n":
                self._newline()
            elif token.startswith("\x1b["):
                self._escape(token)
            else:
                for char in token:
                    if self.col == self.columns:  # the pending wrap of a full line
                        self._newline()
                    self.screen[self.row][self.col] = char
                    self.col += 1

    def _newline(self) -> None:
        self.col = 0
        if self.row < self.rows - 1:
            self.row += 1
            return
        top = self.screen.pop(0)
        if self.screen is self.main:
            self.scrollback.append("".join(top).rstrip())
        self.screen.append([" "] * self.columns)

    def _escape(self, token: str) -> None:
        code, final = token[2:-1], token[-1]
        if token == "\x1b[?1049h":
            self.saved, self.screen, self.row, self.col = (self.row, self.col), self._blank(), 0, 0
        elif token == "\x1b[?1049l":
            self.screen, (self.row, self.col) = self.main, self.saved
        elif final == "H":
            self.row, self.col = 0, 0
        elif final == "F":
            self.row, self.col = max(self.row - int(code or 1), 0), 0
        elif final == "K":
            self.screen[self.row][self.col:] = [" "] * (self.columns - self.col)
        elif final == "J":
            self.screen[self.row][self.col:] = [" "] * (self.columns - self.col)
            for line in self.screen[self.row + 1:]:
                line[:] = [" "] * self.columns

    def lines(self) -> list[str]:
        """What the operator can scroll through: the scrollback and the screen, blank lines at the end left out."""
        shown = [*self.scrollback, *("".join(line).rstrip() for line in self.screen)]
        while shown and not shown[-1]:
            shown.pop()
        return shown


class _Watcher:
    """Serves the same tables, then Ctrl-C on look ``stop``; ``suite``: the suite's /diagnostics entry."""

    namespace = "/mpi"

    def __init__(self, stop: int = 3, suite=None):
        self.looks, self.stop, self.seen, self.suite = 0, stop, [], suite

    def latest(self):
        self.looks += 1
        if self.looks == self.stop:
            raise KeyboardInterrupt
        return _cell()

    def twins_on_graph(self) -> list[str]:
        return []  # one suite: no warning line

    def suite_status(self):
        return self.suite


class _Frames(io.StringIO):
    """The live view's output, and the terminal it is fed to, frame by frame (a flush each)."""

    def __init__(self, terminal: Terminal):
        super().__init__()
        self.terminal, self.after_frame = terminal, []

    def flush(self) -> None:
        self.terminal.feed(self.getvalue())
        self.seek(0)
        self.truncate()
        self.after_frame.append(self.terminal.lines())


@pytest.mark.parametrize(("columns", "rows"), [(80, 24), (200, 50)])
def test_live_status_redraws_in_place_without_stacking(columns, rows):
    terminal = Terminal(columns, rows)
    terminal.feed("$ mpi-ros status\n")
    frames = _Frames(terminal)
    with pytest.raises(KeyboardInterrupt):
        _live(_Watcher(stop=4), frames, tty=True, interval=0.0, size=lambda: os.terminal_size((columns, rows)))
    first, second, third, after = frames.after_frame
    table = render(*_cell(), "/mpi", width=columns)
    assert first == second == third == table  # each redraw over the last: not one line more
    assert max(len(line) for line in first) < columns  # nothing wrapped
    assert after == ["$ mpi-ros status", *table]  # the operator's screen back, with the last table on it


def test_live_status_on_a_short_terminal_cuts_the_table_and_says_so():
    terminal = Terminal(80, 10)
    frames = _Frames(terminal)
    with pytest.raises(KeyboardInterrupt):
        _live(_Watcher(), frames, tty=True, interval=0.0, size=lambda: os.terminal_size((80, 10)))
    first, second, after = frames.after_frame
    assert first == second
    assert len(first) == 10
    assert first[-1].startswith("... ")
    assert first[-1].endswith("more lines: a taller terminal shows them")
    assert after[-13:] == render(*_cell(), "/mpi", width=80)  # all of the last table left on leaving


def test_live_status_off_a_terminal_prints_tables_one_after_another():
    out = io.StringIO()
    with pytest.raises(KeyboardInterrupt):
        _live(_Watcher(), out, tty=False, interval=0.0)
    assert "\x1b" not in out.getvalue()
    assert out.getvalue().count("/mpi  sample 100") == 2
    assert "IN_FINE_POSITION" in out.getvalue()  # off a terminal, every column


def _feedback(progress: float, state: str = "MOVING") -> SimpleNamespace:
    return SimpleNamespace(progress=progress, state_name=state, command_position=[progress * 1000, 0.0],
                           actual_position=[progress * 1000, 0.0])


def test_progress_bar_on_a_terminal_and_lines_per_tenth_otherwise():
    tty = io.StringIO()
    view = ProgressView(tty, tty=True)
    view.show(_feedback(0.5))
    view.end()
    assert tty.getvalue() == (f"\r[{'#' * 15}{'-' * 15}]  50.0%  MOVING         command [500.0, 0.0]\x1b[K\n")
    plain = io.StringIO()
    view = ProgressView(plain, tty=False)
    for progress in (0.0, 0.01, 0.12, 0.15, 1.0):
        view.show(_feedback(progress))
    view.end()
    assert [line.split()[1] for line in plain.getvalue().splitlines()] == ["0%", "10%", "100%"]


def _args(*argv: str) -> argparse.Namespace:
    return build_parser().parse_args(["move", *argv])


def test_goal_from_flags():
    goal = goal_from_args(_args("-p", "1000", "-250.5", "-v", "500", "-a", "5000", "-d", "5000", "-j", "50",
                                "--attribute", "relative", "--id", "7"))
    assert goal == {"type": "S_CURVE", "position": [1000.0, -250.5],
                    "trajectory": [{"velocity": 500.0, "acceleration": 5000.0, "deceleration": 5000.0,
                                    "jerk_percent": 50.0}],
                    "id": 7, "attributes": ["RELATIVE", "ID"]}
    velocity = goal_from_args(_args("--type", "velocity", "-v", "-300", "-a", "2000"))
    assert velocity["type"] == "VELOCITY"
    assert "position" not in velocity
    # a type the controller does not know is the controller's to refuse (TYPE_INVALID)
    assert goal_from_args(_args("--type", "invalid"))["type"] == "INVALID"


def test_goal_yaml_with_flags_overriding_its_fields():
    goal = goal_from_args(_args("--goal", "{type: TRAPEZOIDAL, position: [1, 2], attributes: [APPEND], "
                                          "trajectory: [{velocity: 1, acceleration: 2}, {velocity: 3}]}",
                                "-v", "500", "--delay", "0.5", "0.5"))
    assert goal["trajectory"] == [{"velocity": 500.0, "acceleration": 2}, {"velocity": 500.0}]  # every axis'
    assert goal["attributes"] == ["APPEND", "DELAY"]
    assert goal["delay"] == [0.5, 0.5]
    goal = goal_from_args(_args("--goal", "{position: [1, 2], trajectory: [{velocity: 1, deceleration: 9}, "
                                          "{velocity: 1}]}", "-a", "5000"))
    # no deceleration is made up (docs/decisions.md, "Deceleration"): the goal is the controller's to refuse
    assert [t.get("deceleration") for t in goal["trajectory"]] == [9, None]


@pytest.mark.parametrize(("argv", "text"), [
    (["-p", "1", "2", "-a", "5"], "--velocity and --deceleration needed for a S_CURVE move"),
    (["-p", "1", "2", "-v", "1", "-a", "5"], "--deceleration needed for a S_CURVE move"),
    (["--type", "VELOCITY"], "--velocity and --acceleration needed for a VELOCITY move"),
    # what each type needs is its family record's (mpi_ros/mpi/planning/families.py); fields
    # without a flag are named as the goal's fields
    (["--type", "S_CURVE_JERK", "-p", "1", "2", "-v", "1", "-a", "5", "-d", "5"],
     "acceleration_jerk and deceleration_jerk needed for a S_CURVE_JERK move"),
    (["--type", "PVT", "-p", "1", "2"], "point_velocity and time needed for a PVT move"),
    (["--type", "CAM_LINEAR"], "master_distance and slave_position needed for a CAM_LINEAR move"),
    (["--goal", "{type: [unclosed"], "--goal: not valid YAML"),
    (["--goal", "- 1"], "--goal: expected a mapping of goal fields"),
    (["--goal", "{trajectory: 5}", "-v", "1"], "--goal: trajectory must be a list of mappings"),
])
def test_goal_usage_errors(argv, text):
    with pytest.raises(UsageError) as caught:
        goal_from_args(_args(*argv))
    assert str(caught.value).startswith(text)


@pytest.mark.parametrize("verb", ["move", "modify", "stop", "e-stop", "abort", "reset", "resume", "fault",
                                  "status", "events", "echo", "demo"])
def test_every_console_verb_explains_itself_with_an_example(verb):
    sub = build_parser()._subparsers._group_actions[0].choices[verb]
    text = sub.format_help()
    assert f"\n  mpi-ros {verb}" in text  # an example command line
    if verb != "demo":
        assert "--namespace NS" in text
        assert "--supervisor N" in text
        assert "--timeout S" in text


def _suite_entry(level: int, message: str):
    from diagnostic_msgs.msg import DiagnosticStatus

    return DiagnosticStatus(name="mpi/suite", level=bytes([level]), message=message)


BEHIND = ("behind real time: 2.43 s behind the wall clock, real time factor 0.69; on a loaded machine "
          "ros.clock_priority keeps it in time")


def _live_lines(suite) -> list[str]:
    out = io.StringIO()
    with pytest.raises(KeyboardInterrupt):
        _live(_Watcher(stop=2, suite=suite), out, tty=False, interval=0.0)
    return out.getvalue().splitlines()


@pytest.mark.parametrize("level", [1, 2], ids=["WARN", "ERROR"])
def test_live_status_says_when_the_suite_is_behind_real_time(level):
    lines = _live_lines(_suite_entry(level, BEHIND))
    assert lines[:2] == ["/mpi  sample 100", f"warning: the suite (mpi/suite on /diagnostics): {BEHIND}"]


@pytest.mark.parametrize("suite", [None, _suite_entry(0, "3 samples behind the wall clock")],
                         ids=["before its first entry", "OK"])
def test_live_status_says_nothing_of_a_suite_in_time(suite):
    lines = _live_lines(suite)
    assert lines[0] == "/mpi  sample 100"
    assert lines[1].startswith("ms ")  # the table's titles, right under the header
