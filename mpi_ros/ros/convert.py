"""Conversions at the ROS edge: messages <-> plain dicts, controller snapshots -> messages."""

from __future__ import annotations

import array
import math
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time
from rclpy._rclpy_pybind11 import RCLError
from sensor_msgs.msg import JointState

from mpi_ros.msg import AxisStatus, MotionEvent, MotionStatus

from ..mpi.events import Event
from ..mpi.snapshot import AxisSnapshot, MotionSnapshot


def to_dict(msg) -> dict[str, Any]:
    """A ROS message as a dict of plain Python values (nested messages as dicts)."""
    out: dict[str, Any] = {}
    for name in msg.get_fields_and_field_types():
        out[name] = _plain(getattr(msg, name))
    return out


def _plain(value):
    if hasattr(value, "get_fields_and_field_types"):
        return to_dict(value)
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (array.array, np.ndarray)):
        return [v.item() if hasattr(v, "item") else v for v in value]
    return value


def fill(msg, data: dict[str, Any]):
    """Set a message's fields from a dict (floats converted at the edge)."""
    types = msg.get_fields_and_field_types()
    for name, value in data.items():
        if name not in types:
            continue
        current = getattr(msg, name)
        kind = types[name]
        if hasattr(current, "get_fields_and_field_types"):
            fill(current, value)
        elif kind.startswith("sequence<") and "/" in kind:
            element = type(msg).SLOT_TYPES[list(types).index(name)].value_type
            cls = _message_class(element)
            setattr(msg, name, [fill(cls(), v) for v in value])
        elif "float" in kind or "double" in kind:
            setattr(msg, name, [float(v) for v in value] if kind.startswith("sequence") else float(value))
        elif kind.startswith("sequence<int") or kind.startswith("sequence<uint"):
            setattr(msg, name, [int(v) for v in value])
        else:
            setattr(msg, name, value)
    return msg


def _message_class(namespaced_type):
    import importlib

    module = importlib.import_module(".".join(namespaced_type.namespaces))
    return getattr(module, namespaced_type.name)


def answer(response, reply):
    """Put a controller reply's message (name and code) into a service response."""
    response.message = reply.message.name
    response.code = reply.message.code
    return response


def stamp(sample: int, rate: float) -> Time:
    """Controller time of a sample."""
    nanoseconds = int(round(sample * 1e9 / rate))
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def _finite(x: float) -> float:
    return float(x) if math.isfinite(x) else 0.0


def axis_status(snap: AxisSnapshot, rate: float) -> AxisStatus:
    msg = AxisStatus()
    msg.stamp = stamp(snap.sample, rate)
    msg.sample = snap.sample
    msg.number = snap.number
    msg.state = int(snap.state)
    msg.state_name = snap.state.name
    msg.command_position = _finite(snap.command_position)
    msg.actual_position = _finite(snap.actual_position)
    msg.position_error = _finite(snap.position_error)
    msg.target_position = float(snap.target_position)  # NaN: no target (a velocity move)
    msg.origin = _finite(snap.origin)
    msg.command_velocity = _finite(snap.command_velocity)
    msg.actual_velocity = _finite(snap.actual_velocity)
    msg.command_acceleration = _finite(snap.command_acceleration)
    msg.done = snap.done
    msg.at_target = snap.at_target
    msg.in_fine_position = snap.in_fine_position
    msg.in_coarse_position = snap.in_coarse_position
    msg.settled = snap.settled
    msg.at_velocity = snap.at_velocity
    msg.trajectory_complete = snap.trajectory_complete
    msg.amp_enabled = snap.amp_enabled
    msg.move_id = snap.move_id
    msg.element_id = snap.element_id
    msg.frame_count = snap.frame_count
    msg.supervisor = snap.supervisor
    return msg


def motion_status(snap: MotionSnapshot, rate: float) -> MotionStatus:
    msg = MotionStatus()
    msg.stamp = stamp(snap.sample, rate)
    msg.sample = snap.sample
    msg.number = snap.number
    msg.state = int(snap.state)
    msg.state_name = snap.state.name
    msg.axis_numbers = list(snap.axis_numbers)
    msg.axes = [axis_status(a, rate) for a in snap.axes]
    msg.done = snap.done
    msg.at_target = snap.at_target
    msg.settled = snap.settled
    msg.move_id = snap.move_id
    msg.element_id = snap.element_id
    msg.feedrate = float(snap.feedrate)
    msg.last_action = snap.last_action
    msg.action_source = snap.action_source
    msg.moves_pending = snap.moves_pending
    msg.motion_type = snap.motion_type
    return msg


def joint_state(ctl) -> JointState:
    """Every axis as a joint: actual position and velocity."""
    msg = JointState()
    msg.header.stamp = stamp(ctl.sample, ctl.rate)
    msg.name = [f"axis{a.number}" for a in ctl.axes]
    msg.position = [float(a.actual_position) for a in ctl.axes]
    msg.velocity = [float(a.act_v) for a in ctl.axes]
    return msg


def motion_event(event: Event, rate: float) -> MotionEvent:
    msg = MotionEvent()
    msg.stamp = stamp(event.sample, rate)
    msg.sample = event.sample
    msg.type = event.type_name
    msg.supervisor = event.supervisor
    msg.axis = event.axis
    msg.move_id = event.move_id
    msg.element_id = event.element_id
    msg.detail = event.detail
    return msg


def publish(node, publisher, msg) -> None:
    """Publish unless the node's context has shut down (a Ctrl-C races the clock thread)."""
    if not node.context.ok():
        return
    try:
        publisher.publish(msg)
    except RCLError:
        if node.context.ok():
            raise
