"""A generic recorder of the ROS graph, as `ros2 bag record -a` is, for the tests: it knows
nothing of mpi_ros beyond what is on the graph.

    python graph_recorder.py OUTPUT.mcap

Every 50 ms it looks for new topics and subscribes to each one that is not hidden (no name
part starting with "_", as rosbag2 leaves out action internals), with the QoS its
publishers offer (reliable if they all are, transient local if they all are, rosbag2's
rule), history 1000. Every message is serialised again with rclpy.serialization and written
with the plain mcap Writer in the rosbag2 layout (profile ros2, ros2msg schemas, cdr, log
time = the time it arrived, a sequence number per channel). It prints "subscribed TOPIC
TYPE" for each topic (so a test knows when it listens) and, when stopped with SIGINT or
SIGTERM, takes what has already arrived (for up to 2 s), finishes the file and prints "recorded N messages".
"""

from __future__ import annotations

import importlib
import signal
import sys
import threading
import time

import rclpy
import yaml
from mcap.writer import CompressionType, Writer
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message
from rclpy.signals import SignalHandlerOptions

from mpi_ros.bag.schema import ros2msg  # the .msg text of a type, from its package's share folder


def message_class(type_name: str):
    package, _, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), name)


def hidden(topic: str) -> bool:
    return any(part.startswith("_") for part in topic.split("/"))


class GraphRecorder:
    def __init__(self, node, writer: Writer):
        self.node = node
        self.writer = writer
        self.schemas: dict[str, int] = {}
        self.channels: dict[str, int] = {}
        self.sequence: dict[str, int] = {}
        self.count = 0
        self.handled = 0  # callbacks run, to know when nothing more is arriving

    def discover(self) -> None:
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self.channels or hidden(topic) or len(types) != 1:
                continue
            publishers = self.node.get_publishers_info_by_topic(topic)
            if not publishers:
                continue
            try:
                cls = message_class(types[0])
            except (ImportError, AttributeError, ValueError):
                print(f"skipped {topic} {types[0]}", flush=True)
                self.channels[topic] = -1
                continue
            reliable = all(p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers)
            latched = all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers)
            qos = QoSProfile(depth=1000, history=HistoryPolicy.KEEP_LAST,
                             reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)
            if types[0] not in self.schemas:
                self.schemas[types[0]] = self.writer.register_schema(
                    name=types[0], encoding="ros2msg", data=ros2msg(types[0]).encode())
            offered = [{"history": "keep_last", "depth": 1000,
                        "reliability": "reliable" if reliable else "best_effort",
                        "durability": "transient_local" if latched else "volatile"}]
            self.channels[topic] = self.writer.register_channel(
                topic=topic, message_encoding="cdr", schema_id=self.schemas[types[0]],
                metadata={"offered_qos_profiles": yaml.safe_dump(offered)})
            self.sequence[topic] = 0
            self.node.create_subscription(cls, topic, lambda msg, topic=topic: self.on_message(topic, msg), qos)
            print(f"subscribed {topic} {types[0]}", flush=True)

    def on_message(self, topic: str, msg) -> None:
        now = time.time_ns()
        self.writer.add_message(channel_id=self.channels[topic], log_time=now, publish_time=now,
                                data=serialize_message(msg), sequence=self.sequence[topic])
        self.sequence[topic] += 1
        self.count += 1
        self.handled += 1


def main(argv: list[str]) -> int:
    output = argv[1]
    stop = threading.Event()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    node = rclpy.create_node("graph_recorder")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    with open(output, "wb") as stream:
        writer = Writer(stream, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="graph_recorder (test)")
        recorder = GraphRecorder(node, writer)
        try:
            next_look = 0.0
            while not stop.is_set():
                if time.monotonic() >= next_look:
                    recorder.discover()
                    next_look = time.monotonic() + 0.05
                executor.spin_once(timeout_sec=0.02)
            # take what has arrived: until two spins in a row find no message (at most 2 s:
            # suites that keep running keep publishing)
            idle, drained_by = 0, time.monotonic() + 2.0
            while idle < 2 and time.monotonic() < drained_by:
                before = recorder.handled
                executor.spin_once(timeout_sec=0.2)
                idle = idle + 1 if recorder.handled == before else 0
        finally:
            writer.finish()
    print(f"recorded {recorder.count} messages", flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
