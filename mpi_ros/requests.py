"""Requests as plain data (dicts with the ROS interfaces' field names) <-> MPI structs.

The ROS layer turns messages into these dicts at the edge; recordings store them as
JSON; replay and the Python client build them directly. Names are the spec's without
prefix (type "S_CURVE", attribute "APPEND", hold type "GATE", event "MOTION_DONE").

Parsing only checks that a request can be read (a mapping where one is expected, a
number where a number is): anything else raises :class:`Refused`, the only error
the command layer answers as the user's (MPIMessagePARAM_INVALID unless named). Ranges
are the structs' validators' business (mpi_ros/mpi/base/params.py), run by the controller.

Size: before any of it is read, a request must be small enough (:func:`check_size`: at
most params.MAX_REQUEST_VALUES array elements and params.MAX_REQUEST_TEXT characters of
text in all). A request refused for its size is recorded compacted (:func:`compact`): its
long arrays and strings are replaced by markers that count as their sizes, so the record
stays small and is refused again, with the same message, when it is replayed.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any

from mpi_ros import scalars
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.params import (
    MAX_REQUEST_TEXT,
    MAX_REQUEST_VALUES,
    AxisFaultConfig,
    AxisInPosition,
    AxisMaster,
    DecelTime,
    Hold,
    MotionConfig,
    MotionParams,
    Output,
    SecondaryFeedback,
    Trajectory,
    UserFrame,
    shown,
)
from mpi_ros.mpi.base.types import AxisMasterType, HoldType, MotionAttr, MPIMotionType, OutputType


@dataclass(frozen=True, slots=True)
class MotionRequest:
    type: MPIMotionType
    attributes: MotionAttr
    params: MotionParams | None  # None: the parameters stored with params_set


def _unreadable(what: str, expected: str, value: Any) -> Refused:
    return Refused(Message.MPIMessagePARAM_INVALID, f"{what}: {expected} expected, got {shown(value)}")


# -- size ----------------------------------------------------------------------------------------
# A compacted record puts one of these mappings where a long array or string was: {OMITTED_VALUES:
# n, OMITTED_TEXT: c} counts as n array elements and c characters (either key may be left out).
OMITTED_VALUES = "omitted_values"
OMITTED_TEXT = "omitted_characters"
_MARKER_KEYS = frozenset((OMITTED_VALUES, OMITTED_TEXT))
_COMPACT_ELEMENTS = 32  # a compacted record keeps arrays up to this long ...
_COMPACT_TEXT = 256  # ... and strings up to this long
_LEAVES = (int, float, bool, type(None))
# Empty, these add nothing to a size: a goal's dict holds a dozen empty arrays, not walked.
# (Exact types only: the truth of anything else, a numpy array say, is not asked.)
_EMPTIABLE = frozenset((list, dict, str))


@dataclass(frozen=True, slots=True)
class RequestSize:
    """How much a request carries: array elements (over every array, nested ones too) and
    characters of text (over every string; mapping keys are field names and not counted),
    with the longest array and the longest string (where, how long)."""

    values: int = 0
    text: int = 0
    longest_array: tuple[str, int] = ("", 0)
    longest_text: tuple[str, int] = ("", 0)

    @property
    def ok(self) -> bool:
        return self.values <= MAX_REQUEST_VALUES and self.text <= MAX_REQUEST_TEXT

    def refusal(self) -> Refused:
        """The answer to a request of this size, when it is not ``ok``."""
        if self.values > MAX_REQUEST_VALUES:
            where, count = self.longest_array
            return Refused(Message.MPIMessagePARAM_INVALID,
                                f"request too large: {self.values:,} array elements ({where} has {count:,}); at most "
                                f"{MAX_REQUEST_VALUES:,} in one request (params.MAX_REQUEST_VALUES): stream a longer "
                                "path in parts (APPEND)")
        where, count = self.longest_text
        return Refused(Message.MPIMessagePARAM_INVALID,
                            f"request too large: {self.text:,} characters of text ({where} has {count:,}); at most "
                            f"{MAX_REQUEST_TEXT:,} in one request (params.MAX_REQUEST_TEXT)")


def _marker(value: Mapping) -> tuple[int, int] | None:
    """(values, characters) of a compacted record's marker; None if ``value`` is not one."""
    if not value or not set(value) <= _MARKER_KEYS:
        return None
    counts = [value.get(OMITTED_VALUES, 0), value.get(OMITTED_TEXT, 0)]
    if not all(isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in counts):
        return None
    return counts[0], counts[1]


def _longer(found: tuple[str, int], where: str, count: int) -> tuple[str, int]:
    # the longest; among equals the first name in order (the same whatever the mapping's order)
    return (where, count) if count > found[1] or (count == found[1] and count and where < found[0]) else found


def request_size(data: Any, where: str = "request") -> RequestSize:
    """The size of ``data`` (a request, or any part of one).

    Walks the request once, without recursion (no nesting depth can overflow the stack). The
    elements of an array longer than MAX_REQUEST_VALUES are not looked at: its length alone
    refuses the request."""
    values = text = 0
    longest_array = longest_text = ("", 0)
    stack = [(where, data)]
    while stack:
        here, value = stack.pop()
        kind = type(value)  # exact types first: the ABC check below costs more than the rest
        if kind is str or (kind is not list and kind is not dict and isinstance(value, str)):
            text += len(value)
            longest_text = _longer(longest_text, here, len(value))
        elif kind is list or (kind is not dict and isinstance(value, (list, tuple))):
            values += len(value)
            longest_array = _longer(longest_array, here, len(value))
            if len(value) <= MAX_REQUEST_VALUES:
                stack.extend((f"{here}[{i}]", item) for i, item in enumerate(value) if not isinstance(item, _LEAVES))
        elif isinstance(value, Mapping):
            marker = _marker(value)
            if marker is not None:
                values += marker[0]
                text += marker[1]
                longest_array = _longer(longest_array, here, marker[0])
                longest_text = _longer(longest_text, here, marker[1])
            else:
                prefix = "" if here == "request" else f"{here}."
                stack.extend((f"{prefix}{key}", item) for key, item in value.items()
                             if not isinstance(item, _LEAVES) and (item or type(item) not in _EMPTIABLE))
    return RequestSize(values, text, longest_array, longest_text)


def check_size(data: Any) -> None:
    """Raise Refused (MPIMessagePARAM_INVALID, naming the longest array or string) if
    the request is too large to be read (see :class:`RequestSize`)."""
    size = request_size(data)
    if not size.ok:
        # raised as made: an exception held in a local of this frame would make a cycle
        # (exception -> traceback -> frame -> exception) that keeps the request until the
        # cyclic garbage collector runs
        raise size.refusal()


def compact(data: Any) -> Any:
    """``data`` with every array longer than 32 elements and every string longer than 256
    characters replaced by a marker of its size ({"omitted_values": n, "omitted_characters":
    c}): what a record keeps of a request refused for its size. Its size, as
    :func:`request_size` counts it, is the request's, so replayed it is refused again."""
    if isinstance(data, str):
        return {OMITTED_TEXT: len(data)} if len(data) > _COMPACT_TEXT else data
    if isinstance(data, (list, tuple)):
        if len(data) > _COMPACT_ELEMENTS:
            size = request_size(data)
            return {key: count for key, count in ((OMITTED_VALUES, size.values), (OMITTED_TEXT, size.text)) if count}
        return [compact(item) for item in data]
    if isinstance(data, Mapping) and _marker(data) is None:
        return {key: compact(item) for key, item in data.items()}
    return data


def mapping(data: Any, what: str) -> Mapping[str, Any]:
    """A mapping (None: an empty one)."""
    if data is None:
        return {}
    if type(data) is not dict and not isinstance(data, Mapping):  # (a dict: no ABC check)
        raise _unreadable(what, "a mapping", data)
    return data


def sequence(values: Any, what: str) -> list:
    """A list (None: an empty one); a string is not a list of its characters."""
    if values is None:
        return []
    if not isinstance(values, (list, tuple)):
        raise _unreadable(what, "a list", values)
    return list(values)


# The scalars of a request are read by the rule the configuration file is read by
# (mpi_ros/scalars.py): a number is a real number or a string that spells one (nan passes:
# its range is the validators' business); an integer is an int, never 3.0; true or false is a
# bool, never 0 or 1 (docs/decisions.md, "One reader for plain data").
_READ = scalars.readers(_unreadable)
number = _READ.number
integer = _READ.integer
boolean = _READ.boolean
text = _READ.text


def numbers(values: Any, what: str) -> list[float]:
    if values is None:  # most of a request's arrays are absent
        return []
    values = sequence(values, what)
    if all(type(v) is float for v in values):  # what the ROS edge gives: read as is, no name per element
        return values
    return [number(v, f"{what}[{i}]") for i, v in enumerate(values)]


def integers(values: Any, what: str) -> list[int]:
    if values is None:
        return []
    values = sequence(values, what)
    if all(type(v) is int for v in values):
        return values
    return [integer(v, f"{what}[{i}]") for i, v in enumerate(values)]


def enum_by_name(enum, name: Any, what: str, message: Message = Message.MPIMessagePARAM_INVALID):
    key = str(name).strip().upper()
    member = enum.__members__.get(key)
    if member is None:
        raise Refused(message, f"unknown {what} {shown(name)}")
    return member


def event_mask(names: Any, what: str) -> MPIEventType:
    values = sequence(names, what)
    mask = MPIEventType.parse(values)
    if mask is None:
        raise Refused(Message.MPIMessagePARAM_INVALID, f"{what}: unknown event type in {shown(values)}")
    return mask


def _struct(cls, data: Any, what: str, enum_fields: dict | None = None):
    """Dataclass ``cls`` from a mapping of its fields (each read as its default's type)."""
    enum_fields = enum_fields or {}
    kwargs = {}
    readers = _readers(cls)
    for key, value in mapping(data, what).items():
        if key not in readers:
            raise Refused(Message.MPIMessagePARAM_INVALID, f"{what}: unknown field {shown(key)}")
        if key in enum_fields:
            enum, message = enum_fields[key]
            kwargs[key] = enum.NONE if value in ("", None) else enum_by_name(enum, value, f"{what} type", message)
            continue
        read = readers[key]
        assert read is not None  # (only an enum's field has none: read above)
        kwargs[key] = read(value, f"{what}.{key}")
    return cls(**kwargs)


@functools.cache
def _readers(cls) -> dict[str, Callable[[Any, str], Any] | None]:
    """The reader of each field of dataclass ``cls``, by its default's type (None for an
    enum's: read by name); made once per class, not per request."""
    defaults = cls()
    return {f.name: _READ.of(type(getattr(defaults, f.name))) for f in fields(cls)}


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
        raise Refused(Message.MPIMotionMessageTYPE_INVALID, f"unknown attribute in {shown(names)}")
    if boolean(data.get("use_stored_params", False), "use_stored_params"):
        return MotionRequest(motion_type, attributes, None)
    return MotionRequest(motion_type, attributes, motion_params(data))


_HOLD_TYPED = {"type": (HoldType, Message.MPIMessagePARAM_INVALID)}
_OUTPUT_TYPED = {"type": (OutputType, Message.MPIMessagePARAM_INVALID)}


# Each field of MotionParams a request may hold, with its reader, in the order they are read.
_PARAM_READERS: dict[str, Callable[[Any, str], Any]] = {
    "trajectory": lambda values, what: _structs(Trajectory, values, what),
    "position": numbers,
    "point_velocity": numbers,
    "time": numbers,
    "feedforward": numbers,
    "final": boolean,
    "retain": boolean,
    "empty_count": integer,
    "delay": numbers,
    "id": integer,
    "element_id": integers,
    "final_velocity": numbers,
    "hold": lambda values, what: _structs(Hold, values, what, _HOLD_TYPED),
    "output": lambda values, what: _structs(Output, values, what, _OUTPUT_TYPED),
    "event_mask": event_mask,
    "master_start": integer,
    "repeat_from": integer,
    "master_distance": numbers,
    "slave_position": numbers,
    "gear_ratio": numbers,
    "frames": lambda values, what: _structs(UserFrame, values, what),
    "behavior": integer,
    "low_count": integer,
    "expected_axes": integer,
}


def motion_params(data: Any) -> MotionParams:
    """The fields a request holds, read in _PARAM_READERS' order (a request with several bad
    fields is refused for the first); the others keep MotionParams' defaults, which are what
    reading their absence gives (a request holds a few of the two dozen: each is read once)."""
    data = mapping(data, "params")
    return MotionParams(**{name: read(data[name], name) for name, read in _PARAM_READERS.items() if name in data})


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
        raise Refused(Message.MPIMessagePARAM_INVALID, f"config: unknown field {shown(unknown[0])}")
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


KEEP_MOTOR = -2  # AxisMaster.msg's encoder_fault_motor_number default: keep the current one
_MASTER_FIELDS = frozenset({"type", "number", "address", "encoder_fault_motor_number"})


def axis_master(data: Any, correction: Any, current: AxisMaster) -> AxisMaster:
    """The AxisMaster message (as a dict: type, number, address) and master_correction of an
    AxisConfigSet request, over the axis' ``current`` master: an absent master (a request
    recorded before the field existed) or an empty type keeps the current source, an absent
    master_correction the current correction. Ranges are checked by the controller."""
    master = current.copy()
    if data is not None:
        data = mapping(data, "master")
        unknown = sorted(str(key) for key in data if key not in _MASTER_FIELDS)
        if unknown:
            raise Refused(Message.MPIMessagePARAM_INVALID, f"master: unknown field {shown(unknown[0])}")
        kind = text(data.get("type", ""), "master.type")
        if kind.strip():
            master.type = enum_by_name(AxisMasterType, kind, "master type (MOTOR_FEEDBACK_PRIMARY, "
                                       "MOTOR_FEEDBACK_SECONDARY, AXIS_COMMANDED_POSITION, AXIS_ACTUAL_POSITION, "
                                       "ADDRESS)")
            master.number = integer(data.get("number", 0), "master.number")
            master.address = integer(data.get("address", 0), "master.address")
        motor = integer(data.get("encoder_fault_motor_number", KEEP_MOTOR), "master.encoder_fault_motor_number")
        master.encoder_fault_motor_number = None if motor == KEEP_MOTOR else motor
    if correction is not None:
        master.correction = integer(correction, "master_correction")
    return master


def axis_master_to_dict(master: AxisMaster) -> dict[str, Any]:
    """The AxisMaster message's fields (master_correction is a field of the service beside it)."""
    motor = master.encoder_fault_motor_number
    return {"type": master.type.name, "number": master.number, "address": master.address,
            "encoder_fault_motor_number": KEEP_MOTOR if motor is None else motor}


def secondary_feedback(data: Any) -> tuple[int, SecondaryFeedback]:
    """A MotorFeedbackSecondarySet request (as a dict): (motor, the input's new reading)."""
    data = mapping(data, "request")
    return (integer(data.get("motor", -1), "motor"),
            SecondaryFeedback(number(data.get("position", 0.0), "position"),
                              number(data.get("velocity", 0.0), "velocity")))


def fault_config(data: Any, base: AxisFaultConfig) -> AxisFaultConfig:
    """An AxisFaultConfig message (as a dict) over ``base`` (the axis' configuration): the
    fields it leaves out keep their values. Action names are read in any case; the ranges
    are checked by the controller (AxisFaultConfig.validate)."""
    merged = {**fault_config_to_dict(base), **mapping(data, "config")}
    config = _struct(AxisFaultConfig, merged, "config")
    for key in config.__slots__:
        if key.endswith("_action"):
            setattr(config, key, getattr(config, key).strip().upper())
    return config


def fault_config_to_dict(cfg: AxisFaultConfig) -> dict[str, Any]:
    return {key: getattr(cfg, key) for key in cfg.__slots__}
