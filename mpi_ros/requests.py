"""Requests as plain data (dicts with the ROS interfaces' field names) <-> MPI structs.

The ROS layer turns messages into these dicts at the edge; recordings store them as
JSON; replay and the Python client build them directly. Names are the spec's without
prefix (type "S_CURVE", attribute "APPEND", hold type "GATE", event "MOTION_DONE").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from .mpi.events import MPIEventType
from .mpi.messages import Message
from .mpi.params import AxisInPosition, DecelTime, Hold, MotionConfig, MotionParams, Output, Trajectory, UserFrame
from .mpi.types import HoldType, MotionAttr, MPIMotionType, OutputType


class RequestError(ValueError):
    """A request that cannot be understood; ``message`` is the spec's answer."""

    def __init__(self, message: Message, detail: str):
        super().__init__(detail)
        self.message = message
        self.detail = detail


@dataclass(frozen=True, slots=True)
class MotionRequest:
    type: MPIMotionType
    attributes: MotionAttr
    params: MotionParams | None  # None: the parameters stored with params_set


def _enum_by_name(enum, name: str, what: str, message: Message):
    key = str(name).strip().upper()
    member = enum.__members__.get(key)
    if member is None:
        raise RequestError(message, f"unknown {what} {name!r}")
    return member


def _floats(values, what: str) -> list[float]:
    try:
        return [float(v) for v in (values or [])]
    except (TypeError, ValueError) as exc:
        raise RequestError(Message.MPIMessagePARAM_INVALID, f"{what}: numbers expected") from exc


def _ints(values, what: str) -> list[int]:
    try:
        return [int(v) for v in (values or [])]
    except (TypeError, ValueError) as exc:
        raise RequestError(Message.MPIMessagePARAM_INVALID, f"{what}: integers expected") from exc


def _struct(cls, data: Mapping[str, Any] | None, what: str, enum_fields: dict | None = None):
    data = dict(data or {})
    enum_fields = enum_fields or {}
    kwargs = {}
    defaults = cls()
    for key, value in data.items():
        if not hasattr(defaults, key):
            raise RequestError(Message.MPIMessagePARAM_INVALID, f"{what}: unknown field {key!r}")
        if key in enum_fields:
            enum, message = enum_fields[key]
            kwargs[key] = enum.NONE if value in ("", None) else _enum_by_name(enum, value, f"{what} type", message)
            continue
        default = getattr(defaults, key)
        try:
            kwargs[key] = type(default)(value) if not isinstance(default, bool) else bool(value)
        except (TypeError, ValueError) as exc:
            raise RequestError(Message.MPIMessagePARAM_INVALID, f"{what}.{key}: bad value {value!r}") from exc
    return cls(**kwargs)


def motion_request(data: Mapping[str, Any]) -> MotionRequest:
    """A MotionStart/MotionModify goal (as a dict) to the MPI's type, attributes, params."""
    motion_type = _enum_by_name(MPIMotionType, data.get("type", ""), "motion type",
                                Message.MPIMotionMessageTYPE_INVALID)
    attributes = MotionAttr.parse(data.get("attributes") or [])
    if attributes is None:
        raise RequestError(Message.MPIMotionMessageTYPE_INVALID,
                           f"unknown attribute in {list(data.get('attributes') or [])}")
    if data.get("use_stored_params"):
        return MotionRequest(motion_type, attributes, None)
    return MotionRequest(motion_type, attributes, motion_params(data))


def motion_params(data: Mapping[str, Any]) -> MotionParams:
    event_names = data.get("event_mask") or []
    event_mask = MPIEventType.parse(event_names)
    if event_mask is None:
        raise RequestError(Message.MPIMessagePARAM_INVALID, f"unknown event type in {list(event_names)}")
    return MotionParams(
        trajectory=[_struct(Trajectory, t, "trajectory") for t in data.get("trajectory") or []],
        position=_floats(data.get("position"), "position"),
        point_velocity=_floats(data.get("point_velocity"), "point_velocity"),
        time=_floats(data.get("time"), "time"),
        feedforward=_floats(data.get("feedforward"), "feedforward"),
        final=bool(data.get("final", True)),
        retain=bool(data.get("retain", False)),
        empty_count=int(data.get("empty_count", 5)),
        delay=_floats(data.get("delay"), "delay"),
        id=int(data.get("id", 0)),
        element_id=_ints(data.get("element_id"), "element_id"),
        final_velocity=_floats(data.get("final_velocity"), "final_velocity"),
        hold=[_struct(Hold, h, "hold", {"type": (HoldType, Message.MPIMessagePARAM_INVALID)})
              for h in data.get("hold") or []],
        output=[_struct(Output, o, "output", {"type": (OutputType, Message.MPIMessagePARAM_INVALID)})
                for o in data.get("output") or []],
        event_mask=event_mask,
        master_start=int(data.get("master_start", 0)),
        repeat_from=int(data.get("repeat_from", 0)),
        master_distance=_floats(data.get("master_distance"), "master_distance"),
        slave_position=_floats(data.get("slave_position"), "slave_position"),
        gear_ratio=_floats(data.get("gear_ratio"), "gear_ratio"),
        frames=[_struct(UserFrame, f, "frames") for f in data.get("frames") or []],
    )


def params_to_dict(params: MotionParams) -> dict[str, Any]:
    """MotionParams to the MotionParams message's fields."""
    def plain(obj) -> dict:
        out = {}
        for key in obj.__slots__:
            value = getattr(obj, key)
            out[key] = value.name if isinstance(value, (HoldType, OutputType)) else value
        return out

    return {
        "trajectory": [plain(t) for t in params.trajectory],
        "position": list(params.position),
        "point_velocity": list(params.point_velocity),
        "time": list(params.time),
        "feedforward": list(params.feedforward),
        "final": params.final,
        "retain": params.retain,
        "empty_count": params.empty_count,
        "delay": list(params.delay),
        "id": params.id,
        "element_id": list(params.element_id),
        "final_velocity": list(params.final_velocity),
        "hold": [plain(h) for h in params.hold],
        "output": [plain(o) for o in params.output],
        "event_mask": params.event_mask.names(),
        "master_start": params.master_start,
        "repeat_from": params.repeat_from,
        "master_distance": list(params.master_distance),
        "slave_position": list(params.slave_position),
        "gear_ratio": list(params.gear_ratio),
        "frames": [plain(f) for f in params.frames],
    }


def motion_config(data: Mapping[str, Any]) -> MotionConfig:
    """A MotionConfig message (as a dict) to MPIMotionConfig; axis_numbers is ignored."""
    numbers = {}
    for key in ("decel_time_stop", "decel_time_e_stop", "normal_feedrate", "pause_feedrate", "blend_limit"):
        try:
            numbers[key] = float(data.get(key, 0.0))
        except (TypeError, ValueError) as exc:
            raise RequestError(Message.MPIMessagePARAM_INVALID, f"{key}: a number expected") from exc
    return MotionConfig(
        decel_time=DecelTime(numbers["decel_time_stop"], numbers["decel_time_e_stop"]),
        normal_feedrate=numbers["normal_feedrate"],
        pause_feedrate=numbers["pause_feedrate"],
        user_label=str(data.get("user_label", "")),
        blend_limit=numbers["blend_limit"],
    )


def motion_config_to_dict(config: MotionConfig) -> dict[str, Any]:
    return {
        "decel_time_stop": config.decel_time.stop,
        "decel_time_e_stop": config.decel_time.e_stop,
        "normal_feedrate": config.normal_feedrate,
        "pause_feedrate": config.pause_feedrate,
        "user_label": config.user_label,
        "axis_numbers": list(config.axis_numbers),
        "blend_limit": config.blend_limit,
    }


def in_position(data: Mapping[str, Any]) -> AxisInPosition:
    cfg = _struct(AxisInPosition, data, "in_position")
    numbers = [cfg.position_fine, cfg.velocity, cfg.settling_time]
    if not all(math.isfinite(x) for x in numbers):
        raise RequestError(Message.MPIMessagePARAM_INVALID, "in_position values must be finite")
    return cfg


def in_position_to_dict(cfg: AxisInPosition) -> dict[str, Any]:
    return {key: getattr(cfg, key) for key in cfg.__slots__}
