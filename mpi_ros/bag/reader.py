"""Read a bag this project (or rosbag2) wrote: a bag directory or a bare .mcap file.

A bag whose writer did not finish it (the recorder was killed: no summary, no footer, the
open chunk lost) is read record by record up to its last complete one; ``truncated`` then
says so in words (replay reports it), and nothing raises for the cut itself.
"""

from __future__ import annotations

import io
import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from mcap.data_stream import ReadDataStream
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.reader import make_reader
from mcap.records import Channel, Chunk, ChunkIndex, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, get_chunk_data_stream
from mcap_ros2._dynamic import generate_dynamic

from . import fields, schema


def _older(type_name: str, schema_text: str) -> bool:
    return bool(schema_text) and schema_text != schema.ros2msg(type_name)


@dataclass(frozen=True, slots=True)
class Recorded:
    topic: str
    type: str  # pkg/msg/Type
    log_time: int  # ns
    data: bytes  # CDR
    sequence: int = 0  # the writer's count on the topic: the order messages were written in
    schema_text: str = ""  # the ros2msg definition the bag stores for the type ("": unknown)

    @property
    def older(self) -> bool:
        """Whether the bag stores a definition of the type other than the installed one (a bag
        recorded before the type changed, docs/recording.md "Older recordings")."""
        return _older(self.type, self.schema_text)

    def decode(self):
        """The message: as its generated Python class (the package must be installed) when the
        bag's definition of the type is the installed one; else read by the definition the bag
        stores (a bag recorded before the type changed), with the fields it had."""
        if self.older:
            return _recorded_decoder(self.type, self.schema_text)(self.data)
        from rclpy.serialization import deserialize_message

        return deserialize_message(self.data, schema.message_class(self.type))

    def installed_data(self) -> bytes:
        """The CDR of the message in the installed type: the recorded bytes, or, recorded by an
        older definition, the message rebuilt in the installed type (:func:`upgrade`)."""
        if not self.older:
            return self.data
        from rclpy.serialization import serialize_message

        return serialize_message(upgrade(self.decode(), schema.message_class(self.type)))


@dataclass(frozen=True, slots=True)
class Source:
    """A channel of the bag: its topic, its type and the definition the bag stores for it."""

    topic: str
    type: str  # pkg/msg/Type
    schema_text: str = ""  # the ros2msg definition ("": unknown)

    older: bool = False  # Recorded.older, for every message of the channel

    @classmethod
    def of(cls, recorded: Recorded) -> Source:
        return cls(recorded.topic, recorded.type, recorded.schema_text, recorded.older)

    def recorded(self, log_time: int, data: bytes, sequence: int = 0) -> Recorded:
        return Recorded(self.topic, self.type, log_time, data, sequence, self.schema_text)


def upgrade(old: Any, cls: Any) -> Any:
    """A message of the installed ``cls`` from ``old``, read by an older definition: the fields
    both have, by name (nested messages alike); a field ``old`` lacks keeps its default, except
    a header, which takes a bare ``stamp`` (the layout before the headers)."""
    msg = cls()
    for name, kind in cls.get_fields_and_field_types().items():
        if name == "header" and not hasattr(old, "header") and hasattr(old, "stamp"):
            msg.header.stamp.sec, msg.header.stamp.nanosec = old.stamp.sec, old.stamp.nanosec
            continue
        if not hasattr(old, name):
            continue
        value = getattr(old, name)
        nested = _nested_class(kind)
        if nested is None:
            setattr(msg, name, value)
        elif kind.startswith("sequence<") or kind.endswith("]"):
            setattr(msg, name, [upgrade(item, nested) for item in value])
        else:
            setattr(msg, name, upgrade(value, nested))
    return msg


def _nested_class(kind: str) -> Any:
    """The message class of a field type ('pkg/Type', 'sequence<pkg/Type>', 'pkg/Type[3]'), or None
    for a primitive or a sequence of primitives."""
    base = kind.removeprefix("sequence<").split(">")[0].split(",")[0].split("[")[0]
    return schema.message_class(base) if "/" in base else None


@lru_cache(maxsize=64)
def _recorded_decoder(type_name: str, text: str):
    """A decoder of ``type_name`` by the definition ``text`` (mcap_ros2's dynamic decoding:
    objects with the definition's fields as attributes)."""
    return generate_dynamic(type_name, text)[type_name]


# libyaml's parser where PyYAML was built with it: the same documents, several times faster
# (a bag's metadata.yaml and its configuration are most of opening a short recording)
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def load_yaml(text: str) -> Any:
    """``yaml.safe_load``, by libyaml when it is there."""
    return yaml.load(text, Loader=_YAML_LOADER)


def mcap_path(path: str | Path) -> Path:
    """The .mcap file of a bag directory (from its metadata.yaml), or ``path`` itself."""
    path = Path(path)
    if path.is_file():
        return path
    metadata = path / "metadata.yaml"
    if metadata.is_file():
        info = load_yaml(metadata.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
        return path / info["relative_file_paths"][0]
    files = sorted(path.glob("*.mcap"))
    if not files:
        raise FileNotFoundError(f"{path}: no metadata.yaml and no .mcap file")
    return files[0]


_UNREADABLE = (McapError, struct.error, EOFError, ValueError)  # what a damaged file raises in mcap


@dataclass(slots=True)
class _Scan:
    """A bag read record by record (one without a summary): what it holds up to the cut."""

    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    metadata: dict[str, dict[str, str]]
    messages: list[Message]
    cut: str  # why reading stopped ("" at the end of the file)


class BagReader:
    def __init__(self, path: str | Path):
        self.path = mcap_path(path)
        self._scan: _Scan | None = None if self._finished() else self._read_through()

    def _finished(self) -> bool:
        """Whether the file has its summary (the writer finished it)."""
        with open(self.path, "rb") as stream:
            try:
                return make_reader(stream).get_summary() is not None
            except _UNREADABLE:
                return False

    def _read_through(self) -> _Scan:
        scan = _Scan({}, {}, {}, [], "")
        with open(self.path, "rb") as stream:
            try:
                for record in StreamReader(stream).records:
                    if isinstance(record, Message):
                        scan.messages.append(record)
                    elif isinstance(record, Schema):
                        scan.schemas[record.id] = record
                    elif isinstance(record, Channel):
                        scan.channels[record.id] = record
                    elif isinstance(record, Metadata):
                        scan.metadata[record.name] = dict(record.metadata)
            except EndOfFile:
                scan.cut = "it ends inside a record"
            except _UNREADABLE as exc:
                if not scan.schemas and not scan.messages:
                    raise ValueError(f"{self.path}: not a readable MCAP file ({exc or type(exc).__name__})") from exc
                scan.cut = f"a damaged record ({exc or type(exc).__name__})"
        scan.messages.sort(key=lambda m: m.log_time)  # stable: the order written within a time
        return scan

    @property
    def truncated(self) -> str:
        """"" for a finished bag, else what is wrong and what could still be read."""
        if self._scan is None:
            return ""
        times = [m.log_time for m in self._scan.messages]
        span = f", {(times[-1] - times[0]) / 1e9:.3f} s" if times else ""
        return (f"{self.path} was not finished by its writer (no summary: the recorder was killed or the disk "
                f"filled?) and {self._scan.cut or 'has no summary'}; read up to its last complete record: "
                f"{len(times)} messages{span}")

    def _reader(self, stream):
        try:
            return make_reader(stream)
        except _UNREADABLE as exc:  # not an MCAP file
            raise ValueError(f"{self.path}: not a readable MCAP file ({exc or type(exc).__name__})") from exc

    def metadata(self, name: str) -> dict[str, str] | None:
        """An MCAP metadata record's data, by name."""
        if self._scan is not None:
            return self._scan.metadata.get(name)
        with open(self.path, "rb") as stream:
            for record in self._reader(stream).iter_metadata():
                if record.name == name:
                    return dict(record.metadata)
        return None

    def topics(self) -> dict[str, str]:
        """topic -> pkg/msg/Type."""
        if self._scan is not None:
            return {ch.topic: self._scan.schemas[ch.schema_id].name for ch in self._scan.channels.values()
                    if ch.schema_id in self._scan.schemas}
        with open(self.path, "rb") as stream:
            summary = self._reader(stream).get_summary()
        if summary is None:
            return {}
        return {ch.topic: summary.schemas[ch.schema_id].name for ch in summary.channels.values()}

    def messages(self, topics: Iterable[str] | None = None, in_order: bool = True) -> Iterator[Recorded]:
        """Messages in log-time order; ``in_order`` False: in the order they are stored (each
        topic's still in log-time order as written, and several times faster to read)."""
        wanted = list(topics) if topics is not None else None
        if self._scan is not None:
            yield from self._scanned(wanted)
            return
        with open(self.path, "rb") as stream:
            for schema_, channel, message in self._reader(stream).iter_messages(topics=wanted,
                                                                                 log_time_order=in_order):
                yield _recorded(schema_, channel, message)

    def _scanned(self, wanted: list[str] | None) -> Iterator[Recorded]:
        assert self._scan is not None
        scan = self._scan
        for message in scan.messages:
            channel = scan.channels.get(message.channel_id)
            if channel is None or channel.schema_id not in scan.schemas or (
                    wanted is not None and channel.topic not in wanted):
                continue
            yield _recorded(scan.schemas[channel.schema_id], channel, message)

    def stored(self, topics: Iterable[str]) -> Iterator[Recorded]:
        """The messages of ``topics`` in the order they are stored (each topic's in log-time
        order as written): :meth:`payloads`, each as a Recorded."""
        for source, sequence, log_time, data in self.payloads(topics):
            yield source.recorded(log_time, data, sequence)

    def payloads(self, topics: Iterable[str]) -> Iterator[tuple[Source, int, int, bytes]]:
        """(source, sequence, log time, CDR) of the messages of ``topics`` in the order they
        are stored, without building mcap's record objects for them: the chunks that hold
        them are read where the summary's chunk indexes say, and a chunk's records are
        stepped over by their headers (opcode, length; MCAP's "Records"), its messages read
        at their fixed offsets. Several times faster than :meth:`messages` on a recording
        whose status topics are most of it; a bag without a summary (not finished) is read by
        :meth:`messages` instead."""
        wanted = set(topics)
        if self._scan is not None:
            for recorded in self._scanned(list(wanted)):
                yield Source.of(recorded), recorded.sequence, recorded.log_time, recorded.data
            return
        with open(self.path, "rb") as stream:
            summary = self._reader(stream).get_summary()
            assert summary is not None  # _finished() said so
            sources = {cid: _source(summary.schemas[channel.schema_id], channel)
                       for cid, channel in summary.channels.items()
                       if channel.topic in wanted and channel.schema_id in summary.schemas}
            if summary.chunk_indexes:
                # the chunks where the summary says they are, as mcap's own indexed reading
                # finds them (the message indexes between them not parsed)
                for index in sorted(summary.chunk_indexes, key=lambda index: index.chunk_start_offset):
                    if sources.keys() & index.message_index_offsets.keys():
                        stream.seek(index.chunk_start_offset + _RECORD.size)
                        yield from _chunk_payloads(Chunk.read(ReadDataStream(stream)), sources)
                return
            stream.seek(0)
            for record in StreamReader(stream).records:
                if isinstance(record, Message) and record.channel_id in sources:
                    yield sources[record.channel_id], record.sequence, record.log_time, record.data

    def columns(self, topics: Iterable[str]) -> list[Column]:
        """The messages of ``topics``, a column per channel: what :meth:`payloads` gives,
        with the positions ordering them as stored. A finished bag's are found by its
        message indexes (MCAP's "Message Index": where each channel's messages lie in a
        chunk), read as arrays, one pass per chunk and channel; a bag whose indexes are not
        all there or do not agree with its chunks is read message by message."""
        wanted = set(topics)
        found = self._indexed(wanted) if self._scan is None else None
        return found if found is not None else _columns(self.payloads(wanted))

    def _indexed(self, wanted: set[str]) -> list[Column] | None:
        """:meth:`columns` by the message indexes; None where they cannot be trusted: not
        there for every message the summary's statistics count, or not pointing at a
        message of their channel inside the chunk."""
        with open(self.path, "rb") as stream:
            summary = self._reader(stream).get_summary()
            if summary is None or summary.statistics is None:
                return None
            sources = {cid: _source(summary.schemas[channel.schema_id], channel)
                       for cid, channel in summary.channels.items()
                       if channel.topic in wanted and channel.schema_id in summary.schemas}
            parts: dict[int, list[tuple]] = {cid: [] for cid in sources}
            base = 0  # the chunk's first position: the records of the chunks before it
            for index in sorted(summary.chunk_indexes, key=lambda index: index.chunk_start_offset):
                if sources.keys() & index.message_index_offsets.keys():
                    for cid, part in _chunk_columns(stream, index, sources.keys()).items():
                        if part is None:
                            return None
                        sequence, log_time, offsets, data = part
                        parts[cid].append((sequence, log_time, offsets + base, data))
                base += index.uncompressed_size
        counts = summary.statistics.channel_message_counts
        if any(sum(len(part[0]) for part in parts[cid]) != counts.get(cid, 0) for cid in sources):
            return None
        return [_column(sources[cid], chunk_parts) for cid, chunk_parts in parts.items()]

    def decoded(self, topics: Iterable[str] | None = None) -> Iterator[tuple[Recorded, Any]]:
        for recorded in self.messages(topics):
            yield recorded, recorded.decode()

    def counts(self) -> dict[str, int]:
        if self._scan is not None:
            found: dict[str, int] = {}
            for recorded in self._scanned(None):
                found[recorded.topic] = found.get(recorded.topic, 0) + 1
            return found
        with open(self.path, "rb") as stream:
            summary = self._reader(stream).get_summary()
        if summary is None or summary.statistics is None:
            return {}
        return {summary.channels[cid].topic: n for cid, n in summary.statistics.channel_message_counts.items()}


_RECORD = struct.Struct("<BQ")  # a record's opcode and content length
_MESSAGE = struct.Struct("<HIQQ")  # a Message record's channel id, sequence, log time, publish time


def _chunk_payloads(chunk: Chunk, sources: dict[int, Source]) -> Iterator[tuple[Source, int, int, bytes]]:
    """The messages of ``sources``' channels in a chunk (decompressed by mcap), others stepped over."""
    records, end = get_chunk_data_stream(chunk)
    data = records.read(end)
    pos = 0
    while pos < end:
        opcode, length = _RECORD.unpack_from(data, pos)
        pos += _RECORD.size
        if opcode == Opcode.MESSAGE:
            channel_id, sequence, log_time, _ = _MESSAGE.unpack_from(data, pos)
            source = sources.get(channel_id)
            if source is not None:
                yield source, sequence, log_time, data[pos + _MESSAGE.size:pos + length]
        pos += length


@dataclass(frozen=True, slots=True)
class Column:
    """The messages of one channel, in the order they are stored (:meth:`BagReader.columns`)."""

    source: Source
    sequence: np.ndarray  # int64, the writer's count on the topic
    log_time: np.ndarray  # int64, ns
    position: np.ndarray  # int64: orders the messages of every column of a read as they are stored
    data: list[bytes]  # CDR


def _column(source: Source, parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, list[bytes]]]) -> Column:
    """A column of the parts of a channel's messages (sequences, log times, positions, CDR)."""
    def joined(k: int) -> np.ndarray:
        return np.concatenate([part[k] for part in parts]).astype(np.int64) if parts else np.zeros(0, np.int64)

    return Column(source, joined(0), joined(1), joined(2), [data for part in parts for data in part[3]])


def _columns(payloads: Iterable[tuple[Source, int, int, bytes]]) -> list[Column]:
    """Columns of messages read one by one (:meth:`BagReader.payloads`)."""
    rows: dict[Source, list[tuple[int, int, int, bytes]]] = {}
    for position, (source, sequence, log_time, data) in enumerate(payloads):
        rows.setdefault(source, []).append((sequence, log_time, position, data))
    return [_column(source, [(np.array([row[0] for row in found]), np.array([row[1] for row in found]),
                              np.array([row[2] for row in found]), [row[3] for row in found])])
            for source, found in rows.items()]


_INDEX_HEAD = struct.Struct("<BQHI")  # a Message Index record: opcode, length, channel id, entries' length


def _chunk_columns(stream, index: ChunkIndex, channels: Iterable[int]) -> dict[int, tuple | None]:
    """(sequence, log time, offset in the chunk, CDR) of the messages of ``channels`` in the
    chunk of ``index``, by their message indexes (after the chunk, in the same read); None
    for a channel whose index does not point at its messages."""
    stream.seek(index.chunk_start_offset)
    raw = stream.read(index.chunk_length + index.message_index_length)
    records, end = get_chunk_data_stream(Chunk.read(ReadDataStream(io.BytesIO(raw[_RECORD.size:index.chunk_length]))))
    data = records.read(end)
    chunk = np.frombuffer(data, np.uint8)
    found: dict[int, tuple | None] = {}
    for cid in channels:
        at = index.message_index_offsets.get(cid)
        if at is None:
            continue
        at -= index.chunk_start_offset
        opcode, _, channel, length = _INDEX_HEAD.unpack_from(raw, at)
        if opcode != Opcode.MESSAGE_INDEX or channel != cid or at + _INDEX_HEAD.size + length > len(raw):
            found[cid] = None
            continue
        # (log time, offset) pairs of uint64: the offsets
        offsets = np.frombuffer(raw, "<u8", length // 8, at + _INDEX_HEAD.size)[1::2].astype(np.int64)
        found[cid] = _messages_at(data, chunk, offsets, cid)
    return found


def _messages_at(data: bytes, chunk: np.ndarray, offsets: np.ndarray, cid: int) -> tuple | None:
    """The Message records of channel ``cid`` at ``offsets`` of a chunk's records, read
    at their fixed offsets (opcode, length, then _MESSAGE); None if one is not such a record."""
    if not ((offsets >= 0) & (offsets + _RECORD.size + _MESSAGE.size <= len(data))).all():
        return None
    lengths = fields.gather(chunk, offsets + 1, "<u8")
    ends = offsets + _RECORD.size + lengths.astype(np.int64)
    channels = fields.gather(chunk, offsets + _RECORD.size, "<u2")
    if not ((chunk[offsets] == Opcode.MESSAGE).all() and (channels == cid).all()
            and (lengths >= _MESSAGE.size).all() and (ends <= len(data)).all()):
        return None
    starts = offsets + _RECORD.size + _MESSAGE.size
    sequence = fields.gather(chunk, offsets + _RECORD.size + 2, "<u4").astype(np.int64)
    log_time = fields.gather(chunk, offsets + _RECORD.size + 6, "<u8").astype(np.int64)
    return sequence, log_time, offsets, [data[a:b] for a, b in zip(starts.tolist(), ends.tolist(), strict=True)]


def _source(schema_: Schema, channel: Channel) -> Source:
    text = schema_.data.decode("utf-8", errors="replace")
    return Source(channel.topic, schema_.name, text, _older(schema_.name, text))


def _recorded(schema_: Schema, channel: Channel, message: Message) -> Recorded:
    return Recorded(channel.topic, schema_.name, message.log_time, message.data, message.sequence,
                    schema_.data.decode("utf-8", errors="replace"))
