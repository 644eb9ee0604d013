"""The Controller (mpi_ros/mpi/control.py): objects, the sample clock, stepping, gates and I/O."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mpi_ros.mpi import (
    Controller,
    ControllerConfig,
    IoSpace,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Trajectory,
)
from mpi_ros.mpi.base.messages import Message

T = MPIMotionType
M = Message


def test_defaults():
    # issue 3: "sample rate (default 2000 Hz) ... frame buffer size (128)"; MPI 000, mpiMotionStart "With the
    # sample rate configured for 2000 (default)"; README.md, "Configuration": 4 axes, 2 supervisors
    ctl = Controller()
    assert ctl.rate == 2000.0
    assert ctl.config.frame_buffer_size == 128
    assert len(ctl.axes) == 4
    assert ctl.config.supervisor_count == 2
    assert not ctl.config.firmware_option_21


def test_sample_rate_must_be_positive():
    # issue 3: the controller advances in whole samples of a positive rate
    with pytest.raises(ValueError):
        Controller(ControllerConfig(sample_rate=0.0))


def test_create_selects_the_next_unused_supervisor():
    # MPI 000, mpiMotionCreate "If number is -1, MotionCreate selects the next unused motion supervisor"
    ctl = Controller()
    _, a = ctl.create_motion(-1)
    _, b = ctl.create_motion(-1)
    assert (a.number, b.number) == (0, 1)
    assert ctl.create_motion(-1) == (M.MPIMotionMessageMOTION_INVALID, None)  # none left


@pytest.mark.parametrize("number", [-2, 2, 100])
def test_create_out_of_range(number):
    # MPI 000, MPIMotionMessageMOTION_INVALID MOTION_INVALID "if the motion supervisor number is less than zero or
    # greater than or equal to MEIXmpMAX_MSs"; MPI 000, mpiMotionCreate, return values MPIHandleVOID
    assert Controller().create_motion(number) == (M.MPIMotionMessageMOTION_INVALID, None)


def test_create_twice_the_same_number():
    # MPI 000, mpiMotionCreate, return values "MPIHandleVOID if the object could not be created"
    ctl = Controller()
    ctl.create_motion(1)
    assert ctl.create_motion(1) == (M.MPIMotionMessageMOTION_INVALID, None)


def test_validate_after_create_and_delete(ctl, ms):
    # MPI 000, mpiMotionValidate "Always call mpiMotionValidate after creating"; MPI 000, mpiMotionDelete delete
    # "invalidates its handle"; MPI 000, mpiMotionDelete "does not delete any of the Axis objects"
    assert ms.validate().ok
    assert ctl.delete_motion(ms).ok
    assert ms.validate().message is M.MPIMessageHANDLE_INVALID
    assert ctl.supervisor(0) is None
    assert len(ctl.axes) == 4
    assert ctl.delete_motion(ms).message is M.MPIMessageHANDLE_INVALID
    assert ms.start(T.TRAPEZOIDAL).message is M.MPIMessageHANDLE_INVALID
    assert ms.action(MPIAction.STOP).message is M.MPIMessageHANDLE_INVALID
    assert ctl.create_motion(0)[0].ok  # the number is free again


def test_delete_while_moving(ctl, ms, bring):
    # MPI 000, Motion Objects, introduction the supervisor's axis map is not changed while the axes move
    bring(MPIState.MOVING)
    refused = ctl.delete_motion(ms)
    assert refused.message is M.MPIMotionMessageMOVING
    assert refused.detail == "state: supervisor 0 is MOVING (IDLE or ERROR only)"  # why, from where decided
    assert ms.validate().ok


def test_a_command_takes_effect_at_the_next_sample(ctl, ms, params):
    # docs/decisions.md, "Samples, commands and replay": a command is applied at the first sample after
    # the controller's current one and recorded with that sample's index
    ctl.step(17)
    assert ctl.effective_sample == 18
    ms.start(T.TRAPEZOIDAL, params=params((100.0, 0.0)))
    assert ctl.axes[0].cmd_p == 0.0
    ctl.step(1)
    assert ctl.axes[0].cmd_p == pytest.approx(0.5 * 10_000.0 * (1 / 2000.0) ** 2)
    assert ctl.time == 18 / 2000.0


def test_step_counts_samples(ctl):
    # docs/decisions.md, "Samples, commands and replay": the controller advances in whole samples
    ctl.step(0)
    assert ctl.sample == 0
    ctl.step(12_345)
    assert ctl.sample == 12_345
    with pytest.raises(ValueError):
        ctl.step(-1)


def test_run_until(ctl, ms, params):
    # issue 3 "Stepping API for tests and tools: step N samples, run until a condition"
    ms.start(T.TRAPEZOIDAL, params=params((100.0, 0.0)))
    assert ctl.run_until(lambda c: c.axes[0].cmd_p >= 50.0, 10_000)
    assert ctl.axes[0].cmd_p >= 50.0
    k = ctl.sample
    assert not ctl.run_until(lambda c: False, 250, chunk=100)
    assert ctl.sample == k + 250  # stops exactly at the limit


def test_a_long_move_simulates_far_faster_than_real_time(ctl, ms, params):
    # issue 3: "a fast path that advances many samples at once (vectorised over time) so long moves
    # simulate far faster than real time": ten simulated minutes in one call
    ms.start(T.TRAPEZOIDAL, params=params((600_000.0, 0.0)))
    started = time.perf_counter()
    ctl.step(600 * 2000)
    assert time.perf_counter() - started < 60.0  # 10x real time at the very least (measured: ~100x more)
    assert ctl.axes[0].command_position == pytest.approx(599_950.0)


def test_gates_and_io(ctl):
    # MPI 000, MEIMotionAttrHoldTypeGATE meiControlGateGet/Set; io.py: the simulated I/O image
    assert ctl.gate_set(3, True).ok
    assert ctl.gate_get(3) == (M.MPIMessageOK, True)
    assert ctl.gate_get(32)[0] is M.MPIMessagePARAM_INVALID
    assert ctl.io_set(IoSpace.MOTOR_DEDICATED_IO, 3, 0b101).ok
    assert ctl.io_get(IoSpace.MOTOR_DEDICATED_IO, 3) == (M.MPIMessageOK, 0b101)
    assert ctl.io_set(IoSpace.IO, 1, 0b111, mask=0b010).ok
    assert ctl.io_get(IoSpace.IO, 1) == (M.MPIMessageOK, 0b010)


def test_supervisors_are_listed_by_number(ctl):
    # MPI 000, mpiMotionNumber mpiMotionNumber: the index of a Motion object
    _, b = ctl.create_motion(1)
    _, _a = ctl.create_motion(0)
    assert [s.number for s in ctl.supervisors] == [0, 1]
    assert ctl.supervisor(1) is b


def test_drain_events_empties_the_queue(ctl, ms, params):
    # docs/decisions.md, "Samples, commands and replay": each event reaches a listener once
    ms.start(T.TRAPEZOIDAL, params=params((100.0, 0.0)))
    assert ctl.drain_events()
    assert ctl.drain_events() == []


def test_events_not_drained_are_bounded_the_oldest_going_first(ctl, ms, params, monkeypatch):
    # A suite gives every event to its listeners and never drains: the queue keeps the latest.
    from mpi_ros.mpi import control

    assert ctl.events.maxlen == control.EVENTS_KEPT
    monkeypatch.setattr(control, "EVENTS_KEPT", 3)
    bounded = control.Controller()
    heard = []
    bounded.listeners.append(heard.append)
    for n in range(5):
        bounded.emit(control.MPIEventType.MOTION_DONE, sample=n)
    assert [e.sample for e in bounded.events] == [2, 3, 4]
    assert [e.sample for e in heard] == [0, 1, 2, 3, 4]


def test_motion_snapshot(ctl, ms, params, run_to):
    # MPI 000, mpiMotionStatus mpiMotionStatus "gets a Motion's status"
    ms.start(T.S_CURVE, params=params((1000.0, 0.0), jerk_percent=20.0))
    ctl.step(1000)
    snap = ms.snapshot()
    assert snap.state is MPIState.MOVING
    assert snap.axis_numbers == (0, 1)
    assert snap.motion_type == "S_CURVE"
    assert not snap.done
    assert 0.0 < snap.progress < 1.0
    assert snap.feedrate == 1.0
    run_to(ctl, ms, MPIState.IDLE, 10_000, chunk=100)
    snap = ms.snapshot()
    assert snap.done
    assert snap.at_target
    assert snap.progress == 1.0


def test_settling_at_rest_does_not_depend_on_how_samples_are_batched():
    # docs/decisions.md, "Samples, commands and replay" (replay is exact): the loop settling onto a resting
    # command (where the servo model counts it as settled exactly) must fall on the same sample
    # whether the controller steps one sample at a time or in large batches.
    from mpi_ros.mpi import MotionParams, MPIAction, MPIMotionType, Trajectory

    def run(batches):
        ctl = Controller()
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        ms.start(MPIMotionType.S_CURVE, params=MotionParams(
            trajectory=[Trajectory(2000.0, 20000.0, 20000.0, 50.0)], position=[700.0, -300.0]))
        script = {400: MPIAction.E_STOP, 1000: MPIAction.RESET}  # RESET leaves the axes at rest
        seen = []
        batch = iter(batches)
        while ctl.sample < 12_000:
            if ctl.sample in script:
                ms.action(script[ctl.sample])
            upcoming = min([k for k in script if k > ctl.sample] + [12_000])
            ctl.step(min(next(batch), upcoming - ctl.sample))
            seen.append((ctl.sample, [(a.act_p, a.act_v, a.cmd_p) for a in ctl.axes]))
        return {sample: values for sample, values in seen}

    one_by_one = run(iter(lambda: 1, None))
    rng = np.random.default_rng(3)
    lumpy = run(iter(lambda: int(rng.integers(1, 400)), None))
    different = [s for s, values in lumpy.items() if one_by_one[s] != values]
    assert not different, f"{len(different)} samples differ, first {different[:3]}"


def test_axis_snapshots_read_together_are_each_axis_own_values():
    # MPI 002, mpiAxisStatus: the snapshots read from the arrays at once (axis_snapshots) hold
    # what each axis reports on its own, moving, with an origin, with its amplifier off (ABORT:
    # no servo effort) and unmapped (no supervisor: IDLE, no frames)
    ctl = Controller(ControllerConfig(axis_count=5, supervisor_count=2))
    _, first = ctl.create_motion(0)
    first.axis_list_set([0, 1])
    _, second = ctl.create_motion(1)
    second.axis_list_set([3])
    ctl.axes[1].origin = 12.5
    first.start(T.S_CURVE, params=MotionParams(trajectory=[Trajectory(4000.0, 40000.0, 40000.0, 50.0)],
                                               position=[1234.5, -20.0]))
    second.start(T.VELOCITY, params=MotionParams(trajectory=[Trajectory(-700.0, 9000.0, 9000.0, 0.0)]))
    seen = set()
    for step in range(40):
        ctl.step(29)
        if step == 20:
            second.action(MPIAction.ABORT)
        together = ctl.axis_snapshots()
        assert ctl.axis_snapshots([3, 1]) == [together[3], together[1]]
        for axis, snap in zip(ctl.axes, together, strict=True):
            owner = ctl.supervisor(axis.owner)
            assert (snap.number, snap.sample, snap.supervisor) == (axis.number, ctl.sample, axis.owner)
            assert snap.state is (owner.own_state if owner is not None else MPIState.IDLE)
            assert (snap.command_position, snap.actual_position, snap.position_error) == (
                axis.command_position, axis.actual_position, axis.position_error)
            assert (snap.command_velocity, snap.actual_velocity, snap.command_acceleration) == (
                axis.cmd_v, axis.act_v, axis.cmd_a)
            assert (snap.done, snap.settled, snap.at_velocity) == (
                axis.status.done, axis.status.settled, axis.status.at_velocity)
            assert (snap.servo_effort, snap.feedforward, snap.element_id, snap.frame_count, snap.amp_enabled) == (
                axis.servo_effort(), axis.feedforward, axis.current_element_id, ctl.frame_count(axis.number),
                axis.amp_enabled)
            seen.add((snap.state, snap.amp_enabled, snap.servo_effort != 0.0))
    assert (MPIState.IDLE, True, False) in seen  # the unmapped axes
    assert (MPIState.MOVING, True, True) in seen
    assert (MPIState.ERROR, False, False) in seen  # axis 3 after ABORT
