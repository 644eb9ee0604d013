"""The runner: periodic work at exact samples, commands at the next sample, real time."""

from __future__ import annotations

import logging
import os
import re
import threading

import pytest

from mpi_ros import config
from mpi_ros.commands import Command
from mpi_ros.mpi.move_log import MoveLog
from mpi_ros.runner import ControllerRunner

GOAL = {"type": "TRAPEZOIDAL", "position": [100.0, 0.0],
        "trajectory": [{"velocity": 1000.0, "acceleration": 10000.0, "deceleration": 10000.0}]}


def manual():
    return ControllerRunner(config.load().build_controller(), time_scale=None)


def test_periodic_callbacks_run_at_exact_samples_and_their_output_after_the_lock():
    runner = manual()
    seen, published = [], []

    def collect(ctl):
        seen.append(ctl.sample)
        assert runner.lock._is_owned()
        return lambda s=ctl.sample: published.append((s, runner.lock._is_owned()))

    runner.add_periodic(100.0, collect)  # every 20 samples at 2 kHz
    runner.step(100)
    assert seen == [20, 40, 60, 80, 100]
    assert published == [(s, False) for s in seen]


def test_a_command_takes_effect_at_the_next_sample_and_listeners_see_it():
    runner = manual()
    log = []
    runner.on_command(lambda sample, command, reply: log.append((sample, command.operation, reply.message.name)))
    runner.step(37)
    reply, sample = runner.submit(Command("motion_start", 0, request=GOAL))
    # docs/decisions.md, "Samples, commands and replay": a command is applied at the first sample after
    # the controller's current one
    assert sample == 38
    assert log == [(38, "motion_start", "MPIMessageOK")]
    runner.step(2000)
    assert [end.message.name for end in runner.ctl.move_log.ends(reply.serial)] == ["MPIMessageOK"]


def test_wait_wakes_when_the_controller_changes():
    runner = manual()
    reply, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    result = {}
    waiter = threading.Thread(target=lambda: result.setdefault(
        "ok", runner.wait(lambda ctl: bool(ctl.move_log.ends(reply.serial)), timeout=10.0)))
    waiter.start()
    runner.step(2000)
    waiter.join(timeout=10.0)
    assert result == {"ok": True}


def test_real_time_mode_keeps_up_with_wall_time():
    runner = ControllerRunner(config.load().build_controller(), time_scale=50.0)
    runner.start()
    try:
        assert runner.wait(lambda ctl: ctl.sample >= 20_000, timeout=10.0)
    finally:
        runner.stop()
    assert not runner.running


def test_change_hooks_see_every_batch_and_command_with_the_moves_ended_in_the_log():
    runner = manual()
    seen = []

    def hook(ctl):
        assert runner.lock._is_owned()
        seen.append((ctl.sample, [(e.serial, e.message.name) for e in ctl.move_log.recent()]))
        return lambda: seen.append(("output", runner.lock._is_owned()))

    runner.on_change(hook)
    reply, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    assert seen == [(0, []), ("output", False)]
    runner.step(2000)  # the move ends within this batch: the hook sees its end
    assert seen[2:] == [(2000, [(reply.serial, "MPIMessageOK")]), ("output", False)]


def test_after_the_change_hooks_the_ends_are_read_and_the_log_may_let_them_go(caplog):
    # mpi_ros/mpi/move_log.py: the goals' reviews are change hooks; once they ran, every end
    # recorded so far is read, and beyond KEPT_READ moves the log lets it go.
    runner = manual()
    runner.ctl.move_log = MoveLog(kept_read=1)
    seen = []
    runner.on_change(lambda ctl: seen.append(sorted({e.serial for e in ctl.move_log.recent()
                                                     if ctl.move_log.ends(e.serial)})))
    first, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    runner.step(2000)
    second, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    runner.step(2000)
    assert seen[1] == [first.serial]
    assert seen[-1] == [second.serial]
    assert runner.ctl.move_log.ends(first.serial) == ()

    def failing(ctl):
        raise RuntimeError("a hook that did not read")

    runner.on_change(failing)  # a hook failed: what it may not have read stays
    third, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    runner.step(2000)
    fourth, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    runner.step(2000)
    assert runner.ctl.move_log.ends(third.serial)
    assert runner.ctl.move_log.ends(fourth.serial)
    assert "a change hook failed" in caplog.text


def test_a_modified_move_keeps_each_of_its_outcomes_in_order():
    # MPI 000, mpiMotionModify: a modify keeps the move (its serial); a VELOCITY move reaches
    # its velocity once per command, and a goal needs the outcome of its own command.
    runner = manual()
    velocity = {"type": "VELOCITY", "trajectory": [{"velocity": 200.0, "acceleration": 5000.0}]}
    reply, _ = runner.submit(Command("motion_start", 0, request=velocity))
    runner.step(400)
    modified, modify_sample = runner.submit(Command("motion_modify", 0, request={
        **velocity, "trajectory": [{"velocity": -300.0, "acceleration": 5000.0}]}))
    runner.step(400)
    assert modified.serial == reply.serial
    ends = runner.ctl.move_log.ends(reply.serial)
    assert [(e.message.name, e.detail) for e in ends] == [("MPIMessageOK", "at velocity")] * 2
    assert ends[0].sample < modify_sample <= ends[1].sample


def test_deferred_work_of_a_command_runs_on_the_clock_thread_while_it_runs():
    # An E_STOP service answers at once: the output a command leaves (publishing) is not the
    # caller's to run while the clock thread runs; without it (manual mode) the caller runs it.
    runner = ControllerRunner(config.load().build_controller(), time_scale=1.0)
    commands, ran = [], []
    done = threading.Event()
    runner.on_command(lambda sample, command, reply: commands.append(command.request["action"]))

    def hook(ctl):
        if commands:  # right after the command, under the lock
            action = commands.pop()
            return lambda: (ran.append((action, threading.current_thread().name)), done.set())
        return None

    runner.on_change(hook)
    runner.start()
    try:
        runner.submit(Command("action", 0, request={"action": "E_STOP"}))
        assert done.wait(10.0)
    finally:
        runner.stop()
    runner.submit(Command("action", 0, request={"action": "RESET"}))
    assert ran == [("E_STOP", "mpi-controller-clock"), ("RESET", threading.current_thread().name)]


def test_the_clock_thread_steps_to_the_last_periodic_stop_due_and_catches_up_in_pieces():
    # Every stretch stepped costs the controller a fixed amount: the clock thread steps to the
    # periodic stops (where something reads the controller), not a few samples past them.
    from mpi_ros.runner import CATCH_UP

    runner = ControllerRunner(config.load().build_controller(), time_scale=1.0)  # not started
    runner.add_periodic(100.0, lambda ctl: None)  # every 20 samples
    runner.add_periodic(1.0, lambda ctl: None)  # every 2000
    period = 0.01  # s: 20 samples a wake
    runner.step(20)  # the first stop is done
    assert runner._clock_target(33, period) == 20  # nothing new is due: nothing to step
    assert runner._clock_target(47, period) == 40
    assert runner._clock_target(60, period) == 60
    # behind by more than CATCH_UP wakes: a piece at a time, each ending at a stop
    far = 20 + CATCH_UP * 20
    assert runner._clock_target(5000, period) == far
    runner.step(far - 20)
    assert runner._clock_target(5000, period) == far + CATCH_UP * 20
    # no periodic work, or as fast as possible: straight to the sample due
    assert ControllerRunner(config.load().build_controller(), time_scale=1.0)._clock_target(47, period) == 47
    fast = ControllerRunner(config.load().build_controller(), time_scale=0.0)
    fast.add_periodic(100.0, lambda ctl: None)
    assert fast._clock_target(2047, period) == 2047


# -- statuses stepped in stretches (runner.add_status, ros.publish_period; issue 35) ------------------
def _status_run(publish_period: float, script: list[tuple[str, int]]):
    """Steps a manual runner through ``script`` (("step", n) or ("e_stop", supervisor)) with
    a 1 kHz status (every 2 samples at 2 kHz) and a 100 Hz live periodic; what each saw."""
    runner = ControllerRunner(config.load().build_controller(), time_scale=None, publish_period=publish_period)
    statuses, live, stretches = [], [], []
    step_snapshots = runner.ctl.step_snapshots
    runner.ctl.step_snapshots = lambda samples, at: stretches.append(samples) or step_snapshots(samples, at)

    def status(ctl, at):
        motions, axes = at.taken()
        statuses.append((at.sample, ctl.sample, motions, axes))

    runner.add_status(1000.0, status)
    runner.add_periodic(100.0, lambda ctl: live.append(ctl.sample))
    runner.submit(Command("motion_start", 0, request=GOAL))
    answers = []
    for what, value in script:
        if what == "step":
            runner.step(value)
        else:
            answers.append(runner.submit(Command("action", value, request={"action": "E_STOP"})))
    return statuses, live, stretches, answers


SCRIPT = [("step", 37), ("step", 3), ("e_stop", 0), ("step", 1), ("step", 150), ("e_stop", 1), ("step", 61)]


def test_statuses_in_stretches_equal_the_statuses_stepped_one_by_one():
    batched, live, stretches, answers = _status_run(0.005, SCRIPT)
    single, single_live, single_stretches, single_answers = _status_run(0.0, SCRIPT)
    # every status at its own sample, with what stepping there gives (Controller.step_snapshots)
    assert [s[0] for s in batched] == list(range(2, 253, 2))
    assert [(s[0], s[2], s[3]) for s in batched] == [(s[0], s[2], s[3]) for s in single]
    # the commands took effect at the same samples (the sample after the controller's)
    assert [sample for _, sample in answers] == [sample for _, sample in single_answers] == [41, 192]
    # live periodic work still stops the stepping at its sample
    assert live == single_live == list(range(20, 253, 20))
    # and fewer stretches were stepped (each costs about the same whatever its length)
    assert len(stretches) < len(single_stretches) / 3


def test_a_status_waits_at_most_the_publish_period_in_manual_stepping():
    batched, _, _, _ = _status_run(0.005, SCRIPT)  # 10 samples at 2 kHz
    waits = [controller - sample for sample, controller, _, _ in batched]
    assert max(waits) == 10
    assert min(waits) == 0
    one_by_one, _, _, _ = _status_run(0.0, SCRIPT)
    assert {controller - sample for sample, controller, _, _ in one_by_one} == {0}


def test_an_e_stop_between_two_status_stops_shows_from_its_sample_on():
    # E_STOP at sample 41 (after step 40, between the statuses of 40 and 42): MPI 000,
    # mpiMotionAction, "E_STOP" decelerates the motion to the ERROR state
    batched, _, _, answers = _status_run(0.005, SCRIPT)
    states = {sample: motions[0].state.name for sample, _, motions, _ in batched}
    assert answers[0][1] == 41
    assert states[40] == "MOVING"
    assert states[42] in ("STOPPING_ERROR", "ERROR")


def test_a_status_period_shorter_than_its_rate_waits_for_nothing():
    # 100 Hz status (20 samples) with a 5 ms period (10 samples): no second status would join
    # the first's stretch, so it is not held back at all
    runner = ControllerRunner(config.load().build_controller(), time_scale=None, publish_period=0.005)
    seen = []
    runner.add_status(100.0, lambda ctl, at: seen.append((at.sample, ctl.sample)))
    runner.step(100)
    assert seen == [(s, s) for s in range(20, 101, 20)]


def test_a_negative_publish_period_is_refused():
    with pytest.raises(ValueError, match=re.escape("publish_period must be >= 0 s, got -0.001")):
        ControllerRunner(config.load().build_controller(), time_scale=None, publish_period=-0.001)


def test_live_periodic_work_with_nothing_to_do_neither_runs_nor_ends_a_stretch():
    # Feedback without a goal: its stops pass without a call and without cutting the stepping;
    # once wanted, it runs at its own exact samples again (add_periodic's wanted).
    runner = ControllerRunner(config.load().build_controller(), time_scale=None, publish_period=0.005)
    wanted, live, stretches = [False], [], []
    step_snapshots = runner.ctl.step_snapshots
    runner.ctl.step_snapshots = lambda samples, at: stretches.append(samples) or step_snapshots(samples, at)
    runner.add_status(1000.0, lambda ctl, at: None)  # every 2 samples, gathered 10 samples at a time
    runner.add_periodic(100.0, lambda ctl: live.append(ctl.sample), wanted=lambda: wanted[0])  # every 20
    runner.step(105)
    assert live == []
    # the status' stretches alone: each to a status' sample + 10 (12, 24, ... 96), none cut at 20, 40, ...
    assert stretches == [12] * 8 + [9]
    wanted[0] = True
    stretches.clear()
    runner.step(60)
    assert live == [120, 140, 160]
    # cut at each of them: 105 -> 116 (status 106 + 10), 120, 132, 140, 152, 160, 165
    assert stretches == [11, 4, 12, 8, 12, 8, 5]
    wanted[0] = False
    runner.step(40)
    assert live == [120, 140, 160]


def _fifo_allowed() -> bool:
    """Whether this process may put a thread under SCHED_FIFO (root, CAP_SYS_NICE or an
    rtprio limit): tried on a thread of its own, which ends with it."""
    allowed = []

    def attempt() -> None:
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
            allowed.append(True)
        except PermissionError:
            allowed.append(False)

    thread = threading.Thread(target=attempt)
    thread.start()
    thread.join()
    return allowed[0]


@pytest.mark.parametrize(("priority", "time_scale"), [(0, 1.0), (1, 1.0), (1, 0.0)])
def test_the_clock_thread_runs_at_the_priority_asked_or_says_why_not(priority, time_scale, caplog):
    # as fast as possible (0) it never sleeps: a real-time thread would hold its core
    runner = ControllerRunner(config.load().build_controller(), time_scale=time_scale, priority=priority)
    seen, ran = [], threading.Event()
    runner.add_periodic(100.0, lambda ctl: seen.append((os.sched_getscheduler(0), os.sched_getparam(0).sched_priority))
                        or ran.set())
    with caplog.at_level(logging.WARNING, logger="mpi_ros.runner"):
        runner.start()
        try:
            assert ran.wait(10.0)
        finally:
            runner.stop()
    assert os.sched_getscheduler(0) == os.SCHED_OTHER  # the caller's thread as it was
    refused = [r.getMessage() for r in caplog.records if "SCHED_FIFO" in r.getMessage()]
    if priority and time_scale and _fifo_allowed():
        assert seen[0] == (os.SCHED_FIFO, priority)
        assert not refused
        assert (runner.scheduling, runner.priority_refused) == (f"SCHED_FIFO {priority}", False)
    else:
        assert seen[0] == (os.SCHED_OTHER, 0)
        assert bool(refused) == bool(priority), refused
        assert runner.priority_refused == bool(priority)  # (/diagnostics: WARN)
        assert runner.scheduling.startswith("normal")


@pytest.mark.parametrize("priority", [-1, 100])
def test_a_priority_outside_sched_fifo_is_refused(priority):
    with pytest.raises(ValueError, match="SCHED_FIFO priority"):
        ControllerRunner(config.load().build_controller(), priority=priority)
