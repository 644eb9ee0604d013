"""Axis (mpi_ros/mpi/axes/axis.py, plant.py): positions, origin, position set rules, the servo."""

from __future__ import annotations

import math

import pytest

from mpi_ros.mpi import AxisInPosition, Controller, ControllerConfig, MPIAction, MPIMotionType, MPIState, PlantConfig
from mpi_ros.mpi.base.messages import Message

M = Message
T = MPIMotionType


def test_error_is_command_minus_actual(ctl, ms, params):
    # MPI 002, Axis Objects, introduction "The Axis object contains command, actual, and error position data"
    ms.start(T.TRAPEZOIDAL, params=params((5000.0, 0.0)))
    for _ in range(20):
        ctl.step(37)
        snap = ctl.axis_snapshot(0)
        assert snap.position_error == snap.command_position - snap.actual_position


def test_actual_lags_command_and_settles_in_real_time(params):
    # issue 3: "A simulated servo/plant so actual position lags command and settling takes real time"
    ctl = Controller(plant=PlantConfig(bandwidth_hz=5.0, velocity_feedforward=0.0))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0])
    ms.start(T.TRAPEZOIDAL, params=params((2000.0,)))
    ctl.step(1000)
    axis = ctl.axes[0]
    assert axis.command_position - axis.actual_position > 20.0  # behind while moving forward
    ctl.step(4200 - 1000)  # the command has arrived (2.1 s)
    assert axis.command_position == 2000.0
    assert axis.actual_position != 2000.0
    assert ctl.run_until(lambda c: axis.actual_position == 2000.0 and abs(axis.act_v) < 1.0, 10_000)


def test_the_encoder_reads_whole_counts(ctl, ms, params):
    # PlantConfig.encoder_resolution (1 count by default): the actual position is an encoder reading
    ms.start(T.S_CURVE, params=params((1234.5, 0.0), jerk_percent=50.0))
    for _ in range(30):
        ctl.step(41)
        assert ctl.axes[0].actual_position == math.floor(ctl.axes[0].actual_position)


def test_origin_offsets_every_reported_position(ctl, ms, params, run_to):
    # MPI 002, Configuration and Information Methods, <u>mpiAxisOriginGet</u> mpiAxisOriginGet/Set; axis.py: "Positions
    # seen by users are raw positions minus the origin"
    assert ctl.axis_origin_set(0, 100.0).ok
    assert ctl.axes[0].command_position == -100.0
    ms.start(T.TRAPEZOIDAL, params=params((500.0, 0.0)))
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=100)
    snap = ctl.axis_snapshot(0)
    assert snap.command_position == 500.0
    assert snap.target_position == 500.0
    assert snap.origin == 100.0
    assert ctl.axes[0].cmd_p == 600.0  # the raw command


def test_origin_must_be_finite(ctl):
    # MPI 000, MPIMessagePARAM_INVALID / docs/quality.md, "Robust": bad input changes nothing
    assert ctl.axis_origin_set(0, float("nan")).message is M.MPIMessagePARAM_INVALID
    assert ctl.axes[0].origin == 0.0


def test_actual_position_set_moves_the_reading_not_the_command(ctl, ms):
    # MPI 002, Configuration and Information Methods, <u>mpiAxisActualPositionSet</u> mpiAxisActualPositionSet "Set
    # actual position"
    assert ctl.axis_actual_position_set(0, 250.0).ok
    axis = ctl.axes[0]
    assert axis.actual_position == 250.0
    assert axis.command_position == 0.0
    ctl.step(1)
    assert axis.actual_position != 0.0
    assert axis.command_position == 0.0
    assert ctl.run_until(lambda c: c.axes[0].actual_position == 0.0, 20_000)  # the loop removes the error


def test_command_position_set_when_idle(ctl, ms):
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET "set the command position when the motion is in an IDLE state"
    assert ctl.axis_command_position_set(1, -75.0).ok
    axis = ctl.axes[1]
    assert axis.command_position == -75.0
    assert ctl.axis_snapshot(1).target_position == -75.0
    assert ctl.run_until(lambda c: axis.actual_position == -75.0, 20_000)


@pytest.mark.parametrize("state", [MPIState.MOVING, MPIState.STOPPING, MPIState.STOPPED])
def test_command_not_set_while_moving_stopping_or_stopped(ctl, ms, bring, state):
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET COMMAND_NOT_SET when "Axis is in a STOPPING, STOPPED, or MOVING state"
    bring(state)
    before = ctl.axes[0].cmd_p
    assert ctl.axis_command_position_set(0, 5.0).message is M.MPIAxisMessageCOMMAND_NOT_SET
    assert ctl.axes[0].cmd_p == before


def test_command_not_set_while_the_command_follows_the_actual(ctl, params):
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET "disableAction ... CMD_EQ_ACT and the motor's Amp Enable is disabled";
    # MPI 002, mpiAxisValidate, return values "the command position is continually set to the actual position"; here: an
    # E_STOP with settleOnEstopCmdEqAct (MPI 002, MPIAxisInPosition, settleOnEstopCmdEqAct)
    ctl = Controller(in_position=AxisInPosition(settle_on_estop_cmd_eq_act=True))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0])
    ms.start(T.TRAPEZOIDAL, params=params((50_000.0,)))
    ctl.step(500)
    ms.action(MPIAction.E_STOP)
    ctl.step(10)
    assert ctl.axis_command_position_set(0, 5.0).message is M.MPIAxisMessageCOMMAND_NOT_SET


def test_command_position_set_after_reset(ctl, ms, bring):
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET once IDLE again, the command position can be set
    bring(MPIState.ERROR)
    assert ms.action(MPIAction.RESET).ok
    assert ctl.axis_command_position_set(0, 5.0).ok
    assert ctl.axes[0].command_position == 5.0


@pytest.mark.parametrize("number", [-1, 4, 99])
def test_axis_invalid_out_of_range(ctl, number):
    # MPI 002, MPIAxisMessageAXIS_INVALID AXIS_INVALID "The axis number is out of range"
    assert ctl.axis_command_position_set(number, 0.0).message is M.MPIAxisMessageAXIS_INVALID
    assert ctl.axis_actual_position_set(number, 0.0).message is M.MPIAxisMessageAXIS_INVALID
    assert ctl.axis_origin_set(number, 0.0).message is M.MPIAxisMessageAXIS_INVALID
    assert ctl.axis_in_position_set(number, AxisInPosition()).message is M.MPIAxisMessageAXIS_INVALID


def test_non_finite_positions_are_refused(ctl):
    # MPI 000, MPIMessagePARAM_INVALID / docs/quality.md, "Robust": bad input changes nothing
    assert ctl.axis_command_position_set(0, float("inf")).message is M.MPIMessagePARAM_INVALID
    assert ctl.axis_actual_position_set(0, float("nan")).message is M.MPIMessagePARAM_INVALID
    assert ctl.axes[0].cmd_p == 0.0
    assert ctl.axes[0].act_p == 0.0


@pytest.mark.parametrize(("field", "value"), [("position_fine", -1.0), ("position_coarse", -1), ("velocity", -1.0),
                                         ("settling_time", float("nan"))])
def test_in_position_values_are_checked(ctl, field, value):
    # MPI 002, MPIAxisInPosition, tolerance tolerances and settling time are distances, a velocity and a duration
    tol = AxisInPosition()
    setattr(tol, field, value)
    assert ctl.axis_in_position_set(0, tol).message is M.MPIMessagePARAM_INVALID
    assert ctl.axis_in_position_set(0, AxisInPosition(position_fine=3.0)).ok
    assert ctl.axes[0].in_position.position_fine == 3.0


def test_motion_position_get_one_value_per_axis(ctl, ms, params):
    # MPI 000, mpiMotionPositionGet mpiMotionPositionGet: "actual and command arguments each point to an array with a
    # size equal to the number of axes"
    ms.start(T.TRAPEZOIDAL, params=params((300.0, -200.0)))
    ctl.step(500)
    message, actual, command = ms.position_get()
    assert message.ok
    assert command == [a.command_position for a in ctl.axes[:2]]
    assert actual == [a.actual_position for a in ctl.axes[:2]]


def test_motion_position_set(ctl, ms):
    # MPI 000, mpiMotionPositionSet mpiMotionPositionSet "sets the actual and command position values for all axes"
    assert ms.position_set([10.0, 20.0], [30.0, 40.0]).ok
    assert [a.actual_position for a in ctl.axes[:2]] == [10.0, 20.0]
    assert [a.command_position for a in ctl.axes[:2]] == [30.0, 40.0]


def test_motion_position_set_checks_its_arrays(ctl, ms):
    # MPI 000, mpiMotionPositionSet arrays "with a size equal to the number of axes"
    assert ms.position_set([1.0], [1.0, 2.0]).message is M.MPIMessagePARAM_INVALID
    assert ms.position_set([1.0, float("nan")], [1.0, 2.0]).message is M.MPIMessagePARAM_INVALID
    assert [a.cmd_p for a in ctl.axes[:2]] == [0.0, 0.0]
    assert [a.act_p for a in ctl.axes[:2]] == [0.0, 0.0]
    _, empty = ctl.create_motion(1)
    assert empty.position_set([], []).message is M.MPIMotionMessageAXIS_COUNT


def test_motion_position_set_while_moving_changes_nothing(ctl, ms, bring):
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET COMMAND_NOT_SET while MOVING
    bring(MPIState.MOVING)
    actual = [a.act_p for a in ctl.axes[:2]]
    assert ms.position_set([0.0, 0.0], [0.0, 0.0]).message is M.MPIAxisMessageCOMMAND_NOT_SET
    assert [a.act_p for a in ctl.axes[:2]] == actual


def test_motion_trajectory_reads_velocity_and_acceleration(ctl, ms, params):
    # MPI 000, mpiMotionTrajectory mpiMotionTrajectory "reads the current velocity and acceleration for all axes";
    # MPI 000, mpiMotionTrajectory the other fields cannot be read
    ms.start(T.TRAPEZOIDAL, params=params((3000.0, 4000.0)))
    ctl.step(50)  # accelerating at 10000 along (0.6, 0.8)
    message, values = ms.trajectory()
    assert message.ok
    (v0, a0), (v1, a1) = values
    assert a0 == pytest.approx(6000.0)
    assert a1 == pytest.approx(8000.0)
    assert v0 == pytest.approx(6000.0 * 50 / 2000)
    assert v1 == pytest.approx(8000.0 * 50 / 2000)


def test_axis_snapshot_reports_the_owner_and_frames(ctl, ms, ms1, params):
    # MPI 000, MEIMotionFrameBufferStatus, frameCount frameCount; the axis status names the supervisor commanding it
    ms1.start(T.TRAPEZOIDAL, params=params((100.0, 100.0)))
    snap = ctl.axis_snapshot(2)
    assert snap.supervisor == 1
    assert snap.state is MPIState.MOVING
    assert snap.frame_count > 0
    assert ctl.axis_snapshot(0).state is MPIState.IDLE


def test_the_plant_is_deterministic(params):
    # docs/decisions.md, "Samples, commands and replay": the controller is deterministic
    def run():
        ctl = Controller(ControllerConfig(axis_count=2, supervisor_count=1))
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        ms.start(T.S_CURVE, params=params((777.0, -333.0), jerk_percent=40.0))
        out = []
        for _ in range(40):
            ctl.step(53)
            out.append([(a.cmd_p, a.act_p, a.act_v) for a in ctl.axes])
        return out

    assert run() == run()


def test_plant_config_is_checked():
    # PlantConfig: bandwidth, damping and coast time constant must be positive
    for bad in (PlantConfig(bandwidth_hz=0.0), PlantConfig(damping=-1.0), PlantConfig(coast_time_constant=0.0)):
        with pytest.raises(ValueError):
            Controller(plant=bad)
