"""Write a rosbag2-compatible bag directory: metadata.yaml beside one .mcap file.

MCAP as rosbag2 writes it (docs/recording.md, "The MCAP file"): profile ``ros2``; schema ``pkg/msg/Type`` with
encoding ``ros2msg``; channels with message encoding ``cdr`` and the metadata
``offered_qos_profiles`` (a YAML string) and ``topic_type_hash``; log and publish times
in nanoseconds; a ``rosbag2`` metadata record carrying the bag information. The mcap
Writer keeps messages in memory until a chunk fills, so ``close`` must run on every exit
path (use the writer as a context manager).

Messages are stored as canonical CDR (cdr.py): exactly as long as their data, alignment
padding zeroed. rclpy's serializer returns a longer buffer for messages with empty
sequences of 8-byte elements, which strict readers (rosbags) refuse.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path

import yaml
from mcap.writer import CompressionType, Writer

from . import cdr, schema

METADATA_VERSION = 9
ROS_DISTRO = "jazzy"


@dataclass(frozen=True, slots=True)
class TopicQos:
    """The QoS a topic was offered with (rosbag2's offered_qos_profiles)."""

    reliable: bool = True
    depth: int = 10
    transient_local: bool = False

    def as_dict(self) -> dict:
        zero = {"sec": 0, "nsec": 0}
        return {
            "history": "keep_last",
            "depth": self.depth,
            "reliability": "reliable" if self.reliable else "best_effort",
            "durability": "transient_local" if self.transient_local else "volatile",
            "deadline": dict(zero),
            "lifespan": dict(zero),
            "liveliness": "automatic",
            "liveliness_lease_duration": dict(zero),
            "avoid_ros_namespace_conventions": False,
        }


@dataclass(slots=True)
class _Topic:
    name: str
    type: str
    qos: TopicQos
    channel_id: int
    count: int = 0


class BagWriter:
    """``with BagWriter(directory) as bag: bag.write(topic, msg, log_time_ns)``."""

    def __init__(self, directory: str | Path, compress: bool = True):
        self.directory = Path(directory)
        if self.directory.exists() and any(self.directory.iterdir()):
            raise FileExistsError(f"{self.directory} exists and is not empty")
        self.directory.mkdir(parents=True, exist_ok=True)
        self.file_name = f"{self.directory.name}_0.mcap"
        self._stream = open(self.directory / self.file_name, "wb")  # noqa: SIM115 - closed in close()
        self._writer = Writer(self._stream, compression=CompressionType.ZSTD if compress else CompressionType.NONE)
        self._writer.start(profile="ros2", library="mpi_ros")
        self._schemas: dict[str, int] = {}
        self._topics: dict[str, _Topic] = {}
        self._lock = threading.Lock()
        self._first: int | None = None
        self._last: int | None = None
        self._closed = False
        self.custom_data: dict[str, str] = {}

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def add_topic(self, name: str, msg_type: str, qos: TopicQos = TopicQos()) -> None:
        """Declare a topic (done implicitly on first write with the default QoS)."""
        with self._lock:
            self._add_topic(name, msg_type, qos)

    def _add_topic(self, name: str, msg_type: str, qos: TopicQos) -> _Topic:
        topic = self._topics.get(name)
        if topic is not None:
            if topic.type != msg_type:
                raise ValueError(f"topic {name} is {topic.type}, not {msg_type}")
            return topic
        if msg_type not in self._schemas:
            self._schemas[msg_type] = self._writer.register_schema(
                name=msg_type, encoding="ros2msg", data=schema.ros2msg(msg_type).encode())
        channel = self._writer.register_channel(
            topic=name, message_encoding="cdr", schema_id=self._schemas[msg_type],
            metadata={"offered_qos_profiles": yaml.safe_dump([qos.as_dict()], sort_keys=False),
                      "topic_type_hash": schema.type_hash(msg_type)})
        topic = _Topic(name, msg_type, qos, channel)
        self._topics[name] = topic
        return topic

    def write(self, name: str, msg, log_time: int) -> None:
        """Serialise a ROS message (canonical CDR) and store it (thread-safe)."""
        data = cdr.serialize(msg)
        self.write_raw(name, schema.full_name(type(msg)), data, log_time)

    def write_raw(self, name: str, msg_type: str, data: bytes, log_time: int) -> None:
        with self._lock:
            if self._closed:
                raise ValueError("the bag is closed")
            topic = self._add_topic(name, msg_type, TopicQos())
            self._writer.add_message(channel_id=topic.channel_id, log_time=log_time, data=data,
                                     publish_time=log_time, sequence=topic.count)
            topic.count += 1
            self._first = log_time if self._first is None else min(self._first, log_time)
            self._last = log_time if self._last is None else max(self._last, log_time)

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        """An MCAP metadata record (e.g. the configuration the run used)."""
        with self._lock:
            self._writer.add_metadata(name, data)

    def information(self) -> dict:
        """The rosbag2_bagfile_information of metadata.yaml."""
        start = self._first or 0
        duration = (self._last or 0) - start
        count = sum(t.count for t in self._topics.values())
        return {
            "version": METADATA_VERSION,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": count,
            "topics_with_message_count": [
                {"topic_metadata": {"name": t.name, "type": t.type, "serialization_format": "cdr",
                                    "offered_qos_profiles": [t.qos.as_dict()],
                                    "type_description_hash": schema.type_hash(t.type)},
                 "message_count": t.count}
                for t in self._topics.values()
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [self.file_name],
            "files": [{"path": self.file_name, "starting_time": {"nanoseconds_since_epoch": start},
                       "duration": {"nanoseconds": duration}, "message_count": count}],
            "custom_data": dict(self.custom_data),
            "ros_distro": ROS_DISTRO,
        }

    def close(self) -> None:
        """Finish the MCAP file and write metadata.yaml (idempotent)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            info = self.information()
            self._writer.add_metadata("rosbag2", {"serialized_metadata": yaml.safe_dump(info, sort_keys=False),
                                                  "ROS_DISTRO": ROS_DISTRO})
            self._writer.finish()
            self._stream.close()
            text = yaml.safe_dump({"rosbag2_bagfile_information": info}, sort_keys=False)
            (self.directory / "metadata.yaml").write_text(text, encoding="utf-8")
