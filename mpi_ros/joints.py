"""An axis as a joint of the machine: its name, its kind, and counts <-> SI units.

The controller speaks counts (MPI 002: every position, velocity and acceleration of an axis is
in counts and counts/s). The ROS robot stack speaks radians and metres under the machine's
own joint names (REP 103; sensor_msgs/JointState, URDF, trajectory_msgs). A ``Joint`` is the
bridge, configured per axis as ``axes.defaults|overrides.<n>.joint`` (docs/joints.md):

    joint: {name: x, type: prismatic, counts_per_unit: 1.0e6, offset: 0.0, max_velocity: 0.5}

``counts_per_unit`` is counts per metre (prismatic) or per radian (revolute, continuous);
negative flips the direction. ``offset`` is the joint position (units) at count 0, so
``units = offset + counts / counts_per_unit``. ``max_velocity`` (units/s, 0 = none given)
is the URDF's velocity limit and the fastest a JointTrajectory may ask. ``axis`` (x, y or z;
empty: by order, see mpi_ros/description.py) is the direction it moves or turns about in the
generated robot description. An axis without a joint block keeps the name ``axis<k>`` and
reports counts, as before joints existed.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

from mpi_ros.mpi.base.outcome import VALID, Outcome
from mpi_ros.mpi.base.params import check_magnitude, first_refusal, refuse, shown

JOINT_TYPES = ("revolute", "prismatic", "continuous")
JOINT_AXES = ("x", "y", "z")
# A URDF joint name and a ROS name token: letters, digits and underscores, not starting with
# a digit (the namespace prefix rule of docs/cell.md adds "<ns>/" in front).
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
# Beyond this a unit conversion loses the count (2^53 counts over 1e-9 units).
_COUNTS_PER_UNIT_MAX = 1e15


@dataclass(slots=True)
class Joint:
    """One axis as a joint; the defaults are what an axis without a joint block reports."""

    name: str = ""
    type: str = "prismatic"
    counts_per_unit: float = 1.0
    offset: float = 0.0
    max_velocity: float = 0.0  # units/s; 0: none given
    axis: str = ""  # x, y or z of the link before it; "": by order (description.py)

    def validate(self) -> Outcome:
        return first_refusal((
            self._name(),
            self._type(),
            self._counts_per_unit(),
            check_magnitude("offset", self.offset, _COUNTS_PER_UNIT_MAX),
            self._max_velocity(),
            self._axis(),
        ))

    def _name(self) -> Outcome:
        if not isinstance(self.name, str) or not _NAME.fullmatch(self.name):
            return refuse(f"name: expected letters, digits and underscores, not starting with a digit, got "
                          f"{shown(self.name)}")
        return VALID

    def _type(self) -> Outcome:
        if self.type not in JOINT_TYPES:
            return refuse(f"type: expected one of {', '.join(JOINT_TYPES)}, got {shown(self.type)}")
        return VALID

    def _counts_per_unit(self) -> Outcome:
        value = self.counts_per_unit
        if not isinstance(value, float) or not math.isfinite(value) or value == 0.0 \
                or abs(value) > _COUNTS_PER_UNIT_MAX:
            return refuse(f"counts_per_unit: expected a finite, non-zero number of magnitude at most "
                          f"{_COUNTS_PER_UNIT_MAX:g}, got {shown(value)}")
        return VALID

    def _max_velocity(self) -> Outcome:
        value = self.max_velocity
        if not isinstance(value, float) or not math.isfinite(value) or value < 0.0:
            return refuse(f"max_velocity: expected a finite number >= 0 (0: none), got {shown(value)}")
        return VALID

    def _axis(self) -> Outcome:
        if self.axis not in ("", *JOINT_AXES):
            return refuse(f"axis: expected one of {', '.join(JOINT_AXES)} (or none: by order), got {shown(self.axis)}")
        return VALID

    # -- conversions (the joint's units are metres or radians, its rates per second)
    def position(self, counts: float) -> float:
        return self.offset + counts / self.counts_per_unit

    def rate(self, counts_per_second: float) -> float:
        """A velocity, acceleration or effort in counts/s^n as units/s^n."""
        return counts_per_second / self.counts_per_unit

    def counts(self, position: float) -> float:
        return (position - self.offset) * self.counts_per_unit

    def counts_rate(self, units_per_second: float) -> float:
        return units_per_second * self.counts_per_unit


@dataclass(frozen=True, slots=True)
class AxisJoint:
    """The joint of axis ``axis`` as the ROS graph names it (``name`` with its namespace
    prefix), or an axis without one (``joint`` None: ``axis<k>`` in counts)."""

    axis: int
    name: str
    joint: Joint | None

    def position(self, counts: float) -> float:
        return counts if self.joint is None else self.joint.position(counts)

    def rate(self, counts_per_second: float) -> float:
        return counts_per_second if self.joint is None else self.joint.rate(counts_per_second)


def axis_joints(joints: list[Joint | None], prefix: str) -> list[AxisJoint]:
    """Every axis as the graph names it: its joint's name, or ``axis<k>``, after ``prefix``."""
    return [AxisJoint(k, prefix + (joint.name if joint is not None else f"axis{k}"), joint)
            for k, joint in enumerate(joints)]


class JointStates:
    """/joint_states for a suite: the names, and every axis' counts converted at once.

    Built once (the scales and offsets precomputed as tuples); :meth:`convert` is on the
    path of every JointState (100 Hz and more). Plain Python over the tuples: for 4 to 32
    axes as fast as numpy within the noise (the arrays' creation and tolist() cost as much as
    the arithmetic) and about 1.6x faster than a method call per axis and value at 32 axes
    (bench/bench_joints.py, bench/RESULTS.md "Joint states in SI units").
    """

    __slots__ = ("_identity", "_offset", "_scale", "names")

    def __init__(self, joints: Sequence[AxisJoint]):
        self.names: tuple[str, ...] = tuple(j.name for j in joints)
        self._scale = tuple(1.0 if j.joint is None else j.joint.counts_per_unit for j in joints)
        # An axis without a joint gets offset -0.0: x + (-0.0) is x bit for bit, -0.0 included
        # (x + 0.0 would turn -0.0 into 0.0), and x / 1.0 is x, so it reports its counts exactly.
        self._offset = tuple(-0.0 if j.joint is None else j.joint.offset for j in joints)
        self._identity = all(j.joint is None for j in joints)

    def convert(self, position: list[float], velocity: list[float], effort: list[float]
                ) -> tuple[list[float], list[float], list[float]]:
        """Positions (counts), velocities (counts/s) and efforts (counts/s^2) of every axis as
        its joint's units (m or rad, per s, per s^2); as Joint.position and Joint.rate."""
        if self._identity:
            return position, velocity, effort
        scale = self._scale
        return ([o + p / s for p, s, o in zip(position, scale, self._offset, strict=True)],
                [v / s for v, s in zip(velocity, scale, strict=True)],
                [e / s for e, s in zip(effort, scale, strict=True)])
