"""Conversions at the ROS edge: controller snapshots -> messages (messages <-> plain dicts: mpi_ros/message_dicts.py).

Time: every stamp is controller time anchored to the wall clock, ``epoch + sample / rate``,
where the epoch is the wall-clock time of sample 0 (ns since the Unix epoch). The suite
anchors its controller when it is built (:func:`anchor`), so a stamp is "now" for RViz, tf,
Foxglove and every tool that does not use sim time, /clock carries the same time, and the
epoch is published (latched, <ns>/configuration) and recorded in bags so replay reproduces
every stamp. Functions that stamp take ``epoch_ns``; left out, they use the epoch of the
suite anchored last in this process (one suite per process is the rule; pass it explicitly
where two may coexist).

Headers: the statuses, events and commands carry a std_msgs/Header, its stamp as above and its
frame_id naming the message's source within the suite, the namespace first without its
leading slash, as /diagnostics names them (:func:`frame_id`: ``mpi/axis0``, ``mpi/ms1``,
``mpi/controller``; ``cell_a/axis0`` in /cell_a). They are names, not tf frames.
"""

from __future__ import annotations

import math
import time
import weakref
from collections.abc import Iterable, Mapping, Sequence
from operator import attrgetter
from typing import Any

from builtin_interfaces.msg import Time
from rclpy.exceptions import InvalidHandle
from sensor_msgs.msg import JointState
from std_msgs.msg import Header

from mpi_ros import graph_names
from mpi_ros.config import DEFAULT_NAMESPACE
from mpi_ros.joints import AxisJoint, JointStates
from mpi_ros.message_dicts import fill as fill  # the nodes' message <-> dict edge
from mpi_ros.message_dicts import to_dict as to_dict
from mpi_ros.mpi.base.events import Event
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
from mpi_ros.msg import AxisStatus, MotionEvent, MotionStatus
from mpi_ros.msg import Command as CommandMsg

from . import rcl


def answer(response, reply):
    """Put a controller reply's outcome (the message's name and code, and why in words) into a
    service response: every response of the suite's services has the three fields."""
    response.message = reply.message.name
    response.code = reply.message.code
    response.detail = reply.detail
    return response


def event_mask_answer(response, message, mask):
    """An EventNotifyGet response (mpiMotionEventNotifyGet and mpiAxisEventNotifyGet alike)."""
    response.event_types = mask.names()
    response.message = message.name
    response.code = message.code
    response.detail = "" if message.ok else f"no event mask: {message.name}"
    return response


_default_epoch_ns = 0  # the epoch of the suite anchored last in this process
_EPOCHS: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()


def anchor(controller, epoch_ns: int | None = None) -> int:
    """Anchor ``controller``'s time to the wall clock: sample k is stamped ``epoch + k / rate``.

    ``epoch_ns`` defaults to now minus the controller's current time (so its current sample
    is stamped now). The epoch also becomes this process's default for :func:`stamp`."""
    global _default_epoch_ns
    if epoch_ns is None:
        epoch_ns = time.time_ns() - sample_ns(controller.sample, controller.rate)
    _EPOCHS[controller] = int(epoch_ns)
    _default_epoch_ns = int(epoch_ns)
    return int(epoch_ns)


def epoch_of(controller) -> int | None:
    """The epoch ``controller`` was anchored with (None if it never was)."""
    return _EPOCHS.get(controller)


def default_epoch() -> int:
    """The epoch stamps use when none is given: the suite anchored last (0 before any)."""
    return _default_epoch_ns


def sample_ns(sample: int, rate: float) -> int:
    """Controller time of a sample since sample 0, in ns."""
    return round(sample * 1e9 / rate)


def stamp_ns(sample: int, rate: float, epoch_ns: int | None = None) -> int:
    """Wall-anchored time of a sample in ns since the Unix epoch."""
    return (_default_epoch_ns if epoch_ns is None else int(epoch_ns)) + sample_ns(sample, rate)


def stamp(sample: int, rate: float, epoch_ns: int | None = None) -> Time:
    """The stamp of a sample: ``epoch + sample / rate`` (see the module's docstring)."""
    nanoseconds = stamp_ns(sample, rate, epoch_ns)
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def time_ns(value: Time) -> int:
    """A builtin_interfaces/Time in ns."""
    return int(value.sec) * 1_000_000_000 + int(value.nanosec)


def frame_id(namespace: str, supervisor: int = -1, axis: int = -1) -> str:
    """The source a message's header names: the most specific object given, the axis
    (``mpi/axis<k>``) if ``axis`` >= 0, else the supervisor (``mpi/ms<n>``) if ``supervisor``
    >= 0, else the controller (``mpi/controller``); ``mpi`` being the namespace without its
    leading slash (``plant/cell_a/axis0`` in /plant/cell_a), as /diagnostics names them."""
    if axis >= 0:
        return graph_names.axis_prefix(namespace, axis).lstrip("/")
    if supervisor >= 0:
        return graph_names.supervisor_node(namespace, supervisor).lstrip("/")
    return f"{graph_names.ns(namespace)}/{graph_names.CONTROLLER_NODE}".lstrip("/")


def header(sample: int, rate: float, epoch_ns: int | None, frame: str) -> Header:
    """A std_msgs/Header: the stamp of ``sample`` and the source ``frame`` (:func:`frame_id`)."""
    return Header(stamp=stamp(sample, rate, epoch_ns), frame_id=frame)


def _finite(x: float) -> float:
    return float(x) if math.isfinite(x) else 0.0


def axis_status(snap: AxisSnapshot, rate: float, epoch_ns: int | None = None,
                namespace: str = DEFAULT_NAMESPACE) -> AxisStatus:
    msg = AxisStatus()
    msg.header = header(snap.sample, rate, epoch_ns, frame_id(namespace, axis=snap.number))
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
    msg.feedforward = _finite(snap.feedforward)
    msg.faults = list(snap.faults)
    return msg


def motion_status(snap: MotionSnapshot, rate: float, epoch_ns: int | None = None,
                  namespace: str = DEFAULT_NAMESPACE) -> MotionStatus:
    msg = MotionStatus()
    msg.header = header(snap.sample, rate, epoch_ns, frame_id(namespace, supervisor=snap.number))
    msg.sample = snap.sample
    msg.number = snap.number
    msg.state = int(snap.state)
    msg.state_name = snap.state.name
    msg.axis_numbers = list(snap.axis_numbers)
    msg.axes = [axis_status(a, rate, epoch_ns, namespace) for a in snap.axes]
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


def joint_values(ctl, snapshots: Mapping[int, AxisSnapshot] | None = None
                 ) -> tuple[list[float], list[float], list[float]]:
    """Every axis' (actual position, actual velocity, servo effort): what /joint_states
    carries (the effort: the simulated servo's, plant.servo_effort). ``snapshots``: every
    axis' AxisSnapshot at the sample published, if they were taken (runner.AtSample)."""
    if snapshots is not None:
        return joint_readings([snapshots[n] for n in range(len(ctl.axes))])
    position, velocity, effort = ctl.joint_values()
    return _joint_floats(position, velocity, effort)


_JOINT_READING = attrgetter("actual_position", "actual_velocity", "servo_effort")


def joint_readings(snaps: Sequence[AxisSnapshot]) -> tuple[list[float], list[float], list[float]]:
    """:func:`joint_values` of these axes' snapshots."""
    if not snaps:
        return [], [], []
    position, velocity, effort = zip(*map(_JOINT_READING, snaps), strict=True)
    return _joint_floats(position, velocity, effort)


def _joint_floats(position: Sequence[float], velocity: Sequence[float], effort: Sequence[float]
                  ) -> tuple[list[float], list[float], list[float]]:
    # the sum is finite only if every effort is: one check for the usual case
    efforts = list(map(float, effort)) if math.isfinite(sum(effort)) else [_finite(e) for e in effort]
    return list(map(float, position)), list(map(float, velocity)), efforts


def joint_names(ctl, prefix: str = "") -> list[str]:
    """``<prefix>axis<k>``: the names of axes without a joint block; the prefix is
    RosSettings.joint_prefix (the namespace of a suite in a cell, none for the default one)."""
    return [f"{prefix}axis{a.number}" for a in ctl.axes]


def default_joints(ctl, prefix: str = "") -> JointStates:
    """Every axis as ``<prefix>axis<k>`` in counts: a suite whose axes have no joint block."""
    return JointStates([AxisJoint(a.number, name, None) for a, name in zip(ctl.axes, joint_names(ctl, prefix),
                                                                           strict=True)])


def joint_state(ctl, epoch_ns: int | None = None, joints: JointStates | None = None, sample: int | None = None,
                snapshots: Mapping[int, AxisSnapshot] | None = None) -> JointState:
    """Every axis as a joint (``joints``: SuiteConfig.axis_joints() as JointStates; default:
    ``axis<k>`` in counts): actual position (m or rad; counts without a joint), actual velocity
    (per s) and the servo's control effort (per s^2: the acceleration the servo demands, see
    plant.servo_effort). At the controller's sample, or at ``sample`` from every axis'
    ``snapshots`` there (a status stepped past: runner.AtSample)."""
    joints = default_joints(ctl) if joints is None else joints
    msg = JointState()
    msg.header.stamp = stamp(ctl.sample if sample is None else sample, ctl.rate, epoch_ns)
    msg.name = list(joints.names)
    msg.position, msg.velocity, msg.effort = joints.convert(*joint_values(ctl, snapshots))
    return msg


def command(sample: int, command, reply, rate: float, epoch_ns: int | None = None,
            namespace: str = DEFAULT_NAMESPACE) -> CommandMsg:
    """An applied command (mpi_ros.commands.Command) and the controller's reply, with the
    sample at which it took effect, as published on <ns>/commands and recorded for replay;
    its frame_id names the object it addressed (:func:`frame_id`)."""
    msg = CommandMsg()
    msg.header = header(sample, rate, epoch_ns, frame_id(namespace, command.supervisor, command.axis))
    msg.sample = int(sample)
    msg.operation = command.operation
    msg.supervisor = int(command.supervisor)
    msg.axis = int(command.axis)
    msg.request = command.to_json()
    msg.message = reply.message.name
    return msg


def configuration(config, rate: float, start_sample: int, epoch_ns: int):
    """The latched <ns>/configuration message: what a replay builds its controller from."""
    import yaml

    from mpi_ros import __version__
    from mpi_ros.msg import SuiteConfiguration

    msg = SuiteConfiguration()
    msg.stamp = stamp(start_sample, rate, epoch_ns)
    msg.config = yaml.safe_dump(config.raw, sort_keys=False)
    msg.source = str(config.source)
    msg.sample_rate = float(rate)
    msg.start_sample = int(start_sample)
    msg.epoch_ns = int(epoch_ns)
    msg.ros_namespace = config.ros.namespace
    msg.mpi_ros_version = __version__
    return msg


def motion_event(event: Event, rate: float, epoch_ns: int | None = None,
                 namespace: str = DEFAULT_NAMESPACE) -> MotionEvent:
    """An event; its frame_id names its source, the most specific object it names (:func:`frame_id`)."""
    msg = MotionEvent()
    msg.header = header(event.sample, rate, epoch_ns, frame_id(namespace, event.supervisor, event.axis))
    msg.sample = event.sample
    msg.type = event.type_name
    msg.supervisor = event.supervisor
    msg.axis = event.axis
    msg.move_id = event.move_id
    msg.element_id = event.element_id
    msg.detail = event.detail
    return msg


def publish(node, publisher, msg) -> None:
    """Publish unless the node's context has shut down (a Ctrl-C races the clock thread).
    ``msg``: a message of the publisher's type, or its CDR (bytes, published raw)."""
    publish_all(node, ((publisher, msg),))


def publish_all(node, sends: Iterable[tuple[Any, Any]]) -> None:
    """``publish`` for each (publisher, message) of one node. The context is looked at only
    when publishing fails: once it has shut down, rcl refuses to publish ("publisher's context
    is invalid") or the publisher is gone with its node, and what is left is not published."""
    try:
        for publisher, msg in sends:
            publisher.publish(msg)
    except (rcl.RCLError, InvalidHandle):
        if node.context.ok():
            raise
