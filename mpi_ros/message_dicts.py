"""ROS messages <-> plain dicts: the one conversion the nodes, the bag tools, the client and the console use.

:func:`to_dict` reads any generated message (and a message read from a bag by the definition
the bag stores) into plain Python values. :func:`fill` sets a message's fields from a mapping,
as ``ros2 action send_goal`` reads its YAML, with one rule (docs/decisions.md, "message <->
dict: unknown fields raise"): every name must be a field of the message and every value of
its type, else ValueError naming the field (and the valid ones); numbers become float64 at
the edge, as the generated messages want.

Pure: it imports no rclpy and nothing of the simulated controller (the client depends on it);
rosidl_parser is imported when a class is first read.
"""

from __future__ import annotations

import importlib
import numbers
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any


# -- message -> dict ---------------------------------------------------------------------------------
def to_dict(msg: Any) -> dict[str, Any]:
    """A ROS message as a dict of plain Python values (nested messages as dicts), in field
    order; also a message read from a bag by the definition the bag stores (its fields are its slots)."""
    plan = _reading(type(msg))
    if plan is None:
        return {name: _plain(getattr(msg, name)) for name in _fields(msg)}
    values = dict(zip(plan.names, plan.read_all(msg), strict=True))
    for name, read in plan.converted:
        values[name] = read(values[name])
    return values


@dataclass(frozen=True, slots=True)
class _Reading:
    """How a generated message class becomes a dict, decided once from its declared types: a
    goal has some thirty fields and arrives hundreds of times a second."""

    names: tuple[str, ...]
    read_all: Callable[[Any], tuple[Any, ...]]  # every field's value at once (its slot, not its property)
    converted: tuple[tuple[str, Callable[[Any], Any]], ...]  # the fields not plain already, and how


_READINGS: dict[type, _Reading] = {}  # generated classes only: a bag's message classes come and go


def _reading(cls: type) -> _Reading | None:
    plan = _READINGS.get(cls)
    if plan is None:
        plan = _plan(cls)
        if plan is not None:
            _READINGS[cls] = plan
    return plan


def _plan(cls: type) -> _Reading | None:
    """None for classes other than generated ones (those are read by value). A generated
    class keeps field ``x`` in slot ``_x`` behind a property; reading the slots directly
    takes a third of the time (the properties are Python functions)."""
    slot_types = getattr(cls, "SLOT_TYPES", None)
    if slot_types is None or not hasattr(cls, "get_fields_and_field_types"):
        return None
    names = tuple(cls.get_fields_and_field_types())
    slots = set(getattr(cls, "__slots__", ()))
    attributes = [f"_{name}" if f"_{name}" in slots else name for name in names]
    getter = operator.attrgetter(*attributes)
    read_all = getter if len(names) > 1 else (lambda msg: (getter(msg),))
    readers = ((name, _reader(slot_type)) for name, slot_type in zip(names, slot_types, strict=True))
    return _Reading(names, read_all, tuple((name, read) for name, read in readers if read is not None))


def _reader(slot_type: Any) -> Callable[[Any], Any] | None:
    """How a field's value becomes plain; None when it is plain already."""
    from rosidl_parser import definition

    if isinstance(slot_type, definition.NamespacedType):
        return to_dict
    if isinstance(slot_type, definition.AbstractNestedType):
        value_type = slot_type.value_type
        if isinstance(value_type, definition.NamespacedType):
            return _dicts
        if isinstance(value_type, definition.BasicType) and value_type.typename in _NUMBERS:
            return _numbers  # array.array (sequences) or numpy (fixed arrays)
        return _plain  # strings, booleans, bytes: plain lists
    if isinstance(slot_type, definition.BasicType) and slot_type.typename in _BYTES:
        return _plain
    return None


# element types rosidl keeps in array.array or numpy arrays (both have tolist)
_NUMBERS = frozenset({"float", "double", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"})
_BYTES = frozenset({"octet", "byte"})  # kept as bytes of length 1


def _numbers(value: Any) -> list[Any]:
    return list(value.tolist())  # Python numbers


def _dicts(messages: Any) -> list[dict[str, Any]]:
    return [to_dict(m) for m in messages]


def _fields(msg: Any) -> list[str]:
    if hasattr(msg, "get_fields_and_field_types"):
        return list(msg.get_fields_and_field_types())
    return [name for name in msg.__slots__ if not name.startswith("_")]


def _plain(value: Any) -> Any:
    if hasattr(value, "get_fields_and_field_types") or (hasattr(value, "__slots__") and hasattr(value, "_type")):
        return to_dict(value)
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, bytes):  # an octet (DiagnosticStatus.level) reads as its number
        return value[0] if len(value) == 1 else list(value)
    if hasattr(value, "tolist"):  # array.array for sequences, numpy arrays for fixed arrays
        return value.tolist()
    return value


# -- type name -> class ---------------------------------------------------------------------------------
def message_class(type_name: str) -> type:
    """The generated class of ``pkg/msg/Type`` (or ``pkg/Type``)."""
    parts = type_name.split("/")
    if len(parts) == 2:
        parts.insert(1, "msg")
    if len(parts) != 3:
        raise ValueError(f"{type_name!r}: not a message type name (pkg/msg/Type)")
    cls: type = getattr(importlib.import_module(f"{parts[0]}.{parts[1]}"), parts[2])
    return cls


# -- dict -> message ------------------------------------------------------------------------------------
def fill(msg: Any, data: Mapping[str, Any], where: str = "") -> Any:
    """Set ``msg``'s fields from ``data`` and return it. An unknown field or a value of the
    wrong type raises ValueError naming the field (``where``: the path to ``msg``, for nested ones)."""
    if not isinstance(data, Mapping):
        raise ValueError(f"{where or type(msg).__name__}: expected a mapping of fields, got {data!r}")
    types = msg.get_fields_and_field_types()
    for name, value in data.items():
        path = f"{where}.{name}" if where else str(name)
        if name not in types:
            raise ValueError(f"{path}: no such field in {type(msg).__name__} (fields: {', '.join(types)})")
        setattr(msg, name, _convert(types[name], value, path))
    return msg


_INTEGERS = frozenset({"int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64", "char"})


def _convert(kind: str, value: Any, where: str) -> Any:
    element = _element_kind(kind)
    if element is not None:
        if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__iter__"):
            raise ValueError(f"{where}: expected a list, got {value!r}")
        return [_convert(element, v, f"{where}[{i}]") for i, v in enumerate(value)]
    if "/" in kind:
        return fill(message_class(kind)(), value, where)
    return _scalar(kind, value, where)


def _scalar(kind: str, value: Any, where: str) -> Any:
    if kind in ("double", "float"):
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ValueError(f"{where}: expected a number, got {value!r}")
        return float(value)
    if kind in _INTEGERS:
        return _integer(value, where)
    if kind in _BYTES:
        if isinstance(value, bytes) and len(value) == 1:
            return value
        number = _integer(value, where)
        if not 0 <= number <= 255:
            raise ValueError(f"{where}: expected a byte (0..255), got {value!r}")
        return bytes([number])
    if kind == "boolean":
        if not isinstance(value, bool):
            raise ValueError(f"{where}: expected true or false, got {value!r}")
        return value
    if kind.startswith(("string", "wstring")):
        if not isinstance(value, str):
            raise ValueError(f"{where}: expected a string, got {value!r}")
        return str(value)  # a StrEnum member becomes its plain name
    raise ValueError(f"{where}: fields of type {kind} cannot be set here")


def _integer(value: Any, where: str) -> int:
    """A whole number (3.0 included, as YAML may spell it), else ValueError."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return int(value)
    if isinstance(value, float) and value.is_integer():
        return int(value)
    raise ValueError(f"{where}: expected an integer, got {value!r}")


def _element_kind(kind: str) -> str | None:
    """``double`` for ``sequence<double>``, ``sequence<double, 5>`` or ``double[3]``; None for scalars."""
    if kind.startswith("sequence<"):
        return kind[len("sequence<"):-1].split(",")[0].strip()
    if kind.endswith("]") and "[" in kind:
        return kind[:kind.index("[")]
    return None
