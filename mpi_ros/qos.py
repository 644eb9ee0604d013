"""The one place the suite's QoS (plain data, mpi_ros/graph_names.py) becomes rclpy's QoSProfile.

At the package's top rather than in mpi_ros/ros: the client uses it and imports nothing of the suite's nodes."""

from __future__ import annotations

from collections.abc import Iterable
from functools import cache
from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from mpi_ros.graph_names import Durability, History, Qos, Reliability

_RELIABILITY = {Reliability.RELIABLE: ReliabilityPolicy.RELIABLE,
                Reliability.BEST_EFFORT: ReliabilityPolicy.BEST_EFFORT}
_DURABILITY = {Durability.VOLATILE: DurabilityPolicy.VOLATILE,
               Durability.TRANSIENT_LOCAL: DurabilityPolicy.TRANSIENT_LOCAL}
_HISTORY = {History.KEEP_LAST: HistoryPolicy.KEEP_LAST, History.KEEP_ALL: HistoryPolicy.KEEP_ALL}


@cache
def profile(qos: Qos) -> QoSProfile:
    """rclpy's profile for ``qos``; the same object for equal profiles (the goal front
    recognises its action services' profile by identity)."""
    return QoSProfile(depth=qos.depth, reliability=_RELIABILITY[qos.reliability],
                      durability=_DURABILITY[qos.durability], history=_HISTORY[qos.history])


def action_qos(qos: Qos) -> dict[str, QoSProfile]:
    """The keyword arguments giving an ActionClient's (or ActionServer's) services ``qos``."""
    services = profile(qos)
    return {"goal_service_qos_profile": services, "result_service_qos_profile": services,
            "cancel_service_qos_profile": services}


def matching(publishers: Iterable[Any], depth: int) -> QoSProfile:
    """A subscriber's profile every one of ``publishers`` (their TopicEndpointInfo) accepts:
    reliable unless one is best effort (/clock is); transient local when all are (latched topics)."""
    offered = [p.qos_profile for p in publishers]
    best_effort = any(q.reliability == ReliabilityPolicy.BEST_EFFORT for q in offered)
    latched = bool(offered) and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered)
    return profile(Qos(depth, Reliability.BEST_EFFORT if best_effort else Reliability.RELIABLE,
                       Durability.TRANSIENT_LOCAL if latched else Durability.VOLATILE))
