"""A 1-D profile request to cross-check, and the controller's plan of it.

Fields (counts, seconds): ``type`` (TRAPEZOIDAL, S_CURVE or VELOCITY), ``target`` or
``distance`` (point to point; target = start_position + distance), ``velocity`` (the limit,
or VELOCITY's commanded velocity), ``acceleration``, ``deceleration`` (defaults to the
acceleration), ``jerk_percent``, ``start_position``, ``start_velocity`` and
``start_acceleration`` (a modify from motion: the state the axis is in), ``final_velocity``
(the FINAL_VEL attribute).

Text forms (the CLI's arguments): a YAML flow mapping
``"{type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, jerk_percent: 50}"`` or
comma-separated ``key=value`` pairs ``type=S_CURVE,distance=1000,velocity=500,...``.

The plan is made by the controller's own planner (``compile_move``) for one axis, exactly as
a start (or, with a start velocity, a modify) of that request on a one-axis supervisor.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.params import MotionParams, Trajectory
from mpi_ros.mpi.base.types import MotionAttr, MPIMotionType
from mpi_ros.mpi.planning import validate
from mpi_ros.mpi.planning.frames import AxisPlan
from mpi_ros.mpi.planning.planner import compile_move
from mpi_ros.mpi.planning.start import AxisStart

SUPPORTED_TYPES = (MPIMotionType.TRAPEZOIDAL, MPIMotionType.S_CURVE, MPIMotionType.VELOCITY)
_ALIASES = {"jerk": "jerk_percent", "jerkpercent": "jerk_percent", "v0": "start_velocity",
            "a0": "start_acceleration", "p0": "start_position", "vf": "final_velocity",
            "accel": "acceleration", "decel": "deceleration", "vel": "velocity"}


class RequestInvalid(ValueError):
    """The request cannot be understood or the controller refuses it (the message says why)."""


def motion_type(value: Any) -> MPIMotionType:
    kind: MPIMotionType | None
    if isinstance(value, MPIMotionType):
        kind = value
    else:
        name = str(value).strip().upper()
        if name.startswith("MPIMOTIONTYPE"):  # the spec's full name, MPIMotionTypeS_CURVE
            name = name[len("MPIMOTIONTYPE"):]
        kind = MPIMotionType.__members__.get(name)
        if kind is None:
            raise RequestInvalid(f"unknown motion type {value!r}")
    if kind not in SUPPORTED_TYPES:
        raise RequestInvalid(f"{kind.name} is not cross-checked (only {', '.join(t.name for t in SUPPORTED_TYPES)})")
    return kind


@dataclass(frozen=True, slots=True)
class ProfileRequest:
    type: MPIMotionType
    velocity: float
    acceleration: float
    deceleration: float | None = None
    jerk_percent: float = 0.0
    target: float = 0.0
    start_position: float = 0.0
    start_velocity: float = 0.0
    start_acceleration: float = 0.0
    final_velocity: float = 0.0

    @property
    def decel(self) -> float:
        return self.acceleration if self.deceleration is None else self.deceleration

    @property
    def distance(self) -> float:
        return self.target - self.start_position

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> ProfileRequest:
        known = {f.name for f in fields(cls)}
        values: dict[str, Any] = {}
        distance = None
        for key, value in dict(data).items():
            name = _ALIASES.get(str(key).strip().lower(), str(key).strip().lower())
            if name == "distance":
                distance = value
                continue
            if name not in known:
                raise RequestInvalid(f"unknown key {key!r} (known: distance, {', '.join(sorted(known))})")
            values[name] = value
        if "type" not in values:
            raise RequestInvalid("a request needs a type (TRAPEZOIDAL, S_CURVE or VELOCITY)")
        values["type"] = motion_type(values["type"])
        try:
            for name in list(values):
                if name != "type" and values[name] is not None:
                    values[name] = float(values[name])
            if distance is not None:
                if "target" in values:
                    raise RequestInvalid("give a distance or a target, not both")
                values["target"] = values.get("start_position", 0.0) + float(distance)
        except (TypeError, ValueError) as exc:
            raise RequestInvalid(f"numbers expected: {exc}") from exc
        for name in ("velocity", "acceleration"):
            if name not in values:
                raise RequestInvalid(f"a request needs {name}")
        return cls(**values)

    @classmethod
    def parse(cls, text: str) -> ProfileRequest:
        """From a YAML flow mapping or ``key=value,key=value``."""
        text = text.strip()
        if text.startswith("{"):
            import yaml

            try:
                data = yaml.safe_load(text)
            except yaml.YAMLError as exc:
                raise RequestInvalid(f"not a YAML mapping: {text!r}") from exc
            if not isinstance(data, dict):
                raise RequestInvalid(f"not a YAML mapping: {text!r}")
            return cls.from_mapping(data)
        data = {}
        for part in filter(None, (p.strip() for p in text.split(","))):
            key, sep, value = part.partition("=")
            if not sep:
                raise RequestInvalid(f"expected key=value, got {part!r} in {text!r}")
            data[key.strip()] = value.strip()
        return cls.from_mapping(data)

    def trajectory(self) -> Trajectory:
        return Trajectory(self.velocity, self.acceleration, self.decel, self.jerk_percent)

    def label(self) -> str:
        """Compact description for tables and plot titles."""
        parts = [self.type.name]
        if self.type is not MPIMotionType.VELOCITY:
            parts.append(f"x={self.distance:g}")
        parts.append(f"v={self.velocity:g} a={self.acceleration:g}")
        if self.type is not MPIMotionType.VELOCITY and self.decel != self.acceleration:
            parts.append(f"d={self.decel:g}")
        if self.type is not MPIMotionType.TRAPEZOIDAL:
            parts.append(f"j={self.jerk_percent:g}%")
        if self.start_velocity:
            parts.append(f"v0={self.start_velocity:g}")
        if self.start_acceleration:
            parts.append(f"a0={self.start_acceleration:g}")
        if self.final_velocity:
            parts.append(f"vf={self.final_velocity:g}")
        return " ".join(parts)

    def plan(self, sample_rate: float = 2000.0) -> AxisPlan:
        """The controller's plan of this request for one axis (RequestInvalid if refused)."""
        attrs = MotionAttr.FINAL_VEL if self.final_velocity else MotionAttr.NONE
        params = MotionParams(trajectory=[self.trajectory()], position=[self.target],
                              final_velocity=[self.final_velocity] if self.final_velocity else [])
        verdict = validate.check_params(self.type, attrs, params, 1, io_words=0, motors=0, axes=1)
        if not verdict.ok:
            raise RequestInvalid(f"{verdict.message.name}: {verdict.detail}")
        start = AxisStart(0, self.start_position, self.start_velocity, 0.0, self.start_acceleration)
        try:
            move, _ = compile_move(0, self.type, attrs, params, [start], sample_rate)
        except Refused as exc:
            raise RequestInvalid(f"{exc.message.name}: {exc.detail}") from exc
        return move.plans[0]
