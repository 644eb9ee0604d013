"""The motion-family records (mpi_ros/mpi/planning/families.py): one per type, complete, and
what the reference says of each type."""

from __future__ import annotations

from dataclasses import replace
from enum import IntEnum

import pytest

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import MotionParams, Trajectory
from mpi_ros.mpi.base.types import MotionAttr, MPIMotionType
from mpi_ros.mpi.planning.families import FAMILIES, Family, Kind, Shape, index, types_of
from mpi_ros.mpi.planning.validate import check_params, check_type


def test_every_type_but_invalid_has_exactly_one_record():
    assert set(FAMILIES) == set(MPIMotionType) - {MPIMotionType.INVALID}
    assert all(FAMILIES[t].type is t for t in FAMILIES)


def test_a_type_without_a_record_is_an_error_when_the_table_is_made():
    # A new member of the type enum with no record must not fall through to a default
    class Types(IntEnum):
        INVALID = 0
        TRAPEZOIDAL = MPIMotionType.TRAPEZOIDAL
        NEW_TYPE = 99

    with pytest.raises(ValueError, match=r"without a family record: \['NEW_TYPE'\]"):
        index([FAMILIES[MPIMotionType.TRAPEZOIDAL]], Types)


def test_a_type_with_two_records_is_an_error():
    record = FAMILIES[MPIMotionType.S_CURVE]
    with pytest.raises(ValueError, match="S_CURVE has two family records"):
        index([record, record], [MPIMotionType.S_CURVE])


@pytest.mark.parametrize(("change", "problem"), [
    ({"line": None}, "line profile"),
    ({"stop": None}, "stop profile"),
    ({"line": Shape.JERK, "stop": Shape.JERK}, "jerk-limited"),
    ({"limits": ("velocity", "jerk_percent")}, "limits must be trajectory fields"),
    ({"fields": ("position", "speed")}, "unknown goal fields"),
])
def test_an_inconsistent_record_is_refused(change, problem):
    with pytest.raises(ValueError, match=problem):
        replace(FAMILIES[MPIMotionType.S_CURVE], **change)


def test_only_point_to_point_families_have_a_stop_profile_and_every_one_has():
    # _stop_profile (planner.py) reads the record: no type falls through to the S-curve ramp
    for family in FAMILIES.values():
        assert (family.stop is not None) == (family.kind is Kind.POINT_TO_POINT)


def test_modifiable_types_are_the_spec_list_and_the_jerk_types():
    # MPI 000, mpiMotionModify "types of motion whose parameters can be modified while moving are
    # TRAPEZOIDAL, S_CURVE, VELOCITY, PT and PVT"; the jerk types replace the first three's
    # algorithm in firmware option 21 (MPI 000, MPIMotionType), so they modify alike
    modifiable = {t.name for t, f in FAMILIES.items() if f.modifiable}
    assert modifiable == {"TRAPEZOIDAL", "S_CURVE", "VELOCITY", "PT", "PVT", "S_CURVE_JERK", "VELOCITY_JERK"}


def test_jerk_types_need_firmware_option_21_and_plan_jerk_limited():
    # MPI 000, MPIMotionType: S_CURVE_JERK and VELOCITY_JERK are only available with option 21
    option = {t for t, f in FAMILIES.items() if f.option_21}
    assert option == {MPIMotionType.S_CURVE_JERK, MPIMotionType.VELOCITY_JERK}
    assert all(FAMILIES[t].line is Shape.JERK for t in option)


def test_the_kinds_group_the_reference_structures():
    # MPI 000, MPIMotionParams: the point-to-point, velocity, point (path), cam and frame structures
    assert types_of(Kind.POINT_TO_POINT) == {MPIMotionType.TRAPEZOIDAL, MPIMotionType.S_CURVE,
                                             MPIMotionType.S_CURVE_JERK}
    assert types_of(Kind.VELOCITY) == {MPIMotionType.VELOCITY, MPIMotionType.VELOCITY_JERK}
    assert types_of(Kind.CAM) == {MPIMotionType.CAM_LINEAR, MPIMotionType.CAM_CUBIC}
    assert types_of(Kind.FRAME) == {MPIMotionType.FRAME}
    assert len(types_of(Kind.PATH)) == 8


def test_only_spline_of_the_path_types_may_not_append():
    # MPI 000, mpiMotionStart ATTRIBUTE_INVALID: SPLINE may not carry APPEND
    assert {t for t in types_of(Kind.PATH) if not FAMILIES[t].appendable} == {MPIMotionType.SPLINE}


@pytest.mark.parametrize("motion_type", [t for t in MPIMotionType if t is not MPIMotionType.INVALID])
def test_check_type_answers_from_the_record(motion_type):
    family: Family = FAMILIES[motion_type]
    verdict = check_type(motion_type, modify=True, firmware_option_21=True)
    assert verdict.ok == family.modifiable
    without_option = check_type(motion_type, modify=False, firmware_option_21=False)
    assert without_option.message is (Message.MPIMotionMessagePROFILE_NOT_SUPPORTED if family.option_21
                                      else Message.MPIMessageOK)


def test_velocity_jerk_names_only_the_jerk_limit_it_reads():
    # MPI 000, MPIMotionVelocity: "velocity, acceleration, jerkPercent, and accelerationJerk
    # ... are applicable to velocity and velocity-jerk motion profiles"
    params = MotionParams(trajectory=[Trajectory(100.0, 1e4, 0.0, acceleration_jerk=0.0)])
    verdict = check_params(MPIMotionType.VELOCITY_JERK, MotionAttr.NONE, params, 1, 8, 4, 4)
    assert verdict.message is Message.MPIMessagePARAM_INVALID
    assert verdict.detail == "acceleration_jerk must be > 0"
    params.trajectory[0].acceleration_jerk = 1e6
    assert check_params(MPIMotionType.VELOCITY_JERK, MotionAttr.NONE, params, 1, 8, 4, 4).ok
