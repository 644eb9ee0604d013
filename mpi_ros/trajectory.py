"""JointTrajectory commands: a trajectory in SI units under joint names, as MPI path moves.

What trajectory_msgs/JointTrajectory carries (joint names, points with positions, optional
velocities and a ``time_from_start`` each), read without ROS, checked, converted to counts
and cut into chunks that the suite feeds to the controller as one PT or PVT path
(docs/trajectories.md). The ROS node only turns the message into :class:`Trajectory` and
schedules the chunks; the commands' handler (commands.py, ``joint_trajectory``) checks each
chunk again against the supervisor at the sample it is applied and starts, replaces or
extends the path.

- Names: every joint of the supervisor, each once, in any order; nothing else.
- Units: positions in metres or radians, velocities per second (mpi_ros.joints.Joint);
  an axis without a joint block takes counts.
- Times: ``time_from_start`` counts from the start (header.stamp, or now), increasing from
  the first point on; the path starts on the command position (MPI 000, Streaming Point
  Motion Type Calculations: "Any given dt defining a point also specifies how long it will
  take to arrive at that point"), so the MPI ``time`` of point i is t_i - t_(i-1), t_(-1) = 0.
- Kind: positions with velocities run as PVT (cubic Hermite between points), positions
  alone as PT (straight lines). Accelerations and efforts are ignored (neither PT nor PVT has
  them).
- Speeds: no joint may be asked to go faster than its ``max_velocity`` (where given): the
  points' velocities, and the peak speed of every interval as the path would run it (PT: the
  chord; PVT: the peak of the Hermite cubic), the first interval included, from where the
  path starts.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mpi_ros.joints import AxisJoint, Joint
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, Outcome, Refused
from mpi_ros.mpi.base.params import refuse, shown

from . import requests as rq

# Points per chunk when a trajectory is fed to the controller (the frame buffer's size by
# default: one chunk in the buffer, the next one waiting in the library, MPI 001 LOW_COUNT).
CHUNK_POINTS = 128
_SPEED_MARGIN = 1e-9  # relative: a speed this close over the limit is rounding, not a request


@dataclass(frozen=True, slots=True)
class Trajectory:
    """A JointTrajectory in the supervisor's axis order (SI units).

    ``positions`` (points x axes), ``velocities`` the same shape or None (PT),
    ``times`` each point's time_from_start in seconds."""

    joints: tuple[AxisJoint, ...]
    positions: np.ndarray
    velocities: np.ndarray | None
    times: np.ndarray

    @property
    def empty(self) -> bool:
        return len(self.times) == 0

    def validate(self) -> Outcome:
        """NaN, times that do not increase, speeds over a joint's max_velocity between the
        given points (the first interval depends on where the path starts: Chunk.check)."""
        return _check_points(self.joints, self.positions, self.velocities, self.times, 0.0, None)

    def chunks(self, size: int = CHUNK_POINTS) -> list[Chunk]:
        """The trajectory cut in chunks of ``size`` points: the first starts (or replaces) the
        path, the others APPEND to it; the last closes it (final)."""
        if size < 1:
            raise ValueError("chunk size must be >= 1")
        out = []
        n = len(self.times)
        for first in range(0, n, size):
            last = min(first + size, n)
            before = None if first == 0 else (self.positions[first - 1],
                                               None if self.velocities is None else self.velocities[first - 1])
            out.append(Chunk(self.joints, self.positions[first:last],
                             None if self.velocities is None else self.velocities[first:last],
                             self.times[first:last], float(self.times[first - 1]) if first else 0.0,
                             before, final=last == n, append=first > 0))
        return out


@dataclass(frozen=True, slots=True)
class Chunk:
    """Points of a trajectory as one command: the first chunk starts the path at ``begin`` = 0
    from the command position; a later one (``append``) follows the point ``before`` (SI
    positions, velocities) reached at ``begin`` (s from the trajectory's start)."""

    joints: tuple[AxisJoint, ...]
    positions: np.ndarray
    velocities: np.ndarray | None
    times: np.ndarray
    begin: float
    before: tuple[np.ndarray, np.ndarray | None] | None
    final: bool
    append: bool

    def check(self, start: Sequence[tuple[float, float]] | None = None) -> Outcome:
        """The chunk's points, from ``before`` or (the first chunk) from ``start``: each axis'
        command position and velocity in counts, where the path begins."""
        if self.before is not None:
            origin = self.before
        elif start is not None:
            origin = (np.array([j.position(p) for j, (p, _) in zip(self.joints, start, strict=True)]),
                      np.array([j.rate(v) for j, (_, v) in zip(self.joints, start, strict=True)]))
        else:
            origin = None
        return _check_points(self.joints, self.positions, self.velocities, self.times, self.begin, origin)

    def motion_request(self) -> dict[str, Any]:
        """The MPI path request (counts, seconds between points): a MotionStart/MotionModify goal."""
        counts = np.column_stack([_counts(j, self.positions[:, i]) for i, j in enumerate(self.joints)])
        request: dict[str, Any] = {
            "type": "PT" if self.velocities is None else "PVT",
            "attributes": ["APPEND"] if self.append else [],
            "position": counts.ravel().tolist(),  # interleaved by axis, point after point
            "time": np.diff(self.times, prepend=self.begin).tolist(),
            "final": self.final,
        }
        if self.velocities is not None:
            rates = np.column_stack([_rates(j, self.velocities[:, i]) for i, j in enumerate(self.joints)])
            request["point_velocity"] = rates.ravel().tolist()
        return request

    # -- as data (a recorded command) --------------------------------------------------
    def to_request(self) -> dict[str, Any]:
        """The chunk as a command's request (JSON-able): what /mpi/commands records."""
        request: dict[str, Any] = {
            "joints": [_joint_dict(j) for j in self.joints],
            "positions": self.positions.ravel().tolist(),
            "time_from_start": self.times.tolist(),
            "begin": self.begin,
            "final": self.final,
            "append": self.append,
        }
        if self.velocities is not None:
            request["velocities"] = self.velocities.ravel().tolist()
        if self.before is not None:
            request["before_positions"] = self.before[0].tolist()
            if self.before[1] is not None:
                request["before_velocities"] = self.before[1].tolist()
        return request

    @classmethod
    def from_request(cls, data: Any) -> Chunk:
        """A recorded chunk read back (raises Refused for a request that is not one)."""
        data = rq.mapping(data, "joint_trajectory")
        joints = tuple(_joint_of(j, f"joints[{i}]") for i, j in enumerate(rq.sequence(data.get("joints"), "joints")))
        width = len(joints)
        times = np.array(rq.numbers(data.get("time_from_start", []), "time_from_start"), dtype=float)
        positions = _matrix(data.get("positions", []), "positions", len(times), width)
        velocities = (None if data.get("velocities") is None
                      else _matrix(data["velocities"], "velocities", len(times), width))
        before = None
        if data.get("before_positions") is not None:
            before_v = data.get("before_velocities")
            before = (_matrix(data["before_positions"], "before_positions", 1, width)[0],
                      None if before_v is None else _matrix(before_v, "before_velocities", 1, width)[0])
        return cls(joints, positions, velocities, times, rq.number(data.get("begin", 0.0), "begin"), before,
                   rq.boolean(data.get("final", True), "final"), rq.boolean(data.get("append", False), "append"))


def read(joint_names: Sequence[str], points: Sequence[tuple[Sequence[float], Sequence[float], float]],
         joints: Sequence[AxisJoint]) -> Trajectory:
    """A JointTrajectory (its joint names, and per point positions, velocities and
    time_from_start in seconds) for the supervisor whose axes are ``joints``, in its axis
    order. Raises Refused (MPIMessagePARAM_INVALID) for names that are not exactly the
    supervisor's joints, or points of the wrong size."""
    order = _order(list(joint_names), joints)
    columns = np.argsort(order)  # the message's column of each supervisor axis
    width = len(joints)
    with_velocities = bool(points) and len(points[0][1]) > 0
    for i, (p, v, _) in enumerate(points):
        if len(p) != width:
            raise Refused(Message.MPIMessagePARAM_INVALID,
                          f"points[{i}].positions: {len(p)} values for {width} joints")
        if len(v) != (width if with_velocities else 0):
            raise Refused(Message.MPIMessagePARAM_INVALID,
                          f"points[{i}].velocities: {len(v)} values for {width} joints (all points give "
                          "velocities, or none does)")
    positions = np.array([p for p, _, _ in points], dtype=float).reshape(len(points), width)[:, columns]
    velocities = (np.array([v for _, v, _ in points], dtype=float).reshape(len(points), width)[:, columns]
                  if with_velocities else None)
    times = np.array([float(t) for _, _, t in points])
    return Trajectory(tuple(joints), positions, velocities, times)


def _order(names: list[str], joints: Sequence[AxisJoint]) -> list[int]:
    """Where each named joint is in the supervisor's axis order."""
    known = {j.name: i for i, j in enumerate(joints)}
    all_names = ", ".join(j.name for j in joints)
    for name in names:
        if name not in known:
            raise Refused(Message.MPIMessagePARAM_INVALID,
                          f"joint_names: unknown joint {shown(name)} (this supervisor moves {all_names})")
    if len(set(names)) != len(names):
        twice = sorted({n for n in names if names.count(n) > 1})
        raise Refused(Message.MPIMessagePARAM_INVALID, f"joint_names: {', '.join(twice)} named twice")
    missing = [j.name for j in joints if j.name not in names]
    if missing:
        raise Refused(Message.MPIMessagePARAM_INVALID,
                      f"joint_names: {', '.join(missing)} missing (a trajectory commands every joint of the "
                      f"supervisor: {all_names})")
    return [known[name] for name in names]


def _check_points(joints: Sequence[AxisJoint], positions: np.ndarray, velocities: np.ndarray | None,
                  times: np.ndarray, begin: float,
                  origin: tuple[np.ndarray, np.ndarray | None] | None) -> Outcome:
    """NaN first (MEIMotionMessageBAD_PATH_DATA, as every path), then times, then speeds."""
    values = [positions, times] + ([] if velocities is None else [velocities])
    if not all(np.isfinite(v).all() for v in values) or not math.isfinite(begin):
        return refuse("a position, velocity or time_from_start is NaN or infinite",
                      Message.MEIMotionMessageBAD_PATH_DATA)
    dts = np.diff(times, prepend=begin)
    if len(dts) and not (dts > 0.0).all():
        i = int(np.argmax(dts <= 0.0))
        before = f"points[{i - 1}] at {times[i - 1]:g} s" if i else f"the start at {begin:g} s"
        return refuse(f"time_from_start must increase: points[{i}] at {times[i]:g} s is not after {before}",
                      Message.MPIMotionMessagePATH_ERROR)
    return _check_speeds(joints, positions, velocities, dts, origin)


def _check_speeds(joints: Sequence[AxisJoint], positions: np.ndarray, velocities: np.ndarray | None,
                  dts: np.ndarray, origin: tuple[np.ndarray, np.ndarray | None] | None) -> Outcome:
    for i, aj in enumerate(joints):
        limit = aj.joint.max_velocity if aj.joint is not None else 0.0
        if limit <= 0.0 or not len(dts):
            continue
        x = positions[:, i]
        v = None if velocities is None else velocities[:, i]
        if v is not None and (np.abs(v) > limit * (1 + _SPEED_MARGIN)).any():
            k = int(np.argmax(np.abs(v)))
            return _too_fast(aj, abs(float(v[k])), limit, f"at points[{k}]")
        if origin is not None:  # the first interval runs from where the path starts
            x0 = np.concatenate(([origin[0][i]], x[:-1]))
            v0 = None if v is None else np.concatenate(([0.0 if origin[1] is None else origin[1][i]], v[:-1]))
            first = 0
        else:  # from points[0] on: the intervals between the given points
            x0, v0, first = x[:-1], None if v is None else v[:-1], 1
        peaks = _peak_speeds(x0, v0, x[first:], None if v is None else v[first:], dts[first:])
        if len(peaks) and (peaks > limit * (1 + _SPEED_MARGIN)).any():
            k = int(np.argmax(peaks))
            where = f"between points[{k + first - 1}] and points[{k + first}]" if k + first else \
                "from the start to points[0]"
            return _too_fast(aj, float(peaks[k]), limit, where)
    return VALID


def _too_fast(aj: AxisJoint, speed: float, limit: float, where: str) -> Outcome:
    unit = "rad/s" if aj.joint is not None and aj.joint.type != "prismatic" else "m/s"
    return refuse(f"joint {aj.name}: {speed:.6g} {unit} {where}, over its max_velocity {limit:g} {unit}")


def _peak_speeds(x0: np.ndarray, v0: np.ndarray | None, x1: np.ndarray, v1: np.ndarray | None,
                 dt: np.ndarray) -> np.ndarray:
    """The largest |velocity| of each interval: PT's chord, or PVT's Hermite cubic
    (MPI 000, Streaming Point Motion Type Calculations, PVT Moves: v(t) = v0 + a0 t + j t^2/2
    with a0 = 6(x1-x0)/dt^2 - (2 v1 + 4 v0)/dt, j = -12(x1-x0)/dt^3 + 6(v1+v0)/dt^2): its ends,
    and its vertex t = -a0/j where that lies inside the interval."""
    if v0 is None or v1 is None:
        return np.abs(x1 - x0) / dt
    dx = x1 - x0
    a0 = 6.0 * (dx / dt**2) - (2.0 * v1 + 4.0 * v0) / dt
    j = -12.0 * (dx / dt**3) + 6.0 * ((v1 + v0) / dt**2)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(j != 0.0, -a0 / j, -1.0)
    inside = (t > 0.0) & (t < dt)
    vertex = np.where(inside, np.abs(v0 + a0 * t + 0.5 * j * t * t), 0.0)
    return np.maximum(np.maximum(np.abs(v0), np.abs(v1)), vertex)


def feed_samples(start: int, chunks: Sequence[Chunk], rate: float) -> list[int]:
    """The controller sample each chunk is applied at, the path starting at ``start``: the
    first two at the start, then chunk k as chunk k-1 begins to run (when the path reaches
    the last point of chunk k-2). So one chunk always waits behind the one running, and the
    open path never runs short of points (no FRAMES_LOW or FRAMES_EMPTY: docs/trajectories.md)."""
    samples: list[int] = []
    for k in range(len(chunks)):
        at = start if k < 2 else start + math.floor(float(chunks[k - 2].times[-1]) * rate)
        samples.append(max(at, samples[-1] if samples else start))
    return samples


def start_sample(stamp_ns: int, epoch_ns: int, rate: float, now: int) -> int:
    """The controller sample a trajectory stamped ``stamp_ns`` starts at: the first at or after
    the stamp (controller time is epoch + sample / rate); zero, or a stamp already past, is now."""
    if stamp_ns == 0:
        return now
    due = math.ceil((stamp_ns - epoch_ns) * rate / 1e9 - 1e-9)
    return max(now, due)


def _counts(joint: AxisJoint, positions: np.ndarray) -> np.ndarray:
    return positions if joint.joint is None else (positions - joint.joint.offset) * joint.joint.counts_per_unit


def _rates(joint: AxisJoint, velocities: np.ndarray) -> np.ndarray:
    return velocities if joint.joint is None else velocities * joint.joint.counts_per_unit


def _joint_dict(aj: AxisJoint) -> dict[str, Any]:
    out: dict[str, Any] = {"axis": aj.axis, "name": aj.name}
    if aj.joint is not None:
        out.update(type=aj.joint.type, counts_per_unit=aj.joint.counts_per_unit, offset=aj.joint.offset,
                   max_velocity=aj.joint.max_velocity)
    return out


def _joint_of(data: Any, what: str) -> AxisJoint:
    data = rq.mapping(data, what)
    axis = rq.integer(data.get("axis", -1), f"{what}.axis")
    name = rq.text(data.get("name", ""), f"{what}.name")
    if "counts_per_unit" not in data:
        return AxisJoint(axis, name, None)
    joint = Joint(name.rsplit("/", 1)[-1], rq.text(data.get("type", "prismatic"), f"{what}.type"),
                  rq.number(data["counts_per_unit"], f"{what}.counts_per_unit"),
                  rq.number(data.get("offset", 0.0), f"{what}.offset"),
                  rq.number(data.get("max_velocity", 0.0), f"{what}.max_velocity"))
    verdict = joint.validate()
    if not verdict.ok:
        raise Refused(verdict.message, f"{what}.{verdict.detail}")
    return AxisJoint(axis, name, joint)


def _matrix(values: Any, what: str, rows: int, width: int) -> np.ndarray:
    flat = rq.numbers(values, what)
    if len(flat) != rows * width:
        raise Refused(Message.MPIMessagePARAM_INVALID, f"{what}: {len(flat)} values, expected {rows} x {width}")
    return np.array(flat, dtype=float).reshape(rows, width)
