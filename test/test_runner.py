"""The runner: periodic work at exact samples, commands at the next sample, real time."""

from __future__ import annotations

import threading

from mpi_ros import config
from mpi_ros.commands import Command
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
    # DESIGN.md: "a command is applied at the first sample after the controller's current one"
    assert sample == 38 and log == [(38, "motion_start", "MPIMessageOK")]
    runner.step(2000)
    assert runner.outcomes[reply.serial].message.name == "MPIMessageOK"


def test_wait_wakes_when_the_controller_changes():
    runner = manual()
    reply, _ = runner.submit(Command("motion_start", 0, request=GOAL))
    result = {}
    waiter = threading.Thread(target=lambda: result.setdefault(
        "ok", runner.wait(lambda ctl: reply.serial in runner.outcomes, timeout=10.0)))
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
