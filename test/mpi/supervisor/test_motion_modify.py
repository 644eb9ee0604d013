"""Modify on the fly (mpi_ros/mpi/supervisor/motion.py, planner.py): from the current position and
velocity (and acceleration for the jerk types), including reversal, for trapezoidal, S-curve,
velocity and vector moves."""

from __future__ import annotations

import numpy as np
import pytest

from mpi_ros.mpi import Controller, ControllerConfig, MotionAttr, MPIAction, MPIMotionType, MPIState, Trajectory
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message

T = MPIMotionType
A = MotionAttr
RATE = 2000.0


def rig(axes=1, **config):
    ctl = Controller(ControllerConfig(axis_count=axes, supervisor_count=1, **config))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set(list(range(axes)))
    ms.log_open(10_000_000)
    return ctl, ms


def finish(ctl, ms):
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 2_000_000, chunk=1000)
    return np.concatenate(ms.log.columns)  # per sample and axis: command, actual, command velocity


def assert_smooth(velocity, accel_limit):
    """No velocity step larger than the acceleration allows over one sample."""
    v = np.concatenate(([0.0], velocity))
    assert np.max(np.abs(np.diff(v))) <= accel_limit / RATE * (1 + 1e-9)


@pytest.mark.parametrize(("kind", "jerk_percent"), [(T.TRAPEZOIDAL, 0.0), (T.S_CURVE, 0.0), (T.S_CURVE, 70.0)])
def test_modify_to_a_farther_target(params, kind, jerk_percent):
    # MPI 000, mpiMotionModify "mpiMotionModify modifies the parameters of a Motion object (motion) if motion is
    # in progress"; the motion continues from where it is to the new target
    ctl, ms = rig()
    ms.start(kind, params=params((1000.0,), jerk_percent=jerk_percent))
    ctl.step(700)
    assert ms.modify(kind, params=params((2500.0,), jerk_percent=jerk_percent)).ok
    log = finish(ctl, ms)
    assert ctl.axes[0].command_position == 2500.0
    assert np.all(np.diff(log[:, 0]) >= 0.0)
    assert_smooth(log[:, 2], 10_000.0 / (1 - jerk_percent / 200.0))
    assert np.max(np.abs(log[:, 2])) <= 1000.0 * (1 + 1e-12)


@pytest.mark.parametrize(("kind", "jerk_percent"), [(T.TRAPEZOIDAL, 0.0), (T.S_CURVE, 50.0)])
def test_modify_to_a_target_behind_reverses(params, kind, jerk_percent):
    # issue 3: "Modify on the fly from the current position, velocity and acceleration (including
    # reversal)"; MPI 000, MPIMotionMessagePROFILE_ERROR (a target "in the reverse direction" is legal without
    # NO_REVERSAL)
    ctl, ms = rig()
    ms.start(kind, params=params((5000.0,), jerk_percent=jerk_percent))
    ctl.step(1000)
    assert ms.modify(kind, params=params((-200.0,), jerk_percent=jerk_percent)).ok
    log = finish(ctl, ms)
    velocity = log[:, 2]
    assert velocity.max() == pytest.approx(1000.0)
    assert velocity.min() == pytest.approx(-1000.0)
    assert_smooth(velocity, 10_000.0 / (1 - jerk_percent / 200.0))
    assert ctl.axes[0].command_position == -200.0


def test_modify_a_target_too_close_to_stop_overshoots_and_comes_back(params):
    # issue 3 "including reversal": the target is ahead but closer than the stopping distance
    ctl, ms = rig()
    ms.start(T.TRAPEZOIDAL, params=params((5000.0,)))
    ctl.step(1000)
    here = ctl.axes[0].command_position
    assert ms.modify(T.TRAPEZOIDAL, params=params((here + 10.0,))).ok
    log = finish(ctl, ms)
    assert log[:, 0].max() == pytest.approx(here + 50.0)  # v^2 / 2D = 50 counts to stop
    assert ctl.axes[0].command_position == here + 10.0
    assert_smooth(log[:, 2], 10_000.0)


def test_modify_lowers_the_velocity_with_the_deceleration(params):
    # MPI 000, MPIMotionSCurve the S-curve/trapezoid uses "velocity, acceleration, deceleration": slowing to a
    # lower velocity limit is a deceleration
    ctl, ms = rig()
    ms.start(T.TRAPEZOIDAL, params=params((10_000.0,), velocity=1000.0))
    ctl.step(1000)
    ms.modify(T.TRAPEZOIDAL, params=params((10_000.0,), velocity=200.0, acceleration=1e4, deceleration=4000.0))
    ctl.step(400)  # 0.2 s at 4000 counts/s^2
    assert ctl.axes[0].cmd_v == pytest.approx(200.0)
    ctl.step(1)
    assert ctl.axes[0].cmd_v == 200.0


def test_s_curve_modify_restarts_the_acceleration_from_zero(params):
    # docs/profiles.md, "Modify: from the current state": a modify of S_CURVE (or TRAPEZOIDAL/VELOCITY)
    # during a ramp restarts from the current position and velocity with zero acceleration (a step in
    # acceleration, as the real firmware does)
    ctl, ms = rig()
    ms.start(T.S_CURVE, params=params((10_000.0,), jerk_percent=50.0))
    ctl.step(100)  # mid-ramp, at the peak acceleration 13333
    assert ctl.axes[0].cmd_a == pytest.approx(10_000.0 / 0.75)
    v = ctl.axes[0].cmd_v
    ms.modify(T.S_CURVE, params=params((10_000.0,), velocity=2000.0, jerk_percent=50.0))
    ctl.step(1)
    assert abs(ctl.axes[0].cmd_a) < 1000.0  # the new ramp starts from a = 0
    assert ctl.axes[0].cmd_v == pytest.approx(v, abs=1.0)  # the velocity is continuous


def test_s_curve_jerk_modify_keeps_the_acceleration(params):
    # docs/profiles.md, "Modify: from the current state": only S_CURVE_JERK / VELOCITY_JERK (firmware
    # option 21) plan from the full state with jerk limits
    ctl, ms = rig(firmware_option_21=True)
    jerk = [Trajectory(1000.0, 10_000.0, 10_000.0, 0.0, 2e5, 2e5)]
    ms.start(T.S_CURVE_JERK, params=params((10_000.0,), trajectory=jerk))
    ctl.step(100)
    a = ctl.axes[0].cmd_a
    assert a > 5000.0
    ms.modify(T.S_CURVE_JERK, params=params((8000.0,), trajectory=jerk))
    ctl.step(1)
    assert abs(ctl.axes[0].cmd_a - a) <= 2e5 / RATE * (1 + 1e-9)  # changed at most by the jerk
    finish(ctl, ms)
    assert ctl.axes[0].command_position == 8000.0


def test_velocity_modify_changes_speed_and_direction(params):
    # MPI 000, mpiMotionModify VELOCITY moves can be modified; MPI 000, MPIMotionVelocity the acceleration is used for
    # every ramp ("deceleration is ignored")
    ctl, ms = rig()
    ms.start(T.VELOCITY, params=params((), velocity=500.0, acceleration=5000.0, deceleration=1.0))
    ctl.step(1000)
    ms.modify(T.VELOCITY, params=params((), velocity=-500.0, acceleration=5000.0, deceleration=1.0))
    ctl.step(400)  # 1000 counts/s of change at 5000 counts/s^2: 0.2 s
    assert ctl.axes[0].cmd_v == pytest.approx(-500.0)
    assert ms.state is MPIState.MOVING


def test_a_velocity_modify_reaches_its_velocity_at_the_end_of_its_own_ramp(params):
    # MPI 000, MPIEventTypeMOTION_AT_VELOCITY and mpiMotionModify: the outcome a goal on a
    # velocity move waits for is decided from the move the command made, at the sample its
    # axes reach the new velocity, never from the earlier velocity the modify replaced.
    ctl, ms = rig()
    ms.start(T.VELOCITY, params=params((), velocity=200.0, acceleration=5000.0))
    ctl.step(200)
    first = ctl.move_log.recent(ms.number)
    assert [(e.message, e.detail) for e in first] == [(Message.MPIMessageOK, "at velocity")]
    modified = ctl.effective_sample
    assert ms.modify(T.VELOCITY, params=params((), velocity=-300.0, acceleration=5000.0)).ok
    ramp = 500.0 / 5000.0 * RATE  # samples from +200 to -300 counts/s
    ctl.step(int(ramp) - 2)
    assert ctl.move_log.recent(ms.number) == first
    assert ctl.axes[0].cmd_v > -300.0
    ctl.step(200)
    (end,) = ctl.move_log.recent(ms.number)[len(first):]
    assert end.message is Message.MPIMessageOK
    assert end.serial == first[0].serial
    assert end.sample >= modified + ramp - 1
    assert ctl.axes[0].cmd_v == pytest.approx(-300.0)
    events = [e for e in ctl.drain_events() if e.type is MPIEventType.MOTION_AT_VELOCITY]
    assert [e.sample for e in events] == [first[0].sample, end.sample]


def test_velocity_modify_to_zero_ends_the_move(params):
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, DONE DONE after the velocity
    # move is over; a velocity of zero ends the motion
    ctl, ms = rig()
    ms.start(T.VELOCITY, params=params((), velocity=500.0))
    ctl.step(500)
    ms.modify(T.VELOCITY, params=params((), velocity=0.0))
    finish(ctl, ms)
    assert ctl.axes[0].cmd_v == 0.0
    assert any(e.type is MPIEventType.MOTION_DONE for e in ctl.drain_events())


def test_point_to_point_modified_into_a_velocity_move(params):
    # MPI 000, mpiMotionModify the modifiable types include both point-to-point and VELOCITY
    ctl, ms = rig()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0,)))
    ctl.step(500)
    assert ms.modify(T.VELOCITY, params=params((), velocity=300.0)).ok
    ctl.step(2000)
    assert ctl.axes[0].cmd_v == 300.0


def test_modify_is_one_move(params):
    # MPI 000, MPIMotionAttrAPPEND MOTION_DONE when "the motion is complete": a modified motion is still one motion
    ctl, ms = rig()
    ms.start(T.TRAPEZOIDAL, params=params((1000.0,)))
    for target in (1200.0, 900.0, 1500.0):
        ctl.step(300)
        assert ms.modify(T.TRAPEZOIDAL, params=params((target,))).ok
    finish(ctl, ms)
    assert len([e for e in ctl.drain_events() if e.type is MPIEventType.MOTION_DONE]) == 1


def test_modify_replaces_the_appended_moves(params):
    # motion.py: "A modify: the move in progress (and anything appended) becomes move"
    ctl, ms = rig()
    ms.start(T.TRAPEZOIDAL, params=params((1000.0,)))
    ms.start(T.TRAPEZOIDAL, A.APPEND, params((2000.0,)))
    ctl.step(100)
    ms.modify(T.TRAPEZOIDAL, params=params((500.0,)))
    assert not ms.queue
    finish(ctl, ms)
    assert ctl.axes[0].command_position == 500.0


def test_vector_modify_along_the_line(params):
    # MPI 000, MPIMotionSCurve one vector trajectory: a modify along the line keeps the axes on it
    ctl, ms = rig(axes=2)
    ms.start(T.S_CURVE, params=params((3000.0, 4000.0), jerk_percent=40.0))
    ctl.step(600)
    ms.modify(T.S_CURVE, params=params((-300.0, -400.0), jerk_percent=40.0))  # back along the line
    log = finish(ctl, ms)
    assert np.max(np.abs(log[:, 0] * 4000.0 - log[:, 3] * 3000.0)) < 1e-6
    assert np.max(np.hypot(log[:, 2], log[:, 5])) <= 1000.0 * (1 + 1e-9)
    assert [a.command_position for a in ms.axes] == [-300.0, -400.0]


def test_vector_modify_off_the_line_stops_then_goes_straight_within_the_vector_limits(params):
    # docs/decisions.md: a vector modify off its line first brings the vector to rest along the
    # line it is on, then moves on a straight line; the vector's limits hold throughout
    ctl, ms = rig(axes=2)
    ms.start(T.TRAPEZOIDAL, params=params((5000.0, 0.0)))
    ctl.step(1000)
    assert ms.modify(T.TRAPEZOIDAL, params=params((0.0, 3000.0))).ok
    log = finish(ctl, ms)
    assert [a.command_position for a in ms.axes] == [0.0, 3000.0]
    assert_smooth(log[:, 2], 10_000.0)
    assert_smooth(log[:, 5], 10_000.0)
    speed = np.hypot(log[:, 2], log[:, 5])
    assert speed.max() <= 1000.0 * (1 + 1e-9)
    stopped = int(np.flatnonzero(speed < 1e-9)[0])  # at rest once, between the two lines
    assert abs(log[stopped, 3]) < 1e-9
    assert log[stopped, 0] > 0.0
    plan = ms.current.plans[0] if ms.current else ms.last_move.plans[0]
    assert "stops along its line" in plan.composite


def test_modify_during_the_resume_ramp(params):
    # docs/decisions.md, "Stopping" (feedrate ramps): the modify plans in profile time from the
    # current state while the feedrate still ramps up after RESUME; the motion stays continuous
    ctl, ms = rig()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0,)))
    ctl.step(1000)
    ms.action(MPIAction.STOP)
    ctl.step(1000)
    ms.action(MPIAction.RESUME)
    ctl.step(250)
    v = ctl.axes[0].cmd_v
    assert ms.modify(T.TRAPEZOIDAL, params=params((0.0,))).ok
    ctl.step(1)
    assert abs(ctl.axes[0].cmd_v - v) < 100.0
    finish(ctl, ms)
    assert ctl.axes[0].command_position == 0.0


def test_modify_answers_stay_put_when_refused(params):
    # MPI 000, MPIMotionMessageIDLE modify in IDLE answers IDLE and nothing starts
    ctl, ms = rig()
    assert ms.modify(T.TRAPEZOIDAL, params=params((100.0,))).message is Message.MPIMotionMessageIDLE
    ctl.step(1000)
    assert ctl.axes[0].cmd_p == 0.0
