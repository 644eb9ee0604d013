"""The controller's 32-bit positions (mpi_ros/mpi/base/wrap.py; docs/paths.md, "The controller's 32-bit positions").

MPI 000, MPIMotionType, Example: 2^31 + 10 and 2^31 + 10 - 2^32 are "the same value" to the
controller, which keeps positions in 32 bits; "from the MPI's point of view, they are 2^32
apart". What the controller reports wraps into [-2^31, 2^31); the motion runs on across the wrap.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from mpi_ros.mpi import Controller, MotionParams, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.params import MAX_POSITION
from mpi_ros.mpi.base.types import MotionAttr
from mpi_ros.mpi.base.wrap import HALF, WRAP, turn_offset, wrap_position, wrap_positions

from ..conftest import make_params, run_to_state

T = MPIMotionType


@given(st.floats(-MAX_POSITION * 4, MAX_POSITION * 4))
def test_a_wrapped_position_is_in_range_and_congruent(x):
    r = wrap_position(x)
    assert -HALF <= r < HALF
    assert (x - r) % WRAP == 0.0
    assert x - r == turn_offset(x)
    assert wrap_positions(np.array([x]))[0] == r


@pytest.mark.parametrize("x", [0.0, 0.1, -0.1, HALF - 2.0**-22, -HALF, -HALF + 0.1, 123456.789])
def test_a_position_in_range_is_returned_exactly(x):
    assert wrap_position(x) == x
    assert turn_offset(x) == 0.0


@pytest.mark.parametrize(("x", "r"), [(HALF, -HALF), (HALF + 10, -HALF + 10), (-HALF - 10, HALF - 10),
                                      (WRAP, 0.0), (3 * WRAP + 0.25, 0.25), (-WRAP - 0.5, -0.5)])
def test_positions_past_the_range_wrap_by_whole_turns(x, r):
    # MPI 000, MPIMotionType, Example: 2147483658 is -2147483638 to the controller
    assert wrap_position(x) == r
    assert wrap_position(2147483658.0) == -2147483638.0


def _velocity_move(start: float, samples: int) -> list:
    """Axis 0 from ``start`` at 100,000 counts/s (50 counts a sample): its status every sample."""
    ctl = Controller()
    ms = ctl.create_motion(0)[1]
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    assert ctl.axis_command_position_set(0, start).ok
    assert ctl.axis_actual_position_set(0, start).ok
    assert ms.start(T.VELOCITY, params=make_params(velocity=100_000.0, acceleration=1e6)).ok
    ctl.step(200)  # at speed after 0.1 s
    snaps = []
    for _ in range(samples):
        ctl.step(1)
        snaps.append(ctl.axis_snapshot(0))
    _, actual, command = ms.position_get()  # mpiMotionPositionGet: the same 32-bit values
    assert command[0] == snaps[-1].command_position
    assert actual[0] == snaps[-1].actual_position
    return snaps


def test_a_velocity_move_crossing_the_wrap_reports_wrapped_positions_without_a_velocity_jump():
    # Across 2^31 after about 60 samples; the same move across 0 is the reference for the servo
    crossing, plain = _velocity_move(HALF - 13_000.0, 200), _velocity_move(-13_000.0, 200)
    before, wraps = crossing[0], 0
    for now, twin in zip(crossing[1:], plain[1:], strict=True):
        for value in (now.command_position, now.actual_position):
            assert -HALF <= value < HALF
        step = now.command_position - before.command_position
        if step < 0:  # the reported position wrapped: by exactly one turn
            wraps += 1
            step += WRAP
        assert step == pytest.approx(50.0, abs=1e-6)  # 100,000 counts/s at 2 kHz, every sample
        assert now.command_velocity == 100_000.0
        # the servo sees no jump: velocity and following error as in the move that does not wrap
        assert now.actual_velocity == pytest.approx(twin.actual_velocity, abs=1e-3)
        assert now.position_error == pytest.approx(twin.position_error, abs=1e-3)
        before = now
    assert wraps == 1
    assert before.command_position == pytest.approx(-HALF + 2000.0, abs=1e-6)
    assert math.isnan(before.target_position)  # a velocity move has no target


def test_a_point_to_point_target_past_the_wrap_moves_on_and_settles_there(ctl, ms):
    # "the same value" to the controller: the target 2^31 + 1000 is reported as -2^31 + 1000
    start = HALF - 1000.0
    assert ctl.axis_command_position_set(0, start).ok
    assert ctl.axis_actual_position_set(0, start).ok
    assert ms.start(T.S_CURVE, params=make_params((HALF + 1000.0, 0.0), velocity=10_000.0,
                                                  acceleration=100_000.0, jerk_percent=50.0)).ok
    ctl.step(1)
    assert ctl.axis_snapshot(0).target_position == -HALF + 1000.0
    peak = 0.0
    while ms.state is MPIState.MOVING and ctl.sample < 20_000:
        ctl.step(1)
        peak = max(peak, abs(ctl.axes[0].cmd_v))
    assert ms.state is MPIState.IDLE
    assert peak <= 10_000.0 * (1 + 1e-9)
    snap = ctl.axis_snapshot(0)
    assert snap.command_position == -HALF + 1000.0
    assert abs(snap.actual_position - (-HALF + 1000.0)) < 10.0
    assert snap.done
    assert snap.settled
    assert snap.in_fine_position
    assert snap.at_target
    end = ctl.move_log.recent(ms.number)[-1]
    assert end.message.ok
    assert end.command_position[0] == -HALF + 1000.0


def test_an_absolute_target_is_read_in_the_turn_the_axis_is_in(ctl, ms):
    # After the wrap the axis reports -2^31 + 1000. The distance of a move is its target minus
    # the reported position: -2^31 + 3000 is 2000 counts ahead, -2^31 + 1000 2000 back, and
    # 2^31 - 1000 (where the axis started) 2^32 - 2000 ahead, not the short way back: only a
    # path's first point is taken the short way (MPI 000, MPIMotionType, Example, NOTE).
    assert ctl.axis_command_position_set(0, HALF - 1000.0).ok
    assert ctl.axis_actual_position_set(0, HALF - 1000.0).ok
    trajectory = dict(velocity=10_000.0, acceleration=100_000.0)
    assert ms.start(T.TRAPEZOIDAL, params=make_params((HALF + 1000.0, 0.0), **trajectory)).ok
    run_to_state(ctl, ms, MPIState.IDLE, 20_000)
    for target, travel in ((-HALF + 3000.0, 2000.0), (-HALF + 1000.0, -2000.0)):
        before = ctl.axes[0].unwrapped_command
        assert ms.start(T.TRAPEZOIDAL, params=make_params((target, 0.0), **trajectory)).ok
        run_to_state(ctl, ms, MPIState.IDLE, 20_000)
        assert ctl.axes[0].unwrapped_command - before == pytest.approx(travel, abs=1e-6)
        assert ctl.axes[0].command_position == target
    before = ctl.axes[0].unwrapped_command
    # (fast: at 10,000 counts/s its frame would pass the 16,384,000-sample limit)
    assert ms.start(T.TRAPEZOIDAL, params=make_params((HALF - 1000.0, 0.0), velocity=1e8, acceleration=1e9)).ok
    ctl.step(1)
    assert ctl.axes[0].target - ctl.axes[0].origin - before == WRAP - 2000.0
    assert ctl.axis_snapshot(0).target_position == HALF - 1000.0
    assert ctl.axes[0].cmd_v > 0.0


def test_a_relative_move_across_the_wrap(ctl, ms):
    assert ctl.axis_command_position_set(0, -HALF + 100.0).ok
    assert ctl.axis_actual_position_set(0, -HALF + 100.0).ok
    assert ms.start(T.TRAPEZOIDAL, MotionAttr.RELATIVE, make_params((-300.0, 0.0))).ok
    run_to_state(ctl, ms, MPIState.IDLE, 20_000)
    assert ctl.axes[0].command_position == HALF - 200.0  # 300 counts back, across -2^31
    assert ctl.axis_snapshot(0).done


@pytest.mark.parametrize(("given_", "reported"), [(HALF - 1.0, HALF - 1.0), (-HALF, -HALF), (HALF, -HALF),
                                                  (HALF + 0.5, -HALF + 0.5), (-HALF - 1.0, HALF - 1.0)])
def test_a_position_set_near_the_wrap_reads_back_as_the_controller_holds_it(ctl, ms, given_, reported):
    # 002 mpiAxisCommandPositionSet / mpiAxisActualPositionSet: the controller holds 32 bits
    assert ctl.axis_command_position_set(0, given_).ok
    assert ctl.axis_actual_position_set(0, given_).ok
    ctl.step(10)
    snap = ctl.axis_snapshot(0)
    assert snap.command_position == reported
    assert snap.actual_position == reported
    assert snap.target_position == reported
    assert snap.position_error == 0.0
    # a move from there: a small distance, whichever way the value was given
    assert ms.start(T.TRAPEZOIDAL, params=make_params((reported + 100.0, 0.0))).ok
    run_to_state(ctl, ms, MPIState.IDLE, 20_000)
    assert ctl.axes[0].unwrapped_command - given_ == pytest.approx(100.0, abs=1e-6)


def test_the_origin_shifts_the_32_bit_window(ctl, ms):
    # reported = raw - origin, in 32 bits: an origin of -200 brings raw 2^31 - 150 to -2^31 + 50
    assert ctl.axis_command_position_set(0, HALF - 150.0).ok
    assert ctl.axis_actual_position_set(0, HALF - 150.0).ok
    assert ctl.axis_origin_set(0, -200.0).ok
    ctl.step(1)
    snap = ctl.axis_snapshot(0)
    assert snap.command_position == snap.actual_position == -HALF + 50.0
    assert snap.origin == -200.0
    assert ms.start(T.TRAPEZOIDAL, params=make_params((-HALF + 150.0, 0.0))).ok  # 100 counts ahead
    run_to_state(ctl, ms, MPIState.IDLE, 20_000)
    assert ctl.axes[0].cmd_p == pytest.approx(HALF - 150.0 + 100.0, abs=1e-6)


def test_the_motion_log_reports_32_bit_positions(ctl, ms):
    # meiMotionLogOpen: command and actual positions per sample, as the controller reports them
    assert ctl.axis_command_position_set(0, HALF - 100.0).ok
    assert ctl.axis_actual_position_set(0, HALF - 100.0).ok
    assert ms.log_open(10_000).ok
    assert ms.start(T.TRAPEZOIDAL, params=make_params((HALF + 100.0, 0.0))).ok
    run_to_state(ctl, ms, MPIState.IDLE, 20_000)
    columns = np.vstack(ms.log.columns)
    positions = columns[:, :2]  # axis 0: command, actual
    assert ((positions >= -HALF) & (positions < HALF)).all()
    assert positions[0, 0] == pytest.approx(HALF - 100.0, abs=0.01)
    assert positions[-1, 0] == -HALF + 100.0


def test_a_path_after_the_wrap_takes_its_first_point_the_short_way_in_either_turn(ctl, ms):
    # MPI 000, MPIMotionType, Example: "With the shortest path algorithm, -2147483638 is converted to
    # 2147483658": the first point, given in the reported (32-bit) value or in the MPI's continuous
    # one, is taken the short way from where the axis is; the later points keep their distances
    assert ctl.axis_command_position_set(0, HALF - 100.0).ok
    assert ctl.axis_actual_position_set(0, HALF - 100.0).ok
    assert ms.start(T.TRAPEZOIDAL, params=make_params((HALF + 100.0, 0.0))).ok
    run_to_state(ctl, ms, MPIState.IDLE, 20_000)
    assert ctl.axes[0].command_position == -HALF + 100.0
    for first in (-HALF + 150.0, HALF + 150.0, -HALF + 150.0 + 2 * WRAP):
        before = ctl.axes[0].unwrapped_command
        points = MotionParams(position=[first, 0.0, first + 50.0, 0.0], time=[0.05, 0.05])
        assert ms.start(T.PT, MotionAttr.NONE, points).ok
        peak = 0.0
        while ms.state is not MPIState.IDLE and ctl.sample < 100_000:
            ctl.step(1)
            peak = max(peak, abs(ctl.axes[0].cmd_v))
        assert ctl.axes[0].unwrapped_command - before == pytest.approx(100.0, abs=1e-6)
        assert peak == pytest.approx(1000.0, rel=1e-9)  # 50 counts in 0.05 s: no 2^32 jump anywhere
        assert ctl.axes[0].command_position == wrap_position(first + 50.0)
        assert ms.start(T.TRAPEZOIDAL, params=make_params((-HALF + 100.0, 0.0))).ok  # back for the next
        run_to_state(ctl, ms, MPIState.IDLE, 20_000)
