"""Axis status bits (mpi_ros/mpi/axes/status.py) exactly as the two tables at the end of MPI 002
(MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events) with NOTE 1-3
(MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events) say,
settleOnStop/settleOnEstop (MPI 002, MPIAxisInPosition, settleOnStop, MPI 002, Configuration of
IN_POSITION and DONE Events after STOP or E-STOP Events) and settleOnEstopCmdEqAct (MPI 002,
MPIAxisInPosition, settleOnEstopCmdEqAct).

The tests step one sample at a time and recompute each bit from its definition (the
criteria and how many consecutive samples they held), next to the controller's answer.
A slow servo (5 Hz, no feed-forward) makes the actual position lag by tens of counts, so
settling takes real time and the tolerances matter.
"""

from __future__ import annotations

import math

import pytest

from mpi_ros.mpi import (
    AxisInPosition,
    Controller,
    ControllerConfig,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    PlantConfig,
    Trajectory,
)
from mpi_ros.mpi.base.events import MPIEventType

RATE = 2000.0
SLOW = PlantConfig(bandwidth_hz=5.0, damping=0.9, velocity_feedforward=0.0)
V, ACC = 1000.0, 10_000.0


def rig(in_position: AxisInPosition, plant: PlantConfig = SLOW):
    ctl = Controller(ControllerConfig(axis_count=1, supervisor_count=1), in_position=in_position, plant=plant)
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0]).ok
    assert ms.action(MPIAction.MAP).ok
    return ctl, ms, ctl.axes[0]


def trapezoid(position: float) -> MotionParams:
    return MotionParams(trajectory=[Trajectory(V, ACC, ACC, 0.0)], position=[position])


def duration(distance: float) -> float:
    """Trapezoid duration with a cruise (distance >= V^2/ACC)."""
    return distance / V + V / ACC


def held_for(settling_time: float) -> int:
    """Samples after the first at which a criterion that keeps holding sets its bit."""
    return math.ceil(settling_time * RATE - 1e-9)


class Run:
    """Counts consecutive samples a criterion holds."""

    def __init__(self):
        self.count = 0

    def update(self, criterion: bool) -> int:
        self.count = self.count + 1 if criterion else 0
        return self.count


def test_bits_after_a_point_to_point_move_follow_note_3():
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, IN_FINE_POSITION (settleOn*
    # FALSE table, column "After S-curve or Trapezoidal Move"):
    # IN_FINE_POSITION per note 3, IN_COARSE_POSITION "Based on target distance", AT_TARGET "TRUE
    # when command = target", DONE "TRUE if both TC and IN_FINE_POSITION are true".
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events NOTE 3: TC, |target - actual| <
    # fine, |command velocity - actual velocity| < velocity tolerance, "satisfied for a duration specified by the
    # settling time parameter".
    tol = AxisInPosition(position_fine=5.0, position_coarse=200, velocity=50.0, settling_time=0.02)
    ctl, ms, axis = rig(tol)
    target, k0 = 2000.0, ctl.sample
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(target)).ok
    fine, seen = Run(), set()
    for _ in range(int(duration(target) * RATE) + 3000):
        ctl.step(1)
        tc = (ctl.sample - k0) / RATE >= duration(target) - 1e-12  # NOTE 2: every frame executed
        distance = abs(target - axis.actual_position)
        crit = tc and distance < tol.position_fine and abs(axis.cmd_v - axis.act_v) < tol.velocity
        in_fine = fine.update(crit) > held_for(tol.settling_time)
        bits = axis.status
        assert bits.in_fine_position == in_fine
        assert bits.in_coarse_position == (distance < tol.position_coarse)
        assert bits.at_target == (axis.command_position == target) == tc
        assert bits.done == (tc and in_fine)
        seen.add((tc, in_fine, bits.in_coarse_position))
    # every phase happened: moving far, coarse but not fine, TC without fine yet, done
    assert {(False, False, False), (False, False, True), (True, False, True), (True, True, True)} <= seen
    assert ms.state is MPIState.IDLE


def test_velocity_tolerance_delays_in_fine_position():
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events "|command velocity - actual
    # velocity| < velocity tolerance"; MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events
    # "the default setting for velocity tolerance so large that this criteria is ignored"
    def fine_sample(velocity_tolerance):
        ctl, ms, axis = rig(AxisInPosition(position_fine=30.0, velocity=velocity_tolerance, settling_time=0.0))
        ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(1000.0))
        ctl.step(int(duration(1000.0) * RATE))  # to the end of the move, where the bits can change
        assert ctl.run_until(lambda c: axis.status.in_fine_position, 20_000)
        return ctl.sample, abs(axis.cmd_v - axis.act_v)

    loose, _ = fine_sample(AxisInPosition().velocity)
    tight, residual = fine_sample(1.0)
    assert tight > loose
    assert residual < 1.0


def test_settling_time_zero_sets_in_fine_at_the_first_sample():
    # MPI 002, MPIAxisInPosition, settlingTime settlingTime "Duration in seconds that an axis must satisfy the
    # positionFine and/or velocity tolerance, before the respective status flag is set"
    def first(settling_time):
        ctl, ms, axis = rig(AxisInPosition(position_fine=5.0, settling_time=settling_time))
        ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(1000.0))
        ctl.step(int(duration(1000.0) * RATE))  # to the end of the move, where the bits can change
        assert ctl.run_until(lambda c: axis.status.in_fine_position, 20_000)
        return ctl.sample

    assert first(0.05) - first(0.0) == held_for(0.05)


def test_bits_during_a_velocity_move_are_false():
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, IN_FINE_POSITION column "During
    # Velocity Move": IN_FINE_POSITION, IN_COARSE_POSITION, AT_TARGET and DONE are FALSE
    ctl, ms, axis = rig(AxisInPosition(position_coarse=10**9))
    ms.start(MPIMotionType.VELOCITY, params=MotionParams(trajectory=[Trajectory(500.0, 5000.0)]))
    for _ in range(60):
        ctl.step(50)
        bits = axis.status
        assert not (bits.in_fine_position)
        assert not (bits.in_coarse_position)
        assert not (bits.at_target)
        assert not (bits.done)
    assert axis.status.at_velocity


def test_at_velocity_after_the_ramp_within_tolerance_for_the_settling_time():
    # MPI 002, MPIAxisInPosition, velocity velocity tolerance: "from the final move velocity at which the controller
    # sets the at velocity status flag"; MPI 002, MPIAxisInPosition, settlingTime held for the settling time
    tol = AxisInPosition(velocity=20.0, settling_time=0.01)
    ctl, ms, axis = rig(tol)
    k0 = ctl.sample
    ms.start(MPIMotionType.VELOCITY, params=MotionParams(trajectory=[Trajectory(500.0, 5000.0)]))
    ramp_end = 500.0 / 5000.0
    run = Run()
    for _ in range(4000):
        ctl.step(1)
        crit = (ctl.sample - k0) / RATE >= ramp_end - 1e-12 and abs(axis.cmd_v - axis.act_v) < tol.velocity
        assert axis.status.at_velocity == (run.update(crit) > held_for(tol.settling_time))
    assert axis.status.at_velocity


def stop_then_watch(action, tol, samples=3000):
    ctl, ms, axis = rig(tol)
    ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(50_000.0))
    ctl.step(1000)
    assert ms.action(action).ok
    rows = []
    for _ in range(samples):
        ctl.step(1)
        rows.append((ctl.sample, ms.state, axis.cmd_v, axis.command_position, axis.actual_position,
                     axis.act_v, axis.status))
    return ctl, ms, axis, rows


@pytest.mark.parametrize("action", [MPIAction.STOP, MPIAction.E_STOP])
def test_after_stop_without_settle_done_is_command_velocity_zero(action):
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, IN_FINE_POSITION
    # (settleOnStop/settleOnEstop = FALSE, column "After STOP (E-STOP)"):
    # IN_FINE_POSITION FALSE, IN_COARSE_POSITION FALSE, AT_TARGET FALSE, DONE "TRUE when command
    # velocity = 0"; MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events "DONE to be based
    # solely on command velocity"
    _, _, _, rows = stop_then_watch(action, AxisInPosition(position_fine=5.0, position_coarse=10**9))
    for _, _, cmd_v, _, _, _, bits in rows:
        assert not (bits.in_fine_position)
        assert not (bits.in_coarse_position)
        assert not (bits.at_target)
        assert bits.done == (cmd_v == 0.0)
    assert rows[-1][-1].done


@pytest.mark.parametrize(("action", "flag"),
                         [(MPIAction.STOP, "settle_on_stop"), (MPIAction.E_STOP, "settle_on_estop")])
def test_after_stop_with_settle_in_fine_follows_note_1(action, flag):
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, IN_FINE_POSITION (settleOn* =
    # TRUE, "After STOP (E-STOP)"): IN_FINE_POSITION "Based on position error (see note 1)", DONE "Same as
    # IN_FINE_POSITION", IN_COARSE/AT_TARGET FALSE.
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events NOTE 1: trajectory complete,
    # |command - actual| < fine, |target velocity - actual velocity| < velocity tolerance, held for the settling time.
    tol = AxisInPosition(position_fine=5.0, velocity=20.0, settling_time=0.02, **{flag: True})
    _, _, _, rows = stop_then_watch(action, tol)
    run = Run()
    for _, _, cmd_v, cmd_p, act_p, act_v, bits in rows:
        crit = cmd_v == 0.0 and abs(cmd_p - act_p) < tol.position_fine and abs(0.0 - act_v) < tol.velocity
        in_fine = run.update(crit) > held_for(tol.settling_time)
        assert bits.in_fine_position == in_fine
        assert bits.done == in_fine
        assert not (bits.in_coarse_position)
        assert not (bits.at_target)
    assert rows[-1][-1].done


@pytest.mark.parametrize(("action", "flag", "state", "decel"), [
    (MPIAction.STOP, "settle_on_stop", MPIState.STOPPED, 0.5),
    (MPIAction.E_STOP, "settle_on_estop", MPIState.ERROR, 0.05),
])
def test_settle_on_stop_keeps_the_state_until_settled(action, flag, state, decel):
    # MPI 002, MPIAxisInPosition, settleOnStop settleOnStop: "the axis will stay in an MPIStateSTOPPING state until: 1.
    # The settling criteria are satisfied AND 2. The stop duration ... has elapsed"; "If settleOnStop
    # = FALSE, the axis will stay in an MPIStateSTOPPING state only until the stop duration"
    # MPI 002, MPIAxisInPosition, settleOnEstop the same for settleOnEstop and MPIStateSTOPPING_ERROR
    def arrival(settle):
        tol = AxisInPosition(position_fine=2.0, settling_time=0.02, **{flag: settle})
        _, _ms, _, rows = stop_then_watch(action, tol, samples=1600)
        first = next(i for i, row in enumerate(rows) if row[1] is state)
        return rows[first][0] - rows[0][0] + 1, rows[first][-1]

    without, _ = arrival(False)
    with_settle, bits = arrival(True)
    assert without == round(decel * RATE)
    assert with_settle > without
    assert bits.done
    assert bits.in_fine_position


def test_after_abort_only_done_is_true():
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, IN_FINE_POSITION and MPI 002,
    # Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, IN_FINE_POSITION, column "After ABORT":
    # IN_FINE_POSITION, IN_COARSE_POSITION, AT_TARGET FALSE; DONE TRUE (with either settle setting)
    for settle in (False, True):
        tol = AxisInPosition(position_coarse=10**9, settle_on_stop=settle, settle_on_estop=settle)
        _, _ms, _, rows = stop_then_watch(MPIAction.ABORT, tol, samples=2000)
        for row in rows:
            bits = row[-1]
            assert bits.done
            assert not (bits.in_fine_position)
            assert not (bits.in_coarse_position)
            assert not (bits.at_target)
        assert not bits.settled  # the motor coasts, nothing holds it on the command


def test_settle_on_estop_cmd_eq_act_command_follows_previous_actual():
    # MPI 002, MPIAxisInPosition, settleOnEstopCmdEqAct settleOnEstopCmdEqAct: "During an Estop, Cmd Eq Act action, the
    # command position is set equal to the actual position from the previous servo sample"; MPI 002, MPIAxisInPosition
    # "for the amount of time that the Axis' Motion Supervisor Estop time"; MPI 002, MPIAxisInPosition "After the Estop
    # time elapses, the axis' motors will disable the amplifiers."
    ctl, ms, axis = rig(AxisInPosition(settle_on_estop_cmd_eq_act=True))
    ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(50_000.0))
    ctl.step(1000)
    k = ctl.sample
    previous = axis.actual_position
    assert ms.action(MPIAction.E_STOP).ok
    for _ in range(99):
        ctl.step(1)
        assert ms.state is MPIState.STOPPING_ERROR
        assert axis.command_position == previous
        assert axis.amp_enabled
        previous = axis.actual_position
    ctl.step(1)
    assert ms.state is MPIState.ERROR
    assert ctl.sample == k + 100
    assert not axis.amp_enabled


def test_without_cmd_eq_act_e_stop_ramps_the_command():
    # MPI 002, MPIAxisInPosition, settleOnEstopCmdEqAct "During normal motion, there is no difference" / E_STOP
    # otherwise decelerates the command (MPI 000, MPIActionE_STOP): the command does not copy the actual position
    ctl, ms, axis = rig(AxisInPosition())
    ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(50_000.0))
    ctl.step(1000)
    ms.action(MPIAction.E_STOP)
    previous = axis.actual_position
    ctl.step(1)
    assert axis.command_position != previous
    assert ctl.run_until(lambda c: ms.state is MPIState.ERROR, 200)
    assert axis.amp_enabled


def test_settled_event_when_the_axis_rests_on_its_command():
    # MPI 002, MPIAxisInPosition, positionFine positionFine is "used as part of the Axis settling criteria to determine
    # ...
    # when MPIEventTypeMOTION_DONE and MEIEventTypeSETTLED events are generated"
    ctl, ms, axis = rig(AxisInPosition(position_fine=5.0, settling_time=0.01))
    ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(1000.0))
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000)
    events = ctl.drain_events()
    settled = [e for e in events if e.type is MPIEventType.SETTLED and e.axis == 0]
    done = [e for e in events if e.type is MPIEventType.MOTION_DONE]
    assert len(settled) == 1
    assert len(done) == 1
    assert settled[0].sample <= done[0].sample
    assert axis.status.settled
    assert abs(axis.position_error) < 5.0


def test_coarse_tolerance_does_not_affect_done():
    # MPI 002, MPIAxisInPosition, positionCoarse positionCoarse "This value does not affect the settling time status"
    def done_sample(coarse):
        ctl, ms, _axis = rig(AxisInPosition(position_fine=5.0, position_coarse=coarse))
        ms.start(MPIMotionType.TRAPEZOIDAL, params=trapezoid(1000.0))
        ctl.step(int(duration(1000.0) * RATE))
        assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000)
        return ctl.sample

    assert done_sample(0) == done_sample(10**6)


def test_final_velocity_move_never_sets_at_target_done_or_in_fine_while_it_runs_on():
    # MPI 002, the status tables: AT_TARGET is "TRUE when command = target", DONE is TC and
    # IN_FINE_POSITION. A FINAL_VEL move leaves its target at the final velocity: its last frame
    # runs on, so TC, AT_TARGET, IN_FINE_POSITION and DONE stay FALSE while the axis moves.
    ctl, ms, axis = rig(AxisInPosition())
    params = trapezoid(1000.0)
    params.final_velocity = [500.0]
    assert ms.start(MPIMotionType.TRAPEZOIDAL, MotionAttr.FINAL_VEL, params).ok
    for _ in range(600):
        ctl.step(10)
        bits = axis.status
        assert not (bits.at_target)
        assert not (bits.done)
        assert not (bits.in_fine_position)
        assert not (bits.trajectory_complete)
    assert axis.command_position > 1500.0
    assert axis.cmd_v == 500.0
    assert ms.state is MPIState.MOVING


def test_sync_start_sets_at_target_on_each_axis_when_its_command_arrives():
    # MPI 002, the status tables: AT_TARGET is "TRUE when command = target". With SYNC_START the
    # axes start together and the shorter one arrives first; it is at its target from then on.
    ctl = Controller(ControllerConfig(axis_count=2, supervisor_count=1))
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    params = MotionParams(trajectory=[Trajectory(V, ACC, ACC, 0.0)] * 2, position=[500.0, 3000.0])
    assert ms.start(MPIMotionType.TRAPEZOIDAL, MotionAttr.SYNC_START, params).ok
    short, long_ = ctl.axes
    assert ctl.run_until(lambda c: short.command_position == 500.0 and short.cmd_v == 0.0, 20_000)
    ctl.step(1)
    assert short.status.at_target
    assert not long_.status.at_target
    assert long_.cmd_v != 0.0


def test_a_velocity_move_reports_no_target_position():
    # MPI 002, the status-bit tables: AT_TARGET is "TRUE when command = target" after a point-to-
    # point move and FALSE "During Velocity Move"; a velocity move has no target at all, so the
    # axis status says so (NaN) instead of the far end of the velocity move's long frame.
    ctl, ms, _axis = rig(AxisInPosition())
    ms.start(MPIMotionType.VELOCITY, params=MotionParams(trajectory=[Trajectory(500.0, 5000.0)]))
    ctl.step(400)
    assert math.isnan(ctl.axis_snapshot(0).target_position)
    assert ms.modify(MPIMotionType.TRAPEZOIDAL, params=trapezoid(1000.0)).ok  # a target again
    ctl.step(1)
    assert ctl.axis_snapshot(0).target_position == 1000.0
