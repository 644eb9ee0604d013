"""The run-time cross-check (mpi_ros/crosscheck/monitor.py) on the pure-Python controller and
runner: every started or modified move is checked, a deliberately wrong plan becomes a
CROSSCHECK event, nothing else does, and a fault in the check never breaks a command."""

from __future__ import annotations

import pytest

from mpi_ros import config as suite_config
from mpi_ros.commands import Command
from mpi_ros.crosscheck import Verdict
from mpi_ros.crosscheck import monitor as monitor_module
from mpi_ros.crosscheck.monitor import CrosscheckMonitor
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.planning.frames import Listed
from mpi_ros.mpi.supervisor import motion as motion_module
from mpi_ros.runner import ControllerRunner


@pytest.fixture
def rig():
    ctl = suite_config.load().build_controller()  # ms0 on axes 0 and 1, events: ALL
    runner = ControllerRunner(ctl, time_scale=None)
    found = []
    monitor = CrosscheckMonitor(ctl, on_disagreement=found.append)
    runner.on_command(monitor)
    return ctl, runner, monitor, found


def _goal(kind="S_CURVE", position=(1000.0, 500.0), velocity=500.0, acceleration=5000.0, deceleration=5000.0,
          jerk_percent=50.0, **extra):
    return {"type": kind, "position": list(position),
            "trajectory": [{"velocity": velocity, "acceleration": acceleration, "deceleration": deceleration,
                            "jerk_percent": jerk_percent}], **extra}


def _crosscheck_events(ctl):
    return [e for e in ctl.drain_events() if e.type is MPIEventType.CROSSCHECK]


def test_start_and_modify_are_checked_without_events(rig):
    ctl, runner, monitor, found = rig
    reply, _ = runner.submit(Command("motion_start", 0, request=_goal()))
    assert reply.accepted
    assert monitor.verdicts[Verdict.AGREE] == 2  # both axes of the vector move
    runner.step(60)  # inside the first ramp: the modify restarts from zero acceleration
    reply, _ = runner.submit(Command("motion_modify", 0, request=_goal(position=(-200.0, 300.0))))
    assert reply.accepted
    assert sum(monitor.verdicts.values()) == 4
    assert monitor.verdicts[Verdict.DISAGREE] == 0
    assert not found
    assert not _crosscheck_events(ctl)
    summary = monitor.summary()
    assert summary["checked"] == 4
    assert summary["disagree"] == 0
    assert summary["last_disagreement"] == ""


def test_check_command_returns_the_results_of_the_move(rig):
    _ctl, runner, monitor, _ = rig
    command = Command("motion_start", 0, request=_goal(kind="TRAPEZOIDAL", position=(0.0, -700.0)))
    reply, _ = runner.submit(command)
    results = monitor.check_command(command, reply)
    assert [r.verdict for r in results] == [Verdict.AGREE, Verdict.AGREE]
    assert results[0].controller_duration == 0.0  # axis 0 does not move
    assert results[1].controller_duration > 0.0


def _plan_with_twice_the_acceleration(monkeypatch):
    """A planner bug: frames planned with twice the acceleration, the limits recorded as asked."""
    real = motion_module.compile_move

    def wrong(supervisor, motion_type, attrs, params, starts, rate):
        from dataclasses import replace

        asked = list(params.trajectory)
        fast = replace(params, trajectory=[replace(t, acceleration=2 * t.acceleration) for t in asked])
        move, notes = real(supervisor, motion_type, attrs, fast, starts, rate)
        for plan in move.plans:
            plan.source = Listed(plan.segments, replace(plan.limits, acceleration=plan.limits.acceleration / 2))
        return move, notes

    monkeypatch.setattr(motion_module, "compile_move", wrong)


def test_a_wrong_plan_produces_a_crosscheck_event(rig, monkeypatch):
    ctl, runner, monitor, found = rig
    _plan_with_twice_the_acceleration(monkeypatch)
    reply, sample = runner.submit(Command("motion_start", 0, request=_goal(
        position=(1000.0, 0.0), attributes=["ID"], id=42)))
    assert reply.accepted  # the command itself is not refused: the check reports
    events = _crosscheck_events(ctl)
    assert [(e.supervisor, e.axis, e.move_id) for e in events] == [(0, 0, 42)]
    assert "DISAGREE" in events[0].detail
    assert "average rate" in events[0].detail
    assert len(found) == 1
    assert found[0].result.axis == 0
    assert found[0].sample == sample
    assert MPIEventType.CROSSCHECK in ctl.supervisor(0).latched
    summary = monitor.summary()
    assert summary["disagree"] == 1
    assert "DISAGREE" in summary["last_disagreement"]
    # axis 1 does not move: nothing to get wrong
    assert monitor.verdicts[Verdict.AGREE] == 1


def test_the_event_follows_the_notify_mask(rig, monkeypatch):
    ctl, runner, _monitor, found = rig
    assert runner.submit(Command("event_notify_set", 0, request={"event_types": ["MOTION_DONE"]}))[0].accepted
    _plan_with_twice_the_acceleration(monkeypatch)
    runner.submit(Command("motion_start", 0, request=_goal()))
    assert not _crosscheck_events(ctl)  # not asked for: latched only
    assert MPIEventType.CROSSCHECK in ctl.supervisor(0).latched
    assert len(found) == 2  # still reported to the suite (log, diagnostics)


def test_append_checks_the_queued_move(rig):
    ctl, runner, monitor, _ = rig
    runner.submit(Command("motion_start", 0, request=_goal()))
    runner.step(100)
    reply, _ = runner.submit(Command("motion_start", 0, request=_goal(position=(0.0, 0.0), attributes=["APPEND"])))
    assert reply.accepted
    assert reply.serial == ctl.supervisor(0).queue[-1].serial
    assert monitor.verdicts[Verdict.AGREE] == 4


def test_refused_and_unchecked_commands_are_ignored(rig):
    ctl, runner, monitor, _ = rig
    reply, _ = runner.submit(Command("motion_start", 0, request=_goal(velocity=-1.0)))
    assert not reply.accepted
    ctl.config.firmware_option_21 = True  # S_CURVE_JERK: planned from the full state, not checked here
    goal = _goal(kind="S_CURVE_JERK")
    goal["trajectory"][0].update(acceleration_jerk=1e6, deceleration_jerk=1e6)
    reply, _ = runner.submit(Command("motion_start", 0, request=goal))
    assert reply.accepted
    runner.submit(Command("action", 0, request={"action": "STOP"}))
    assert sum(monitor.verdicts.values()) == 0
    assert monitor.errors == 0


def test_a_fault_in_the_check_is_counted_not_raised(rig, monkeypatch):
    ctl, runner, monitor, found = rig

    def broken(plan, motion_type):
        raise RuntimeError("boom")

    monkeypatch.setattr(monitor_module, "check_plan", broken)
    reply, _ = runner.submit(Command("motion_start", 0, request=_goal()))
    assert reply.accepted
    assert monitor.errors == 2
    assert "boom" in monitor.summary()["last_error"]
    assert not found
    assert not _crosscheck_events(ctl)
