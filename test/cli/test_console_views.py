"""How the console draws, without a suite: the status table redrawn in place on a terminal
(printed anew otherwise), the progress bar of a move, goals built from flags and YAML."""

from __future__ import annotations

import argparse
import io
from types import SimpleNamespace

import pytest

from mpi_ros.cli import build_parser
from mpi_ros.cli.console import UsageError
from mpi_ros.cli.goals import ProgressView, goal_from_args
from mpi_ros.cli.status import _live, render


def _axis(number: int, supervisor: int, position: float = 0.0, **bits) -> SimpleNamespace:
    flags = {"done": True, "at_target": True, "in_fine_position": True, "settled": True, **bits}
    return SimpleNamespace(number=number, supervisor=supervisor, state_name="IDLE", command_position=position,
                           actual_position=position, command_velocity=0.0, sample=100, **flags)


def _supervisor(number: int, axes: list, state: str = "IDLE", last_action: str = "NONE") -> SimpleNamespace:
    return SimpleNamespace(number=number, state_name=state, axis_numbers=[a.number for a in axes], axes=axes,
                           move_id=3, motion_type="S_CURVE", moves_pending=0, last_action=last_action,
                           action_source="USER", sample=100)


def test_render_has_a_row_per_supervisor_and_axis_with_the_status_bits():
    ms0 = _supervisor(0, [_axis(0, 0, 1000.0), _axis(1, 0, settled=False)], "MOVING", last_action="START")
    lines = render({0: ms0}, {4: _axis(4, -1)}, "/mpi")
    assert lines[0] == "/mpi  sample 100"
    assert lines[2].split() == ["ms0", "MOVING", "0", "1", "3", "S_CURVE", "0", "START", "(USER)"]
    rows = [line.split() for line in lines[5:]]
    assert rows[0] == ["0", "0", "IDLE", "1000.0", "1000.0", "0.0", "yes", "yes", "yes", "yes"]
    assert rows[1][-1] == "-"  # not SETTLED
    assert rows[2][:2] == ["4", "-"]  # an axis no supervisor has
    idle = render({0: _supervisor(0, [])}, {}, "/mpi")
    assert idle[2].split()[-1] == "-"  # no action yet


def test_render_says_when_the_status_is_stale():
    assert "(no newer status for 3 s: is the suite still running?)" in render({}, {}, "/mpi", stale=3.0)[0]


class _Watcher:
    """Serves the same tables, then Ctrl-C on the third look."""

    namespace = "/mpi"

    def __init__(self):
        self.looks = 0

    def latest(self):
        self.looks += 1
        if self.looks == 3:
            raise KeyboardInterrupt
        return {0: _supervisor(0, [_axis(0, 0), _axis(1, 0)])}, {}

    def twins_on_graph(self) -> list[str]:
        return []  # one suite: no warning line


def test_live_status_redraws_in_place_on_a_terminal():
    out = io.StringIO()
    with pytest.raises(KeyboardInterrupt):
        _live(_Watcher(), out, tty=True, interval=0.0)
    text = out.getvalue()
    table_lines = len(render(*_Watcher().latest(), "/mpi"))
    assert text.startswith("\x1b[?25l")  # cursor hidden while drawing ...
    assert text.endswith("\x1b[?25h")  # ... and shown again, Ctrl-C or not
    assert text.count(f"\x1b[{table_lines}F") == 1  # the second table goes up over the first
    assert text.count("/mpi  sample 100") == 2


def test_live_status_off_a_terminal_prints_tables_one_after_another():
    out = io.StringIO()
    with pytest.raises(KeyboardInterrupt):
        _live(_Watcher(), out, tty=False, interval=0.0)
    assert "\x1b" not in out.getvalue() and out.getvalue().count("/mpi  sample 100") == 2


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
    assert velocity["type"] == "VELOCITY" and "position" not in velocity


def test_goal_yaml_with_flags_overriding_its_fields():
    goal = goal_from_args(_args("--goal", "{type: TRAPEZOIDAL, position: [1, 2], attributes: [APPEND], "
                                          "trajectory: [{velocity: 1, acceleration: 2}, {velocity: 3}]}",
                                "-v", "500", "--delay", "0.5", "0.5"))
    assert goal["trajectory"] == [{"velocity": 500.0, "acceleration": 2}, {"velocity": 500.0}]  # every axis'
    assert goal["attributes"] == ["APPEND", "DELAY"] and goal["delay"] == [0.5, 0.5]
    goal = goal_from_args(_args("--goal", "{position: [1, 2], trajectory: [{velocity: 1, deceleration: 9}, "
                                          "{velocity: 1}]}", "-a", "5000"))
    # no deceleration is made up (docs/decisions.md, "Deceleration"): the goal is the controller's to refuse
    assert [t.get("deceleration") for t in goal["trajectory"]] == [9, None]


@pytest.mark.parametrize("argv, text", [
    (["-p", "1", "2", "-a", "5"], "--velocity and --deceleration needed for a S_CURVE move"),
    (["-p", "1", "2", "-v", "1", "-a", "5"], "--deceleration needed for a S_CURVE move"),
    (["--type", "VELOCITY"], "--velocity and --acceleration needed for a VELOCITY move"),
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
        assert "--namespace NS" in text and "--supervisor N" in text and "--timeout S" in text
