"""The goals' bookkeeping: what accepting a goal, ending it and publishing the status array
cost with ``n`` goals kept, rcl_action's goal handles side by side with GoalTable.

A goal server keeps every goal until its result expires (result_timeout after it ended): at
800 modifies a second and results kept 10 s, about 1,000-2,000 goals per action server.
rcl_action (through rclpy's C ActionServer and ActionGoalHandle, as GoalServer used them
before it kept its goals itself) scans all of them for every goal accepted, every goal
ended and every status array; GoalTable (mpi_ros/ros/goal_table.py) does not. Both publish
their status array on a publisher with no subscriber. Each figure is the mean over
``--goals`` operations at that size, the two alternating in one process, best of ``--rounds``.

    python -P bench/bench_goals.py [--rounds 3] [--goals 500]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import rclpy
from action_msgs.msg import GoalInfo, GoalStatusArray
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos import QoSProfile, qos_profile_action_status_default
from rclpy.type_support import check_for_type_support

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # this tree's mpi_ros, before the installed one
from mpi_ros.action import MotionModify
from mpi_ros.ros import goal_table
from mpi_ros.ros.goal_table import GoalTable

SIZES = (100, 1000, 2000, 8000)
_EVENT = _rclpy.GoalEvent


class RclAction:
    """Goals kept in rcl_action's handles."""

    def __init__(self, node, name: str):
        check_for_type_support(MotionModify)
        qos = QoSProfile(depth=10).get_c_qos_profile()
        with node.handle, node.get_clock().handle:
            self.server = _rclpy.ActionServer(node.handle, node.get_clock().handle, MotionModify, name, qos, qos, qos,
                                              qos, qos_profile_action_status_default.get_c_qos_profile(), 1e6)
        self.stamp = node.get_clock().now().to_msg()
        self.handles: dict[bytes, object] = {}

    def accept(self, key: bytes) -> None:
        info = GoalInfo(stamp=self.stamp)
        info.goal_id.uuid = list(key)
        self.handles[key] = _rclpy.ActionGoalHandle(self.server, info)

    def end(self, key: bytes) -> None:
        handle = self.handles[key]
        handle.update_goal_state(_EVENT.EXECUTE)
        handle.update_goal_state(_EVENT.SUCCEED)
        self.server.notify_goal_done()

    def publish(self) -> None:
        self.server.publish_status()


class Table:
    """Goals kept in a GoalTable, its array published raw."""

    def __init__(self, node, name: str):
        self.goals = GoalTable(1e6)
        self.publisher = node.create_publisher(GoalStatusArray, f"{name}/_action/status",
                                               qos_profile_action_status_default)
        self.stamp_ns = node.get_clock().now().nanoseconds

    def accept(self, key: bytes) -> None:
        self.goals.accept(key, self.stamp_ns)

    def end(self, key: bytes) -> None:
        self.goals.execute(key)
        self.goals.end(key, goal_table.SUCCEEDED)

    def publish(self) -> None:
        self.publisher.publish(self.goals.status_array())


def fill(kept, count: int) -> list[bytes]:
    keys = [os.urandom(16) for _ in range(count)]
    for key in keys:
        kept.accept(key)
    return keys


def measure(kept, size: int, goals: int) -> dict[str, float]:
    """At ``size`` goals kept: ``goals`` more accepted, then ended, then arrays published."""
    fill(kept, size)
    keys = [os.urandom(16) for _ in range(goals)]
    start = time.perf_counter()
    for key in keys:
        kept.accept(key)
    accepted = time.perf_counter()
    for key in keys:
        kept.end(key)
    ended = time.perf_counter()
    for _ in range(max(goals // 10, 1)):
        kept.publish()
    published = time.perf_counter()
    return {"accept_us": (accepted - start) / goals * 1e6, "end_us": (ended - accepted) / goals * 1e6,
            "status_us": (published - ended) / max(goals // 10, 1) * 1e6}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--goals", type=int, default=500, help="goals accepted and ended at each size")
    args = parser.parse_args()
    rclpy.init()
    node = rclpy.create_node("bench_goals")
    print("| goals kept | operation | rcl_action (us) | GoalTable (us) | ratio |")
    print("| --- | --- | --- | --- | --- |")
    made = 0
    for size in SIZES:
        best: dict[str, dict[str, float]] = {"rcl": {}, "table": {}}
        for _ in range(args.rounds):
            for kind, cls in (("rcl", RclAction), ("table", Table)):
                made += 1
                result = measure(cls(node, f"bench{made}"), size, args.goals)
                for key, value in result.items():
                    best[kind][key] = min(best[kind].get(key, value), value)
        for op in ("accept_us", "end_us", "status_us"):
            theirs, ours = best["rcl"][op], best["table"][op]
            print(f"| {size:,} | {op[:-3]} | {theirs:.1f} | {ours:.1f} | {theirs / ours:.1f}x |")
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
