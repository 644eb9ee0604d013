"""Publish a bag's topics to the ROS graph with their original timing (or scaled),
like ``ros2 bag play``, for machines without rosbag2."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable
from pathlib import Path

from rclpy.node import Node

from .. import graph_names
from ..qos import profile
from . import schema
from .reader import BagReader


def play(node: Node, path: str | Path, rate: float = 1.0, topics: Iterable[str] | None = None,
         stop: threading.Event | None = None, wait_for_subscribers: int = 0, timeout: float = 10.0) -> int:
    """Publish the bag's messages from ``node``; returns how many were published.

    ``rate`` 2 plays twice as fast; ``stop`` ends playback early when set;
    ``wait_for_subscribers`` N waits (up to ``timeout`` s) until every topic has N
    subscribers, so that nothing is published before anyone listens.
    """
    if rate <= 0.0:
        raise ValueError("rate must be > 0")
    reader = BagReader(path)
    wanted = set(topics) if topics is not None else None
    kinds = {t: k for t, k in reader.topics().items() if wanted is None or t in wanted}
    qos = profile(graph_names.PLAYBACK_QOS)
    publishers = {t: node.create_publisher(schema.message_class(k), t, qos) for t, k in kinds.items()}
    stop = stop or threading.Event()
    deadline = time.monotonic() + timeout
    while wait_for_subscribers and any(pub.get_subscription_count() < wait_for_subscribers
                                       for pub in publishers.values()):
        if time.monotonic() > deadline or stop.wait(0.01):
            raise TimeoutError(f"no {wait_for_subscribers} subscriber(s) on every topic within {timeout} s")
    start_wall = time.monotonic()
    first = None
    count = 0
    for item in reader.messages(list(kinds)):
        first = item.log_time if first is None else first
        due = start_wall + (item.log_time - first) / 1e9 / rate
        delay = due - time.monotonic()
        if delay > 0.0 and stop.wait(delay):
            break
        if stop.is_set():
            break
        # a message recorded before its type changed is sent in the installed type (reader.upgrade)
        publishers[item.topic].publish(item.installed_data())
        count += 1
    return count
