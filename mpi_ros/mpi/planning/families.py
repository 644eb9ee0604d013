"""The motion families: one record per motion type, read by everything that tells types apart.

Validation (validate.py), planning (planner.py, paths.py, cams.py, blend.py), the supervisor
and the command line all ask this table, never a set of types of their own: a new type is one
record here, its profile and its tests. A type of MPIMotionType without a record is an error
when this module is imported (``index``), so no caller can fall through to a default.

The records are per type, not per family, because the types of one family differ in what the
reference lets them carry (MPI 000: SPLINE may not APPEND, PTF/PVTF add feedforward, PVT/PVTF
point velocities, only PT and PVT may be modified); ``kind`` names the family.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from mpi_ros.mpi.base.types import CAM_ATTRS, HOLD_ATTRS, PATH_ATTRS, MotionAttr, MPIMotionType
from mpi_ros.mpi.planning.profiles.path import PathKind

A = MotionAttr


class Kind(enum.Enum):
    """The family: how a request of the type becomes a plan."""

    POINT_TO_POINT = "point-to-point"  # to targets under velocity/acceleration limits (planner.py)
    VELOCITY = "velocity"  # to a velocity, held until the next command (planner.py)
    PATH = "path"  # through timed points (paths.py, profiles/path.py)
    FRAME = "frame"  # the frames as given (paths.py)
    CAM = "cam"  # a table over a master's position (cams.py)

    @property
    def streamed(self) -> bool:
        """Points go through the frame buffer and may be appended while it runs (MPI 000,
        MPIMotionPoint)."""
        return self in (Kind.PATH, Kind.FRAME)

    @property
    def reads_position(self) -> bool:
        """MPI 000, MPIMotionSCurve, position: VELOCITY "will ignore these values"."""
        return self is not Kind.VELOCITY

    @property
    def reads_path_data(self) -> bool:
        """Times, point velocities, feedforward, cam tables or frames: the arrays of MPIMotionPT
        .. MPIMotionCam and MEIMotionFrame."""
        return self in (Kind.PATH, Kind.FRAME, Kind.CAM)


class Shape(enum.Enum):
    """How a point-to-point or velocity family ramps (its line) and comes to rest (its stop).
    Each member says what the planner reads, so no type falls through to another's ramp."""

    # (value, reads jerk_percent, jerk-limited from the full state)
    TRAPEZOID = ("trapezoid", False, False)  # constant acceleration (profiles/ramps.py)
    S_CURVE = ("s-curve", True, False)  # the trapezoid's ramps reshaped by jerkPercent (profiles/scurve.py)
    JERK = ("jerk", False, True)  # jerk limits, from position, velocity and acceleration (profiles/jerk.py)

    def __init__(self, label: str, reads_jerk_percent: bool, jerk_limited: bool) -> None:
        self.label = label
        self.reads_jerk_percent = reads_jerk_percent
        # MPI 000, MPIMotionType: the jerk types replace the S-curve algorithm (firmware option
        # 21), which alone plans from the current acceleration; the others start from a = 0
        self.jerk_limited = jerk_limited


# Goal fields (MotionStart's names) whose values a path family reads, in the order the
# array-length rules check them (MPI 000, MPIMotionPT .. MPIMotionPVTF)
POINT_ARRAYS = ("position", "point_velocity", "feedforward")
_KNOWN_FIELDS = frozenset({*POINT_ARRAYS, "time", "frames", "master_distance", "slave_position", "gear_ratio"})
_TRAJECTORY_FIELDS = ("velocity", "acceleration", "deceleration", "jerk_percent", "acceleration_jerk",
                      "deceleration_jerk")


@dataclass(frozen=True, slots=True)
class Family:
    """One motion type's record (MPI 000, MPIMotionType and the structure its params take).

    ``fields``: the goal fields it needs (without defaults); ``trajectory``: the trajectory
    fields it needs, of which ``limits`` must be > 0 and ``jerk_limits`` too (checked after
    them, with a message of their own); ``allowed``: the reference's list of the attributes it
    may carry (None: the reference gives no list; the path and cam attributes still belong to
    their families), ``forbidden``: attributes the reference forbids it; ``modifiable``: MPI
    000, mpiMotionModify's list; ``option_21``: needs firmware option 21; ``line`` and
    ``stop``: its ramp profiles (point-to-point and velocity families); ``path``: the path
    kind it is planned as (path families)."""

    type: MPIMotionType
    kind: Kind
    fields: tuple[str, ...]
    trajectory: tuple[str, ...] = ()
    limits: tuple[str, ...] = ()
    jerk_limits: tuple[str, ...] = ()
    allowed: MotionAttr | None = None
    forbidden: MotionAttr = MotionAttr.NONE
    modifiable: bool = False
    option_21: bool = False
    line: Shape | None = None
    stop: Shape | None = None
    path: PathKind | None = None

    def __post_init__(self) -> None:
        problem = self._problem()
        if problem:
            raise ValueError(f"motion family {self.type.name}: {problem}")

    def _problem(self) -> str:
        """What is inconsistent in the record ("" if nothing): each kind has the profiles it
        is planned with and no others."""
        ramps = self.kind in (Kind.POINT_TO_POINT, Kind.VELOCITY)
        if ramps != (self.line is not None):
            return "a line profile is for the point-to-point and velocity families (and they need one)"
        if (self.kind is Kind.POINT_TO_POINT) != (self.stop is not None):
            return "a stop profile is for the point-to-point families (and they need one)"
        if (self.kind is Kind.PATH) != (self.path is not None):
            return "a path kind is for the path families (and they need one)"
        if not set(self.fields) <= _KNOWN_FIELDS:
            return f"unknown goal fields {sorted(set(self.fields) - _KNOWN_FIELDS)}"
        if not set(self.limits + self.jerk_limits) <= set(self.trajectory) <= set(_TRAJECTORY_FIELDS):
            return "limits must be trajectory fields it needs"
        if self.line is not None and self.line.jerk_limited != bool(self.jerk_limits):
            return "a jerk-limited profile needs jerk limits, and only it"
        return ""

    @property
    def appendable(self) -> bool:
        """May points be added to it (APPEND among its allowed attributes)?"""
        return self.allowed is not None and bool(self.allowed & A.APPEND)


def index(families: Iterable[Family], types: Iterable[MPIMotionType]) -> Mapping[MPIMotionType, Family]:
    """The records by type: exactly one for each of ``types`` but INVALID. A type without a
    record (or with two) raises here, when the table is made."""
    table: dict[MPIMotionType, Family] = {}
    for family in families:
        if family.type in table:
            raise ValueError(f"motion type {family.type.name} has two family records")
        table[family.type] = family
    wanted = {t for t in types if t.name != "INVALID"}
    missing = sorted(t.name for t in wanted - table.keys())
    if missing or table.keys() - wanted:
        raise ValueError(f"motion types without a family record: {missing}; records of no type: "
                         f"{sorted(t.name for t in table.keys() - wanted)}")
    return MappingProxyType(table)


_P2P_TRAJECTORY = ("velocity", "acceleration", "deceleration")
_VELOCITY_FORBIDDEN = A.SYNC_END | A.SYNC_START | A.FINAL_VEL | A.NO_REVERSAL
# MPI 000, the ATTRIBUTE_INVALID lists of the point types, with the path attributes of MPI 001
# (MPIMotionPathAttrMask: docs/paths.md)
_PATH_ALLOWED = A.APPEND | A.RELATIVE | A.ID | A.ELEMENT_ID | HOLD_ATTRS | A.OUTPUT | PATH_ATTRS
# The reference has no ATTRIBUTE_INVALID list for the cams: they take their own attributes
# (MPIMotionAttrMask: REPEAT, MASTER_START, NO_BACKTRACK, NO_BACKTRACK_HOLD), ID and EVENT, which
# every move may carry. A cam's slave distances are relative by definition (MPIMotionCam), and
# its start is MASTER_START, not a time (DELAY) or a HOLD (docs/cams.md).
_CAM_ALLOWED = CAM_ATTRS | A.ID | A.EVENT


def _path(motion_type: MPIMotionType, kind: PathKind, fields: tuple[str, ...], modifiable: bool = False,
          allowed: MotionAttr = _PATH_ALLOWED) -> Family:
    return Family(motion_type, Kind.PATH, fields, allowed=allowed, modifiable=modifiable, path=kind)


T = MPIMotionType
FAMILIES: Mapping[MPIMotionType, Family] = index((
    # MPI 000, MPIMotionTrapezoidal / MPIMotionSCurve: "specified by acceleration, velocity,
    # deceleration, [jerkPercent,] and final position"
    Family(T.TRAPEZOIDAL, Kind.POINT_TO_POINT, ("position",), _P2P_TRAJECTORY, _P2P_TRAJECTORY, modifiable=True,
           line=Shape.TRAPEZOID, stop=Shape.TRAPEZOID),
    Family(T.S_CURVE, Kind.POINT_TO_POINT, ("position",), _P2P_TRAJECTORY, _P2P_TRAJECTORY, modifiable=True,
           line=Shape.S_CURVE, stop=Shape.S_CURVE),
    # "... accelerationJerk, decelerationJerk, and final position"; firmware option 21
    Family(T.S_CURVE_JERK, Kind.POINT_TO_POINT, ("position",),
           (*_P2P_TRAJECTORY, "acceleration_jerk", "deceleration_jerk"), _P2P_TRAJECTORY,
           ("acceleration_jerk", "deceleration_jerk"), modifiable=True, option_21=True,
           line=Shape.JERK, stop=Shape.JERK),
    # MPI 000, MPIMotionVelocity: "velocity, acceleration, jerkPercent, and accelerationJerk";
    # "VELOCITY, VELOCITY_JERK Moves are not permitted to have the following"
    Family(T.VELOCITY, Kind.VELOCITY, (), ("velocity", "acceleration"), ("acceleration",),
           forbidden=_VELOCITY_FORBIDDEN, modifiable=True, line=Shape.S_CURVE),
    Family(T.VELOCITY_JERK, Kind.VELOCITY, (), ("velocity", "acceleration", "acceleration_jerk"),
           ("acceleration",), ("acceleration_jerk",), forbidden=_VELOCITY_FORBIDDEN, modifiable=True,
           option_21=True, line=Shape.JERK),
    # MPI 000, MPIMotionPT .. MPIMotionPVTF, MPIMotionSPLINE ..; modifiable: PT and PVT only
    _path(T.PT, PathKind.PT, ("position", "time"), modifiable=True),
    _path(T.PTF, PathKind.PT, ("position", "feedforward", "time")),
    _path(T.PVT, PathKind.PVT, ("position", "point_velocity", "time"), modifiable=True),
    _path(T.PVTF, PathKind.PVT, ("position", "point_velocity", "feedforward", "time")),
    _path(T.SPLINE, PathKind.SPLINE, ("position", "time"), allowed=_PATH_ALLOWED & ~A.APPEND),
    _path(T.BESSEL, PathKind.BESSEL, ("position", "time")),
    _path(T.BSPLINE, PathKind.BSPLINE, ("position", "time")),
    _path(T.BSPLINE2, PathKind.BSPLINE2, ("position", "time")),
    # MPI 000, MPIMotionCam: gearRatio "is only used with" the cubic cam
    Family(T.CAM_LINEAR, Kind.CAM, ("master_distance", "slave_position"), allowed=_CAM_ALLOWED),
    Family(T.CAM_CUBIC, Kind.CAM, ("master_distance", "slave_position", "gear_ratio"), allowed=_CAM_ALLOWED),
    # MEIMotionFrame: the frames as given
    Family(T.FRAME, Kind.FRAME, ("frames",), allowed=A.APPEND | A.ID),
), MPIMotionType)


def family_of(motion_type: MPIMotionType) -> Family | None:
    """The record of ``motion_type``; None for INVALID (MPIMotionMessageTYPE_INVALID)."""
    return FAMILIES.get(motion_type)


def types_of(kind: Kind) -> frozenset[MPIMotionType]:
    return frozenset(t for t, family in FAMILIES.items() if family.kind is kind)
