"""Fixtures shared by the bag tests."""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.writer import Writer

from mpi_ros.bag.reader import BagReader

BAGS = Path(__file__).resolve().parents[1] / "fixtures" / "bags"


@pytest.fixture
def unchunked_bag(tmp_path: Path) -> Path:
    """The two_supervisors fixture written again without chunks: no chunk indexes, so no
    message indexes, and a reader must take the records one by one from the start."""
    source = BagReader(BAGS / "two_supervisors")
    path = tmp_path / "flat.mcap"
    with open(path, "wb") as stream:
        writer = Writer(stream, use_chunking=False)
        writer.start(profile="ros2", library="test")
        channels: dict[str, int] = {}
        for recorded in source.messages():
            if recorded.topic not in channels:
                schema_id = writer.register_schema(recorded.type, "ros2msg", recorded.schema_text.encode())
                channels[recorded.topic] = writer.register_channel(recorded.topic, "cdr", schema_id)
            writer.add_message(channels[recorded.topic], recorded.log_time, recorded.data, recorded.log_time,
                               recorded.sequence)
        writer.finish()
    return path
