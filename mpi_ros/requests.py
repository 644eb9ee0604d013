"""Requests as plain data (dicts with the ROS interfaces' field names) <-> MPI structs.

The ROS layer turns messages into these dicts at the edge; recordings store them as
JSON; replay and the Python client build them directly. Names are the spec's without
prefix (type "S_CURVE", attribute "APPEND", hold type "GATE", event "MOTION_DONE").

Parsing only checks that a request can be read (a mapping where one is expected, a
number where a number is): anything else raises :class:`RequestError`, the only error
the command layer answers as the user's (MPIMessagePARAM_INVALID unless named). Ranges
are the structs' validators' business (mpi_ros/mpi/params.py), run by the controller.
"""

from __future__ import annotations

import numbers as _numbers
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

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


def _unreadable(what: str, expected: str, value: Any) -> RequestError:
    return RequestError(Message.MPIMessagePARAM_INVALID, f"{what}: {expected} expected, got {value!r}")


def mapping(data: Any, what: str) -> Mapping[str, Any]:
    """A mapping (None: an empty one)."""
    if data is None:
        return {}
    if not isinstance(data, Mapping):
        raise _unreadable(what, "a mapping", data)
    return data


def sequence(values: Any, what: str) -> list:
    """A list (None: an empty one); a string is not a list of its characters."""
    if values is None:
        return []
    if not isinstance(values, (list, tuple)):
        raise _unreadable(what, "a list", values)
    return list(values)


def number(value: Any, what: str) -> float:
    """A number as a float (its range is the validators' business: nan passes here). A
    string that spells a number reads as one, as in the YAML loader (PyYAML reads 1e9,
    without an exponent sign, as a string)."""
    if isinstance(value, bool) or not isinstance(value, (_numbers.Real, str)):
        raise _unreadable(what, "a number", value)
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError) as exc:  # an int beyond every double, a word
        raise _unreadable(what, "a number", value) from exc


def integer(value: Any, what: str) -> int:
    """An integer (an integral float such as 3.0 reads as 3; its range is the validators')."""
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise _unreadable(what, "an integer", value)
    if isinstance(value, _numbers.Integral):
        return int(value)
    try:
        if float(value).is_integer():  # nan and inf are not integers either
            # typeshed's numbers.Real promises no __int__ (every Real has one: float, Fraction, numpy's)
            return int(value)  # type: ignore[call-overload]
    except (TypeError, ValueError, OverflowError):
        pass
    raise _unreadable(what, "an integer", value)


def boolean(value: Any, what: str) -> bool:
    """true or false (1 and 0 too, as C's long flags)."""
    if isinstance(value, bool):
        return value
    if isinstance(value, _numbers.Integral) and value in (0, 1):
        return bool(value)
    raise _unreadable(what, "true or false", value)


def text(value: Any, what: str) -> str:
    if not isinstance(value, str):
        raise _unreadable(what, "a string", value)
    return value


def numbers(values: Any, what: str) -> list[float]:
    return [number(v, f"{what}[{i}]") for i, v in enumerate(sequence(values, what))]


def integers(values: Any, what: str) -> list[int]:
    return [integer(v, f"{what}[{i}]") for i, v in enumerate(sequence(values, what))]


def enum_by_name(enum, name: Any, what: str, message: Message = Message.MPIMessagePARAM_INVALID):
    key = str(name).strip().upper()
    member = enum.__members__.get(key)
    if member is None:
        raise RequestError(message, f"unknown {what} {name!r}")
    return member


def event_mask(names: Any, what: str) -> MPIEventType:
    values = sequence(names, what)
    mask = MPIEventType.parse(values)
    if mask is None:
        raise RequestError(Message.MPIMessagePARAM_INVALID, f"{what}: unknown event type in {values}")
    return mask


_READERS = {bool: boolean, int: integer, float: number, str: text}


def _struct(cls, data: Any, what: str, enum_fields: dict | None = None):
    """Dataclass ``cls`` from a mapping of its fields (each read as its default's type)."""
    enum_fields = enum_fields or {}
    kwargs = {}
    defaults = cls()
    known = {f.name for f in fields(cls)}
    for key, value in mapping(data, what).items():
        if key not in known:
            raise RequestError(Message.MPIMessagePARAM_INVALID, f"{what}: unknown field {key!r}")
        if key in enum_fields:
            enum, message = enum_fields[key]
            kwargs[key] = enum.NONE if value in ("", None) else enum_by_name(enum, value, f"{what} type", message)
            continue
        kwargs[key] = _READERS[type(getattr(defaults, key))](value, f"{what}.{key}")
    return cls(**kwargs)


def _structs(cls, values: Any, what: str, enum_fields: dict | None = None) -> list:
    return [_struct(cls, v, f"{what}[{i}]", enum_fields) for i, v in enumerate(sequence(values, what))]


def motion_request(data: Any) -> MotionRequest:
    """A MotionStart/MotionModify goal (as a dict) to the MPI's type, attributes, params."""
    data = mapping(data, "goal")
    motion_type = enum_by_name(MPIMotionType, data.get("type", ""), "motion type",
                               Message.MPIMotionMessageTYPE_INVALID)
    names = sequence(data.get("attributes"), "attributes")
    attributes = MotionAttr.parse(names)
    if attributes is None:
        raise RequestError(Message.MPIMotionMessageTYPE_INVALID, f"unknown attribute in {names}")
    if boolean(data.get("use_stored_params", False), "use_stored_params"):
        return MotionRequest(motion_type, attributes, None)
    return MotionRequest(motion_type, attributes, motion_params(data))


_HOLD_TYPED = {"type": (HoldType, Message.MPIMessagePARAM_INVALID)}
_OUTPUT_TYPED = {"type": (OutputType, Message.MPIMessagePARAM_INVALID)}


def motion_params(data: Any) -> MotionParams:
    data = mapping(data, "params")
    return MotionParams(
        trajectory=_structs(Trajectory, data.get("trajectory"), "trajectory"),
        position=numbers(data.get("position"), "position"),
        point_velocity=numbers(data.get("point_velocity"), "point_velocity"),
        time=numbers(data.get("time"), "time"),
        feedforward=numbers(data.get("feedforward"), "feedforward"),
        final=boolean(data.get("final", True), "final"),
        retain=boolean(data.get("retain", False), "retain"),
        empty_count=integer(data.get("empty_count", 5), "empty_count"),
        delay=numbers(data.get("delay"), "delay"),
        id=integer(data.get("id", 0), "id"),
        element_id=integers(data.get("element_id"), "element_id"),
        final_velocity=numbers(data.get("final_velocity"), "final_velocity"),
        hold=_structs(Hold, data.get("hold"), "hold", _HOLD_TYPED),
        output=_structs(Output, data.get("output"), "output", _OUTPUT_TYPED),
        event_mask=event_mask(data.get("event_mask"), "event_mask"),
        master_start=integer(data.get("master_start", 0), "master_start"),
        repeat_from=integer(data.get("repeat_from", 0), "repeat_from"),
        master_distance=numbers(data.get("master_distance"), "master_distance"),
        slave_position=numbers(data.get("slave_position"), "slave_position"),
        gear_ratio=numbers(data.get("gear_ratio"), "gear_ratio"),
        frames=_structs(UserFrame, data.get("frames"), "frames"),
        behavior=integer(data.get("behavior", 0), "behavior"),
        low_count=integer(data.get("low_count", 0), "low_count"),
        expected_axes=integer(data.get("expected_axes", 0), "expected_axes"),
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
        "behavior": params.behavior,
        "low_count": params.low_count,
        "expected_axes": params.expected_axes,
    }


_CONFIG_NUMBERS = ("decel_time_stop", "decel_time_e_stop", "normal_feedrate", "pause_feedrate", "blend_limit")
_CONFIG_FIELDS = frozenset(_CONFIG_NUMBERS) | {"user_label", "axis_numbers"}


def motion_config(data: Any) -> MotionConfig:
    """A MotionConfig message (as a dict) to MPIMotionConfig; axis_numbers (read only) is
    ignored, an unknown field refused (a misspelt one would otherwise set its field to 0)."""
    data = mapping(data, "config")
    unknown = sorted(str(key) for key in data if key not in _CONFIG_FIELDS)
    if unknown:
        raise RequestError(Message.MPIMessagePARAM_INVALID, f"config: unknown field {unknown[0]!r}")
    value = {key: number(data.get(key, 0.0), key) for key in _CONFIG_NUMBERS}
    return MotionConfig(
        decel_time=DecelTime(value["decel_time_stop"], value["decel_time_e_stop"]),
        normal_feedrate=value["normal_feedrate"],
        pause_feedrate=value["pause_feedrate"],
        user_label=text(data.get("user_label", ""), "user_label"),
        blend_limit=value["blend_limit"],
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


def in_position(data: Any) -> AxisInPosition:
    """An AxisInPosition message (as a dict); its ranges are checked by the controller."""
    return _struct(AxisInPosition, data, "in_position")


def in_position_to_dict(cfg: AxisInPosition) -> dict[str, Any]:
    return {key: getattr(cfg, key) for key in cfg.__slots__}
