"""Publish a bag's topics to the ROS graph with their original timing, like `ros2 bag play`.

  mpi-ros play BAG [--rate X] [--topics T ...]
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", help="bag directory or .mcap file")
    parser.add_argument("--rate", type=float, default=1.0, help="playback speed (2 = twice as fast)")
    parser.add_argument("--topics", nargs="+", help="only these topics")
    parser.add_argument("--wait-for-subscribers", type=int, default=0, metavar="N",
                        help="start once every topic has N subscribers (default: start at once)")


def run(args) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException

    from mpi_ros.bag.playback import play

    rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])])
    node = rclpy.create_node("mpi_ros_player")
    try:
        count = play(node, args.bag, args.rate, args.topics, wait_for_subscribers=args.wait_for_subscribers)
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
