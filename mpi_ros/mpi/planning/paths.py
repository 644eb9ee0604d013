"""Path (streaming point) moves: PT, PTF, PVT, PVTF, SPLINE, BESSEL, BSPLINE, BSPLINE2, FRAME.

A path request compiles, per axis, into constant-jerk segments (profiles/path.py computes
them; FRAME moves give them directly), the same AxisPlan every move runs on. What makes a
path different from a point-to-point move lives here:

- it starts at the command position when the move begins; point i is reached dt_i after
  point i-1, the first dt_0 after the start (MPI 000, Streaming Point Motion Type
  Calculations: "Any given dt defining a point also specifies how long it will take to
  arrive at that point"); positions are interleaved by axis, one time per point;
- the shortest-path rule for the first point (MPI 000, MPIMotionType, example): the
  controller's positions are 32-bit, so the first point is taken as the one of its values
  2^32 apart that lies nearest the current position; the points after it keep their
  distances to it (the rule "DOES NOT apply to points within the points list");
- it may be open (MPIMotionPoint.final false): more points arrive with APPEND and extend
  the path where it ends; executed points are flushed (docs/paths.md);
- per point: an element id (ELEMENT_ID), outputs by pointIndex (OUTPUT), the frame count.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.params import MotionParams, Output
from mpi_ros.mpi.base.types import HOLD_ATTRS, MotionAttr, MPIMotionType
from mpi_ros.mpi.base.wrap import WRAP
from mpi_ros.mpi.planning.families import FAMILIES, Kind
from mpi_ros.mpi.planning.frames import AxisPlan, Listed, reached
from mpi_ros.mpi.planning.profiles.path import PathKind, SplineHistory, path_segments, peaks
from mpi_ros.mpi.planning.profiles.segment import Segment

A = MotionAttr


def _path_kind(motion_type: MPIMotionType) -> PathKind:
    """The path kind a path type is planned as (its family record)."""
    kind = FAMILIES[motion_type].path
    if kind is None:
        raise ValueError(f"{motion_type.name} is not a path type")
    return kind


def _is_frame(motion_type: MPIMotionType) -> bool:
    return FAMILIES[motion_type].kind is Kind.FRAME


# How closely a frame must begin where the axis is (counts, counts/s): the user computes each
# frame's start from the one before it in floating point, which rounds far below a count.
FRAME_JOIN_ABS = 1e-6
FRAME_JOIN_REL = 1e-12


@dataclass(slots=True)
class PathStart:
    """Where an axis' points start: raw command position and velocity (profile time), and
    the axis' origin (user positions are raw minus origin)."""

    axis: int
    position: float
    velocity: float
    origin: float


def point_count(motion_type: MPIMotionType, params: MotionParams, axes: int) -> int:
    """pointCount of a request: frames per axis for FRAME, else one per time."""
    if _is_frame(motion_type):
        return len(params.frames) // axes if axes else 0
    return len(params.time)


def compile_path(motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams,
                 starts: list[PathStart], relative: bool) -> tuple[list[AxisPlan], list[tuple[float, float]]]:
    """Per-axis plans of a (validated) path request starting at ``starts``, and each axis'
    peak velocity and acceleration. Times in the plans are profile time from the start."""
    axes = len(starts)
    frame_type = _is_frame(motion_type)
    if frame_type:
        per_axis = _frame_segments(params, starts)
        times = [[f.time for f in params.frames[k::axes]] for k in range(axes)]
        ends = [segments[-1].end_state()[0] if segments else start.position
                for segments, start in zip(per_axis, starts, strict=True)]
    else:
        points = _points(params, starts, relative)
        path_kind = _path_kind(motion_type)
        velocities = np.asarray(params.point_velocity, dtype=float).reshape(-1, axes) if \
            path_kind is PathKind.PVT else None
        per_axis = [
            path_segments(path_kind, start.position, start.velocity, points[:, k], params.time,
                          None if velocities is None else velocities[:, k])
            for k, start in enumerate(starts)
        ]
        times = [list(params.time)] * axes
        # Every kind ends exactly on its last point (the segments reach it within rounding;
        # the command is put on it when the path is done, AxisPlan.evaluate).
        ends = [float(points[-1, k]) for k in range(axes)]
        histories = [_history(path_kind, start, points[:, k], params.time) for k, start in enumerate(starts)]
        if not params.final and histories[0] is not None:
            # An open B-spline runs only as far as its points settle it (docs/paths.md).
            per_axis = [history.pieces(0.0, final=False) for history in histories if history is not None]
            ends = [_curve_end(segments, start.position) for segments, start in zip(per_axis, starts, strict=True)]
    element_ids = _element_ids(params, attrs, len(times[0]) if times else 0)
    feedforward = _feedforward(motion_type, params, axes)
    plans = []
    for k, (start, segments) in enumerate(zip(starts, per_axis, strict=True)):
        point_times = np.cumsum(np.asarray(times[k], dtype=float))
        timed = timed_outputs(params, attrs, point_times, 0.0) if k == 0 else []
        plans.append(AxisPlan(
            axis=start.axis, source=Listed(segments), start_position=start.position, target=ends[k],
            outputs=[out for when, out in timed if when <= 0.0], start_velocity=start.velocity,
            point_times=point_times, element_ids=element_ids,
            timed_outputs=[(when, out) for when, out in timed if when > 0.0],
            hold=params.hold[k] if attrs & HOLD_ATTRS else None,
            feedforward=None if feedforward is None else _knots(0.0, math.nan, point_times, feedforward[:, k]),
            spline=None if frame_type else histories[k],
        ))
    return plans, [peaks(plan.segments) for plan in plans]


def _history(kind: PathKind, start: PathStart, points: np.ndarray,
             dts: list[float]) -> SplineHistory | None:
    """A B-spline's control points and dts (None for the other kinds)."""
    if kind not in (PathKind.BSPLINE, PathKind.BSPLINE2):
        return None
    values = (float(start.position), *(float(x) for x in points))
    return SplineHistory(kind, 0.0, values, tuple(float(dt) for dt in dts))


def _curve_end(segments: list[Segment], start: float) -> float:
    """Where the segments end (``start`` if there are none)."""
    return float(segments[-1].end_state()[0]) if segments else start


@dataclass(frozen=True, slots=True)
class SplineContinuation:
    """Points appended to a B-spline path: the curve's history with them (``history``), the
    segments that follow the plan's end, the new points' times from there, where the plan now
    ends, and the time shift of the plan's pending points beyond ``settled`` (its old end)."""

    history: SplineHistory
    segments: list[Segment]
    point_times: np.ndarray
    target: float
    settled: float
    shift: float


def continued_spline(plan: AxisPlan, chunk: AxisPlan, now: float, final: bool) -> SplineContinuation | None:
    """Points ``chunk`` appended to the path ``plan`` (profile time ``now`` into it); None
    unless they are B-spline points.

    An open B-spline plan ends where its points settle the curve; the new points continue the
    one B-spline of all the points from there, so a streamed B-spline is the curve one request
    of all its points makes (docs/paths.md). If the path ran out (``now`` past that end: it
    rested there) the rest of the curve runs from now, later by the wait. Onto a path of
    another kind, the points make a B-spline of their own from the path's end."""
    old, new = plan.spline, chunk.spline
    if new is None:
        return None
    begin = append_time(plan, now)
    if old is None or old.kind is not new.kind:
        history = SplineHistory(new.kind, begin, new.values, new.dts)
        assert chunk.point_times is not None  # (the plan of a path)
        return SplineContinuation(history, chunk.segments, chunk.point_times, chunk.target, math.inf, 0.0)
    return _continued(plan, old, new.values[1:], new.dts, begin, final)


def closed_spline(plan: AxisPlan, now: float) -> SplineContinuation | None:
    """An open B-spline path closed without more points (final true): the rest of its curve,
    to its last point (None for the other kinds: they end on their last point already)."""
    if plan.spline is None:
        return None
    return _continued(plan, plan.spline, (), (), append_time(plan, now), True)


def _continued(plan: AxisPlan, old: SplineHistory, values: tuple[float, ...], dts: tuple[float, ...], begin: float,
               final: bool) -> SplineContinuation:
    settled = plan.duration
    shift = begin - settled
    history = old.continued(shift, values, dts)
    segments = history.pieces(begin, final)
    last_old = old.end_time() + shift  # the old last point, after the wait
    point_times = (last_old - begin) + np.cumsum(np.asarray(dts, dtype=float))
    target = history.values[-1] if final else _curve_end(segments, plan.target)
    return SplineContinuation(history, segments, point_times, target, settled, shift)


def _feedforward(motion_type: MPIMotionType, params: MotionParams, axes: int) -> np.ndarray | None:
    """PTF/PVTF: (points, axes) feedforward values (raw DAC counts), else None."""
    if "feedforward" not in FAMILIES[motion_type].fields:
        return None
    return np.asarray(params.feedforward, dtype=float).reshape(-1, axes)


def _knots(begin: float, first: float, point_times: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Feedforward knots: ``first`` at ``begin`` (NaN: the value the axis holds then), each
    value at its point's time (MPI 000, MPIMotionPTF: "When the motion reaches a specified
    position ... the interpolated feedforward value will be equal to what is specified")."""
    return np.concatenate([[begin], begin + point_times]), np.concatenate([[first], values])


def _points(params: MotionParams, starts: list[PathStart], relative: bool) -> npt.NDArray[np.float64]:
    """(points, axes) raw positions: RELATIVE from the start, else absolute with the
    shortest-path rule applied to the first point."""
    axes = len(starts)
    given: npt.NDArray[np.float64] = np.asarray(params.position, dtype=float).reshape(-1, axes)
    start: npt.NDArray[np.float64] = np.array([s.position for s in starts])
    if relative:
        return given + start
    absolute: npt.NDArray[np.float64] = given + np.array([s.origin for s in starts])
    turns: npt.NDArray[np.float64] = np.round((absolute[0] - start) / WRAP) if len(absolute) else np.zeros(axes)
    return absolute - turns * WRAP


def _frame_segments(params: MotionParams, starts: list[PathStart]) -> list[list[Segment]]:
    """FRAME: the user's frames (MEIXmpFrame) run as given, interleaved by axis; positions
    are user positions (raw = position + origin). Each frame must begin in the state the axis
    is in when it begins (:func:`_check_frames_join`)."""
    axes = len(starts)
    per_axis = [
        [Segment(f.time, f.position + start.origin, f.velocity, f.acceleration, f.jerk)
         for f in params.frames[k::axes] if f.time > 0.0]
        for k, start in enumerate(starts)
    ]
    for start, segments in zip(starts, per_axis, strict=True):
        _check_frames_join(start, segments)
    return per_axis


def _joins(expected: float, given: float) -> bool:
    """``given`` continues ``expected``: equal within what the user's own arithmetic rounds."""
    return math.isclose(given, expected, rel_tol=FRAME_JOIN_REL, abs_tol=FRAME_JOIN_ABS)


def _check_frames_join(start: PathStart, segments: list[Segment]) -> None:
    """Refuse frames that would step an axis' command (MPIMotionMessagePATH_ERROR).

    A frame is loaded as a constant-jerk segment from its own position and velocity (MPI 000,
    MEIMotionFrame / MEIXmpFrame), so a first frame that does not start where the axis is, or
    a frame that does not start where the one before it ends, makes the command jump (a
    position step, or a velocity step: an unbounded acceleration). The firmware would load
    it; the twin refuses it and moves nothing (docs/paths.md, "FRAME moves"). A step in
    acceleration is allowed, as in every profile that starts with a ramp."""
    position, velocity = start.position, start.velocity
    for index, segment in enumerate(segments):
        if not (_joins(position, segment.p) and _joins(velocity, segment.v)):
            where = "the axis' command" if index == 0 else f"the end of frame {index - 1}"
            raise Refused(Message.MPIMotionMessagePATH_ERROR,
                          f"axis {start.axis}: frame {index} starts at position {segment.p - start.origin:.9g}, "
                          f"velocity {segment.v:.9g}; {where} is at {position - start.origin:.9g}, "
                          f"velocity {velocity:.9g} (a FRAME move may not step the command)")
        position, velocity, _ = segment.end_state()


def _element_ids(params: MotionParams, attrs: MotionAttr, count: int) -> tuple[int, ...]:
    """ELEMENT_ID: one id per point (the id while the path runs toward it), or one for all."""
    if A.ELEMENT_ID not in attrs or not params.element_id:
        return ()
    if len(params.element_id) == 1:
        return (int(params.element_id[0]),) * count
    return tuple(int(x) for x in params.element_id[:count])


def timed_outputs(params: MotionParams, attrs: MotionAttr, point_times: np.ndarray,
                  begin: float) -> list[tuple[float, Output]]:
    """OUTPUT on a path: each output with the profile time at which it is applied, as the
    segment toward its point (MEIMotionAttrOutput.pointIndex) begins: index 0 when the
    points begin (``begin``), index i when point i-1 is reached."""
    if A.OUTPUT not in attrs:
        return []
    return [(begin if out.point_index == 0 else float(point_times[out.point_index - 1]), out)
            for out in params.output]


def extend(plan: AxisPlan, now: float, segments: list[Segment], point_times: np.ndarray,
           element_ids: tuple[int, ...], outputs: list[tuple[float, Output]], target: float,
           feedforward: np.ndarray | None = None, held: float = 0.0,
           spline: SplineContinuation | None = None) -> AxisPlan:
    """``plan`` with points appended (profile time ``now`` into it): the executed segments
    and points are flushed; the new ones follow the last point, or start now if the path
    has run out of points (it rests on its last point meanwhile). ``point_times``: when the
    new points are reached, from the time they begin; ``outputs``: (time from
    the first new point's interval, output); ``target``: where the new points end;
    ``feedforward``: the new points' values (PTF/PVTF), ``held`` the axis' feedforward now;
    ``spline``: B-spline points (:func:`continued_spline`): the old points and outputs beyond
    the curve's settled end come later by the time the path waited there."""
    begin = append_time(plan, now)
    kept = [s for s, end in zip(plan.segments, plan.table.end, strict=True) if end > now]
    first = float(plan.table.start[len(plan.segments) - len(kept)]) if kept else begin
    old_times = plan.point_times
    assert old_times is not None  # the plan of a path (compile_path)
    timed = plan.timed_outputs
    if spline is not None and spline.shift > 0.0:
        old_times = np.where(old_times > spline.settled, old_times + spline.shift, old_times)
        timed = [(w + spline.shift if w > spline.settled else w, o) for w, o in timed]
    pending = old_times > reached(now)
    new_times = begin + point_times
    shifted = [*kept, *segments]
    ids = _pending_ids(plan, pending, element_ids, len(point_times))
    return AxisPlan(
        axis=plan.axis, source=Listed(shifted), start_position=plan.start_position, target=target,
        start_velocity=plan.start_velocity, origin_time=first,
        point_times=np.concatenate([old_times[pending], new_times]),
        element_ids=ids,
        timed_outputs=[(w, o) for w, o in timed if w > now] + [(begin + w, o) for w, o in outputs],
        feedforward=_extended_feedforward(plan, begin, point_times, feedforward, held),
        spline=None if spline is None else spline.history,
    )


def _extended_feedforward(plan: AxisPlan, begin: float, point_times: np.ndarray, values: np.ndarray | None,
                          held: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The feedforward knots of a plan with points appended: the old ones, then the new
    points' values (from the value reached where they begin); points without values hold
    it. ``held``: the axis' feedforward where the old plan has none."""
    if plan.feedforward is None and values is None:
        return None
    last = plan.feedforward_at(begin, held)
    old_t, old_v = plan.feedforward if plan.feedforward is not None else (np.array([begin]), np.array([last]))
    if values is None:
        return old_t, old_v
    new_t, new_v = _knots(begin, last, point_times, values)
    return np.concatenate([old_t, new_t]), np.concatenate([old_v, new_v])


def _pending_ids(plan: AxisPlan, pending: np.ndarray, new: tuple[int, ...], count: int) -> tuple[int, ...]:
    """Element ids of the points still to come and of ``count`` new ones (ids ``new``, or
    none): points without ids of their own keep the last id (the field is not filled), and
    points before the first ids read 0."""
    old = plan.element_ids
    if not old and not new:
        return ()
    kept = tuple(int(x) for x in np.asarray(old)[pending]) if old else (0,) * int(np.count_nonzero(pending))
    added = new if new else (old[-1],) * count
    return kept + added


def append_time(plan: AxisPlan, now: float) -> float:
    """Profile time at which appended points begin: the end of the path, or now if the path
    has already run out of points."""
    return max(plan.duration, now)


def last_point_time(plan: AxisPlan) -> float:
    """Profile time at which the plan's last point is reached (its end, if none is left)."""
    times = plan.point_times
    return float(times[-1]) if times is not None and len(times) else plan.duration


def end_state(plan: AxisPlan, now: float) -> tuple[float, float]:
    """Position and velocity (profile time) the next appended points start from: the last
    point's, or at rest on it once the path has run out. (A B-spline's points continue its
    curve, continued_spline; its last point is where RELATIVE points are measured from.)"""
    if plan.spline is not None:
        return plan.spline.values[-1], 0.0
    if now >= plan.duration:
        return plan.target, 0.0
    _, v, _ = plan.segments[-1].end_state()
    return plan.target, v
