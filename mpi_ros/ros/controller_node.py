"""The node that serves the controller as a whole: /<ns>/controller.

Publishes /<ns>/axis<k>/status, /<ns>/events, /joint_states, /diagnostics and /clock
(controller time, for use_sim_time consumers; ros.clock: false leaves it to another suite of
a cell). Joint states are in SI units under the configured joint names (axes without a joint
block: ``axis<k>`` in counts; docs/joints.md), and the robot description (generated from the
joints, or the user's checked URDF) is latched on /<ns>/robot_description. In a namespace
other than /mpi, joint states go to <ns>/joint_states with names prefixed by the namespace
(RosSettings.joint_states_topic, joint_prefix; docs/cell.md); /diagnostics is shared by
design, its statuses named by namespace. Serves the axis services
(/<ns>/axis<k>/config_get|config_set|position_set, and
fault_config_get|fault_config_set|fault_inject: docs/faults.md) and the control's gates and
I/O (/<ns>/gate_set|gate_get|io_get|io_set), and the motors' secondary feedback inputs that
cams can follow (/<ns>/motor_feedback_secondary_set).

For recordings any tool can make: every command the controller applied goes out on
/<ns>/commands (mpi_ros/msg/Command, with the sample at which it took effect) and the
configuration in effect on /<ns>/configuration (latched), so a bag of the graph made by any
recorder (`ros2 bag record -a`) replays exactly with `mpi-ros replay`. Both are reliable and
transient local: a recorder that joins late still gets the configuration and the last
COMMAND_HISTORY commands.

Stamps (and /clock) are controller time anchored to the wall clock: epoch + sample / rate
(mpi_ros/ros/convert.py).
"""

from __future__ import annotations

from collections.abc import Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.msg import AxisStatus, MotionEvent, SuiteConfiguration
from mpi_ros.msg import Command as CommandMsg
from mpi_ros.srv import (
    AxisConfigGet,
    AxisConfigSet,
    AxisFaultConfigGet,
    AxisFaultConfigSet,
    AxisFaultInject,
    AxisPositionSet,
    GateGet,
    GateSet,
    IoGet,
    IoSet,
    MotorFeedbackSecondarySet,
)

from .. import graph_names as gn
from .. import requests as rq
from ..commands import Command, Operation, Reply, io_space
from ..config import RosSettings
from ..joints import AxisJoint, JointStates
from ..qos import profile
from ..runner import ControllerRunner
from . import convert, snapshots, wire

_LEVELS = {
    MPIState.ERROR: DiagnosticStatus.ERROR,
    MPIState.STOPPING_ERROR: DiagnosticStatus.ERROR,
    MPIState.STOPPED: DiagnosticStatus.WARN,
    MPIState.STOPPING: DiagnosticStatus.WARN,
}


def _level(value: int) -> bytes:
    return bytes([value]) if isinstance(value, int) else value


class ControllerNode(Node):
    """``joints``: every axis as /joint_states names it (SuiteConfig.axis_joints(); default:
    ``axis<k>`` in counts). ``robot_description``: the URDF published latched on
    <ns>/robot_description (none: not published)."""

    def __init__(self, runner: ControllerRunner, settings: RosSettings, joints: Sequence[AxisJoint] | None = None,
                 robot_description: str | None = None, **kwargs):
        super().__init__("controller", namespace=settings.namespace, **kwargs)
        self.runner = runner
        self.settings = settings
        self._snapshots = snapshots.shared(runner)
        self.joints = (convert.default_joints(runner.ctl, settings.joint_prefix) if joints is None
                       else JointStates(joints))
        if not wire.AVAILABLE:  # correct, only slower: say so, or a benchmark would not know why
            self.get_logger().warning("the installed interfaces differ from the layouts mpi_ros/ros/wire.py packs: "
                                      "status topics are built as messages (about 3x the CPU)")
        # the wall-clock time of sample 0 (the suite anchors its controller before building nodes)
        epoch = convert.epoch_of(runner.ctl)
        self.epoch_ns = convert.anchor(runner.ctl) if epoch is None else epoch
        self._service_group = ReentrantCallbackGroup()
        count = len(runner.ctl.axes)
        ns = settings.namespace
        self._pub_axis_status = [self._publisher(AxisStatus, gn.AXIS_STATUS, gn.AXIS_STATUS.name(ns, k))
                                 for k in range(count)]
        for k in range(count):
            self._service(AxisConfigGet, gn.AXIS_CONFIG_GET.name(ns, k),
                          lambda req, resp, k=k: self._on_config_get(k, resp))
            self._service(AxisConfigSet, gn.AXIS_CONFIG_SET.name(ns, k),
                          lambda req, resp, k=k: self._on_config_set(k, req, resp))
            self._service(AxisPositionSet, gn.AXIS_POSITION_SET.name(ns, k),
                          lambda req, resp, k=k: self._on_position_set(k, req, resp))
            self._service(AxisFaultConfigGet, gn.FAULT_CONFIG_GET.name(ns, k),
                          lambda req, resp, k=k: self._on_fault_config_get(k, resp))
            self._service(AxisFaultConfigSet, gn.FAULT_CONFIG_SET.name(ns, k),
                          lambda req, resp, k=k: self._on_fault_config_set(k, req, resp))
            self._service(AxisFaultInject, gn.FAULT_INJECT.name(ns, k),
                          lambda req, resp, k=k: self._on_fault_inject(k, req, resp))
        self._service(GateSet, gn.GATE_SET.name(ns), self._on_gate_set)
        self._service(GateGet, gn.GATE_GET.name(ns), self._on_gate_get)
        self._service(IoSet, gn.IO_SET.name(ns), self._on_io_set)
        self._service(IoGet, gn.IO_GET.name(ns), self._on_io_get)
        self._service(MotorFeedbackSecondarySet, gn.MOTOR_FEEDBACK_SECONDARY_SET.name(ns), self._on_secondary_set)
        self._pub_events = self._publisher(MotionEvent, gn.EVENTS, gn.EVENTS.name(ns))
        self._pub_joints = self._publisher(JointState, gn.JOINT_STATES, gn.joint_states(ns))
        self._pub_diagnostics = self._publisher(DiagnosticArray, gn.DIAGNOSTICS, gn.DIAGNOSTICS.name())
        self._pub_commands = self._publisher(CommandMsg, gn.COMMANDS, gn.COMMANDS.name(ns))
        self._pub_configuration = self._publisher(SuiteConfiguration, gn.CONFIGURATION,
                                                  gn.CONFIGURATION.name(ns))
        if robot_description is not None:  # once, latched: robot_state_publisher's own topic and QoS
            self._pub_description = self._publisher(String, gn.ROBOT_DESCRIPTION,
                                                    gn.ROBOT_DESCRIPTION.name(ns))
            self._pub_description.publish(String(data=robot_description))
        self._applied: list = []  # commands applied since the last change hook, to publish after the lock
        runner.on_command(self._on_command)
        runner.on_change(self._collect_commands)
        runner.add_periodic(settings.status_rate, self._collect_axis_status)
        runner.add_periodic(settings.joint_states_rate, self._collect_joints)
        self.diagnostic_providers: list = []  # add_diagnostic(): more statuses for /diagnostics
        runner.add_periodic(settings.diagnostics_rate, self._collect_diagnostics)
        if settings.clock:
            self._pub_clock = self._publisher(Clock, gn.CLOCK, gn.CLOCK.name())
            runner.add_periodic(settings.clock_rate, self._collect_clock)
        runner.on_event(lambda event: convert.publish(
            self, self._pub_events, convert.motion_event(event, runner.ctl.rate, self.epoch_ns, settings.namespace)))

    def _service(self, srv_type, name, callback):
        self.create_service(srv_type, name, callback, qos_profile=profile(gn.SERVICE_QOS),
                            callback_group=self._service_group)

    def _publisher(self, msg_type, endpoint: gn.Endpoint, name: str):
        return self.create_publisher(msg_type, name, profile(endpoint.qos))

    def publish_configuration(self, config, start_sample: int | None = None) -> SuiteConfiguration:
        """Publish (latched) the configuration the suite runs: ``config`` (a SuiteConfig), the
        sample rate, the sample the suite started at and the epoch of its stamps."""
        start = self.runner.read(lambda ctl: ctl.sample) if start_sample is None else start_sample
        msg = convert.configuration(config, self.runner.ctl.rate, start, self.epoch_ns)
        convert.publish(self, self._pub_configuration, msg)
        return msg

    # -- applied commands -------------------------------------------------------------------
    def _on_command(self, sample, command, reply) -> None:
        # under the runner lock: keep it; it is published once the lock is released
        self._applied.append(convert.command(sample, command, reply, self.runner.ctl.rate, self.epoch_ns,
                                             self.settings.namespace))

    def _collect_commands(self, ctl):
        if not self._applied:
            return None
        messages, self._applied = self._applied, []

        def publish() -> None:
            for msg in messages:
                convert.publish(self, self._pub_commands, msg)

        return publish

    # -- periodic topics ------------------------------------------------------------------
    def _collect_axis_status(self, ctl):
        # packed straight into CDR and published raw where the interfaces allow (wire.py: the
        # same bytes, a third of the work); the snapshots are the supervisors' (snapshots.py)
        encode = wire.axis_status if wire.AVAILABLE else convert.axis_status
        messages = [encode(self._snapshots.axis(ctl, a.number), ctl.rate, self.epoch_ns, self.settings.namespace)
                    for a in ctl.axes]
        return lambda: convert.publish_all(self, zip(self._pub_axis_status, messages, strict=True))

    def _collect_joints(self, ctl):
        if not wire.AVAILABLE:
            msg = convert.joint_state(ctl, self.epoch_ns, self.joints)
        else:  # packed straight into CDR, from the axis topics' snapshots when they were taken now
            values = self.joints.convert(*convert.joint_values(ctl, self._snapshots.taken_axes(ctl)))
            msg = wire.joint_state(ctl.sample, ctl.rate, self.epoch_ns, self.joints.names, *values)
        return lambda: convert.publish(self, self._pub_joints, msg)

    def _collect_clock(self, ctl):
        msg = Clock(clock=convert.stamp(ctl.sample, ctl.rate, self.epoch_ns))
        return lambda: convert.publish(self, self._pub_clock, msg)

    def _collect_diagnostics(self, ctl):
        array = DiagnosticArray()
        array.header.stamp = convert.stamp(ctl.sample, ctl.rate, self.epoch_ns)
        for ms in ctl.supervisors:
            array.status.append(self._supervisor_diagnostic(ms))
        for axis in ctl.axes:
            array.status.append(self._axis_diagnostic(ctl, axis))
        for provider in self.diagnostic_providers:
            array.status.extend(provider(ctl))
        return lambda: convert.publish(self, self._pub_diagnostics, array)

    def add_diagnostic(self, provider) -> None:
        """``provider(controller) -> [DiagnosticStatus, ...]``, called (under the runner lock)
        with every /diagnostics message; keep it cheap (e.g. the cross-check's counts)."""
        self.diagnostic_providers.append(provider)

    def _supervisor_diagnostic(self, ms) -> DiagnosticStatus:
        snap = ms.snapshot()
        status = DiagnosticStatus()
        status.name = convert.frame_id(self.settings.namespace, supervisor=ms.number)
        status.hardware_id = "mpi_ros simulated controller"
        status.level = _level(_LEVELS.get(snap.state, DiagnosticStatus.OK))
        status.message = f"{snap.state.name} ({snap.last_action} by {snap.action_source})"
        status.values = [KeyValue(key=k, value=str(v)) for k, v in (
            ("state", snap.state.name), ("last_action", snap.last_action), ("action_source", snap.action_source),
            ("axes", list(snap.axis_numbers)), ("feedrate", f"{snap.feedrate:.3f}"), ("move_id", snap.move_id),
            ("motion_type", snap.motion_type), ("moves_pending", snap.moves_pending),
            ("latched_events", ",".join(snap.latched_events)))]
        return status

    def _axis_diagnostic(self, ctl, axis) -> DiagnosticStatus:
        snap = ctl.axis_snapshot(axis.number)
        status = DiagnosticStatus()
        status.name = convert.frame_id(self.settings.namespace, axis=axis.number)
        status.hardware_id = "mpi_ros simulated controller"
        if snap.faults:
            level, message = DiagnosticStatus.ERROR, f"fault {', '.join(snap.faults)}: RESET once cleared"
        elif not snap.amp_enabled:
            level, message = DiagnosticStatus.ERROR, "amplifier disabled (ABORT): RESET to enable"
        elif abs(snap.position_error) > axis.in_position.position_coarse:
            level, message = DiagnosticStatus.WARN, f"position error {snap.position_error:.1f} counts"
        else:
            level = _LEVELS.get(snap.state, DiagnosticStatus.OK)
            message = snap.state.name + (", settled" if snap.settled else "")
        status.level = _level(level)
        status.message = message
        status.values = [KeyValue(key=k, value=str(v)) for k, v in (
            ("state", snap.state.name), ("command_position", f"{snap.command_position:.3f}"),
            ("actual_position", f"{snap.actual_position:.3f}"), ("position_error", f"{snap.position_error:.3f}"),
            ("command_velocity", f"{snap.command_velocity:.3f}"), ("done", snap.done), ("settled", snap.settled),
            ("in_fine_position", snap.in_fine_position), ("frame_count", snap.frame_count),
            ("supervisor", snap.supervisor), ("amp_enabled", snap.amp_enabled), ("faults", ",".join(snap.faults)))]
        return status

    # -- services -------------------------------------------------------------------------
    def _on_config_get(self, k: int, response):
        cfg, master = self.runner.read(lambda ctl: (ctl.axes[k].in_position.copy(), ctl.axes[k].master.copy()))
        convert.fill(response.in_position, rq.in_position_to_dict(cfg))
        convert.fill(response.master, rq.axis_master_to_dict(master))
        response.master_correction = master.correction
        return convert.answer(response, Reply.of(Message.MPIMessageOK))

    def _on_config_set(self, k: int, request, response):
        reply, _ = self.runner.submit(Command(Operation.AXIS_CONFIG_SET, axis=k, request={
            "in_position": convert.to_dict(request.in_position), "master": convert.to_dict(request.master),
            "master_correction": request.master_correction}))
        return convert.answer(response, reply)

    def _on_secondary_set(self, request, response):
        reply, _ = self.runner.submit(Command(Operation.SECONDARY_FEEDBACK_SET, request=convert.to_dict(request)))
        return convert.answer(response, reply)

    def _on_position_set(self, k: int, request, response):
        reply, _ = self.runner.submit(Command(Operation.AXIS_POSITION_SET, axis=k,
                                              request={"which": request.which, "value": request.value}))
        return convert.answer(response, reply)

    def _on_fault_config_get(self, k: int, response):
        message, cfg = self.runner.read(lambda ctl: ctl.axis_fault_config_get(k))
        convert.fill(response.config, rq.fault_config_to_dict(cfg))
        return convert.answer(response, Reply.of(message))

    def _on_fault_config_set(self, k: int, request, response):
        reply, _ = self.runner.submit(Command(Operation.AXIS_FAULT_CONFIG_SET, axis=k,
                                              request={"config": convert.to_dict(request.config)}))
        response.detail = reply.detail
        return convert.answer(response, reply)

    def _on_fault_inject(self, k: int, request, response):
        reply, _ = self.runner.submit(Command(Operation.AXIS_FAULT_INJECT, axis=k,
                                              request={"fault": request.fault, "active": request.active}))
        response.detail = reply.detail
        response.faults = list(reply.value or [])
        return convert.answer(response, reply)

    def _on_gate_set(self, request, response):
        request_data = {"gate": request.gate, "closed": request.closed}
        reply, _ = self.runner.submit(Command(Operation.GATE_SET, request=request_data))
        return convert.answer(response, reply)

    def _on_gate_get(self, request, response):
        message, closed = self.runner.read(lambda ctl: ctl.gate_get(request.gate))
        response.closed = closed
        return convert.answer(response, Reply.of(message))

    def _on_io_set(self, request, response):
        reply, _ = self.runner.submit(Command(Operation.IO_SET, request=convert.to_dict(request)))
        return convert.answer(response, reply)

    def _on_io_get(self, request, response):
        try:
            space = io_space(request.space)
        except Refused as exc:
            return convert.answer(response, Reply.of(exc.message))
        message, value = self.runner.read(lambda ctl: ctl.io_get(space, request.index))
        response.value = int(value)
        return convert.answer(response, Reply.of(message))

