"""`mpi-ros console` driven headless by Textual's pilot against a real suite, at 80x24 and
200x50: what is on screen, the keys' actions as the supervisors' status shows them, the jog
and its stop, the command line."""

from __future__ import annotations

import argparse
import asyncio

import pytest

from mpi_ros.cli.tui import Link, make_app

from .conftest import WAIT

pytestmark = pytest.mark.usefixtures("suite_process")


def _args(**options) -> argparse.Namespace:
    return argparse.Namespace(namespace="/mpi", supervisor=None, timeout=WAIT, jog_speed=1000.0,
                              jog_acceleration=10000.0, ros_args=[], **options)


@pytest.fixture
def link(clients, module_context):
    made = Link(_args(), context=module_context)
    yield made
    made.close()


def _log(app) -> str:
    from textual.widgets import RichLog

    return "\n".join(line.text for line in app.query_one(RichLog).lines)


async def _until(pilot, predicate, what: str) -> None:
    """Let the application run until ``predicate()``; fail after WAIT s."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + WAIT
    while not predicate():
        if loop.time() > deadline:
            pytest.fail(f"no {what} within {WAIT} s")
        await pilot.pause(0.05)


async def _until_status(pilot, client, predicate, what: str):
    """The first MotionStatus of ``client`` that shows ``predicate``, waited for in a thread while
    the application runs on (every status is looked at, not only those seen between pauses)."""
    from mpi_ros.errors import NoResponse

    try:
        return await asyncio.to_thread(client.wait_for, predicate, WAIT, what)
    except NoResponse as exc:
        pytest.fail(f"{exc}; the console's log:\n{_log(pilot.app)}")


def _screen(app) -> str:
    """The text on the screen, as the operator reads it (from the SVG screenshot)."""
    import html
    import re

    svg = app.export_screenshot()
    return html.unescape(re.sub(r"<[^>]+>", "", svg.split("</style>")[-1])).replace("\xa0", " ")


async def _type(pilot, app, line: str) -> None:
    """Open the command line with ":", put ``line`` in it (pressing each key takes seconds on a busy machine), Enter."""
    from textual.widgets import Input

    await pilot.press("colon")
    box = app.query_one(Input)
    assert box.has_focus
    box.value = line
    await pilot.press("enter")


def _state(client):
    return client.status(WAIT).state_name


@pytest.mark.parametrize("size", [(80, 24), (200, 50)])
def test_the_console_shows_the_suite_and_its_keys_act(link, ms0, size):
    async def drive():
        app = make_app(link, _args())
        async with app.run_test(size=size) as pilot:
            from textual.widgets import DataTable

            table = app.query_one(DataTable)
            await _until(pilot, lambda: table.row_count == 6, "row per supervisor and axis")
            assert [table.get_row_at(k)[0] for k in range(6)] == ["ms0 *", "  axis0 *", "  axis1", "ms1",
                                                                  "  axis2", "  axis3"]
            assert app.size == size
            assert table.region.width <= size[0]
            keys = ("space STOP", "e E_STOP", "r RESET", "u RESUME")
            await _until(pilot, lambda: all(key in _screen(app) for key in keys), "the keys on screen")
            assert "selected ms0" in _screen(app)
            await pilot.press("e")
            ms0.wait_for_state("ERROR", WAIT)
            await _until(pilot, lambda: "E_STOP ms0: MPIMessageOK" in _log(app), "E_STOP's answer in the log")
            await pilot.press("r")
            ms0.wait_for_state("IDLE", WAIT)
            await _until(pilot, lambda: table.get_row_at(0)[1] == "IDLE", "ms0 IDLE in the table")
            await pilot.press("tab")  # the next supervisor, and its first axis
            await _until(pilot, lambda: "selected ms1 axis2" in _screen(app), "ms1 selected")

    asyncio.run(drive())


@pytest.mark.parametrize("size", [(80, 24), (200, 50)])
def test_an_arrow_jogs_the_selected_axis_alone_and_stops_when_the_key_is_not_repeated(link, ms0, ms1, size):
    before = ms0.status(WAIT)
    others = [a.command_position for a in ms1.status(WAIT).axes]

    async def drive():
        app = make_app(link, _args())
        async with app.run_test(size=size) as pilot:
            await _until(pilot, lambda: "selected ms0 axis0" in _screen(app), "axis0 selected")
            await pilot.press("down")  # the next axis row: ms0's axis1
            await _until(pilot, lambda: "selected ms0 axis1" in _screen(app), "axis1 selected")
            assert "axis1 *" in _screen(app)
            assert any("jog" in line and "E_STOP" in line for line in _screen(app).splitlines())  # the footer
            await pilot.press("right")
            # one press, no repeat: a VELOCITY move of axis1 alone, STOPped JOG_FIRST s later, then RESET
            # (a status during the jog may not come on a busy machine: the held jog below looks at one)
            await _until(pilot, lambda: "jog ms0 axis1 +1000 counts/s" in _log(app), "the jog in the log")
            await _until(pilot, lambda: "jog ms0 ended: IDLE" in _log(app), "the jog's end in the log")

    asyncio.run(drive())
    after = ms0.status(WAIT)
    assert after.state_name == "IDLE"  # RESET dropped the jog's remainder: RESUME cannot restart it
    assert after.last_action == "RESET"
    assert after.axes[1].command_position > before.axes[1].command_position
    assert after.axes[0].command_position == before.axes[0].command_position
    assert [a.command_position for a in ms1.status(WAIT).axes] == others


def test_a_jog_is_refused_while_the_supervisor_runs_another_move(link, ms0):
    async def drive():
        app = make_app(link, _args())
        async with app.run_test(size=(80, 24)) as pilot:
            move = ms0.move([50_000.0, 0.0], 2000.0, 20_000.0, 20_000.0, wait=False)
            moving = await _until_status(pilot, ms0, lambda s: s.state_name == "MOVING", "the move running")
            await pilot.press("left")
            await _until(pilot, lambda: "jog refused: ms0 is MOVING" in _log(app), "the refusal in the log")
            status = ms0.status(WAIT)
            assert (status.state_name, status.move_id, status.motion_type) == ("MOVING", moving.move_id, "S_CURVE")
            move.cancel(WAIT)

    asyncio.run(drive())


def test_a_held_jog_stops_when_the_console_exits(link, ms0, monkeypatch):
    from mpi_ros.cli import jog

    monkeypatch.setattr(jog, "JOG_FIRST", 10 * WAIT)  # held: only the exit can stop it

    async def drive():
        app = make_app(link, _args())
        async with app.run_test(size=(80, 24)) as pilot:
            await _until(pilot, lambda: "selected ms0 axis0" in _screen(app), "axis0 selected")
            await pilot.press("right")
            moving = await _until_status(pilot, ms0, lambda s: s.state_name == "MOVING"
                                         and s.axes[0].command_velocity > 0.0, "axis0 jogging")
            assert moving.motion_type == "VELOCITY"
            held = moving.axes[1]
            assert (held.command_velocity, held.command_position) == (0.0, before.axes[1].command_position)
            return moving

    before = ms0.status(WAIT)
    moving = asyncio.run(drive())
    after = ms0.wait_for(lambda s: s.state_name == "IDLE" and s.sample > moving.sample, WAIT, "the jog stopped")
    assert after.last_action == "RESET"
    assert after.axes[1].command_position == before.axes[1].command_position
    assert after.axes[0].command_position > before.axes[0].command_position


def test_the_command_line_takes_the_one_shot_verbs(link, ms0):
    async def drive():
        app = make_app(link, _args())
        async with app.run_test(size=(200, 50)) as pilot:
            await _type(pilot, app, "move --position 300 0 -v 3000 -a 30000 -d 30000")
            ms0.wait_for(lambda s: s.state_name == "IDLE" and s.axes[0].command_position == 300.0, WAIT, "at 300")
            await _type(pilot, app, "stop --supervisor 1")
            await _type(pilot, app, "jump")
            await _until(pilot, lambda: "STOP ms1: MPIMotionMessageIDLE" in _log(app), "the refused STOP")
            assert "move sent to ms0" in _log(app)
            assert "unknown command 'jump': the console takes move, modify, stop" in _log(app)

    asyncio.run(drive())


def test_the_console_says_when_the_suite_is_behind_real_time(link, monkeypatch):
    from diagnostic_msgs.msg import DiagnosticStatus

    behind = ("behind real time: 2.43 s behind the wall clock, real time factor 0.69; on a loaded machine "
              "ros.clock_priority keeps it in time")
    entry = DiagnosticStatus(name="mpi/suite", level=DiagnosticStatus.WARN, message=behind)

    async def drive():
        app = make_app(link, _args())
        async with app.run_test(size=(200, 50)) as pilot:
            await _until(pilot, lambda: "selected ms0" in _screen(app), "the heading")
            monkeypatch.setattr(link.watcher, "suite_status", lambda: entry)  # as the suite's entry reads when late
            await _until(pilot, lambda: f"warning: the suite (mpi/suite on /diagnostics): {behind}" in _screen(app),
                         "the warning under the heading")

    asyncio.run(drive())
