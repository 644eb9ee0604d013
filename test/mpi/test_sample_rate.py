"""A controller at 4 kHz keeps the semantics it has at its default 2 kHz (issue 35).

The MPI counts time in samples (MPI 000, MPIControlConfig sampleRate; MPI 002's settling
time is in seconds, converted to samples): the same move in counts and seconds must take
the same time in seconds at either rate, its command must follow the same profile, its
settling must last the same time (twice the samples), and the result must not depend on
how the samples are batched.
"""

from __future__ import annotations

import math

import pytest

from mpi_ros.mpi import (
    Controller,
    ControllerConfig,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIEventType,
    MPIMotionType,
    MPIState,
    Trajectory,
)
from mpi_ros.mpi.axes.status import settle_samples

SECONDS = 1.5  # the move takes about 0.9 s and settles well before this


def _controller(rate: float) -> Controller:
    ctl = Controller(ControllerConfig(sample_rate=rate))
    assert ctl.rate == rate
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    return ctl


def _move(ctl: Controller) -> None:
    ms = ctl.supervisor(0)
    assert ms is not None
    params = MotionParams(trajectory=[Trajectory(5000.0, 20000.0, 20000.0, 50.0)], position=[3000.0, -1000.0])
    assert ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE, params).ok


def _run(rate: float, batch: int) -> tuple[dict[float, list[float]], list[tuple[float, str]]]:
    """Every axis' command position at each 10 ms, and the events with their time in seconds."""
    ctl = _controller(rate)
    _move(ctl)
    every = int(rate / 100)
    positions = {}
    while ctl.sample < SECONDS * rate:
        target = min(ctl.sample + every, int(SECONDS * rate))
        while ctl.sample < target:
            ctl.step(min(batch, target - ctl.sample))
        positions[round(ctl.sample / rate, 6)] = [a.cmd_p for a in ctl.axes[:2]]
    events = [(e.sample / rate, e.type_name) for e in ctl.drain_events()]
    return positions, events


def test_the_same_move_follows_the_same_profile_at_4_khz():
    slow, slow_events = _run(2000.0, 4096)
    fast, fast_events = _run(4000.0, 4096)
    assert slow.keys() == fast.keys()
    for t, values in slow.items():  # the same profile, read at the same times
        assert fast[t] == pytest.approx(values, abs=1e-6), t
    assert fast[max(fast)] == [3000.0, -1000.0]
    # the same events, each within a sample of the slower rate of the same time
    assert [kind for _, kind in fast_events] == [kind for _, kind in slow_events]
    assert MPIEventType.MOTION_DONE.name in [kind for _, kind in fast_events]
    for (t_fast, _), (t_slow, _) in zip(fast_events, slow_events, strict=True):
        assert abs(t_fast - t_slow) <= 1 / 2000.0


def test_settling_lasts_the_same_time_in_twice_the_samples():
    """A criterion holds for the settling time after its first sample (status.settle_samples)."""
    in_position = _controller(2000.0).axes[0].in_position
    slow, fast = settle_samples(in_position, 2000.0) - 1, settle_samples(in_position, 4000.0) - 1
    assert fast == 2 * slow
    assert math.isclose(fast / 4000.0, in_position.settling_time)


def test_4_khz_does_not_depend_on_batching():
    one_by_one, _ = _run(4000.0, 1)
    batched, _ = _run(4000.0, 4096)
    assert one_by_one == batched


def test_a_stop_at_4_khz_takes_its_time_in_seconds():
    """MPI 000, MPIControlConfig / MPIMotionConfig stopTime: the stop lasts the same time
    in seconds at either rate."""
    stopped_after = {}
    for rate in (2000.0, 4000.0):
        ctl = _controller(rate)
        _move(ctl)
        ctl.step(int(0.3 * rate))
        ms = ctl.supervisor(0)
        assert ms is not None
        started = ctl.sample
        assert ms.action(MPIAction.STOP).ok
        assert ctl.run_until(lambda c, ms=ms: ms.state is MPIState.STOPPED, int(2 * rate))
        stopped_after[rate] = (ctl.sample - started) / rate
    assert abs(stopped_after[4000.0] - stopped_after[2000.0]) <= 1 / 2000.0
