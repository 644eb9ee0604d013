"""Validation of a start/modify request, before any calculation.

Implements MPI 000, "Returns for mpiMotionStart and mpiMotionModify" and the "possible
causes for receiving an MPIMotionMessageATTRIBUTE_INVALID" lists (each type's list is its
record in families.py), plus the array-length rules of docs/decisions.md, "The ROS contract:
names, numbers, arrays". Each check answers the
reference's message; the first failing check wins and nothing is changed.
"""

from __future__ import annotations

import math
from dataclasses import replace

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import (
    MAX_COORD_AXES,
    MAX_GATES,
    MAX_REQUEST_VALUES,
    Hold,
    MotionParams,
    Output,
    Trajectory,
)
from mpi_ros.mpi.base.types import CAM_ATTRS, HOLD_ATTRS, PATH_ATTRS, HoldType, MotionAttr, MPIMotionType, OutputType
from mpi_ros.mpi.planning.families import FAMILIES, POINT_ARRAYS, Family, Kind

A = MotionAttr
# The attribute masks of each type's record as plain ints, for the checks every start and
# modify runs: an IntFlag's & and ``in`` are Python calls, an int's are not. (Types whose
# record has no list of the reference have none.)
_DISALLOWED_BITS = {t: int(~f.allowed) for t, f in FAMILIES.items() if f.allowed is not None}
_FORBIDDEN_BITS = {t: int(f.forbidden) for t, f in FAMILIES.items() if f.forbidden}
_PATH_BITS, _CAM_BITS, _HOLD_BITS = int(PATH_ATTRS), int(CAM_ATTRS), int(HOLD_ATTRS)
_SYNC_BITS = int(A.SYNC_START | A.SYNC_END)
_DELAY, _FINAL_VEL, _OUTPUT, _ELEMENT_ID = int(A.DELAY), int(A.FINAL_VEL), int(A.OUTPUT), int(A.ELEMENT_ID)
_NO_BACKTRACK, _NO_BACKTRACK_HOLD = int(A.NO_BACKTRACK), int(A.NO_BACKTRACK_HOLD)
_HOLD_LESS, _HOLD_GREATER = int(A.HOLD_LESS), int(A.HOLD_GREATER)
# The attributes whose data _check_attribute_data reads
_ATTRIBUTE_DATA = _DELAY | _FINAL_VEL | _HOLD_BITS | _OUTPUT | _ELEMENT_ID
# The arrays of pointCount x axes values each path type reads (MPIMotionPT .. MPIMotionPVTF)
_POINT_ARRAYS = {t: tuple(name for name in POINT_ARRAYS if name in f.fields) for t, f in FAMILIES.items()}
# The most values one path request may carry (positions, or frames, over all its axes): a
# bound on the memory and planning time a single request can claim (1 << 20 took 5 s to
# plan, holding the controller). A longer path is streamed in requests (APPEND), as the
# controller's frame buffer is fed anyway. The same bound as a request's arrays in all
# (params.MAX_REQUEST_VALUES), which the command layer checks before reading a request.
MAX_PATH_VALUES = MAX_REQUEST_VALUES


OK = Outcome(Message.MPIMessageOK)


def _bad(message: Message, detail: str) -> Outcome:
    return Outcome(message, detail)


def check_type(
    motion_type: MPIMotionType, modify: bool, firmware_option_21: bool, append: bool = False
) -> Outcome:
    """Is the type known, supported and (for a modify) modifiable? A modify with APPEND adds
    points to a path and changes nothing of the motion in progress, so it is open to every
    type that may carry APPEND (docs/paths.md), not only to the types MPI 000, mpiMotionModify
    lists as modifiable."""
    family = FAMILIES.get(motion_type)
    if family is None:  # (INVALID: every other type has a record, families.index)
        return _bad(Message.MPIMotionMessageTYPE_INVALID, f"motion type {motion_type.name}")
    if family.option_21 and not firmware_option_21:
        return _bad(
            Message.MPIMotionMessagePROFILE_NOT_SUPPORTED,
            f"{motion_type.name} needs firmware option 21 (controller.firmware_option_21)",
        )
    # (Every documented type is supported: the list under MPI 000, mpiMotionStart is visibly
    # incomplete, leaving out VELOCITY and FRAME, which the same reference documents.)
    if modify and not family.modifiable and not (append and family.appendable):
        return _bad(Message.MPIMessageUNSUPPORTED, f"{motion_type.name} moves cannot be modified")
    return OK


def check_running_type(running: MPIMotionType) -> Outcome:
    """May a modify replace the motion in progress? MPI 000, mpiMotionModify: "The types of
    motion whose parameters can be modified while moving are ..." -- the running motion's
    type decides, whatever type the modify itself carries (a TRAPEZOIDAL modify may not
    replace a SPLINE or a cam)."""
    family = FAMILIES.get(running)
    if family is None or not family.modifiable:
        return _bad(Message.MPIMessageUNSUPPORTED, f"the {running.name} motion in progress cannot be modified")
    return OK


def check_attributes(
    motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, modify: bool
) -> Outcome:
    bits = int(attrs)
    if not bits:  # (the usual start or modify: every check below is of an attribute given)
        return OK
    bad = Message.MPIMotionMessageATTRIBUTE_INVALID
    disallowed = bits & (_DISALLOWED_BITS.get(motion_type, 0) | _FORBIDDEN_BITS.get(motion_type, 0))
    if disallowed:
        return _bad(bad, f"{motion_type.name} moves may not have {MotionAttr(disallowed).names()}")
    kind = FAMILIES[motion_type].kind
    if kind is not Kind.PATH and bits & _PATH_BITS:
        return _bad(bad, f"{(attrs & PATH_ATTRS).names()} are path attributes (MPI 001, MPIMotionPathAttrMask)")
    if kind is not Kind.CAM and bits & _CAM_BITS:
        return _bad(bad, f"{(attrs & CAM_ATTRS).names()} are cam attributes")
    if bits & _NO_BACKTRACK and bits & _NO_BACKTRACK_HOLD:
        return _bad(bad, "NO_BACKTRACK and NO_BACKTRACK_HOLD exclude each other")
    if modify and bits & _HOLD_BITS:
        return _bad(bad, "HOLD, HOLD_LESS and HOLD_GREATER are not permitted during motion modifies")
    if bits & _HOLD_LESS and bits & _HOLD_GREATER:
        return _bad(bad, "HOLD_LESS and HOLD_GREATER exclude each other")
    # "attribute specified and its address is NULL": an empty array here.
    if bits & _DELAY and not params.delay:
        return _bad(bad, "DELAY attribute specified and delay is empty")
    if bits & _FINAL_VEL and not params.final_velocity:
        return _bad(bad, "FINAL_VEL attribute specified and final_velocity is empty")
    if bits & _HOLD_BITS and not params.hold:
        return _bad(bad, "HOLD attribute specified and hold is empty")
    if bits & _OUTPUT and not params.output:
        return _bad(bad, "OUTPUT attribute specified and output is empty")
    return OK


def check_params(
    motion_type: MPIMotionType,
    attrs: MotionAttr,
    params: MotionParams,
    axis_count: int,
    io_words: int,
    motors: int,
    axes: int,
    sample_rate: float = 0.0,
    append_to: bool = False,
    frame_buffer_size: int = 128,
) -> Outcome:
    """The request's values for a move of ``axis_count`` axes (``sample_rate``: the
    controller's, for a path's time slices; ``append_to``: the points go to an open path;
    ``frame_buffer_size``: the axes', for LOW_COUNT)."""
    bad = Message.MPIMessagePARAM_INVALID
    if axis_count > MAX_COORD_AXES:
        return _bad(Message.MPIMessageARG_INVALID, f"{axis_count} axes exceed MEIXmpMAX_COORD_AXES ({MAX_COORD_AXES})")
    family = FAMILIES[motion_type]
    kind = family.kind
    if kind is Kind.CAM:
        return _check_cam(family, attrs, params, axis_count)
    if kind.streamed:
        verdict = _check_path_attributes(attrs, params, axis_count, frame_buffer_size)
        if not verdict.ok:
            return verdict
        return _check_path(family, attrs, params, axis_count, io_words, motors, axes, sample_rate, append_to)
    velocity_type = kind is Kind.VELOCITY
    per_axis = bool(int(attrs) & _SYNC_BITS)
    counts = {axis_count} if per_axis else ({1, axis_count} if velocity_type else {1})
    if len(params.trajectory) not in counts:
        want = " or ".join(str(c) for c in sorted(counts))
        return _bad(bad, f"trajectory needs {want} element(s), got {len(params.trajectory)}")
    if not velocity_type and len(params.position) != axis_count:
        return _bad(bad, f"position needs {axis_count} value(s) (one per axis), got {len(params.position)}")
    # Ranges of every value the move reads (emptyCount <= 0 included: it disables, 000/001).
    verdict = params.validate(attrs, position=kind.reads_position, path_data=kind.reads_path_data)
    if not verdict.ok:
        return verdict
    for traj in params.trajectory:
        verdict = _check_trajectory(family, traj)
        if not verdict.ok:
            return verdict
    return _check_attribute_data(attrs, params, axis_count, io_words, motors, axes, points=1)


def _check_attribute_data(attrs: MotionAttr, params: MotionParams, axis_count: int, io_words: int, motors: int,
                          axes: int, points: int) -> Outcome:
    """The arrays the attributes read, for a move of ``points`` points (1 for a
    point-to-point or velocity move)."""
    bits = int(attrs)
    if not bits & _ATTRIBUTE_DATA:  # (the usual move: none of the arrays below is read)
        return OK
    bad = Message.MPIMessagePARAM_INVALID
    for name, attr, values in (
        ("delay", _DELAY, params.delay),
        ("final_velocity", _FINAL_VEL, params.final_velocity),
        ("hold", _HOLD_BITS, params.hold),
    ):
        if bits & attr and len(values) != axis_count:
            return _bad(bad, f"{name} needs {axis_count} value(s) (one per axis), got {len(values)}")
    if bits & _HOLD_BITS:
        for hold in params.hold:
            verdict = _check_hold(hold, attrs, io_words, motors, axes)
            if not verdict.ok:
                return verdict
    if bits & _OUTPUT:
        for output in params.output:
            verdict = _check_output(output, io_words, motors)
            if not verdict.ok:
                return verdict
            if not 0 <= output.point_index < max(points, 1):
                # MEIMotionAttrOutput.pointIndex picks a point "when multiple point motion is
                # used"; a point-to-point or velocity move has one, index 0.
                return _bad(bad, f"output point_index {output.point_index}: the move has {points} point(s) "
                                 f"(index 0..{max(points, 1) - 1})")
    if bits & _ELEMENT_ID and not params.element_id:
        return _bad(bad, "ELEMENT_ID attribute specified and element_id is empty")
    return OK


def _check_path(family: Family, attrs: MotionAttr, params: MotionParams, axis_count: int,
                io_words: int, motors: int, axes: int, sample_rate: float, append_to: bool) -> Outcome:
    """A path or FRAME request (MPI 000, MPIMotionPT .. MEIMotionFrame, MPIMotionPoint).

    Order: non-finite data first (MEIMotionMessageBAD_PATH_DATA: "If any of the motion
    parameters passed to the MPI for path motion are infinite or NAN ... will not load the
    move"), then the arrays' lengths and ranges (MPIMessagePARAM_INVALID: "The length of the
    array must be equal to pointCount multiplied by the number of axes"), then the path
    itself (MPIMotionMessagePATH_ERROR: "when the final point is not specified or the time
    slice is less than one controller sample")."""
    if not _finite_path_data(params):
        return _bad(Message.MEIMotionMessageBAD_PATH_DATA, "a path value is infinite or NaN")
    bad = Message.MPIMessagePARAM_INVALID
    frame_type = family.kind is Kind.FRAME
    values = len(params.frames) if frame_type else len(params.position)
    if values > MAX_PATH_VALUES:
        return _bad(bad, f"{values} values in one request: at most {MAX_PATH_VALUES}; stream longer paths "
                         "with APPEND")
    points = len(params.frames) // axis_count if frame_type else len(params.time)
    verdict = _path_lengths(family, params, axis_count, points)
    if not verdict.ok:
        return verdict
    if points == 0 and not append_to:
        return _bad(bad, "a path needs at least one point")
    if params.retain or A.RETAIN in attrs:
        # MPIMotionPoint.retain and MPI 001 RETAIN keep executed points "for backing up on
        # path", but the reference names no call that backs up along a path: retained points
        # could never be used. Refused rather than accepted and ignored (docs/paths.md).
        return _bad(Message.MPIMessageUNSUPPORTED, "retain: the MPI names no way to back up along a path, so "
                                                   "executed points are not kept; give retain false")
    verdict = params.validate(attrs)
    if not verdict.ok:
        return verdict
    verdict = _check_attribute_data(attrs, params, axis_count, io_words, motors, axes, points)
    if not verdict.ok:
        return verdict
    if A.ELEMENT_ID in attrs and len(params.element_id) not in (1, points):
        return _bad(bad, f"element_id needs 1 or {points} value(s) (one per point), got {len(params.element_id)}")
    return _check_path_shape(family, params, sample_rate)


def _check_cam(family: Family, attrs: MotionAttr, params: MotionParams, axis_count: int) -> Outcome:
    """A cam (MPI 000, MPIMotionCam): pointCount segments, each with a master distance
    (masterDistance: pointCount elements), a slave distance per axis (slavePosition) and, for
    CAM_CUBIC, a gear ratio per axis at its end (gearRatio; a linear cam ignores it). The
    arrays are interleaved by axis like a path's positions. Values are finite and in range
    (MPIMessagePARAM_INVALID, as for any move's values); a master distance of zero would make a
    segment the master never moves through, and distances of both signs a table the master
    runs through back and forth: both refused (docs/cams.md). REPEAT's repeatFrom is "the
    first frame that is repeated" (MPI 000, MPIMotionAttributes): one of the segments."""
    bad = Message.MPIMessagePARAM_INVALID
    points = len(params.master_distance)
    if points == 0:
        return _bad(bad, "master_distance: a cam needs at least one segment (pointCount >= 1)")
    if points * axis_count > MAX_PATH_VALUES:
        return _bad(bad, f"{points} segments x {axis_count} axes: at most {MAX_PATH_VALUES} values in one request")
    cubic = "gear_ratio" in family.fields
    for name in family.fields[1:]:  # (after master_distance, which gives pointCount)
        values = getattr(params, name)
        if len(values) != points * axis_count:
            return _bad(bad, f"{name} needs pointCount x axes = {points} x {axis_count} value(s) (interleaved by "
                             f"axis), got {len(values)}")
    # "with linear cams this field is completely ignored" (MPIMotionCam, gearRatio): not read
    read = params if cubic else replace(params, gear_ratio=[])
    verdict = read.validate(attrs)
    if not verdict.ok:
        return verdict
    if any(d == 0.0 for d in params.master_distance):
        return _bad(bad, "master_distance: every segment's master distance must be non-zero")
    if any(d > 0.0 for d in params.master_distance) and any(d < 0.0 for d in params.master_distance):
        return _bad(bad, "master_distance: all of one sign (the direction of the master along the table)")
    if A.REPEAT in attrs and not 0 <= params.repeat_from < points:
        return _bad(bad, f"repeat_from {params.repeat_from}: must be a segment of the cam, 0..{points - 1}")
    return OK


def _check_path_attributes(attrs: MotionAttr, params: MotionParams, axis_count: int,
                           frame_buffer_size: int) -> Outcome:
    """The fields of MPI 001's path attributes (MPIMotionPathAttributes), read only with
    their attribute."""
    if A.EXPECTED_AXES in attrs and params.expected_axes != axis_count:
        # MPI 001 EXPECTED_AXES: "checked against the number of currently mapped axes, and if
        # they don't match an error will result": the error of a wrong axis count.
        return _bad(Message.MPIMotionMessageAXIS_COUNT,
                    f"expected_axes {params.expected_axes}, but the supervisor has {axis_count} axes")
    if A.BEHAVIOR in attrs and params.behavior != 0:
        # MPI 001 BEHAVIOR selects "a non-default behavior", but names none: 0 is the default.
        return _bad(Message.MPIMessagePARAM_INVALID, f"behavior {params.behavior}: the MPI documents no path "
                                                     "behaviour but the default (0)")
    if A.LOW_COUNT in attrs and not 0 <= params.low_count <= frame_buffer_size:
        return _bad(Message.MPIMessagePARAM_INVALID, f"low_count {params.low_count}: must be 0..{frame_buffer_size} "
                                                     "(the frame buffer's size)")
    return OK


def _finite_path_data(params: MotionParams) -> bool:
    arrays = [params.position, params.time, params.point_velocity, params.feedforward]
    arrays += [[f.position, f.velocity, f.acceleration, f.jerk, f.time] for f in params.frames]
    return all(_finite(x) for values in arrays for x in values)


def _finite(value: object) -> bool:
    try:
        return math.isfinite(value)  # type: ignore[arg-type]
    except (TypeError, OverflowError):
        return True  # not a number at all: the range checks answer it (PARAM_INVALID)


def _path_lengths(family: Family, params: MotionParams, axis_count: int, points: int) -> Outcome:
    bad = Message.MPIMessagePARAM_INVALID
    if family.kind is Kind.FRAME:
        if len(params.frames) % axis_count:
            return _bad(bad, f"frames needs a multiple of {axis_count} (frames per axis, interleaved by axis), "
                             f"got {len(params.frames)}")
        return OK
    for name in _POINT_ARRAYS[family.type]:
        values = getattr(params, name)
        if len(values) != points * axis_count:
            return _bad(bad, f"{name} needs pointCount x axes = {points} x {axis_count} value(s) (one time per "
                             f"point), got {len(values)}")
    return OK


def _check_path_shape(family: Family, params: MotionParams, sample_rate: float) -> Outcome:
    bad = Message.MPIMotionMessagePATH_ERROR
    if not params.final and not family.appendable:
        return _bad(bad, f"final is false, but no points can be appended to a {family.type.name} path "
                         "(it may not carry APPEND): give the final point")
    slices = [f.time for f in params.frames] if family.kind is Kind.FRAME else list(params.time)
    if sample_rate > 0.0 and slices and min(slices) < (1.0 - 1e-9) / sample_rate:
        return _bad(bad, f"a time slice of {min(slices)!r} s is less than one controller sample "
                         f"({1.0 / sample_rate!r} s)")
    return OK


def _check_trajectory(family: Family, traj: Trajectory) -> Outcome:
    """The limits the family's profile divides by must be > 0 (MPI 000, MPITrajectory)."""
    bad = Message.MPIMessagePARAM_INVALID
    for names in (family.limits, family.jerk_limits):
        for name in names:
            if getattr(traj, name) <= 0.0:
                return _bad(bad, f"{_listed(names)} must be > 0")
    if not family.jerk_limits and not 0.0 <= traj.jerk_percent <= 100.0:
        return _bad(bad, "jerk_percent must be within 0..100")
    return OK


def _listed(names: tuple[str, ...]) -> str:
    """"a", "a and b", "a, b and c"."""
    return " and ".join(filter(None, (", ".join(names[:-1]), names[-1])))


def _check_hold(hold: Hold, attrs: MotionAttr, io_words: int, motors: int, axes: int) -> Outcome:
    bad = Message.MPIMessagePARAM_INVALID
    kind = hold.type
    if kind is HoldType.INVALID:
        return _bad(bad, "hold type INVALID")
    if kind is HoldType.GATE and not 0 <= hold.gate < MAX_GATES:
        return _bad(bad, f"hold gate must be 0..{MAX_GATES - 1}")
    if kind in (HoldType.INPUT, HoldType.USER_ADDRESS) and not 0 <= hold.address < io_words:
        return _bad(bad, f"hold address must be an I/O word 0..{io_words - 1}")
    if kind in (HoldType.MOTOR_GENERAL_IO, HoldType.MOTOR_DEDICATED_IO) and not 0 <= hold.number < motors:
        return _bad(bad, f"hold motor must be 0..{motors - 1}")
    if kind in (HoldType.AXIS_POSITION_ACTUAL, HoldType.AXIS_POSITION_COMMAND) and not 0 <= hold.number < axes:
        return _bad(bad, f"hold axis must be 0..{axes - 1}")
    return OK


def _check_output(output: Output, io_words: int, motors: int) -> Outcome:
    bad = Message.MPIMessagePARAM_INVALID
    if output.type is OutputType.INVALID:
        return _bad(bad, "output type INVALID")
    if output.type is OutputType.OUTPUT and not 0 <= output.address < io_words:
        return _bad(bad, f"output address must be an I/O word 0..{io_words - 1}")
    if output.type is OutputType.MOTOR and not 0 <= output.motor < motors:
        return _bad(bad, f"output motor must be 0..{motors - 1}")
    return OK
