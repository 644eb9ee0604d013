"""A few fields of a recorded message, read straight from its CDR bytes.

Why: a plot of a 3-minute recording needs seven numbers from each of about 100,000 status
messages, and building each message (rclpy's deserialize_message, nested AxisStatus and
all) took 120 to 180 us of it: 15 s before anything was drawn. :func:`field_reader` lays
out, once per type and from the generated class's own slot types (so it follows the
definitions as they change), where the wanted fields lie, and reads them with one
``struct`` call per run of fixed-size fields. The layout is the one mpi_ros.bag.cdr writes
and walks (plain CDR, XCDR1, little endian; alignment relative to the data after the
4-byte header; nested messages inline). It reads primitives, strings and sequences of
primitives, and the fields up to the last one wanted: a field after a sequence of messages
is refused when the reader is made (:class:`Unreadable`), not guessed.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from rosidl_parser import definition as d

from .cdr import HEADER

_CODES = {"boolean": "?", "octet": "B", "char": "B", "uint8": "B", "int8": "b", "uint16": "H", "int16": "h",
          "uint32": "I", "int32": "i", "float": "f", "uint64": "Q", "int64": "q", "double": "d"}
LITTLE_ENDIAN = 0x01  # the second byte of the encapsulation header: CDR_LE


class Unreadable(TypeError):
    """The wanted fields cannot be read without building the message (a field after a
    sequence of messages, a type this reader does not know, big-endian data)."""


def _layout(msg_class: Any, prefix: str = "") -> list[tuple[str, str, Any]]:
    """The fields in CDR order, nested messages flattened: (dotted name, kind, detail) with
    kind "p" (detail: the type's struct code), "s" string, "q" sequence of primitives
    (detail: the element's code), "x" anything else (the reader stops there)."""
    steps: list[tuple[str, str, Any]] = []
    for name, slot in zip(msg_class.get_fields_and_field_types(), msg_class.SLOT_TYPES, strict=True):
        dotted = prefix + name
        if isinstance(slot, d.BasicType) and slot.typename in _CODES:
            steps.append((dotted, "p", _CODES[slot.typename]))
        elif isinstance(slot, (d.UnboundedString, d.BoundedString)):
            steps.append((dotted, "s", None))
        elif isinstance(slot, d.NamespacedType):
            import importlib

            steps += _layout(getattr(importlib.import_module(".".join(slot.namespaces)), slot.name), dotted + ".")
        elif (isinstance(slot, (d.UnboundedSequence, d.BoundedSequence)) and isinstance(slot.value_type, d.BasicType)
              and slot.value_type.typename in _CODES):
            steps.append((dotted, "q", _CODES[slot.value_type.typename]))
        else:
            steps.append((dotted, "x", None))
    return steps


def _run_structs(codes: list[str]) -> tuple[tuple[struct.Struct, int], ...]:
    """For each start offset mod 8: the Struct of the run (alignment gaps as pad bytes) and its size."""
    table = []
    for start in range(8):
        pos, fmt = start, "<"
        for code in codes:
            size = struct.calcsize(code)
            aligned = (pos + size - 1) & -size
            fmt += "x" * (aligned - pos) + code
            pos = aligned + size
        table.append((struct.Struct(fmt), pos - start))
    return tuple(table)


def field_names(msg_class: Any) -> list[str]:
    """Every field of a message, nested ones flattened (dotted names, e.g. "header.stamp.sec"),
    in the order of its CDR."""
    return [name for name, _, _ in _layout(msg_class)]


def field_reader(msg_class: Any, wanted: Sequence[str]) -> Callable[[bytes], tuple]:
    """A function of a message's CDR (as recorded, header included) giving the ``wanted``
    fields in that order (dotted names for nested ones, e.g. "stamp.sec"; a sequence as a
    tuple). Raises Unreadable when they cannot be read this way."""
    layout = _layout(msg_class)
    names = [name for name, _, _ in layout]
    missing = [name for name in wanted if name not in names]
    if missing:
        raise Unreadable(f"{msg_class.__name__} has no field {', '.join(missing)}")
    last = max(names.index(name) for name in wanted)
    if any(kind == "x" for _, kind, _ in layout[:last + 1]):
        raise Unreadable(f"{msg_class.__name__}: a wanted field lies after a field this reader cannot skip")
    program = _program(layout[:last + 1])
    slots = {name: i for i, name in enumerate(names[:last + 1])}
    order = [slots[name] for name in wanted]

    def read(data: bytes) -> tuple:
        if data[1] != LITTLE_ENDIAN:
            raise Unreadable("big-endian CDR")
        values = _execute(program, data)
        return tuple(values[i] for i in order)

    return read


def _program(layout: list[tuple[str, str, Any]]) -> list[tuple[str, Any]]:
    """Runs of primitives merged into one step ("r", (structs, count)); strings and sequences as they are."""
    program: list[tuple[str, Any]] = []
    codes: list[str] = []
    for _, kind, detail in layout:
        if kind == "p":
            codes.append(detail)
            continue
        if codes:
            program.append(("r", (_run_structs(codes), len(codes))))
            codes = []
        program.append((kind, detail))
    if codes:
        program.append(("r", (_run_structs(codes), len(codes))))
    return program


def _execute(program: list[tuple[str, Any]], data: bytes) -> list:
    values: list = []
    pos = 0  # offset in the data after the header: what alignment is relative to
    for kind, detail in program:
        if kind == "r":
            structs, _ = detail
            unpacker, size = structs[pos & 7]
            values.extend(unpacker.unpack_from(data, HEADER + pos))
            pos += size
            continue
        pos = (pos + 3) & -4
        (count,) = struct.unpack_from("<I", data, HEADER + pos)
        pos += 4
        if kind == "s":
            values.append(data[HEADER + pos:HEADER + pos + count - 1].decode("utf-8"))
            pos += count
        else:  # a sequence of primitives
            size = struct.calcsize(detail)
            if count:
                pos = (pos + size - 1) & -size
            values.append(struct.unpack_from(f"<{count}{detail}", data, HEADER + pos))
            pos += size * count
    return values


def gather(buffer: np.ndarray, at: np.ndarray, dtype: str) -> np.ndarray:
    """The little-endian values of ``dtype`` at byte offsets ``at`` of ``buffer`` (bytes as
    uint8, the offsets unaligned): one field of many records read at once."""
    size = np.dtype(dtype).itemsize
    return buffer[at[:, None] + np.arange(size)].view(dtype)[:, 0]
