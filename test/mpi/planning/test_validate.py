"""Validation of start/modify (mpi_ros/mpi/planning/validate.py): MPI 000's return table
(MPI 000, Returns for mpiMotionStart and mpiMotionModify), the ATTRIBUTE_INVALID causes
(MPI 000, MPIMotionMessageATTRIBUTE_INVALID) and the array lengths of docs/decisions.md
("The ROS contract: names, numbers, arrays").
A refused command answers the spec's message and changes nothing."""

from __future__ import annotations

import math

import pytest

from mpi_ros.mpi import (
    Controller,
    Hold,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Output,
    Trajectory,
)
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import MotionConfig
from mpi_ros.mpi.base.types import PATH_ATTRS, HoldType, OutputType
from mpi_ros.mpi.planning.validate import check_attributes, check_params, check_type

A = MotionAttr
T = MPIMotionType
M = Message
TRAJ = Trajectory(1000.0, 10_000.0, 10_000.0, 0.0)
JERK_TRAJ = Trajectory(1000.0, 10_000.0, 10_000.0, 0.0, 1e6, 1e6)
PATH_ALLOWED = [A.APPEND, A.RELATIVE, A.ID, A.ELEMENT_ID, A.HOLD, A.HOLD_LESS, A.HOLD_GREATER, A.OUTPUT]
ALL_ATTRS = [m for m in A if m is not A.NONE]


def p2p(position=(100.0, 0.0), trajectory=(TRAJ,), **fields) -> MotionParams:
    return MotionParams(trajectory=list(trajectory), position=list(position), **fields)


def full_params() -> MotionParams:
    """Every attribute's data present, so only the mask decides."""
    gate = Hold(type=HoldType.GATE, gate=1)
    return p2p(delay=[0.0, 0.0], final_velocity=[0.0, 0.0], hold=[gate, gate], element_id=[1],
               output=[Output(type=OutputType.OUTPUT, address=0, on_mask=1)])


# ------------------------------------------------------------------ motion type ----
def test_type_invalid():
    # MPI 000, MPIMotionMessageType_INVALID MPIMotionMessageTYPE_INVALID: the motion type is not recognized
    assert check_type(T.INVALID, False, False).message is M.MPIMotionMessageTYPE_INVALID


@pytest.mark.parametrize("kind", [T.S_CURVE_JERK, T.VELOCITY_JERK])
@pytest.mark.parametrize("modify", [False, True])
def test_jerk_types_without_firmware_option_21_are_not_supported(kind, modify):
    # MPI 000, MPIMotionMessagePROFILE_NOT_SUPPORTED PROFILE_NOT_SUPPORTED "returned by mpiMotionStart or
    # mpiMotionModify when an S_CURVE_JERK or VELOCITY_JERK motion type is commanded, but not supported by the firmware"
    assert check_type(kind, modify, False).message is M.MPIMotionMessagePROFILE_NOT_SUPPORTED
    # docs/profiles.md, "Modify": firmware option 21 is turned on by configuration
    assert check_type(kind, modify, True).ok


@pytest.mark.parametrize("kind", [T.CAM_LINEAR, T.CAM_CUBIC])
def test_cams_are_supported_but_cannot_be_modified(kind):
    # MPI 000 documents the cams in full (MPIMotionCam, REPEAT, MASTER_START): supported (test_cams.py); they
    # are not among the types mpiMotionModify can modify
    assert check_type(kind, False, False).ok
    assert check_type(kind, True, False).message is M.MPIMessageUNSUPPORTED


@pytest.mark.parametrize("kind", [T.PTF, T.PVTF, T.SPLINE, T.BESSEL, T.BSPLINE, T.BSPLINE2, T.FRAME])
def test_types_that_cannot_be_modified(kind):
    # MPI 000, mpiMotionModify "The types of motion whose parameters can be modified while moving are
    # TRAPEZOIDAL, S_CURVE, VELOCITY, PT and PVT"
    assert check_type(kind, True, True).message is M.MPIMessageUNSUPPORTED


@pytest.mark.parametrize("kind", [T.TRAPEZOIDAL, T.S_CURVE, T.VELOCITY])
@pytest.mark.parametrize("modify", [False, True])
def test_point_to_point_and_velocity_types_are_accepted(kind, modify):
    # MPI 000, MPIMessageUNSUPPORTED supported list; MPI 000, mpiMotionModify modifiable list
    assert check_type(kind, modify, False).ok


# ------------------------------------------------------------------ attributes ----
@pytest.mark.parametrize("kind", [T.PT, T.PTF, T.PVT, T.PVTF, T.BESSEL, T.BSPLINE, T.BSPLINE2])
def test_path_types_allow_exactly_their_list(kind):
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID "PT (PTF, PVT, PVTF, BESSEL, BSPLINE, BSPLINE2) Moves are only
    # permitted to have motion attributes from the following list: APPEND RELATIVE ID ELEMENT_ID HOLD
    # HOLD_LESS HOLD_GREATER OUTPUT", and the path attributes of MPI 001, MPIMotionPathAttrMask
    params = full_params()
    for attr in ALL_ATTRS:
        verdict = check_attributes(kind, attr, params, modify=False)
        if attr in PATH_ALLOWED or attr in PATH_ATTRS:
            assert verdict.ok, attr
        else:
            assert verdict.message is M.MPIMotionMessageATTRIBUTE_INVALID, attr


def test_spline_allows_the_list_without_append():
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID SPLINE: RELATIVE ID ELEMENT_ID HOLD HOLD_LESS HOLD_GREATER OUTPUT (no
    # APPEND)
    params = full_params()
    assert check_attributes(T.SPLINE, A.APPEND, params, False).message is M.MPIMotionMessageATTRIBUTE_INVALID
    for attr in PATH_ALLOWED[1:] + list(PATH_ATTRS):
        assert check_attributes(T.SPLINE, attr, params, False).ok


@pytest.mark.parametrize("kind", [T.TRAPEZOIDAL, T.S_CURVE, T.VELOCITY, T.FRAME])
def test_path_attributes_belong_to_path_moves(kind):
    # MPI 001, MPIMotionPathAttrMask: the attributes of path motion
    for attr in PATH_ATTRS:
        assert check_attributes(kind, attr, full_params(), False).message is M.MPIMotionMessageATTRIBUTE_INVALID, attr


def test_frame_allows_append_and_id_only():
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID "FRAME Moves are only permitted to have ... APPEND, ID"
    params = full_params()
    for attr in ALL_ATTRS:
        ok = check_attributes(T.FRAME, attr, params, False).ok
        assert ok is (attr in (A.APPEND, A.ID)), attr


@pytest.mark.parametrize("kind", [T.VELOCITY, T.VELOCITY_JERK])
@pytest.mark.parametrize("attr", [A.SYNC_END, A.SYNC_START, A.FINAL_VEL, A.NO_REVERSAL])
def test_velocity_moves_refuse_sync_final_vel_no_reversal(kind, attr):
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID "VELOCITY, VELOCITY_JERK Moves are not permitted to have SYNC_END,
    # SYNC_START, FINAL_VEL, NO_REVERSAL"
    assert check_attributes(kind, attr, full_params(), False).message is M.MPIMotionMessageATTRIBUTE_INVALID


@pytest.mark.parametrize("attr", [A.APPEND, A.AUTO_START, A.DELAY, A.ID, A.RELATIVE, A.EVENT, A.OUTPUT, A.HOLD])
def test_velocity_moves_allow_the_other_attributes(attr):
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID only SYNC_END/SYNC_START/FINAL_VEL/NO_REVERSAL are forbidden for
    # VELOCITY
    assert check_attributes(T.VELOCITY, attr, full_params(), False).ok


@pytest.mark.parametrize("attr", [A.REPEAT, A.MASTER_START, A.NO_BACKTRACK, A.NO_BACKTRACK_HOLD])
def test_cam_attributes_on_a_point_to_point_move(attr):
    # MPI 000, MPIMotionAttrREPEAT: REPEAT, MASTER_START and the NO_BACKTRACK pair are cam attributes
    assert check_attributes(T.TRAPEZOIDAL, attr, full_params(), False).message is M.MPIMotionMessageATTRIBUTE_INVALID


def test_no_backtrack_and_no_backtrack_hold_exclude_each_other():
    # MPI 000, MPIMotionAttrREPEAT_NO_BACKTRACK "This attribute cannot be specified with the MPIMotionAttrNO_BACKTRACK
    # attribute"
    verdict = check_attributes(T.CAM_LINEAR, A.NO_BACKTRACK | A.NO_BACKTRACK_HOLD, full_params(), False)
    assert verdict.message is M.MPIMotionMessageATTRIBUTE_INVALID
    assert check_attributes(T.CAM_LINEAR, A.NO_BACKTRACK, full_params(), False).ok


@pytest.mark.parametrize(("attr", "field"), [
    (A.DELAY, "delay"),  # MPI 000, MPIMotionMessageATTRIBUTE_INVALID
    (A.FINAL_VEL, "final_velocity"),  # MPI 000, MPIMotionMessageATTRIBUTE_INVALID
    (A.HOLD, "hold"), (A.HOLD_LESS, "hold"), (A.HOLD_GREATER, "hold"),  # MPI 000, MPIMotionMessageATTRIBUTE_INVALID
    (A.OUTPUT, "output"),  # MPI 000, MPIMotionMessageATTRIBUTE_INVALID
])
def test_attribute_with_null_data_is_attribute_invalid(attr, field):
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID "<attribute> specified and attributes <field> address is NULL"
    # (docs/decisions.md, "The ROS contract": a NULL pointer is an empty array here)
    params = full_params()
    setattr(params, field, [])
    assert check_attributes(T.TRAPEZOIDAL, attr, params, False).message is M.MPIMotionMessageATTRIBUTE_INVALID
    assert check_attributes(T.TRAPEZOIDAL, attr, full_params(), False).ok


@pytest.mark.parametrize("attr", [A.HOLD, A.HOLD_LESS, A.HOLD_GREATER])
def test_hold_attributes_are_not_permitted_on_modify(attr):
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID "HOLD, HOLD_LESS, and HOLD_GREATER are not permitted during motion
    # modifies"; MPI 000, MEIMotionAttrHOLD
    assert check_attributes(T.TRAPEZOIDAL, attr, full_params(), True).message is M.MPIMotionMessageATTRIBUTE_INVALID
    assert check_attributes(T.TRAPEZOIDAL, attr, full_params(), False).ok


def test_hold_less_and_hold_greater_exclude_each_other():
    # MPI 000, MEIMotionAttrHOLD_LESS HOLD_LESS is "less than or equal", HOLD_GREATER "greater than or equal":
    # both at once has no meaning (decision in validate.py: ATTRIBUTE_INVALID)
    verdict = check_attributes(T.TRAPEZOIDAL, A.HOLD_LESS | A.HOLD_GREATER, full_params(), False)
    assert verdict.message is M.MPIMotionMessageATTRIBUTE_INVALID


# ------------------------------------------------------------------ parameters ----
def params_verdict(params, kind=T.TRAPEZOIDAL, attrs=A.NONE, axis_count=2):
    return check_params(kind, attrs, params, axis_count, io_words=64, motors=4, axes=4)


def test_arg_invalid_past_max_coord_axes():
    # MPI 000, MPIMessageARG_INVALID MPIMessageARG_INVALID "Number of axes on the motion commanded exceeds
    # MEIXmpMAX_COORD_AXES"
    verdict = params_verdict(p2p([0.0] * 9), axis_count=9)
    assert verdict.message is M.MPIMessageARG_INVALID
    assert params_verdict(p2p([0.0] * 8), axis_count=8).ok


def test_one_trajectory_without_sync():
    # MPI 000, MPIMotionAttrMaskNO_BACKTRACK_HOLD, remarks "if neither SYNC_START nor SYNC_END are specified, then only
    # one MPITrajectory structure will be used"; docs/decisions.md, "The ROS contract" (array lengths):
    # anything else is MPIMessagePARAM_INVALID
    assert params_verdict(p2p(trajectory=[TRAJ])).ok
    assert params_verdict(p2p(trajectory=[TRAJ, TRAJ])).message is M.MPIMessagePARAM_INVALID
    assert params_verdict(p2p(trajectory=[])).message is M.MPIMessagePARAM_INVALID


@pytest.mark.parametrize("attr", [A.SYNC_START, A.SYNC_END])
def test_sync_needs_one_trajectory_per_axis(attr):
    # MPI 000, MPIMotionAttrSYNC_END "When enabled, each axis will use its own MPITrajectory values"
    assert params_verdict(p2p(trajectory=[TRAJ, TRAJ]), attrs=attr).ok
    assert params_verdict(p2p(trajectory=[TRAJ]), attrs=attr).message is M.MPIMessagePARAM_INVALID


def test_position_has_one_value_per_axis():
    # MPI 000, MPIMotionSCurve "Each position value specifies the target for each axis"; docs/decisions.md,
    # "The ROS contract" (array lengths)
    assert params_verdict(p2p([1.0])).message is M.MPIMessagePARAM_INVALID
    assert params_verdict(p2p([1.0, 2.0, 3.0])).message is M.MPIMessagePARAM_INVALID


def test_velocity_ignores_position():
    # MPI 000, MPIMotionSCurve "VELOCITY and VELOCITY_JERK do not require target positions and will ignore
    # these values"
    assert params_verdict(p2p([]), kind=T.VELOCITY).ok
    assert params_verdict(p2p([float("nan")] * 5), kind=T.VELOCITY).ok


@pytest.mark.parametrize("field", ["velocity", "acceleration", "deceleration"])
@pytest.mark.parametrize("value", [0.0, -1.0, float("inf"), float("nan")])
def test_point_to_point_limits_must_be_positive_and_finite(field, value):
    # MPI 000, MPIMessagePARAM_INVALID PARAM_INVALID "if the specified motion parameters are not valid with the type"
    traj = Trajectory(1000.0, 10_000.0, 10_000.0, 0.0)
    setattr(traj, field, value)
    assert params_verdict(p2p(trajectory=[traj])).message is M.MPIMessagePARAM_INVALID


def test_velocity_move_velocity_may_be_negative_or_zero():
    # MPI 000, MPIMotionVelocity velocity moves: "deceleration is ignored"; the velocity is signed
    for velocity in (-500.0, 0.0):
        assert params_verdict(p2p([], trajectory=[Trajectory(velocity, 1000.0, 0.0)]), kind=T.VELOCITY).ok
    bad = p2p([], trajectory=[Trajectory(100.0, 0.0, 0.0)])
    assert params_verdict(bad, kind=T.VELOCITY).message is M.MPIMessagePARAM_INVALID


@pytest.mark.parametrize(("jerk_percent", "ok"), [(0.0, True), (100.0, True), (-0.1, False), (100.1, False)])
def test_jerk_percent_within_0_and_100(jerk_percent, ok):
    # MPI 000, MPIMotionSCurve S-curve parameters are velocity, acceleration, deceleration and jerkPercent (a
    # percentage)
    traj = Trajectory(1000.0, 10_000.0, 10_000.0, jerk_percent)
    assert params_verdict(p2p(trajectory=[traj]), kind=T.S_CURVE).ok is ok


def test_jerk_types_need_positive_jerks():
    # MPI 000, MPIMotionSCurveJerk S_CURVE_JERK uses "accelerationJerk, and decelerationJerk"
    assert params_verdict(p2p(trajectory=[JERK_TRAJ]), kind=T.S_CURVE_JERK).ok
    no_jerk = Trajectory(1000.0, 10_000.0, 10_000.0, 0.0, 0.0, 1e6)
    assert params_verdict(p2p(trajectory=[no_jerk]), kind=T.S_CURVE_JERK).message is M.MPIMessagePARAM_INVALID


def test_non_finite_position_is_param_invalid():
    # MPI 000, MPIMessagePARAM_INVALID PARAM_INVALID
    assert params_verdict(p2p([float("nan"), 0.0])).message is M.MPIMessagePARAM_INVALID
    assert params_verdict(p2p([float("inf"), 0.0])).message is M.MPIMessagePARAM_INVALID


@pytest.mark.parametrize(("attr", "field", "value"), [
    (A.DELAY, "delay", [0.1]),
    (A.DELAY, "delay", [0.1, -0.1]),
    (A.DELAY, "delay", [0.1, float("nan")]),
    (A.FINAL_VEL, "final_velocity", [1.0]),
    (A.FINAL_VEL, "final_velocity", [1.0, float("inf")]),
    (A.HOLD, "hold", [Hold(type=HoldType.GATE)]),
])
def test_per_axis_attribute_arrays(attr, field, value):
    # MPI 000, MPIMotionAttrDELAY "delay is a pointer to an array of doubles that assign delay times for each
    # Axis"; MPI 000, MEIMotionAttributes, finalVelocity finalVelocity and hold "for each axis"
    params = p2p()
    setattr(params, field, value)
    assert params_verdict(params, attrs=attr).message is M.MPIMessagePARAM_INVALID


@pytest.mark.parametrize(("hold", "ok"), [
    (Hold(type=HoldType.GATE, gate=31), True),
    (Hold(type=HoldType.GATE, gate=32), False),  # MPI 000, MEIMotionAttrHoldSource, gate gate "between 0 and 31"
    (Hold(type=HoldType.GATE, gate=-1), False),
    (Hold(type=HoldType.INPUT, address=63), True),
    (Hold(type=HoldType.INPUT, address=64), False),  # docs/decisions.md, "The ROS contract": an I/O word index
    (Hold(type=HoldType.MOTOR_GENERAL_IO, number=3), True),
    (Hold(type=HoldType.MOTOR_DEDICATED_IO, number=4), False),
    (Hold(type=HoldType.AXIS_POSITION_ACTUAL, number=4), False),  # MPI 000, MEIMotionAttrHoldSource, axis.number an
                                                                  # axis's number
    (Hold(type=HoldType.AXIS_POSITION_COMMAND, number=3, position=5.0), True),
    (Hold(type=HoldType.INVALID), False),
    (Hold(type=HoldType.GATE, timeout=-1.0), False),
    (Hold(type=HoldType.GATE, timeout=float("nan")), False),
])
def test_hold_sources(hold, ok):
    # MPI 000, MEIMotionAttrHoldSource, gate MEIMotionAttrHoldSource fields
    assert params_verdict(p2p(hold=[hold, hold]), attrs=A.HOLD).ok is ok


@pytest.mark.parametrize(("output", "ok"), [
    (Output(type=OutputType.OUTPUT, address=0, on_mask=1), True),
    (Output(type=OutputType.OUTPUT, address=64), False),  # docs/decisions.md, "The ROS contract"
    (Output(type=OutputType.MOTOR, motor=3), True),  # MPI 000, MEIMotionAttrOutput, motor motor number
    (Output(type=OutputType.MOTOR, motor=4), False),
    (Output(type=OutputType.INVALID), False),
    # MEIMotionAttrOutput.pointIndex "when multiple point motion is used": a point-to-point move
    # has one point, index 0; another index would never be reached
    (Output(type=OutputType.OUTPUT, address=0, on_mask=1, point_index=1), False),
])
def test_output_targets(output, ok):
    # MPI 000, MEIMotionAttrOutput, type MEIMotionAttrOutput
    assert params_verdict(p2p(output=[output]), attrs=A.OUTPUT).ok is ok


def test_element_id_needs_values():
    # MPI 000, MPIMotionAttributes, elementId elementId "array defines the identity for each element"
    assert params_verdict(p2p(), attrs=A.ELEMENT_ID).message is M.MPIMessagePARAM_INVALID
    assert params_verdict(p2p(element_id=[7]), attrs=A.ELEMENT_ID).ok


# ------------------------------------------------------------------ ranges ----
# docs/decisions.md "Validation and ranges": every value a move reads is one a controller can
# hold (MotionParams.validate, the validator the services and the YAML loader use too).
@pytest.mark.parametrize(("attrs", "params"), [
    (A.NONE, p2p([1e300, 0.0])),  # finite, but past any position a controller holds
    (A.NONE, p2p(trajectory=[Trajectory(1e300, 1e4, 1e4)])),
    (A.DELAY, p2p(delay=[0.0, 1e9])),  # more samples than the counter holds
    (A.FINAL_VEL, p2p(final_velocity=[0.0, 1e300])),
    (A.HOLD, p2p(hold=[Hold(type=HoldType.GATE, gate=1, timeout=1e9)] * 2)),
    (A.OUTPUT, p2p(output=[Output(type=OutputType.OUTPUT, address=0, on_mask=2**32)])),
    (A.ID, p2p(id=2**40)),
])
def test_values_no_controller_holds_are_param_invalid(attrs, params):
    # MPI 000 "Returns for mpiMotionStart and mpiMotionModify": MPIMessagePARAM_INVALID "if the
    # specified motion parameters are not valid"; C longs and doubles (MPIMotionParams,
    # MPIMotionAttributes, MEIMotionAttrHold/Output), durations that fit the sample counter
    verdict = params_verdict(params, attrs=attrs)
    assert verdict.message is M.MPIMessagePARAM_INVALID
    assert ":" in verdict.detail


@pytest.mark.parametrize("empty_count", [-1, 0, -100, 1, 5])
def test_every_empty_count_is_accepted(empty_count):
    # MPI 000, MPIMotionPoint: -1 disables; MPI 001, MPIMotionPathAttrMask EMPTY_COUNT: zero disables;
    # docs/decisions.md, "emptyCount <= 0 disables": both do, so neither is refused
    assert params_verdict(p2p(empty_count=empty_count)).ok


def test_empty_count_past_a_c_long_is_param_invalid():
    # MPI 000 MPIMotionPoint: long emptyCount
    assert params_verdict(p2p(empty_count=2**40)).message is M.MPIMessagePARAM_INVALID


# ------------------------------------------------------------------ through the supervisor ----
def test_start_with_no_axes_answers_axis_count(ctl):
    # MPI 000, MPIMotionMessageAXIS_COUNT MPIMotionMessageAXIS_COUNT "if the motion object has no axes"; MPI 000,
    # MPIMotionMessageAXIS_COUNT; MPI 000, mpiMotionStart "There must be at least one Axis in the coordinate system"
    _, ms = ctl.create_motion(0)
    assert ms.start(T.TRAPEZOIDAL, params=p2p([1.0])).message is M.MPIMotionMessageAXIS_COUNT
    assert ms.modify(T.TRAPEZOIDAL, A.AUTO_START, p2p([1.0])).message is M.MPIMotionMessageAXIS_COUNT
    assert ms.state is MPIState.IDLE


def test_config_set_with_no_axes_answers_axis_count(ctl):
    # MPI 000 MPIMotionMessageAXIS_COUNT: "returned from mpiMotionConfigSet(...), mpiMotionStart(...),
    # or mpiMotionModify(...) if there are no axes associated with the motion object"
    _, ms = ctl.create_motion(0)
    before = ms.config.copy()
    assert ms.config_set(MotionConfig(normal_feedrate=0.5)).message is M.MPIMotionMessageAXIS_COUNT
    assert ms.config == before
    assert ms.axis_list_set([0]).ok
    assert ms.config_set(MotionConfig(normal_feedrate=0.5)).ok


def test_start_in_error_answers_error(ms, bring, params):
    # MPI 000, MPIMotionMessageERROR MPIMotionMessageERROR "if MotionStart is called when the Motion Supervisor is
    # in the error state"
    bring(MPIState.ERROR)
    assert ms.start(T.TRAPEZOIDAL, params=params()).message is M.MPIMotionMessageERROR


def test_profile_error_when_the_profile_cannot_be_calculated(ms, params):
    # MPI 000, MPIMotionMessagePROFILE_ERROR PROFILE_ERROR "if the Motion profile specified by the parameters cannot be
    # calculated correctly": a final velocity above the trajectory velocity
    message = ms.start(T.TRAPEZOIDAL, A.FINAL_VEL, params((1000.0, 0.0), final_velocity=[2000.0, 0.0])).message
    assert message is M.MPIMotionMessagePROFILE_ERROR
    assert ms.state is MPIState.IDLE


def twin(setup):
    """Two identical controllers prepared by ``setup(ctl, ms)``."""
    out = []
    for _ in range(2):
        ctl = Controller()
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        ms.action(MPIAction.MAP)
        setup(ctl, ms)
        ctl.drain_events()
        out.append((ctl, ms))
    return out


def observe(ctl, ms, samples=3000):
    """What a refused command must not change: the motion from now on, state, queue, events."""
    trace = []
    for _ in range(samples // 100):
        ctl.step(100)
        trace.append((ms.state, tuple((a.cmd_p, a.act_p) for a in ctl.axes)))
    events = [(e.sample, e.type, e.supervisor, e.axis, e.move_id) for e in ctl.drain_events()]
    return trace, events, len(ms.queue), ms.stored_params


def start_moving(ctl, ms):
    assert ms.start(T.TRAPEZOIDAL, params=p2p((2000.0, 500.0))).ok
    ctl.step(300)


REFUSED = [
    ("type invalid", False, T.INVALID, A.NONE, p2p(), M.MPIMotionMessageTYPE_INVALID),
    ("jerk w/o option", False, T.S_CURVE_JERK, A.NONE, p2p(trajectory=[JERK_TRAJ]),
     M.MPIMotionMessagePROFILE_NOT_SUPPORTED),
    ("cam modify", True, T.CAM_LINEAR, A.NONE, p2p(), M.MPIMessageUNSUPPORTED),
    ("attribute", True, T.VELOCITY, A.FINAL_VEL, p2p(final_velocity=[1.0, 1.0]),
     M.MPIMotionMessageATTRIBUTE_INVALID),
    ("param", True, T.TRAPEZOIDAL, A.NONE, p2p([1.0]), M.MPIMessagePARAM_INVALID),
    ("moving", False, T.TRAPEZOIDAL, A.NONE, p2p(), M.MPIMotionMessageMOVING),
    ("hold on modify", True, T.TRAPEZOIDAL, A.HOLD, full_params(), M.MPIMotionMessageATTRIBUTE_INVALID),
    ("no reversal", True, T.TRAPEZOIDAL, A.NO_REVERSAL, p2p((-100.0, 0.0)), M.MPIMotionMessagePROFILE_ERROR),
    ("illegal delay", True, T.TRAPEZOIDAL, A.DELAY, p2p(delay=[0.5, 0.0]), M.MPIMotionMessageILLEGAL_DELAY),
    ("frame buffer", True, T.S_CURVE, A.APPEND, p2p(trajectory=[Trajectory(1000.0, 1e4, 1e4, 50.0)]),
     M.MPIMotionMessageFRAME_BUFFER_TOO_SMALL),
]


@pytest.mark.parametrize(("name", "modify", "kind", "attrs", "request_params", "expected"), REFUSED,
                         ids=[r[0] for r in REFUSED])
def test_a_refused_command_changes_nothing(name, modify, kind, attrs, request_params, expected):
    # docs/quality.md, "Robust": bad input gets the reference's message and changes nothing; validate.py: "the first
    # failing check wins and nothing is changed"
    def setup(ctl, ms):
        start_moving(ctl, ms)
        if name == "frame buffer":
            ctl.config.frame_buffer_size = ctl.frame_count(0)  # the buffer is full now
    (ctl_a, ms_a), (ctl_b, ms_b) = twin(setup)
    command = ms_b.modify if modify else ms_b.start
    assert command(kind, attrs, request_params).message is expected
    assert observe(ctl_a, ms_a) == observe(ctl_b, ms_b)


EXTREME = [
    (T.VELOCITY, Trajectory(5e-324, 500.0, 500.0, 100.0)),
    (T.VELOCITY, Trajectory(-1e300, 1e-300, 1.0, 50.0)),
    (T.VELOCITY, Trajectory(1e300, 1e300, 1.0, 1e-300)),
    (T.S_CURVE, Trajectory(5e-324, 5e-324, 5e-324, 5e-324)),
    (T.S_CURVE, Trajectory(1e300, 1e300, 1e300, 100.0)),
    (T.S_CURVE, Trajectory(1.0, 1e-300, 1e300, 1e-300)),
    (T.TRAPEZOIDAL, Trajectory(1e-300, 1e300, 1e-300)),
]


@pytest.mark.parametrize(("kind", "traj"), EXTREME)
def test_extreme_valid_values_never_crash(ctl, ms, kind, traj):
    # docs/quality.md, "Robust": no input can crash a node or leave it inconsistent; bad input gets the
    # reference's message and changes nothing. Finite positive limits at the ends of the float range
    message = ms.start(kind, params=p2p((1e6, -1.0), trajectory=[traj])).message
    assert isinstance(message, M)
    for _ in range(5):
        ctl.step(1000)
        assert all(math.isfinite(x) for a in ctl.axes for x in (a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v))
    assert ms.action(MPIAction.ABORT).ok
    ctl.step(1)
    assert ms.action(MPIAction.RESET).ok
    assert ms.state is MPIState.IDLE
