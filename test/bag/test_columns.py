"""BagReader.columns reads a finished bag by its message indexes, as arrays, and replay sorts
its statuses from them (docs/recording.md, "Replay"): what it gives must be what reading
the messages one by one gives, and a bag whose indexes cannot be trusted is read so."""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from mpi_ros.bag import replay as replay_module
from mpi_ros.bag.reader import BagReader, Column, _columns
from mpi_ros.bag.replay import replay
from mpi_ros.ros import wire

BAGS = Path(__file__).resolve().parent.parent / "fixtures" / "bags"


def _one_by_one(reader: BagReader, topics: list[str]) -> list[Column]:
    return _columns(reader.payloads(topics))


def _same(columns: list[Column], expected: list[Column]) -> None:
    """The same messages in each column, and the positions ordering them all alike."""
    assert [c.source for c in columns] == [c.source for c in expected]
    for column, other in zip(columns, expected, strict=True):
        assert column.data == other.data
        assert column.sequence.tolist() == other.sequence.tolist()
        assert column.log_time.tolist() == other.log_time.tolist()

    def order(found: list[Column]) -> list[int]:
        return np.argsort(np.concatenate([c.position for c in found]), kind="stable").tolist()

    assert order(columns) == order(expected)


def _topics(reader: BagReader) -> list[str]:
    return [topic for topic in reader.topics() if topic != "/mpi/configuration"]


@pytest.mark.parametrize("name", ["two_supervisors", "faults", "streamed_path", "cams"])
def test_the_indexed_columns_are_the_messages_read_one_by_one(name: str):
    reader = BagReader(BAGS / name)
    topics = _topics(reader)
    indexed = reader._indexed(set(topics))
    assert indexed is not None  # the fixtures have their message indexes
    _same(indexed, _one_by_one(reader, topics))
    assert sum(len(c.data) for c in indexed) > 500


def _damaged_index(tmp_path: Path) -> Path:
    """A copy of a fixture whose first chunk's index of /mpi/axis0/status points its first
    message at /mpi/axis1/status' first message."""
    copy = tmp_path / "damaged"
    shutil.copytree(BAGS / "two_supervisors", copy)
    reader = BagReader(copy)
    with open(reader.path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    ids = {channel.topic: cid for cid, channel in summary.channels.items()}
    index = summary.chunk_indexes[0]
    # opcode, length, channel id, the entries' length, then (log time, offset) pairs
    first, other = (index.message_index_offsets[ids[topic]] + 1 + 8 + 2 + 4 + 8
                    for topic in ("/mpi/axis0/status", "/mpi/axis1/status"))
    with open(reader.path, "r+b") as stream:
        stream.seek(other)
        offset = stream.read(8)
        stream.seek(first)
        stream.write(offset)
    return copy


def test_a_damaged_message_index_is_not_trusted(tmp_path: Path):
    copy = _damaged_index(tmp_path)
    reader = BagReader(copy)
    topics = _topics(reader)
    assert reader._indexed(set(topics)) is None
    _same(reader.columns(topics), _one_by_one(reader, topics))
    assert replay(copy).identical


def test_a_bag_without_message_indexes_is_read_one_by_one(unchunked_bag: Path):
    """Written without chunks (no chunk indexes, so no message indexes): the statistics count
    messages the indexes do not hold."""
    path = unchunked_bag
    reader = BagReader(path)
    topics = _topics(reader)
    assert reader._indexed(set(topics)) is None
    _same(reader.columns(topics), _one_by_one(reader, topics))


@pytest.mark.parametrize("name", ["two_supervisors", "cams"])
def test_the_statuses_keys_read_together_are_those_read_one_by_one(name: str):
    reader = BagReader(BAGS / name)
    for column in reader.columns([t for t, k in reader.topics().items() if k in replay_module.STATUS_TYPES]):
        keys = replay_module._status_keys(column.source.type, column.data)
        assert keys.tolist() == [list(wire.sample_and_number(data)) for data in column.data]


def test_statuses_whose_bytes_are_not_laid_out_as_expected_are_read_one_by_one():
    """A frame_id length pointing past the message: the key read one by one says what is wrong."""
    reader = BagReader(BAGS / "two_supervisors")
    column = next(c for c in reader.columns(["/mpi/axis0/status"]))
    data = list(column.data)
    data[3] = data[3][:12] + struct.pack("<I", 10_000) + data[3][16:]
    with pytest.raises(struct.error):
        replay_module._status_keys(column.source.type, data)


@pytest.mark.parametrize("name", ["two_supervisors", "faults"])
def test_commands_and_events_read_from_their_bytes_are_what_decoding_gives(name: str):
    """Replay reads what it uses of the commands and every field of the events from their
    CDR (fields.field_reader), without rclpy's serialization."""
    from operator import attrgetter

    from mpi_ros.bag import fields, schema

    reader = BagReader(BAGS / name)
    for column in reader.columns(["/mpi/commands", "/mpi/events"]):
        names = (replay_module._COMMAND_FIELDS if column.source.topic == "/mpi/commands"
                 else tuple(fields.field_names(schema.message_class(column.source.type))))
        read = replay_module._reader(column.source, names)
        assert [read(data) for data in column.data] == [
            attrgetter(*names)(column.source.recorded(0, data).decode()) for data in column.data]
        assert len(column.data) > 1
