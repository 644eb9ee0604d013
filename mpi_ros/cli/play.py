"""Publish a bag's topics to the ROS graph with their original timing, like `ros2 bag play`.

  mpi-ros play BAG [--rate X] [--topics T ...]
  mpi-ros play run.bag --topics events ms0/status /joint_states

--topics takes the names `mpi-ros echo` takes: without a leading / under --namespace first
(default /mpi), then at the root. A name the bag does not have is a usage error (exit 2)
that lists the topics it has.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable

from .console import DEFAULT_NAMESPACE, USAGE
from .echo import candidates


def resolve_topics(names: Iterable[str], namespace: str, recorded: Iterable[str]) -> list[str]:
    """The bag's topic for each name, as `mpi-ros echo` resolves it; ValueError names a missing one."""
    recorded = sorted(recorded)
    found = []
    for name in names:
        match = next((topic for topic in candidates(name, namespace) if topic in recorded), None)
        if match is None:
            raise ValueError(f"no topic {candidates(name, namespace)[0]} in the bag: it has {', '.join(recorded)}")
        found.append(match)
    return found


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", help="bag directory or .mcap file")
    parser.add_argument("--rate", type=float, default=1.0, help="playback speed (2 = twice as fast)")
    parser.add_argument("--topics", nargs="+", metavar="T",
                        help="only these topics: events, ms0/status, /joint_states, ... (as `mpi-ros echo`)")
    parser.add_argument("--namespace", default=DEFAULT_NAMESPACE, metavar="NS",
                        help=f"where --topics names without a leading / are looked for first "
                             f"(default {DEFAULT_NAMESPACE})")
    parser.add_argument("--wait-for-subscribers", type=int, default=0, metavar="N",
                        help="start once every topic has N subscribers (default: start at once)")


def run(args) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException

    from mpi_ros.bag.playback import play
    from mpi_ros.bag.reader import BagReader

    topics = None
    if args.topics:
        try:
            topics = resolve_topics(args.topics, args.namespace, BagReader(args.bag).topics())
        except (OSError, ValueError) as exc:
            print(f"mpi-ros play: {exc}", file=sys.stderr)
            return USAGE
    rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])])
    node = rclpy.create_node("mpi_ros_player")
    try:
        count = play(node, args.bag, args.rate, topics, wait_for_subscribers=args.wait_for_subscribers)
        print(f"published {count} messages from {args.bag}")
        return 0
    except (OSError, ValueError, TimeoutError) as exc:
        print(f"mpi-ros play: {exc}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
