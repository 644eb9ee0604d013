"""The operator console end to end: each `mpi-ros` verb against a real suite (`mpi-ros run`
in its own process), as a user runs it: a process per command (or ``main(argv)`` in this
process), its printed lines and its exit status (0 OK, 1 refused by the controller,
2 usage or connection)."""

from __future__ import annotations

import os
import re
import signal

import pytest
import yaml

from .conftest import WAIT, console, make_idle, mpi_ros

pytestmark = pytest.mark.usefixtures("suite_process")

DOMAIN = os.environ["ROS_DOMAIN_ID"]


def _table_row(table: str, first: str) -> list[str]:
    """The cells of the row of `status` whose first cell is ``first``."""
    for line in table.splitlines():
        cells = line.split()
        if cells and cells[0] == first:
            return cells
    raise AssertionError(f"no row {first!r} in:\n{table}")


# -- move ----------------------------------------------------------------------------------------
def test_move_prints_the_final_message_code_and_positions_and_exits_0(ms0):
    proc = mpi_ros("move", "--type", "S_CURVE", "--position", "1000", "-500", "--velocity", "5000",
                   "--acceleration", "50000", "--deceleration", "50000", "--jerk-percent", "50")
    assert proc.returncode == 0, proc.stderr
    assert "MPIMessageOK (code 0) DONE, state IDLE: motion done" in proc.stdout
    assert "command position [1000.0, -500.0]" in proc.stdout
    assert "actual position  [1000.0, -500.0]" in proc.stdout
    ms0.wait_for(lambda s: [a.command_position for a in s.axes] == [1000.0, -500.0], WAIT, "at the target")


def test_move_from_goal_yaml_with_a_flag_overriding_it_on_ms1(ms1, capsys):
    start = [a.command_position for a in ms1.status(WAIT).axes]
    goal = ("{type: TRAPEZOIDAL, position: [-200.0, 300.0], attributes: [RELATIVE], "
            "trajectory: [{velocity: 1.0, acceleration: 50000.0, deceleration: 50000.0}]}")
    assert console("move", "--goal", goal, "--velocity", "5000", "--supervisor", "1") == 0
    out = capsys.readouterr().out
    expected = f"command position [{start[0] - 200.0:.1f}, {start[1] + 300.0:.1f}]"
    assert "MPIMessageOK (code 0) DONE" in out
    assert expected in out


def test_a_move_with_a_wrong_number_of_positions_is_refused_with_exit_1(ms0):
    before = [a.command_position for a in ms0.status(WAIT).axes]
    proc = mpi_ros("move", "--position", "1000", "--velocity", "500", "--acceleration", "5000",
                   "--deceleration", "5000")
    assert proc.returncode == 1, proc.stderr
    first = proc.stdout.splitlines()[0]
    assert first.startswith("MPIMessagePARAM_INVALID (code 2) REFUSED, state IDLE: position needs 2 value(s)")
    assert f"command position [{before[0]:.1f}, {before[1]:.1f}]" in proc.stdout  # nothing moved


def test_move_usage_errors_exit_2_and_say_what_is_missing(capsys):
    assert console("move", "--position", "1000", "0") == 2
    assert "--velocity and --acceleration and --deceleration needed for a S_CURVE move" in capsys.readouterr().err
    # a point-to-point move's deceleration is never made up (docs/decisions.md, "Deceleration")
    assert console("move", "--position", "1000", "0", "-v", "500", "-a", "5000") == 2
    assert "--deceleration needed for a S_CURVE move" in capsys.readouterr().err
    assert console("move", "--goal", "[1, 2]") == 2
    assert "--goal: expected a mapping of goal fields" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        console("move", "--position", "one")
    assert exc.value.code == 2


def test_a_goal_field_that_does_not_exist_is_a_usage_error(ms0, capsys):
    assert console("move", "--goal", "{type: S_CURVE, positions: [1.0, 2.0]}") == 2
    assert "bad goal: positions: no such field in MotionStart_Goal" in capsys.readouterr().err


# -- where the suite is, or is not -------------------------------------------------------------------
def test_an_unknown_supervisor_exits_2_naming_those_the_suite_runs():
    proc = mpi_ros("stop", "--supervisor", "3")
    assert proc.returncode == 2
    assert proc.stderr.strip() == "mpi-ros stop: no supervisor /mpi/ms3: the suite runs ms0, ms1"


def test_no_suite_exits_2_saying_where_it_looked_and_what_to_do():
    proc = mpi_ros("move", "--position", "0", "0", "-v", "1", "-a", "1", "-d", "1", "--namespace", "/nosuch",
                   "--timeout", "0.5")
    assert proc.returncode == 2
    message = proc.stderr.strip()
    assert message.startswith(f"mpi-ros move: no suite found under /nosuch on ROS_DOMAIN_ID {DOMAIN} within 0.5 s")
    assert message.endswith(": is `mpi-ros run` running, on the same domain?")
    # once discovery has seen the suite's nodes, where they are is named too
    assert message.count("(supervisors found under /mpi)") <= 1


def test_a_one_shot_action_waits_for_its_one_service_not_the_goal_client():
    """`mpi-ros e-stop` and its kin build an ActionCall (the action service alone), not a
    MotionClient (both actions, their round trips, rclpy.action and numpy to import first)."""
    import subprocess
    import sys

    from .conftest import REPO, with_timeout

    probe = ("import sys; from mpi_ros.cli import main; status = main(sys.argv[1:]); "
             "print(status, 'mpi_ros.client' in sys.modules, 'rclpy.action' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe, *with_timeout(["reset"])], capture_output=True, text=True,
                          timeout=WAIT * 2, cwd=REPO, check=False)
    assert done.stdout.splitlines()[-1] == "0 False False", done.stdout + done.stderr


def test_bad_ros_arguments_are_a_usage_error(capsys):
    assert console("status", "--once", "--ros-args", "-p", "nonsense") == 2
    assert "invalid ROS arguments" in capsys.readouterr().err


# -- the actions and the status table ----------------------------------------------------------------
def test_stop_resume_e_stop_reset_change_the_state_as_status_shows(ms0, capsys):
    assert console("move", "--type", "VELOCITY", "-v", "400", "-a", "4000", "--no-wait") == 0
    assert re.match(r"started: ms0 MOVING, move \d+$", capsys.readouterr().out.strip())
    ms0.wait_for(lambda s: s.state_name == "MOVING" and s.axes[0].at_velocity, WAIT, "at velocity")

    proc = mpi_ros("stop")  # the verbs as processes, as a user runs them ...
    assert proc.returncode == 0, proc.stderr
    assert re.match(r"STOP: MPIMessageOK \(code 0\), state STOPPING, sample \d+$", proc.stdout.strip())
    ms0.wait_for_state("STOPPED", WAIT)
    assert console("status", "--once", "--supervisor", "0") == 0  # ... or in this process, faster
    table = capsys.readouterr().out
    assert _table_row(table, "ms0")[:2] == ["ms0", "STOPPED"]
    assert "STOP (USER)" in table
    assert _table_row(table, "0")[2] == "STOPPED"

    assert console("resume") == 0
    assert "RESUME: MPIMessageOK (code 0), state MOVING" in capsys.readouterr().out
    ms0.wait_for(lambda s: s.state_name == "MOVING" and s.axes[0].at_velocity, WAIT, "moving at velocity")

    proc = mpi_ros("e-stop")
    assert proc.returncode == 0
    assert "E_STOP: MPIMessageOK (code 0), state STOPPING_ERROR" in proc.stdout
    ms0.wait_for_state("ERROR", WAIT)
    assert console("status", "--once") == 0  # every supervisor
    table = capsys.readouterr().out
    assert _table_row(table, "ms0")[1] == "ERROR"
    assert _table_row(table, "ms1")[1] == "IDLE"
    assert "E_STOP (USER)" in table

    assert console("move", "--position", "0", "0", "-v", "100", "-a", "1000", "-d", "1000") == 1
    captured = capsys.readouterr()
    assert captured.out.startswith("MPIMotionMessageERROR (code 2315) REFUSED, state ERROR")
    assert "`mpi-ros reset` leaves it" in captured.err

    proc = mpi_ros("reset")
    assert proc.returncode == 0
    assert "RESET: MPIMessageOK (code 0), state IDLE" in proc.stdout
    ms0.wait_for_state("IDLE", WAIT)


def test_abort_then_reset(ms1, capsys):
    assert console("abort", "--supervisor", "1") == 0
    assert "ABORT: MPIMessageOK (code 0), state STOPPING_ERROR" in capsys.readouterr().out
    ms1.wait_for_state("ERROR", WAIT)
    assert console("reset", "-s", "1") == 0
    assert "state IDLE" in capsys.readouterr().out


def test_stop_while_stopped_is_refused_with_a_hint(ms0, capsys):
    ms0.start({"type": "VELOCITY", "trajectory": [{"velocity": 400.0, "acceleration": 4000.0,
                                                   "deceleration": 4000.0}]}).wait(WAIT)
    ms0.wait_for_state("STOPPED", WAIT, newer_than=ms0.stop().sample)
    assert console("stop") == 1
    captured = capsys.readouterr()
    assert captured.out.startswith("STOP: MPIMotionMessageSTOPPED (code 2313), state STOPPED")
    assert "hint: ms0 is STOPPED: `mpi-ros resume` continues the move, `mpi-ros reset` drops it" in captured.err


def test_resume_while_idle_is_refused_with_the_state_message(ms0, capsys):
    assert console("resume") == 1
    captured = capsys.readouterr()
    assert captured.out.startswith("RESUME: MPIMotionMessageIDLE (code 2310), state IDLE")
    assert "hint: ms0 is idle" in captured.err


def test_status_once_prints_every_supervisor_and_axis(ms0, capsys):
    assert console("status", "--once") == 0
    lines = capsys.readouterr().out.splitlines()
    assert re.match(r"/mpi  sample \d+$", lines[0])
    assert lines[1].split() == ["ms", "state", "axes", "move", "type", "pending", "last", "action"]
    header = next(line for line in lines if line.startswith("axis"))  # off a terminal: every column
    assert header.split() == ["axis", "ms", "state", "command", "actual", "error", "velocity", "actual", "vel",
                              "DONE", "AT_TARGET", "IN_FINE_POSITION", "SETTLED", "faults"]
    rows = {line.split()[0]: line.split() for line in lines[lines.index(header) + 1:]}
    assert sorted(rows) == ["0", "1", "2", "3"]
    assert [rows[k][1] for k in "0123"] == ["0", "0", "1", "1"]  # owning supervisor
    state, velocity, done, settled, faults = rows["0"][2], rows["0"][6], rows["0"][8], rows["0"][11], rows["0"][12]
    assert (state, velocity, done, settled, faults) == ("IDLE", "0.0", "yes", "yes", "-")
    assert all(bit in ("yes", "-") for row in rows.values() for bit in row[8:12])


def test_status_live_prints_tables_until_ctrl_c(running):
    live = running("status", "--interval", "0.1")
    for _ in range(2):  # two tables: it refreshes
        live.expect("/mpi  sample")
    live.process.send_signal(signal.SIGINT)
    status, _, err = live.finish()
    assert status == 0, err
    assert "Traceback" not in err


# -- modify ----------------------------------------------------------------------------------------
def test_modify_in_flight_retargets_the_move(ms0):
    goal = ms0.start({"type": "S_CURVE", "position": [100000.0, 0.0],
                      "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0, "deceleration": 20000.0,
                                      "jerk_percent": 50.0}]})
    ms0.wait_for(lambda s: s.state_name == "MOVING", WAIT, "MOVING")
    proc = mpi_ros("modify", "--position", "-300", "250", "--velocity", "8000", "--acceleration", "80000",
                   "--deceleration", "80000")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    final = [line for line in proc.stdout.splitlines() if not line.startswith("progress")]
    assert final[0].startswith("MPIMessageOK (code 0) DONE")
    assert final[1] == "  command position [-300.0, 250.0]"
    assert goal.wait(WAIT, raise_on_error=False).message == "MPIMessageOK"  # the start's goal follows the move


def test_modify_while_idle_is_refused(ms0, capsys):
    assert console("modify", "--position", "0", "0", "-v", "100", "-a", "1000", "-d", "1000") == 1
    assert capsys.readouterr().out.startswith("MPIMotionMessageIDLE (code 2310) REFUSED")


# -- Ctrl-C ------------------------------------------------------------------------------------------
def test_ctrl_c_during_a_move_cancels_it_which_is_a_stop(ms0, running):
    move = running("move", "--position", "100000", "0", "-v", "1000", "-a", "10000", "-d", "10000")
    move.expect("progress")  # it runs
    move.process.send_signal(signal.SIGINT)
    status, out, err = move.finish()
    assert status == 130
    assert "interrupted: cancelling the goal (a STOP)" in err
    assert "MPIMotionMessageSTOPPED" in out  # how the goal ended: stopped
    ms0.wait_for_state("STOPPED", WAIT)


# -- events and echo -------------------------------------------------------------------------------------
def test_events_prints_motion_done_after_a_move_filtered_by_type_and_supervisor(ms0, ms1, running):
    events = running("events", "--supervisor", "0", "--type", "MOTION_DONE", "--type", "motion_start",
                     "--count", "2")
    events.expect("listening on /mpi/events", stream="stderr")
    # another supervisor: not shown
    ms1.move([10.0, 0.0], velocity=5000.0, acceleration=50000.0, deceleration=50000.0, timeout=WAIT)
    ms0.move([300.0, 300.0], velocity=5000.0, acceleration=50000.0, deceleration=50000.0, timeout=WAIT)
    status, out, err = events.finish()
    assert status == 0, err
    lines = out.splitlines()
    assert [line.split()[2] for line in lines] == ["MOTION_START", "MOTION_DONE"]
    assert re.match(r"sample \d+ +MOTION_DONE +ms0 +- +move \d+ +element \d+", lines[1])


def test_an_unknown_event_type_is_a_usage_error(capsys):
    assert console("events", "--type", "MOTION_DONER") == 2
    assert "unknown event type MOTION_DONER (known: MOTION_DONE," in capsys.readouterr().err


def test_echo_prints_one_message_as_yaml():
    proc = mpi_ros("echo", "ms0/status", "--once")
    assert proc.returncode == 0, proc.stderr
    documents = [d for d in yaml.safe_load_all(proc.stdout) if d is not None]
    assert len(documents) == 1
    status = documents[0]
    assert (status["number"], status["axis_numbers"]) == (0, [0, 1])
    assert status["state_name"] in ("IDLE", "MOVING", "STOPPED", "ERROR")
    assert set(status["axes"][0]) >= {"command_position", "actual_position", "settled", "sample"}
    assert proc.stdout.rstrip().endswith("---")


def test_echo_count_and_a_root_topic(capsys):
    assert console("echo", "/joint_states", "--count", "2") == 0
    documents = [d for d in yaml.safe_load_all(capsys.readouterr().out) if d is not None]
    assert len(documents) == 2
    assert len(documents[0]["name"]) == len(documents[0]["position"]) == 4


def test_echo_of_an_unknown_topic_lists_the_suites_topics(capsys):
    assert console("echo", "nope", "--once") == 2
    err = capsys.readouterr().err
    assert err.startswith("mpi-ros echo: no topic /mpi/nope: the suite publishes /clock, /diagnostics, ")
    assert "/mpi/events" in err
    assert "/mpi/ms0/status" in err
    assert "_action" not in err


def test_a_closed_pipe_ends_a_live_view_quietly(running):
    echo = running("echo", "axis0/status")
    echo.expect("---")
    echo.process.stdout.close()  # the reader leaves, as `| head` does
    status, _, err = echo.finish()
    assert status == 0, err
    assert "Traceback" not in err, err


# -- the demo ---------------------------------------------------------------------------------------
def test_demo_refuses_to_start_beside_a_running_suite(tmp_path, capsys):
    assert console("demo", "--output", str(tmp_path / "tour")) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mpi-ros demo: a suite already runs under /mpi on ROS_DOMAIN_ID {DOMAIN} (ms0, ms1): "
                          f"stop it, or run the demo under another namespace (--namespace /demo)")
    assert not (tmp_path / "tour").exists()


@pytest.fixture(autouse=True, scope="module")
def _leave_the_suite_idle(clients):
    yield
    for client in clients.values():
        make_idle(client)


def test_fault_injects_and_clears_and_reset_says_what_persists(ms1, capsys):
    """`mpi-ros fault` (docs/faults.md): an amplifier fault ABORTs ms1; RESET is refused while
    it persists, saying so; cleared, RESET recovers."""
    assert console("fault", "AMP_FAULT", "--axis", "3", "--supervisor", "1") == 0
    assert "AMP_FAULT on axis 3: MPIMessageOK (code 0), faults [AMP_FAULT]" in capsys.readouterr().out
    ms1.wait_for_state("ERROR", WAIT)
    assert console("reset", "-s", "1") == 1
    captured = capsys.readouterr()
    assert "RESET: MPIMotionMessageERROR" in captured.out
    assert "axis 3 AMP_FAULT persists" in captured.out
    # not "`mpi-ros reset` leaves it": another RESET would be refused too
    assert captured.err == ("hint: ms1 stays in ERROR while the fault persists: first "
                            "`mpi-ros fault AMP_FAULT --axis 3 --clear`, then `mpi-ros reset --supervisor 1`\n")
    assert console("fault", "AMP_FAULT", "--axis", "3", "--clear", "-s", "1") == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("AMP_FAULT on axis 3 cleared: MPIMessageOK (code 0), faults [AMP_FAULT]")
    assert captured.err == ("hint: the condition is gone, but AMP_FAULT stays latched on axis 3 (and its "
                            "supervisor in ERROR) until a RESET: `mpi-ros reset --supervisor 1`\n")
    ms1.wait_for_state("ERROR", WAIT, newer_than=ms1.status(WAIT).sample)  # still
    assert console("fault", "OVERHEAT", "--axis", "3", "-s", "1") == 1
    assert "MPIMessagePARAM_INVALID" in (out := capsys.readouterr().out)
    assert "unknown fault" in out
    assert console("reset", "-s", "1") == 0
    assert "state IDLE" in capsys.readouterr().out
