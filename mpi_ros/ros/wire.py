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
std_msgs/Header is its stamp (int32 sec, uint32 nanosec) and its frame_id (a string). A
status' uint64 sample after its header is always 8-aligned, so everything from it on (its
"body") has the same bytes wherever the status starts: :class:`Packer` packs an axis' body
once for its own status and the supervisors' that hold it (replay packs every status of
every sample it compares; docs/recording.md, "Replay"). If the
installed interfaces differ from these layouts (built from older .msg files), :data:`AVAILABLE`
is False, the nodes build messages with convert.py instead and the controller node says so in
its log.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from functools import cache, lru_cache
from operator import attrgetter

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


_STAMP = struct.Struct("<iI")  # a header's stamp: sec, nanosec


@lru_cache(maxsize=1024)
def _frame(namespace: str, supervisor: int, axis: int, start: int) -> bytes:
    """A header's frame_id (convert.frame_id) and the padding after it to the status' body,
    for a header from ``start`` (mod 8): constant per source, packed once. (The stamp before
    it is 8 bytes: the frame_id starts at the same place mod 8.)"""
    frame = convert.frame_id(namespace, supervisor, axis).encode("utf-8")
    layout = _Layout(start + _STAMP.size).string(len(frame))
    return layout.add("x", 1, -layout.pos % 8).struct().pack(len(frame) + 1, frame)


def _body_head(name_length: int) -> _Layout:
    """A status from its sample to its state name, from an 8-aligned start."""
    return _Layout(0).add("Q", 8).add("i", 4).add("B", 1).string(name_length)


@cache
def _axis_body(name_length: int, faults: tuple[int, ...]) -> struct.Struct:
    """An AxisStatus from its sample to its end (an 8-aligned start, so the same bytes wherever
    the status starts), with a state name and faults of those lengths."""
    layout = _body_head(name_length).add("d", 8, 8).add("?", 1, 8).add("i", 4, 4).add("d", 8).add("I", 4)
    for length in faults:
        layout.string(length)
    return layout.struct()


@cache
def _motion_body(name_length: int, axes: int) -> struct.Struct:
    """A MotionStatus from its sample to the count of its axes (an 8-aligned start)."""
    return _body_head(name_length).add("I", 4).add("i", 4, axes).add("I", 4).struct()


@cache
def _motion_tail(start: int, last_action: int, action_source: int, motion_type: int) -> struct.Struct:
    """A MotionStatus after its axes, from ``start`` (mod 8), with strings of those lengths."""
    layout = _Layout(start).add("?", 1, 3).add("i", 4, 2).add("d", 8)
    return layout.string(last_action).string(action_source).add("i", 4).string(motion_type).struct()


_LENGTH = struct.Struct("<I")
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


_STATE_NAMES = {state: state.name.encode("utf-8") for state in MPIState}


def _state_name(state: MPIState) -> bytes:
    found = _STATE_NAMES.get(state)
    return found if found is not None else state.name.encode("utf-8")


# An AxisStatus' values from its sample on, in the message's order but for the state's name
# (after the state) and the faults (last); read at once (one C call, not 24 attribute reads).
_AXIS_VALUES = attrgetter(
    "sample", "number", "state", "command_position", "actual_position", "position_error", "target_position",
    "origin", "command_velocity", "actual_velocity", "command_acceleration", "done", "at_target",
    "in_fine_position", "in_coarse_position", "settled", "at_velocity", "trajectory_complete", "amp_enabled",
    "move_id", "element_id", "frame_count", "supervisor", "feedforward")
_FINITE = frozenset({3, 4, 5, 7, 8, 9, 10, 23})  # the doubles sent finite (target_position may be NaN)


def _axis_body_bytes(snap: AxisSnapshot) -> bytes:
    """An AxisStatus from its sample on: the same wherever the status starts (_axis_body)."""
    values = _AXIS_VALUES(snap)
    # the sum is finite only if every value is: one check for the usual case
    if not math.isfinite(sum(values[3:6]) + sum(values[7:11]) + values[23]):
        values = tuple(_finite(x) if i in _FINITE else x for i, x in enumerate(values))
    name = _state_name(values[2])
    if not snap.faults:
        return _axis_body(len(name), ()).pack(*values[:3], len(name) + 1, name, *values[3:], 0)
    faults = [text.encode("utf-8") for text in snap.faults]
    return _axis_body(len(name), tuple(map(len, faults))).pack(
        *values[:3], len(name) + 1, name, *values[3:], len(faults),
        *(x for text in faults for x in (len(text) + 1, text)))


class Packer:
    """The statuses of one controller (its sample rate, its stamps' epoch, its namespace)
    packed as CDR, keeping what statuses of the same sample share: the stamp, each header
    (stamp and frame_id, by where it starts mod 8), and each axis snapshot's body, which
    its AxisStatus and every MotionStatus holding the same snapshot repeat byte for byte
    (the body starts 8-aligned wherever the status does: only the header's padding differs).

    An axis' body is kept by the snapshot's identity (the snapshot kept with it, so the
    identity is not reused): a snapshot is a value nobody assigns to (base/snapshot.py), so
    its bytes do not change. What is kept is the latest sample's only."""

    def __init__(self, rate: float, epoch_ns: int | None = None, namespace: str = DEFAULT_NAMESPACE):
        self.rate = rate
        self.epoch_ns = epoch_ns
        self.namespace = namespace
        self._sample = -1
        self._stamp = b""
        self._bodies: dict[int, tuple[AxisSnapshot, bytes]] = {}

    def _at(self, sample: int) -> None:
        """Start keeping the statuses of ``sample`` (its stamp), forgetting the last one's."""
        self._sample, self._stamp = sample, _STAMP.pack(*_time(sample, self.rate, self.epoch_ns))
        self._bodies.clear()

    def _axis(self, snap: AxisSnapshot, start: int) -> bytes:
        """An AxisStatus' bytes (no encapsulation header) from ``start`` (mod 8)."""
        if snap.sample != self._sample:  # its own stamp, even inside a MotionStatus of another sample
            self._at(snap.sample)
        kept = self._bodies.get(id(snap))
        if kept is None or kept[0] is not snap:
            kept = self._bodies[id(snap)] = (snap, _axis_body_bytes(snap))
        # the stamp's int32 is 4-aligned: after an AxisStatus whose faults' last string ends
        # anywhere, the next one inside a MotionStatus starts with padding
        pad = -start % 4
        return b"\x00" * pad + self._stamp + _frame(self.namespace, -1, snap.number, start + pad) + kept[1]

    def axis_status(self, snap: AxisSnapshot) -> bytes:
        """The CDR of ``convert.axis_status(snap, rate, epoch_ns, namespace)``."""
        return HEADER + self._axis(snap, 0)

    def motion_status(self, snap: MotionSnapshot) -> bytes:
        """The CDR of ``convert.motion_status(snap, rate, epoch_ns, namespace)``."""
        if snap.sample != self._sample:
            self._at(snap.sample)
        name = _state_name(snap.state)
        body = _motion_body(len(name), len(snap.axis_numbers)).pack(
            snap.sample, snap.number, snap.state, len(name) + 1, name,
            len(snap.axis_numbers), *snap.axis_numbers, len(snap.axes))
        parts = [HEADER, self._stamp, _frame(self.namespace, snap.number, -1, 0), body]
        at = len(self._stamp) + len(parts[2]) + len(body)  # in the data after the encapsulation header
        for axis in snap.axes:
            packed = self._axis(axis, at % 8)
            parts.append(packed)
            at += len(packed)
        last_action, action_source = snap.last_action.encode("utf-8"), snap.action_source.encode("utf-8")
        motion_type = snap.motion_type.encode("utf-8")
        parts.append(_motion_tail(at % 8, len(last_action), len(action_source), len(motion_type)).pack(
            snap.done, snap.at_target, snap.settled, snap.move_id, snap.element_id, float(snap.feedrate),
            len(last_action) + 1, last_action, len(action_source) + 1, action_source, snap.moves_pending,
            len(motion_type) + 1, motion_type))
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
    out = bytearray(HEADER)
    out += struct.pack("<iI", *_time(sample, rate, epoch_ns))
    out += prefix
    out += _joint_values((8 + len(prefix)) % 8, count).pack(count, *position, count, *velocity, count, *effort)
    return bytes(out)
