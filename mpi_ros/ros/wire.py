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
lengths of its strings, so each is one struct.Struct, built once per case and cached. A
std_msgs/Header is its stamp (int32 sec, uint32 nanosec) and its frame_id (a string). If the
installed interfaces differ from these layouts (built from older .msg files), :data:`AVAILABLE`
is False, the nodes build messages with convert.py instead and the controller node says so in
its log.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from functools import cache, lru_cache

from sensor_msgs.msg import JointState

from mpi_ros.config import DEFAULT_NAMESPACE
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
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
             and JointState.get_fields_and_field_types() == _JOINT_FIELDS)


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

    def string(self, length: int) -> _Layout:
        """uint32 length, then the bytes and their NUL (``s`` pads the NUL)."""
        self.add("I", 4)
        self.fmt += f"{length + 1}s"
        self.pos += length + 1
        return self

    def struct(self) -> struct.Struct:
        return struct.Struct(self.fmt)


def _head(start: int, frame_length: int, name_length: int) -> _Layout:
    """A status from its header (stamp, frame_id) to its state name, from ``start`` (mod 8)."""
    layout = _Layout(start).add("i", 4).add("I", 4).string(frame_length)
    return layout.add("Q", 8).add("i", 4).add("B", 1).string(name_length)


@cache
def _axis_layout(start: int, frame_length: int, name_length: int) -> struct.Struct:
    """An AxisStatus up to its faults, starting at ``start`` (mod 8), with a frame_id and a
    state name of those lengths."""
    return _head(start, frame_length, name_length).add("d", 8, 8).add("?", 1, 8).add("i", 4, 4).add("d", 8).struct()


@cache
def _motion_head(frame_length: int, name_length: int, axes: int) -> struct.Struct:
    """A MotionStatus from its header to the count of its axes (it starts the data: at 0)."""
    return _head(0, frame_length, name_length).add("I", 4).add("i", 4, axes).add("I", 4).struct()


@lru_cache(maxsize=1024)
def _frame(namespace: str, supervisor: int, axis: int) -> bytes:
    """A header's frame_id, encoded (convert.frame_id): constant per source, encoded once."""
    return convert.frame_id(namespace, supervisor, axis).encode("utf-8")


@cache
def _motion_tail(start: int, last_action: int, action_source: int, motion_type: int) -> struct.Struct:
    """A MotionStatus after its axes, from ``start`` (mod 8), with strings of those lengths."""
    layout = _Layout(start).add("?", 1, 3).add("i", 4, 2).add("d", 8)
    return layout.string(last_action).string(action_source).add("i", 4).string(motion_type).struct()


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


def _axis(out: bytearray, snap: AxisSnapshot, rate: float, epoch_ns: int | None, namespace: str) -> None:
    name = snap.state.name.encode("utf-8")
    frame = _frame(namespace, -1, snap.number)
    layout = _axis_layout((len(out) - len(HEADER)) % 8, len(frame), len(name))
    out += layout.pack(
        *_time(snap.sample, rate, epoch_ns), len(frame) + 1, frame,
        snap.sample, snap.number, int(snap.state), len(name) + 1, name,
        _finite(snap.command_position), _finite(snap.actual_position), _finite(snap.position_error),
        float(snap.target_position), _finite(snap.origin), _finite(snap.command_velocity),
        _finite(snap.actual_velocity), _finite(snap.command_acceleration),
        snap.done, snap.at_target, snap.in_fine_position, snap.in_coarse_position, snap.settled,
        snap.at_velocity, snap.trajectory_complete, snap.amp_enabled,
        snap.move_id, snap.element_id, snap.frame_count, snap.supervisor, _finite(snap.feedforward))
    _strings(out, snap.faults)


def _strings(out: bytearray, texts: Sequence[str]) -> None:
    """A sequence of strings: its count, then each string (4-byte aligned lengths)."""
    encoded = [text.encode("utf-8") for text in texts]
    layout = _Layout((len(out) - len(HEADER)) % 8).add("I", 4)
    for text in encoded:
        layout.string(len(text))
    out += layout.struct().pack(len(encoded), *(x for text in encoded for x in (len(text) + 1, text)))


def axis_status(snap: AxisSnapshot, rate: float, epoch_ns: int | None = None,
                namespace: str = DEFAULT_NAMESPACE) -> bytes:
    """The CDR of ``convert.axis_status(snap, rate, epoch_ns, namespace)``."""
    out = bytearray(HEADER)
    _axis(out, snap, rate, epoch_ns, namespace)
    return bytes(out)


def motion_status(snap: MotionSnapshot, rate: float, epoch_ns: int | None = None,
                  namespace: str = DEFAULT_NAMESPACE) -> bytes:
    """The CDR of ``convert.motion_status(snap, rate, epoch_ns, namespace)``."""
    name = snap.state.name.encode("utf-8")
    frame = _frame(namespace, snap.number, -1)
    out = bytearray(HEADER)
    out += _motion_head(len(frame), len(name), len(snap.axis_numbers)).pack(
        *_time(snap.sample, rate, epoch_ns), len(frame) + 1, frame,
        snap.sample, snap.number, int(snap.state), len(name) + 1, name,
        len(snap.axis_numbers), *snap.axis_numbers, len(snap.axes))
    for axis in snap.axes:
        _axis(out, axis, rate, epoch_ns, namespace)
    strings = [text.encode("utf-8") for text in (snap.last_action, snap.action_source, snap.motion_type)]
    last_action, action_source, motion_type = strings
    out += _motion_tail((len(out) - len(HEADER)) % 8, *map(len, strings)).pack(
        snap.done, snap.at_target, snap.settled, snap.move_id, snap.element_id, float(snap.feedrate),
        len(last_action) + 1, last_action, len(action_source) + 1, action_source, snap.moves_pending,
        len(motion_type) + 1, motion_type)
    return bytes(out)


def joint_state(sample: int, rate: float, epoch_ns: int | None, names: Sequence[str], position: Sequence[float],
                velocity: Sequence[float], effort: Sequence[float]) -> bytes:
    """The CDR of a JointState stamped at ``sample`` (no frame id), as convert.joint_state
    builds it; the values are floats."""
    prefix = _joint_names(tuple(names))
    count = len(names)
    out = bytearray(HEADER)
    out += struct.pack("<iI", *_time(sample, rate, epoch_ns))
    out += prefix
    out += _joint_values((8 + len(prefix)) % 8, count).pack(count, *position, count, *velocity, count, *effort)
    return bytes(out)
