"""The status topics encoded straight into CDR, for publishing raw.

Why: at 32 axes and 100 Hz the suite publishes 4,900 status messages a second, at 8 axes
and 1 kHz 14,000. Building each as a generated message and publishing it (rclpy converts
it field by field into its C struct, then serializes that) cost three to four times as
much as packing the same bytes here and publishing them raw (bench/RESULTS.md, "The suite
under load").

The bytes are exactly the canonical CDR of the message the functions in convert.py build
from the same values (test/ros/test_wire.py checks it byte for byte, and field for field
after decoding), so subscribers, recorders and replay see no difference. convert.py stays
the one description of what each field holds; this module only lays the same values out.

CDR as ROS 2 writes it (XCDR1, little endian): a 4-byte encapsulation header, then the
fields in order, each primitive aligned to its size (at most 8) from the start of the
data after the header; a string is a uint32 length (with the NUL), its UTF-8 bytes and a
NUL; a sequence is a uint32 count and its elements; nested messages are inline and have
no alignment of their own (an AxisStatus inside a MotionStatus is laid out by where it
starts). The layout of a run of fields depends only on where it starts (mod 8) and on the
lengths of its strings, so each is one struct.Struct, built once per case and cached; the
strings take a handful of values (frame_ids, state names, faults, a MotionStatus' last
strings), each packed once. A std_msgs/Header is its stamp (int32 sec, uint32 nanosec) and its frame_id (a string). A
status' uint64 sample after its header is always 8-aligned, so everything from it on (its
"body") has the same bytes wherever the status starts: :class:`Packer` packs an axis' body
once for its own status and the supervisors' that hold it (replay packs every status of
every sample it compares; docs/recording.md, "Replay"). If the
installed interfaces differ from these layouts (built from older .msg files), :data:`AVAILABLE`
is False, the nodes build messages with convert.py instead (and /clock a rosgraph_msgs/Clock,
here its stamp's 8 bytes) and the controller node says so in its log.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from functools import cache, lru_cache
from operator import attrgetter, itemgetter

from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from mpi_ros.config import DEFAULT_NAMESPACE
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.msg import AxisStatus, MotionStatus

from . import convert

HEADER = b"\x00\x01\x00\x00"  # CDR, little endian, no options
_NS = 1_000_000_000

# The layouts packed below, as the generated classes describe them.
_AXIS_FIELDS = {
    "header": "std_msgs/Header", "sample": "uint64", "number": "int32", "state": "uint8",
    "state_name": "string", "command_position": "double", "actual_position": "double",
    "position_error": "double", "target_position": "double", "origin": "double", "command_velocity": "double",
    "actual_velocity": "double", "command_acceleration": "double", "done": "boolean", "at_target": "boolean",
    "in_fine_position": "boolean", "in_coarse_position": "boolean", "settled": "boolean",
    "at_velocity": "boolean", "trajectory_complete": "boolean", "amp_enabled": "boolean", "move_id": "int32",
    "element_id": "int32", "frame_count": "int32", "supervisor": "int32", "feedforward": "double",
    "faults": "sequence<string>",
}
_MOTION_FIELDS = {
    "header": "std_msgs/Header", "sample": "uint64", "number": "int32", "state": "uint8",
    "state_name": "string", "axis_numbers": "sequence<int32>", "axes": "sequence<mpi_ros/AxisStatus>",
    "done": "boolean", "at_target": "boolean", "settled": "boolean", "move_id": "int32", "element_id": "int32",
    "feedrate": "double", "last_action": "string", "action_source": "string", "moves_pending": "int32",
    "motion_type": "string",
}
_JOINT_FIELDS = {"header": "std_msgs/Header", "name": "sequence<string>", "position": "sequence<double>",
                 "velocity": "sequence<double>", "effort": "sequence<double>"}
AVAILABLE = (AxisStatus.get_fields_and_field_types() == _AXIS_FIELDS
             and MotionStatus.get_fields_and_field_types() == _MOTION_FIELDS
             and JointState.get_fields_and_field_types() == _JOINT_FIELDS
             and Clock.get_fields_and_field_types() == {"clock": "builtin_interfaces/Time"})


class _Layout:
    """Builds a struct format from where it starts in the data (mod 8), tracking alignment."""

    def __init__(self, start: int):
        self.pos = start
        self.fmt = "<"

    def add(self, code: str, size: int, count: int = 1) -> _Layout:
        pad = -self.pos % size if count else 0  # no elements (an empty sequence): no alignment
        self.fmt += f"{pad}x" * bool(pad) + (f"{count}{code}" if count != 1 else code)
        self.pos += pad + size * count
        return self

    def bytes(self, length: int) -> _Layout:
        """``length`` bytes as they are (no alignment)."""
        self.fmt += f"{length}s"
        self.pos += length
        return self

    def string(self, length: int) -> _Layout:
        """uint32 length, then the bytes and their NUL (``s`` pads the NUL)."""
        return self.add("I", 4).bytes(length + 1)

    def struct(self) -> struct.Struct:
        return struct.Struct(self.fmt)


_STAMP = struct.Struct("<iI")  # a header's stamp: sec, nanosec
_LENGTH = struct.Struct("<I")


@lru_cache(maxsize=1024)
def _frame(namespace: str, supervisor: int, axis: int, start: int) -> bytes:
    """A header's frame_id (convert.frame_id) and the padding after it to the status' body,
    for a header from ``start`` (mod 8): constant per source, packed once. (The stamp before
    it is 8 bytes: the frame_id starts at the same place mod 8.)"""
    frame = convert.frame_id(namespace, supervisor, axis).encode("utf-8")
    layout = _Layout(start + _STAMP.size).string(len(frame))
    return layout.add("x", 1, -layout.pos % 8).struct().pack(len(frame) + 1, frame)


# A status from its sample to its state (uint64, int32, uint8), from an 8-aligned start: the
# first 16 bytes of an AxisStatus' and a MotionStatus' body, the state's name after them.
_HEAD = "QiB3x"
_HEAD_SIZE = struct.calcsize("<" + _HEAD)
_MOTION_HEAD = struct.Struct("<" + _HEAD)
# An AxisStatus' body is its head, its state's name (a string padded to the next double), its
# doubles, flags and int32s from command_position to feedforward (8-aligned wherever the name
# ends: the same 96 bytes after any name) and its faults (last). So its numbers pack with one
# struct whatever its strings, and the strings, a few distinct values, are packed once each.
_AXIS_FIXED = struct.Struct("<" + _HEAD + "8d8?4id")


def _strings(*texts: str) -> bytes:
    """CDR strings one after the other, from a 4-aligned start (only 4-alignments within)."""
    encoded = [text.encode("utf-8") for text in texts]
    layout = _Layout(0)
    for text in encoded:
        layout.string(len(text))
    return layout.struct().pack(*(x for text in encoded for x in (len(text) + 1, text)))


@cache
def _axis_state_name(state: MPIState) -> bytes:
    """An AxisStatus' state_name after its head, with the padding to the double after it."""
    packed = _strings(state.name)
    return packed + bytes(-len(packed) % 8)


@lru_cache(maxsize=256)
def _axis_faults(faults: tuple[str, ...]) -> bytes:
    """An AxisStatus' faults, a sequence of strings (from a 4-aligned start)."""
    return _LENGTH.pack(len(faults)) + _strings(*faults)


@lru_cache(maxsize=256)
def _motion_middle(state: MPIState, axis_numbers: tuple[int, ...], axes: int) -> bytes:
    """A MotionStatus after its head (from an 8-aligned start) to the count of its axes: the
    state's name and the axis numbers; a supervisor's are the same for many samples."""
    name = state.name.encode("utf-8")
    layout = _Layout(_HEAD_SIZE).string(len(name)).add("I", 4).add("i", 4, len(axis_numbers)).add("I", 4)
    return layout.struct().pack(len(name) + 1, name, len(axis_numbers), *axis_numbers, axes)


@lru_cache(maxsize=256)
def _motion_tail(start: int, last_action: str, action_source: str, motion_type: str
                 ) -> tuple[struct.Struct, bytes, bytes]:
    """A MotionStatus after its axes, from ``start`` (mod 8): the struct of done, at_target,
    settled, move_id, element_id, feedrate, the strings before moves_pending, moves_pending
    and the string after it; and those strings' bytes (the strings after feedrate start
    8-aligned: their bytes do not depend on ``start``)."""
    before, after = _strings(last_action, action_source), _strings(motion_type)
    layout = _Layout(start).add("?", 1, 3).add("i", 4, 2).add("d", 8).bytes(len(before)).add("i", 4)
    return layout.bytes(len(after)).struct(), before, after


_KEY = struct.Struct("<Qi")


def sample_and_number(data: bytes) -> tuple[int, int]:
    """The sample and the number (supervisor or axis) of a MotionStatus' or an AxisStatus'
    CDR, read where they lie: after the header (stamp, then frame_id, whose length says where
    it ends), the uint64 sample 8-aligned, then the int32 number."""
    if data[1] != HEADER[1]:
        raise ValueError(f"not little-endian CDR (encapsulation {data[:4].hex()})")
    (frame,) = _LENGTH.unpack_from(data, len(HEADER) + 8)
    return _KEY.unpack_from(data, len(HEADER) + ((12 + frame + 7) & -8))


@lru_cache(maxsize=8)
def _joint_names(names: tuple[str, ...]) -> bytes:
    """A JointState's frame_id (empty) and names: constant for a suite, packed once."""
    encoded = [name.encode("utf-8") for name in names]
    layout = _Layout(8).string(0).add("I", 4)  # after the stamp
    for name in encoded:
        layout.string(len(name))
    return layout.struct().pack(1, b"", len(encoded), *(x for name in encoded for x in (len(name) + 1, name)))


@cache
def _joint_values(start: int, count: int) -> struct.Struct:
    """A JointState's position, velocity and effort (``count`` each), from ``start`` (mod 8)."""
    layout = _Layout(start)
    for _ in range(3):
        layout.add("I", 4).add("d", 8, count)
    return layout.struct()


def _time(sample: int, rate: float, epoch_ns: int | None) -> tuple[int, int]:
    nanoseconds = convert.stamp_ns(sample, rate, epoch_ns)  # what convert.stamp() holds
    return nanoseconds // _NS, nanoseconds % _NS


def _finite(x: float) -> float:
    return float(x) if math.isfinite(x) else 0.0  # as convert.axis_status sets the field


# An AxisStatus' values in _AXIS_FIXED's order (its fields but the strings), read at once (one
# C call, not 24 attribute reads)
_AXIS_VALUES = attrgetter(
    "sample", "number", "state", "command_position", "actual_position", "position_error", "target_position",
    "origin", "command_velocity", "actual_velocity", "command_acceleration", "done", "at_target",
    "in_fine_position", "in_coarse_position", "settled", "at_velocity", "trajectory_complete", "amp_enabled",
    "move_id", "element_id", "frame_count", "supervisor", "feedforward")
_FINITE = frozenset({3, 4, 5, 7, 8, 9, 10, 23})  # the doubles sent finite (target_position may be NaN)
_SENT_FINITE = itemgetter(*sorted(_FINITE))


def _sent(values: tuple) -> tuple:
    """An axis' values as convert.axis_status sets the fields."""
    return tuple(_finite(x) if i in _FINITE else x for i, x in enumerate(values))


def _axis_body(snap: AxisSnapshot) -> bytes:
    """An AxisStatus from its sample on: the same bytes wherever the status starts."""
    values = _AXIS_VALUES(snap)
    # the sum is finite only if every value is: one check for the usual case
    if not math.isfinite(sum(_SENT_FINITE(values))):
        values = _sent(values)
    fixed = _AXIS_FIXED.pack(*values)
    return b"".join((fixed[:_HEAD_SIZE], _axis_state_name(snap.state), fixed[_HEAD_SIZE:], _axis_faults(snap.faults)))


_MOTION_HEAD_VALUES = attrgetter("sample", "number", "state")
_MOTION_TAIL_VALUES = attrgetter("done", "at_target", "settled", "move_id", "element_id", "feedrate")
_PADDING = tuple(bytes(n) for n in range(4))


class Packer:
    """The statuses of one controller (its sample rate, its stamps' epoch, its namespace)
    packed as CDR, keeping what the statuses of a sample share: the stamp and each axis
    snapshot's body (its AxisStatus from its sample on), which every MotionStatus holding
    the same snapshot repeats byte for byte (the body starts 8-aligned wherever the status does:
    only the header's padding differs).

    An axis' body is kept by the snapshot's identity (the snapshot kept with it, so the
    identity is not reused): a snapshot is a value nobody assigns to (base/snapshot.py), so
    its bytes do not change. What is kept is the latest sample's only."""

    def __init__(self, rate: float, epoch_ns: int | None = None, namespace: str = DEFAULT_NAMESPACE):
        self.rate = rate
        self.epoch_ns = epoch_ns
        self.namespace = namespace
        self._sample = -1
        self._stamp = b""
        self._bodies: dict[int, bytes] = {}  # by id() of a snapshot in _kept
        self._kept: list[AxisSnapshot] = []

    def _stamp_of(self, sample: int) -> bytes:
        return _STAMP.pack(*_time(sample, self.rate, self.epoch_ns))

    def _at(self, sample: int) -> bytes:
        """Keep the statuses of ``sample`` from now (forgetting the last one's); its stamp."""
        if sample != self._sample:
            self._sample, self._stamp = sample, self._stamp_of(sample)
            self._bodies.clear()
            self._kept.clear()
        return self._stamp

    def _body(self, snap: AxisSnapshot) -> bytes:
        """A snapshot's body: kept, else packed (and kept if of the sample kept)."""
        body = self._bodies.get(id(snap))
        if body is None:
            body = _axis_body(snap)
            if snap.sample == self._sample:
                self._bodies[id(snap)] = body
                self._kept.append(snap)
        return body

    def axis_status(self, snap: AxisSnapshot) -> bytes:
        """The CDR of ``convert.axis_status(snap, rate, epoch_ns, namespace)``."""
        stamp = self._at(snap.sample)
        return b"".join((HEADER, stamp, _frame(self.namespace, -1, snap.number, 0), self._body(snap)))

    def motion_status(self, snap: MotionSnapshot) -> bytes:
        """The CDR of ``convert.motion_status(snap, rate, epoch_ns, namespace)``."""
        stamp = self._at(snap.sample)
        middle = _motion_middle(snap.state, snap.axis_numbers, len(snap.axes))
        parts = [HEADER, stamp, _frame(self.namespace, snap.number, -1, 0),
                 _MOTION_HEAD.pack(*_MOTION_HEAD_VALUES(snap)), middle]
        at = len(middle) % 8  # in the data after the encapsulation header: what precedes it ends 8-aligned
        sample = snap.sample
        for axis in snap.axes:
            # the stamp's int32 is 4-aligned: after an AxisStatus whose faults' last string ends
            # anywhere, the next one starts with padding; its frame_id pads to its body
            pad = -at % 4
            body = self._body(axis)
            parts += (_PADDING[pad], stamp if axis.sample == sample else self._stamp_of(axis.sample),
                      _frame(self.namespace, -1, axis.number, (at + pad) % 8), body)
            at = len(body) % 8
        tail, before, after = _motion_tail(at, snap.last_action, snap.action_source, snap.motion_type)
        parts.append(tail.pack(*_MOTION_TAIL_VALUES(snap), before, snap.moves_pending, after))
        return b"".join(parts)


def axis_status(snap: AxisSnapshot, rate: float, epoch_ns: int | None = None,
                namespace: str = DEFAULT_NAMESPACE) -> bytes:
    """The CDR of ``convert.axis_status(snap, rate, epoch_ns, namespace)``."""
    return Packer(rate, epoch_ns, namespace).axis_status(snap)


def motion_status(snap: MotionSnapshot, rate: float, epoch_ns: int | None = None,
                  namespace: str = DEFAULT_NAMESPACE) -> bytes:
    """The CDR of ``convert.motion_status(snap, rate, epoch_ns, namespace)``."""
    return Packer(rate, epoch_ns, namespace).motion_status(snap)


def joint_state(sample: int, rate: float, epoch_ns: int | None, names: Sequence[str], position: Sequence[float],
                velocity: Sequence[float], effort: Sequence[float]) -> bytes:
    """The CDR of a JointState stamped at ``sample`` (no frame id), as convert.joint_state
    builds it; the values are floats."""
    prefix = _joint_names(tuple(names))
    count = len(names)
    values = _joint_values((_STAMP.size + len(prefix)) % 8, count).pack(count, *position, count, *velocity,
                                                                         count, *effort)
    return b"".join((HEADER, _STAMP.pack(*_time(sample, rate, epoch_ns)), prefix, values))


def clock(sample: int, rate: float, epoch_ns: int | None) -> bytes:
    """The CDR of a rosgraph_msgs/Clock of ``sample``'s stamp (convert.stamp)."""
    return HEADER + _STAMP.pack(*_time(sample, rate, epoch_ns))
