"""Validation of a start/modify request, before any calculation.

Implements MPI 000, "Returns for mpiMotionStart and mpiMotionModify" and the "possible
causes for receiving an MPIMotionMessageATTRIBUTE_INVALID" lists, plus the array-length rules
of docs/decisions.md, "The ROS contract: names, numbers, arrays". Each check answers the
reference's message; the first failing check wins and nothing is changed.
"""

from __future__ import annotations

import math
from dataclasses import replace

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import MAX_COORD_AXES, MAX_GATES, MAX_REQUEST_VALUES, Hold, MotionParams, Output
from mpi_ros.mpi.base.types import (
    CAM_ATTRS,
    CAM_TYPES,
    HOLD_ATTRS,
    JERK_TYPES,
    MODIFIABLE_TYPES,
    PATH_ATTRS,
    PATH_TYPES,
    POINT_TO_POINT_TYPES,
    VELOCITY_TYPES,
    HoldType,
    MotionAttr,
    MPIMotionType,
    OutputType,
)

A = MotionAttr
# MPI 000, ATTRIBUTE_INVALID lists for the point types, and the path attributes of MPI 001
# (MPIMotionPathAttrMask, the attributes of path motion: docs/paths.md).
_PATH_ALLOWED = A.APPEND | A.RELATIVE | A.ID | A.ELEMENT_ID | HOLD_ATTRS | A.OUTPUT | PATH_ATTRS
# MPI 000: which attributes each type may carry.
ALLOWED_ATTRIBUTES: dict[MPIMotionType, MotionAttr] = {
    MPIMotionType.PT: _PATH_ALLOWED,
    MPIMotionType.PTF: _PATH_ALLOWED,
    MPIMotionType.PVT: _PATH_ALLOWED,
    MPIMotionType.PVTF: _PATH_ALLOWED,
    MPIMotionType.SPLINE: _PATH_ALLOWED & ~A.APPEND,
    MPIMotionType.BESSEL: _PATH_ALLOWED,
    MPIMotionType.BSPLINE: _PATH_ALLOWED,
    MPIMotionType.BSPLINE2: _PATH_ALLOWED,
    MPIMotionType.FRAME: A.APPEND | A.ID,
    # The reference has no ATTRIBUTE_INVALID list for the cams: they take their own attributes
    # (MPIMotionAttrMask: REPEAT, MASTER_START, NO_BACKTRACK, NO_BACKTRACK_HOLD), ID and EVENT,
    # which every move may carry. A cam's slave distances are relative by definition
    # (MPIMotionCam), and its start is MASTER_START, not a time (DELAY) or a HOLD (docs/cams.md).
    MPIMotionType.CAM_LINEAR: CAM_ATTRS | A.ID | A.EVENT,
    MPIMotionType.CAM_CUBIC: CAM_ATTRS | A.ID | A.EVENT,
}
# MPI 000: "VELOCITY, VELOCITY_JERK Moves are not permitted to have the following".
FORBIDDEN_ATTRIBUTES: dict[MPIMotionType, MotionAttr] = {
    MPIMotionType.VELOCITY: A.SYNC_END | A.SYNC_START | A.FINAL_VEL | A.NO_REVERSAL,
    MPIMotionType.VELOCITY_JERK: A.SYNC_END | A.SYNC_START | A.FINAL_VEL | A.NO_REVERSAL,
}
# The same masks as plain ints, for the checks every start and modify runs: an IntFlag's & and
# ``in`` are Python calls (about a microsecond each in Python 3.11), an int's cost nothing.
_DISALLOWED_BITS = {motion_type: int(~allowed) for motion_type, allowed in ALLOWED_ATTRIBUTES.items()}
_FORBIDDEN_BITS = {motion_type: int(forbidden) for motion_type, forbidden in FORBIDDEN_ATTRIBUTES.items()}
_PATH_BITS, _CAM_BITS, _HOLD_BITS = int(PATH_ATTRS), int(CAM_ATTRS), int(HOLD_ATTRS)
_SYNC_BITS = int(A.SYNC_START | A.SYNC_END)
_DELAY, _FINAL_VEL, _OUTPUT, _ELEMENT_ID = int(A.DELAY), int(A.FINAL_VEL), int(A.OUTPUT), int(A.ELEMENT_ID)
_NO_BACKTRACK, _NO_BACKTRACK_HOLD = int(A.NO_BACKTRACK), int(A.NO_BACKTRACK_HOLD)
_HOLD_LESS, _HOLD_GREATER = int(A.HOLD_LESS), int(A.HOLD_GREATER)
# Every documented type is supported by the controller. (The list under MPI 000,
# mpiMotionStart is visibly incomplete: it leaves out VELOCITY and FRAME, which the same
# reference documents as supported, so it does not exclude the cams either.)
SUPPORTED_TYPES = frozenset(MPIMotionType) - {MPIMotionType.INVALID}
# Types this simulator executes: all of them.
STREAMED_TYPES = PATH_TYPES | {MPIMotionType.FRAME}
EXECUTED_TYPES = POINT_TO_POINT_TYPES | VELOCITY_TYPES | STREAMED_TYPES | CAM_TYPES
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
    if motion_type is MPIMotionType.INVALID:
        return _bad(Message.MPIMotionMessageTYPE_INVALID, "motion type INVALID")
    if motion_type in JERK_TYPES and not firmware_option_21:
        return _bad(
            Message.MPIMotionMessagePROFILE_NOT_SUPPORTED,
            f"{motion_type.name} needs firmware option 21 (controller.firmware_option_21)",
        )
    if motion_type not in SUPPORTED_TYPES:
        return _bad(Message.MPIMessageUNSUPPORTED, f"{motion_type.name} is not supported by the controller")
    appendable = append and A.APPEND & ALLOWED_ATTRIBUTES.get(motion_type, A.NONE)
    if modify and motion_type not in MODIFIABLE_TYPES and not appendable:
        return _bad(Message.MPIMessageUNSUPPORTED, f"{motion_type.name} moves cannot be modified")
    if motion_type not in EXECUTED_TYPES:
        return _bad(Message.MPIMessageUNSUPPORTED, f"{motion_type.name} motion is not simulated yet")
    return OK


def check_running_type(running: MPIMotionType) -> Outcome:
    """May a modify replace the motion in progress? MPI 000, mpiMotionModify: "The types of
    motion whose parameters can be modified while moving are ..." -- the running motion's
    type decides, whatever type the modify itself carries (a TRAPEZOIDAL modify may not
    replace a SPLINE or a cam)."""
    if running not in MODIFIABLE_TYPES:
        return _bad(Message.MPIMessageUNSUPPORTED, f"the {running.name} motion in progress cannot be modified")
    return OK


def check_attributes(
    motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, modify: bool
) -> Outcome:
    bad = Message.MPIMotionMessageATTRIBUTE_INVALID
    bits = int(attrs)
    if bits & _DISALLOWED_BITS.get(motion_type, 0):
        return _bad(bad, f"{motion_type.name} moves may not have {(attrs & ~ALLOWED_ATTRIBUTES[motion_type]).names()}")
    if bits & _FORBIDDEN_BITS.get(motion_type, 0):
        return _bad(bad, f"{motion_type.name} moves may not have {(attrs & FORBIDDEN_ATTRIBUTES[motion_type]).names()}")
    if motion_type not in PATH_TYPES and bits & _PATH_BITS:
        return _bad(bad, f"{(attrs & PATH_ATTRS).names()} are path attributes (MPI 001, MPIMotionPathAttrMask)")
    if motion_type not in CAM_TYPES and bits & _CAM_BITS:
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
    if motion_type in CAM_TYPES:
        return _check_cam(motion_type, attrs, params, axis_count)
    if motion_type in STREAMED_TYPES:
        verdict = _check_path_attributes(attrs, params, axis_count, frame_buffer_size)
        if not verdict.ok:
            return verdict
        return _check_path(motion_type, attrs, params, axis_count, io_words, motors, axes, sample_rate, append_to)
    velocity_type = motion_type in VELOCITY_TYPES
    per_axis = bool(int(attrs) & _SYNC_BITS)
    counts = {axis_count} if per_axis else ({1, axis_count} if velocity_type else {1})
    if len(params.trajectory) not in counts:
        want = " or ".join(str(c) for c in sorted(counts))
        return _bad(bad, f"trajectory needs {want} element(s), got {len(params.trajectory)}")
    if not velocity_type and len(params.position) != axis_count:
        return _bad(bad, f"position needs {axis_count} value(s) (one per axis), got {len(params.position)}")
    # Ranges of every value the move reads (emptyCount <= 0 included: it disables, 000/001).
    verdict = params.validate(motion_type, attrs)
    if not verdict.ok:
        return verdict
    for traj in params.trajectory:
        verdict = _check_trajectory(motion_type, traj)
        if not verdict.ok:
            return verdict
    return _check_attribute_data(attrs, params, axis_count, io_words, motors, axes, points=1)


def _check_attribute_data(attrs: MotionAttr, params: MotionParams, axis_count: int, io_words: int, motors: int,
                          axes: int, points: int) -> Outcome:
    """The arrays the attributes read, for a move of ``points`` points (1 for a
    point-to-point or velocity move)."""
    bad = Message.MPIMessagePARAM_INVALID
    bits = int(attrs)
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


def _check_path(motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, axis_count: int,
                io_words: int, motors: int, axes: int, sample_rate: float, append_to: bool) -> Outcome:
    """A path or FRAME request (MPI 000, MPIMotionPT .. MEIMotionFrame, MPIMotionPoint).

    Order: non-finite data first (MEIMotionMessageBAD_PATH_DATA: "If any of the motion
    parameters passed to the MPI for path motion are infinite or NAN ... will not load the
    move"), then the arrays' lengths and ranges (MPIMessagePARAM_INVALID: "The length of the
    array must be equal to pointCount multiplied by the number of axes"), then the path
    itself (MPIMotionMessagePATH_ERROR: "when the final point is not specified or the time
    slice is less than one controller sample")."""
    if not _finite_path_data(motion_type, params):
        return _bad(Message.MEIMotionMessageBAD_PATH_DATA, "a path value is infinite or NaN")
    bad = Message.MPIMessagePARAM_INVALID
    frame_type = motion_type is MPIMotionType.FRAME
    values = len(params.frames) if frame_type else len(params.position)
    if values > MAX_PATH_VALUES:
        return _bad(bad, f"{values} values in one request: at most {MAX_PATH_VALUES}; stream longer paths "
                         "with APPEND")
    points = len(params.frames) // axis_count if frame_type else len(params.time)
    verdict = _path_lengths(motion_type, params, axis_count, points)
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
    verdict = params.validate(motion_type, attrs)
    if not verdict.ok:
        return verdict
    verdict = _check_attribute_data(attrs, params, axis_count, io_words, motors, axes, points)
    if not verdict.ok:
        return verdict
    if A.ELEMENT_ID in attrs and len(params.element_id) not in (1, points):
        return _bad(bad, f"element_id needs 1 or {points} value(s) (one per point), got {len(params.element_id)}")
    return _check_path_shape(motion_type, params, sample_rate)


def _check_cam(motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, axis_count: int) -> Outcome:
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
    arrays = [("slave_position", params.slave_position)]
    if motion_type is MPIMotionType.CAM_CUBIC:
        arrays.append(("gear_ratio", params.gear_ratio))
    for name, values in arrays:
        if len(values) != points * axis_count:
            return _bad(bad, f"{name} needs pointCount x axes = {points} x {axis_count} value(s) (interleaved by "
                             f"axis), got {len(values)}")
    # "with linear cams this field is completely ignored" (MPIMotionCam, gearRatio): not read
    read = params if motion_type is MPIMotionType.CAM_CUBIC else replace(params, gear_ratio=[])
    verdict = read.validate(motion_type, attrs)
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


def _finite_path_data(motion_type: MPIMotionType, params: MotionParams) -> bool:
    arrays = [params.position, params.time, params.point_velocity, params.feedforward]
    arrays += [[f.position, f.velocity, f.acceleration, f.jerk, f.time] for f in params.frames]
    return all(_finite(x) for values in arrays for x in values)


def _finite(value: object) -> bool:
    try:
        return math.isfinite(value)  # type: ignore[arg-type]
    except (TypeError, OverflowError):
        return True  # not a number at all: the range checks answer it (PARAM_INVALID)


def _path_lengths(motion_type: MPIMotionType, params: MotionParams, axis_count: int, points: int) -> Outcome:
    bad = Message.MPIMessagePARAM_INVALID
    if motion_type is MPIMotionType.FRAME:
        if len(params.frames) % axis_count:
            return _bad(bad, f"frames needs a multiple of {axis_count} (frames per axis, interleaved by axis), "
                             f"got {len(params.frames)}")
        return OK
    arrays = [("position", params.position)]
    if motion_type in (MPIMotionType.PVT, MPIMotionType.PVTF):
        arrays.append(("point_velocity", params.point_velocity))
    if motion_type in (MPIMotionType.PTF, MPIMotionType.PVTF):
        arrays.append(("feedforward", params.feedforward))
    for name, values in arrays:
        if len(values) != points * axis_count:
            return _bad(bad, f"{name} needs pointCount x axes = {points} x {axis_count} value(s) (one time per "
                             f"point), got {len(values)}")
    return OK


def _check_path_shape(motion_type: MPIMotionType, params: MotionParams, sample_rate: float) -> Outcome:
    bad = Message.MPIMotionMessagePATH_ERROR
    if not params.final and not A.APPEND & ALLOWED_ATTRIBUTES[motion_type]:
        return _bad(bad, f"final is false, but no points can be appended to a {motion_type.name} path "
                         "(it may not carry APPEND): give the final point")
    slices = [f.time for f in params.frames] if motion_type is MPIMotionType.FRAME else list(params.time)
    if sample_rate > 0.0 and slices and min(slices) < (1.0 - 1e-9) / sample_rate:
        return _bad(bad, f"a time slice of {min(slices)!r} s is less than one controller sample "
                         f"({1.0 / sample_rate!r} s)")
    return OK


def _check_trajectory(motion_type: MPIMotionType, traj) -> Outcome:
    bad = Message.MPIMessagePARAM_INVALID
    if motion_type in VELOCITY_TYPES:
        if traj.acceleration <= 0.0:
            return _bad(bad, "acceleration must be > 0")
    else:
        if traj.velocity <= 0.0 or traj.acceleration <= 0.0 or traj.deceleration <= 0.0:
            return _bad(bad, "velocity, acceleration and deceleration must be > 0")
    if motion_type in JERK_TYPES:
        if traj.acceleration_jerk <= 0.0 or (
            motion_type is MPIMotionType.S_CURVE_JERK and traj.deceleration_jerk <= 0.0
        ):
            return _bad(bad, "acceleration_jerk and deceleration_jerk must be > 0")
    elif not 0.0 <= traj.jerk_percent <= 100.0:
        return _bad(bad, "jerk_percent must be within 0..100")
    return OK


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
