"""Print any of the suite's topics as YAML, like `ros2 topic echo`.

  mpi-ros echo events                   /mpi/events (names without a leading / are looked up
  mpi-ros echo ms0/status --once        under --namespace first, then at the root)
  mpi-ros echo axis1/status --count 3
  mpi-ros echo /joint_states --once

Each message is a YAML document followed by "---". The QoS follows the topic's publishers
(reliable unless they are best effort, as /clock is; transient local for latched topics).
"""

from __future__ import annotations

import argparse
import queue
import sys
import threading
import time

from .. import graph_names as gn
from .console import OK, UsageError, add_target_options, fail, run_verb

ROOT_TOPICS = tuple(endpoint.name() for endpoint in gn.ENDPOINTS if endpoint.owner is gn.Owner.ROOT)
TOPIC_WAIT = 1.0  # s for a topic to appear once the suite is there (its endpoints come after its nodes)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topic", help="topic name: events, ms0/status, axis2/status, /joint_states, ...")
    parser.add_argument("--once", action="store_true", help="print one message and exit")
    parser.add_argument("--count", type=int, metavar="N", help="exit after N messages")
    add_target_options(parser, supervisor_default=None)


def run(args: argparse.Namespace) -> int:
    if args.count is not None and args.count < 1:
        return fail(args, "--count must be at least 1")
    return run_verb(args, lambda session: _echo(session, args))


def candidates(topic: str, namespace: str) -> list[str]:
    """Where ``topic`` may be: as given if absolute, else under the namespace, then at the root."""
    if topic.startswith("/"):
        return [topic.rstrip("/")]
    return [f"{namespace.rstrip('/')}/{topic}".rstrip("/"), f"/{topic}".rstrip("/")]


def _find(watcher, args: argparse.Namespace) -> str:
    """The topic's full name, waiting briefly for it to be announced."""
    names = candidates(args.topic, watcher.namespace)
    deadline = time.monotonic() + min(TOPIC_WAIT, args.timeout)
    pause = threading.Event()  # never set: an interruptible wait between graph queries
    while True:
        topics = watcher.topics_on_graph()
        found = [name for name in names if name in topics]
        if found:
            return found[0]
        if time.monotonic() >= deadline:
            break
        pause.wait(0.05)
    raise UsageError(f"no topic {names[0]}: the suite publishes {', '.join(suite_topics(topics, watcher.namespace))}")


def suite_topics(topics, namespace: str) -> list[str]:
    """The suite's own topics among ``topics`` (the actions' internal topics left out)."""
    return sorted(t for t in topics if (t.startswith(namespace.rstrip("/") + "/") or t in ROOT_TOPICS)
                  and not gn.is_action_internal(t))


def _echo(session, args: argparse.Namespace) -> int:
    import yaml

    from mpi_ros.client import message_to_dict

    count = 1 if args.once else args.count
    watcher = session.watcher()
    topic = _find(watcher, args)
    received: queue.Queue = queue.Queue()
    subscription, _type_name = watcher.follow_topic(topic, received.put)
    watcher.wait_matched(subscription, args.timeout)
    shown = 0
    try:
        while count is None or shown < count:
            msg = received.get()  # blocks; Ctrl-C interrupts it
            sys.stdout.write(yaml.safe_dump(message_to_dict(msg), sort_keys=False, default_flow_style=False))
            sys.stdout.write("---\n")
            sys.stdout.flush()
            shown += 1
    except KeyboardInterrupt:
        pass  # Ctrl-C is how a live view ends
    return OK
