"""Read a bag this project (or rosbag2) wrote: a bag directory or a bare .mcap file."""

from __future__ import annotations

import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import yaml
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap_ros2._dynamic import generate_dynamic

from . import schema


@dataclass(frozen=True, slots=True)
class Recorded:
    topic: str
    type: str  # pkg/msg/Type
    log_time: int  # ns
    data: bytes  # CDR
    sequence: int = 0  # the writer's count on the topic: the order messages were written in
    schema_text: str = ""  # the ros2msg definition the bag stores for the type ("": unknown)

    def decode(self):
        """The message: as its generated Python class (the package must be installed) when the
        bag's definition of the type is the installed one; else read by the definition the bag
        stores (a bag recorded before the type changed), with the fields it had."""
        if self.schema_text and self.schema_text != schema.ros2msg(self.type):
            return _recorded_decoder(self.type, self.schema_text)(self.data)
        from rclpy.serialization import deserialize_message

        return deserialize_message(self.data, schema.message_class(self.type))


@lru_cache(maxsize=64)
def _recorded_decoder(type_name: str, text: str):
    """A decoder of ``type_name`` by the definition ``text`` (mcap_ros2's dynamic decoding:
    objects with the definition's fields as attributes)."""
    return generate_dynamic(type_name, text)[type_name]


def mcap_path(path: str | Path) -> Path:
    """The .mcap file of a bag directory (from its metadata.yaml), or ``path`` itself."""
    path = Path(path)
    if path.is_file():
        return path
    metadata = path / "metadata.yaml"
    if metadata.is_file():
        info = yaml.safe_load(metadata.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
        return path / info["relative_file_paths"][0]
    files = sorted(path.glob("*.mcap"))
    if not files:
        raise FileNotFoundError(f"{path}: no metadata.yaml and no .mcap file")
    return files[0]


class BagReader:
    def __init__(self, path: str | Path):
        self.path = mcap_path(path)

    def _reader(self, stream):
        try:
            return make_reader(stream)
        except (McapError, struct.error, EOFError) as exc:  # not an MCAP file (or cut short)
            raise ValueError(f"{self.path}: not a readable MCAP file ({exc or type(exc).__name__})") from exc

    def metadata(self, name: str) -> dict[str, str] | None:
        """An MCAP metadata record's data, by name."""
        with open(self.path, "rb") as stream:
            for record in self._reader(stream).iter_metadata():
                if record.name == name:
                    return dict(record.metadata)
        return None

    def topics(self) -> dict[str, str]:
        """topic -> pkg/msg/Type."""
        with open(self.path, "rb") as stream:
            summary = self._reader(stream).get_summary()
        if summary is None:
            return {}
        return {ch.topic: summary.schemas[ch.schema_id].name for ch in summary.channels.values()}

    def messages(self, topics: Iterable[str] | None = None) -> Iterator[Recorded]:
        """Messages in log-time order."""
        wanted = list(topics) if topics is not None else None
        with open(self.path, "rb") as stream:
            for schema_, channel, message in self._reader(stream).iter_messages(topics=wanted, log_time_order=True):
                yield Recorded(channel.topic, schema_.name, message.log_time, message.data, message.sequence,
                               schema_.data.decode("utf-8", errors="replace"))

    def decoded(self, topics: Iterable[str] | None = None) -> Iterator[tuple[Recorded, Any]]:
        for recorded in self.messages(topics):
            yield recorded, recorded.decode()

    def counts(self) -> dict[str, int]:
        with open(self.path, "rb") as stream:
            summary = self._reader(stream).get_summary()
        if summary is None or summary.statistics is None:
            return {}
        return {summary.channels[cid].topic: n for cid, n in summary.statistics.channel_message_counts.items()}
