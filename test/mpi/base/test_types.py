"""Enumerations (mpi_ros/mpi/base/types.py): the spec's names and the ROS contract's numbers."""

from __future__ import annotations

from mpi_ros.mpi.base.types import (
    HoldType,
    MotionAttr,
    MPIAction,
    MPIMotionType,
    MPIState,
    OutputType,
)


def test_state_numbers_are_the_ros_contract():
    # docs/decisions.md, "The ROS contract": state numbers 0 INVALID, 1 IDLE, 2 MOVING, 3 STOPPING,
    # 4 STOPPED, 5 STOPPING_ERROR, 6 ERROR
    assert [(s.name, int(s)) for s in MPIState] == [
        ("INVALID", 0), ("IDLE", 1), ("MOVING", 2), ("STOPPING", 3), ("STOPPED", 4),
        ("STOPPING_ERROR", 5), ("ERROR", 6)]


def test_motion_types_in_the_order_of_the_spec():
    # MPI 000, MPIMotionType MPIMotionType enum; MPI 000, MEIMotionType MEIMotionTypeFRAME
    assert [t.name for t in MPIMotionType] == [
        "INVALID", "PT", "PTF", "PVT", "PVTF", "SPLINE", "BESSEL", "BSPLINE", "BSPLINE2", "S_CURVE",
        "TRAPEZOIDAL", "S_CURVE_JERK", "VELOCITY", "VELOCITY_JERK", "CAM_LINEAR", "CAM_CUBIC", "FRAME"]


def test_actions_include_every_mpi_action_and_map():
    # MPI 000, mpiMotionAction the actions of mpiMotionAction and MEIActionMAP
    names = {a.name for a in MPIAction}
    assert {"STOP", "E_STOP", "ABORT", "E_STOP_ABORT", "RESET", "RESUME", "MAP"} <= names


def test_attribute_masks_mpi_then_mei_in_spec_order():
    # MPI 000, MPIMotionAttrMask MPIMotionAttrMask and MPI 000, MEIMotionAttrMask MEIMotionAttrMask; each is one bit
    # (MPI 000, mpiMotionAttrMaskBIT mpiMotionAttrMaskBIT(attr) = 0x1 << attr)
    mpi = ["APPEND", "AUTO_START", "DELAY", "ID", "ELEMENT_ID", "RELATIVE", "SYNC_END", "SYNC_START",
           "REPEAT", "MASTER_START", "NO_BACKTRACK", "NO_BACKTRACK_HOLD"]
    mei = ["EVENT", "FINAL_VEL", "NO_REVERSAL", "HOLD", "HOLD_LESS", "HOLD_GREATER", "OUTPUT"]
    assert [int(MotionAttr[n]) for n in mpi] == [1 << i for i in range(len(mpi))]
    mei_bits = [int(MotionAttr[n]) for n in mei]
    assert mei_bits == sorted(mei_bits)
    assert all(b & (b - 1) == 0 for b in mei_bits)
    assert not (sum(mei_bits) & sum(1 << i for i in range(len(mpi))))


def test_attribute_parse_accepts_names_and_rejects_unknown():
    # docs/decisions.md, "The ROS contract": attribute names go without their prefix
    assert MotionAttr.parse(["APPEND", " hold ", "ID"]) == MotionAttr.APPEND | MotionAttr.HOLD | MotionAttr.ID
    assert MotionAttr.parse([]) == MotionAttr.NONE
    assert MotionAttr.parse(["APPEND", "NOT_AN_ATTRIBUTE"]) is None
    assert MotionAttr.parse(["NONE"]) is None
    assert (MotionAttr.APPEND | MotionAttr.OUTPUT).names() == ["APPEND", "OUTPUT"]


def test_hold_and_output_types_in_spec_order():
    # MPI 000, MEIMotionAttrHoldType MEIMotionAttrHoldType; MPI 000, MEIMotionAttrOutputType MEIMotionAttrOutputType
    assert [t.name for t in HoldType] == [
        "INVALID", "NONE", "GATE", "INPUT", "MOTOR_GENERAL_IO", "MOTOR_DEDICATED_IO",
        "AXIS_POSITION_ACTUAL", "AXIS_POSITION_COMMAND", "USER_ADDRESS"]
    assert [t.name for t in OutputType] == ["INVALID", "NONE", "MOTOR", "OUTPUT"]
