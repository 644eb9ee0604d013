"""Canonical CDR: the bytes of a message exactly as long as its data, padding zeroed.

Why: ``rclpy.serialization.serialize_message`` (rmw_fastrtps) returns a buffer as long as
the type support's *estimate* of the serialized size, and the estimate counts alignment
padding for every empty sequence of 8-byte elements as if it had elements (the data itself
is written correctly: an empty sequence is just its 4-byte count). A JointState with an
empty ``effort`` came out 4 bytes longer than its data, two empty sequences 8 bytes; those
trailing bytes, like every alignment gap, are uninitialised memory. Readers that check the
length refuse such a message: rosbags allows at most 3 trailing bytes ("CDR message size
mismatch for sensor_msgs/msg/JointState"). So the bag writer walks the message, finds
where its data ends and where the alignment gaps are, cuts the buffer there and zeroes the
gaps: every reader accepts the result, and recording the same messages twice gives the
same bytes.

The layout is plain CDR (XCDR1) as ROS 2 uses it: a 4-byte encapsulation header, then the
fields in order, each primitive aligned to its size (8 at most) relative to the start of
the data after the header; strings as a uint32 length (with the terminating NUL) and the
UTF-8 bytes with a NUL; sequences as a uint32 count and the elements (no alignment for
elements when there are none); fixed arrays as the elements alone; nested messages inline.
"""

from __future__ import annotations

from functools import cache
from typing import Any

from rosidl_parser import definition as d

HEADER = 4  # encapsulation: representation identifier (2 bytes) and options (2 bytes)

_SIZES = {
    "boolean": 1, "octet": 1, "char": 1, "uint8": 1, "int8": 1,
    "uint16": 2, "int16": 2,
    "uint32": 4, "int32": 4, "float": 4,
    "uint64": 8, "int64": 8, "double": 8,
}


class Unsupported(TypeError):
    """A field type the walk does not know (wide strings, long double): keep the bytes as they are."""


# A plan is a tuple of (attribute, kind, detail) per field:
#   ("p", size)  primitive;  ("r", table) a run of primitive fields (attribute None);
#   ("s", None) string;  ("m", plan) message;
#   ("a", (n, element)) fixed array;  ("q", element) sequence   (element = a (kind, detail) pair)
def _element(slot) -> tuple[str, Any]:  # (kind, its detail: a size, None, a plan, ...)
    if isinstance(slot, d.BasicType):
        try:
            return "p", _SIZES[slot.typename]
        except KeyError:
            raise Unsupported(f"CDR walk: type {slot.typename}") from None
    if isinstance(slot, (d.UnboundedString, d.BoundedString)):
        return "s", None
    if isinstance(slot, d.NamespacedType):
        return "m", plan_of(_message_class(slot))
    if isinstance(slot, d.Array):
        return "a", (slot.size, _element(slot.value_type))
    if isinstance(slot, (d.UnboundedSequence, d.BoundedSequence)):
        return "q", _element(slot.value_type)
    raise Unsupported(f"CDR walk: field type {type(slot).__name__}")


def _message_class(slot: d.NamespacedType):
    import importlib

    return getattr(importlib.import_module(".".join(slot.namespaces)), slot.name)


@cache
def plan_of(msg_class) -> tuple:
    """The field layout of a generated message class (cached per class). Consecutive
    primitive fields become one run ("r"), laid out in advance for each start offset mod 8
    (their layout depends on nothing else), so the walk never reads them."""
    names = list(msg_class.get_fields_and_field_types())
    plan: list = []
    sizes: list[int] = []
    for name, slot in zip(names, msg_class.SLOT_TYPES, strict=True):
        kind, detail = _element(slot)
        if kind == "p":
            sizes.append(detail)
            continue
        if sizes:
            plan.append((None, "r", _run(sizes)))
            sizes = []
        plan.append((name, kind, detail))
    if sizes:
        plan.append((None, "r", _run(sizes)))
    return tuple(plan)


def _run(sizes: list[int]) -> tuple:
    """For each start offset 0..7: (bytes the run takes, its gaps relative to the start)."""
    table = []
    for start in range(8):
        gaps: list[tuple[int, int]] = []
        pos = start
        for size in sizes:
            pos = _align(pos, size, gaps) + size
        table.append((pos - start, tuple((a - start, b - start) for a, b in gaps)))
    return tuple(table)


def _align(pos: int, size: int, gaps: list) -> int:
    aligned = (pos + size - 1) & -size
    if aligned != pos:
        gaps.append((pos, aligned))
    return aligned


def _string(value: str, pos: int, gaps: list) -> int:
    pos = _align(pos, 4, gaps)
    return pos + 4 + len(value.encode("utf-8")) + 1


def _one(kind: str, detail, value, pos: int, gaps: list) -> int:
    if kind == "r":
        taken, relative = detail[pos & 7]
        for a, b in relative:
            gaps.append((pos + a, pos + b))
        return pos + taken
    if kind == "p":
        return _align(pos, detail, gaps) + detail
    if kind == "s":
        return _string(value, pos, gaps)
    if kind == "m":
        return _walk(detail, value, pos, gaps)
    if kind == "a":
        count, (ekind, edetail) = detail
        return _many(ekind, edetail, value, count, pos, gaps)
    # sequence: the count, then the elements
    ekind, edetail = detail
    pos = _align(pos, 4, gaps) + 4
    return _many(ekind, edetail, value, len(value), pos, gaps)


def _many(kind: str, detail, values, count: int, pos: int, gaps: list) -> int:
    if count == 0:
        return pos
    if kind == "p":
        return _align(pos, detail, gaps) + detail * count
    for value in values:
        pos = _one(kind, detail, value, pos, gaps)
    return pos


def _walk(plan: tuple, msg, pos: int, gaps: list) -> int:
    for name, kind, detail in plan:
        pos = _one(kind, detail, None if name is None else getattr(msg, name), pos, gaps)
    return pos


def layout(msg) -> tuple[int, list[tuple[int, int]]]:
    """(length of the data after the header, alignment gaps as [start, end) offsets in it)."""
    gaps: list[tuple[int, int]] = []
    msg_class: type = type(msg)  # (as type[Any], mypy finds it not Hashable for plan_of's cache)
    end = _walk(plan_of(msg_class), msg, 0, gaps)
    return end, gaps


def canonical(data: bytes, msg) -> bytes:
    """``data`` (the CDR of ``msg`` from rclpy) cut to its length, with the gaps zeroed.

    Returns ``data`` unchanged when the message has a field type the walk does not know.
    Raises ValueError when ``data`` is shorter than the message's data (not its CDR)."""
    try:
        end, gaps = layout(msg)
    except Unsupported:
        return data
    if len(data) < HEADER + end:
        raise ValueError(f"CDR of {type(msg).__name__}: {len(data)} bytes, its data needs {HEADER + end}")
    out = bytearray(data[:HEADER + end])
    for start, stop in gaps:
        out[HEADER + start:HEADER + stop] = bytes(stop - start)
    return bytes(out)


def serialize(msg) -> bytes:
    """The canonical CDR of a ROS message."""
    from rclpy.serialization import serialize_message

    return canonical(serialize_message(msg), msg)
