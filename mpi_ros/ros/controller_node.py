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

import threading
from collections.abc import Sequence
from pathlib import Path

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.publisher import Publisher
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.params import AxisMaster, check_settling_reachable, first_refusal
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.msg import AxisStatus, MotionEvent, SuiteConfiguration
from mpi_ros.msg import Command as CommandMsg
from mpi_ros.srv import (
    AmpEnableSet,
    AxisConfigGet,
    AxisConfigSet,
    AxisCreate,
    AxisDelete,
    AxisFaultConfigGet,
    AxisFaultConfigSet,
    AxisFaultInject,
    AxisFlashConfigGet,
    AxisFlashConfigSet,
    AxisPositionSet,
    AxisValidate,
    EventNotifyGet,
    EventNotifySet,
    EventReset,
    GateGet,
    GateSet,
    IoGet,
    IoSet,
    MotionFlashConfigGet,
    MotionFlashConfigSet,
    MotorFeedbackSecondarySet,
)

from .. import flash as flash_file
from .. import graph_names as gn
from .. import requests as rq
from ..commands import Command, Operation, Reply, io_space
from ..config import RosSettings
from ..joints import AxisJoint, JointStates
from ..qos import profile
from ..runner import AtSample, ControllerRunner
from . import convert, wire

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
                 robot_description: str | None = None, flash: Path | None = None,
                 packer: wire.Packer | None = None, **kwargs):
        super().__init__("controller", namespace=settings.namespace, **kwargs)
        self.runner = runner
        self.settings = settings
        # every axis' joint; /joint_states names those of the valid Axis objects (_joints_of)
        self._axis_joints = list(joints) if joints is not None else [
            AxisJoint(a.number, name, None) for a, name in zip(
                runner.ctl.axes, convert.joint_names(runner.ctl, settings.joint_prefix), strict=True)]
        self.joints = JointStates(self._axis_joints)
        self._joint_rows: tuple[int, ...] = tuple(range(len(self._axis_joints)))
        if not wire.AVAILABLE:  # correct, only slower: say so, or a benchmark would not know why
            self.get_logger().warning("the installed interfaces differ from the layouts mpi_ros/ros/wire.py packs: "
                                      "status topics are built as messages (about 3x the CPU)")
        # the wall-clock time of sample 0 (the suite anchors its controller before building nodes)
        epoch = convert.epoch_of(runner.ctl)
        self.epoch_ns = convert.anchor(runner.ctl) if epoch is None else epoch
        # the supervisors' statuses hold the same axis snapshots: one Packer for the suite packs
        # each axis once a sample (wire.Packer)
        self._packer = packer or wire.Packer(runner.ctl.rate, self.epoch_ns, settings.namespace)
        self._service_group = ReentrantCallbackGroup()
        ns = settings.namespace
        self._ns = ns
        self._flash = flash_file.Flash(flash) if flash is not None else None
        # what the next start loads where the flash holds nothing: the configuration, as it started
        self._started = runner.read(_started_configs)
        # Each valid Axis object's status publisher and services, made and destroyed as axes are
        # created and deleted (_sync_axes). Changed only by outputs of the runner, which run in
        # order with the publishing: a deleted axis' publisher goes after its last status.
        self._pub_axis_status: dict[int, Publisher] = {}
        self._axis_endpoints: dict[int, list] = {}
        self._axes_changed = False  # an axis was created or deleted since the last change hook
        self._axes_synced = threading.Condition()
        self._sync_axes(tuple(runner.ctl.valid_axes()))
        self._service(AxisCreate, gn.AXIS_CREATE.name(ns), lambda req, resp: self._on_axis_object(
            Command(Operation.AXIS_CREATE, axis=req.number), True, resp))
        self._service(AxisDelete, gn.AXIS_DELETE.name(ns), lambda req, resp: self._on_axis_object(
            Command(Operation.AXIS_DELETE, axis=req.number), False, resp))
        self._service(AxisValidate, gn.AXIS_VALIDATE.name(ns), self._on_axis_validate)
        for n in self._started["supervisors"]:
            self._service(MotionFlashConfigGet, gn.MOTION_FLASH_CONFIG_GET.name(ns, n),
                          lambda req, resp, n=n: self._on_motion_flash_get(n, resp))
            self._service(MotionFlashConfigSet, gn.MOTION_FLASH_CONFIG_SET.name(ns, n),
                          lambda req, resp, n=n: self._on_motion_flash_set(n, req, resp))
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
        runner.on_change(self._collect_axes)
        runner.add_status(settings.status_rate, self._collect_axis_status)
        runner.add_status(settings.joint_states_rate, self._collect_joints)
        self.diagnostic_providers: list = []  # add_diagnostic(): more statuses for /diagnostics
        runner.add_periodic(settings.diagnostics_rate, self._collect_diagnostics)
        if settings.clock:
            self._pub_clock = self._publisher(Clock, gn.CLOCK, gn.CLOCK.name())
            runner.add_status(settings.clock_rate, self._collect_clock, snapshots=False)
        runner.on_event(lambda event: convert.publish(
            self, self._pub_events, convert.motion_event(event, runner.ctl.rate, self.epoch_ns, settings.namespace)))

    def _service(self, srv_type, name, callback):
        return self.create_service(srv_type, name, callback, qos_profile=profile(gn.SERVICE_QOS),
                                   callback_group=self._service_group)

    def _publisher(self, msg_type, endpoint: gn.Endpoint, name: str):
        return self.create_publisher(msg_type, name, profile(endpoint.qos))

    # -- axis objects (mpiAxisCreate / mpiAxisDelete: docs/decisions.md, "Axis objects") ----
    def _axis_services(self, k: int) -> list:
        """Axis ``k``'s services: (type, endpoint, callback(request, response)) each."""
        services = [
            (AxisConfigGet, gn.AXIS_CONFIG_GET, lambda req, resp: self._on_config_get(k, resp)),
            (AxisConfigSet, gn.AXIS_CONFIG_SET, lambda req, resp: self._on_config_set(k, req, resp)),
            (AxisPositionSet, gn.AXIS_POSITION_SET, lambda req, resp: self._on_position_set(k, req, resp)),
            (AxisFaultConfigGet, gn.FAULT_CONFIG_GET, lambda req, resp: self._on_fault_config_get(k, resp)),
            (AxisFaultConfigSet, gn.FAULT_CONFIG_SET, lambda req, resp: self._on_fault_config_set(k, req, resp)),
            (AxisFaultInject, gn.FAULT_INJECT, lambda req, resp: self._on_fault_inject(k, req, resp)),
            (AxisFlashConfigGet, gn.AXIS_FLASH_CONFIG_GET, lambda req, resp: self._on_axis_flash_get(k, resp)),
            (AxisFlashConfigSet, gn.AXIS_FLASH_CONFIG_SET, lambda req, resp: self._on_axis_flash_set(k, req, resp)),
            # amplifier enable and the axis' events (MPI 002, "Event Methods"): the motion's srv types
            (AmpEnableSet, gn.AMP_ENABLE_SET, lambda req, resp: self._on_amp_enable(k, req, resp)),
            (EventNotifyGet, gn.AXIS_EVENT_NOTIFY_GET, lambda req, resp: convert.event_mask_answer(
                resp, *self.runner.read(lambda ctl: ctl.axis_event_notify_get(k)))),
            (EventNotifySet, gn.AXIS_EVENT_NOTIFY_SET, lambda req, resp: convert.answer(
                resp, self._submit_axis(Operation.AXIS_EVENT_NOTIFY_SET, k, {"event_types": list(req.event_types)}))),
            (EventReset, gn.AXIS_EVENT_RESET, lambda req, resp: self._on_event_reset(k, req, resp)),
        ]
        return [self._service(srv_type, endpoint.name(self._ns, k), callback)
                for srv_type, endpoint, callback in services]

    def _sync_axes(self, valid: tuple[int, ...]) -> None:
        """Give each axis in ``valid`` its endpoints and take them from every other one."""
        with self._axes_synced:
            for k in [k for k in self._axis_endpoints if k not in valid]:
                self.destroy_publisher(self._pub_axis_status.pop(k))
                for service in self._axis_endpoints.pop(k):
                    self.destroy_service(service)
            for k in valid:
                if k not in self._axis_endpoints:
                    status = gn.AXIS_STATUS
                    self._pub_axis_status[k] = self._publisher(AxisStatus, status, status.name(self._ns, k))
                    self._axis_endpoints[k] = self._axis_services(k)
            self._axes_synced.notify_all()

    def _collect_axes(self, ctl):
        if not self._axes_changed:
            return None
        self._axes_changed = False
        valid = tuple(ctl.valid_axes())
        return lambda: self._sync_axes(valid)

    def _on_axis_object(self, command: Command, valid: bool, response):
        """/<ns>/axis_create and axis_delete: answered once the axis' endpoints are there (or gone)."""
        reply, _ = self.runner.submit(command)
        if reply.message.ok:
            with self._axes_synced:
                if not self._axes_synced.wait_for(lambda: (command.axis in self._axis_endpoints) == valid, 5.0):
                    self.get_logger().error(f"axis{command.axis}: its endpoints did not follow {command.operation}")
        return convert.answer(response, reply)

    def _on_axis_validate(self, request, response):
        outcome = self.runner.read(lambda ctl: ctl.axis_validate(request.number))
        return convert.answer(response, Reply(outcome))

    def _submit_axis(self, operation: str, k: int, request: dict) -> Reply:
        reply, _ = self.runner.submit(Command(operation, axis=k, request=request))
        return reply

    def _on_amp_enable(self, k: int, request, response):
        reply = self._submit_axis(Operation.AXIS_AMP_ENABLE_SET, k, {"enable": request.enable})
        response.enabled = bool(reply.value)
        return convert.answer(response, reply)

    def _on_event_reset(self, k: int, request, response):
        reply = self._submit_axis(Operation.AXIS_EVENT_RESET, k, {"event_types": list(request.event_types)})
        response.latched_event_types = list(reply.value or [])
        return convert.answer(response, reply)

    def publish_configuration(self, config, start_sample: int | None = None) -> SuiteConfiguration:
        """Publish (latched) the configuration the suite runs: ``config`` (a SuiteConfig), the
        sample rate, the sample the suite started at and the epoch of its stamps."""
        start = self.runner.read(lambda ctl: ctl.sample) if start_sample is None else start_sample
        msg = convert.configuration(config, self.runner.ctl.rate, start, self.epoch_ns)
        convert.publish(self, self._pub_configuration, msg)
        return msg

    # -- applied commands -------------------------------------------------------------------
    def _on_command(self, sample, command, reply) -> None:
        if command.operation in (Operation.AXIS_CREATE, Operation.AXIS_DELETE) and reply.message.ok:
            self._axes_changed = True
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
    # Status topics: the runner calls these with the snapshots of their sample (runner.add_status),
    # taken once for every node, so the axis topics and the supervisors' statuses show the same
    # reading of an axis; the controller may be past that sample: they read ``at``.
    def _collect_axis_status(self, ctl, at: AtSample):
        # packed straight into CDR and published raw where the interfaces allow (wire.py: the
        # same bytes, a third of the work)
        encode = (self._packer.axis_status if wire.AVAILABLE else
                  lambda snap: convert.axis_status(snap, ctl.rate, self.epoch_ns, self.settings.namespace))
        publishers = self._pub_axis_status
        sends = [(publishers[snap.number], encode(snap))
                 for snap in at.taken()[1] if ctl.axes[snap.number].valid and snap.number in publishers]
        return lambda: convert.publish_all(self, sends)

    def _collect_joints(self, ctl, at: AtSample):
        joints, rows = self._joints_of(ctl)  # the valid axes change by commands only, never within a stretch
        snaps = at.taken()[1]  # every axis', by number
        position, velocity, effort = joints.convert(*convert.joint_readings([snaps[row] for row in rows]))
        if wire.AVAILABLE:  # packed straight into CDR
            msg = wire.joint_state(at.sample, ctl.rate, self.epoch_ns, joints.names, position, velocity, effort)
        else:
            msg = JointState(name=list(joints.names), position=position, velocity=velocity, effort=effort)
            msg.header.stamp = convert.stamp(at.sample, ctl.rate, self.epoch_ns)
        return lambda: convert.publish(self, self._pub_joints, msg)

    def _joints_of(self, ctl) -> tuple[JointStates, tuple[int, ...]]:
        """The joints of the valid Axis objects and their rows among all axes (rebuilt when
        an axis is created or deleted)."""
        rows = tuple(ctl.valid_axes())
        if rows != self._joint_rows:
            self.joints = JointStates([self._axis_joints[row] for row in rows])
            self._joint_rows = rows
        return self.joints, rows

    def _collect_clock(self, ctl, at: AtSample):
        msg = (wire.clock(at.sample, ctl.rate, self.epoch_ns) if wire.AVAILABLE  # packed straight into CDR
               else Clock(clock=convert.stamp(at.sample, ctl.rate, self.epoch_ns)))
        return lambda: convert.publish(self, self._pub_clock, msg)

    def _collect_diagnostics(self, ctl):
        array = DiagnosticArray()
        array.header.stamp = convert.stamp(ctl.sample, ctl.rate, self.epoch_ns)
        for ms in ctl.supervisors:
            array.status.append(self._supervisor_diagnostic(ms))
        for axis in ctl.axes:
            if axis.valid:
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
        elif not snap.amp_enabled and not axis.enabled:  # the host's choice (amp_enable_set), not a failure
            level, message = DiagnosticStatus.WARN, "amplifier disabled by amp_enable_set: enable it to move"
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
        cfg, master = self.runner.read(lambda ctl: (ctl.axes[k].in_position.copy(), ctl.axis_master_get(k)))
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
        return convert.answer(response, reply)

    def _on_fault_inject(self, k: int, request, response):
        reply, _ = self.runner.submit(Command(Operation.AXIS_FAULT_INJECT, axis=k,
                                              request={"fault": request.fault, "active": request.active}))
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

    # -- flash (mpi_ros/flash.py; docs/configuration.md, "Flash") ------------------------------
    def _flash_entry(self, kind: str, number: int) -> tuple[Reply, dict | None]:
        if self._flash is None:
            return Reply.of(Message.MPIMessageUNSUPPORTED, "the suite runs without a configuration file: "
                            "its flash is a file beside one"), None
        outcome, entry = self._flash.get(kind, number)
        return Reply(outcome), (self._started[kind][number] if entry is None else entry) if outcome.ok else None

    def _flash_write(self, kind: str, number: int, entry: dict) -> Reply:
        if self._flash is None:
            return self._flash_entry(kind, number)[0]
        return Reply(self._flash.set(kind, number, entry))

    def _on_motion_flash_get(self, n: int, response):
        """mpiMotionFlashConfigGet (MPI 000)."""
        reply, entry = self._flash_entry("supervisors", n)
        if entry is not None:
            convert.fill(response.config, rq.motion_config_to_dict(rq.motion_config(entry)))
        return convert.answer(response, reply)

    def _on_motion_flash_set(self, n: int, request, response):
        """mpiMotionFlashConfigSet (MPI 000): checked by MotionConfig's validator, then written."""
        try:
            config = rq.motion_config(convert.to_dict(request.config))
        except Refused as exc:
            config, reply = None, Reply.of(exc.message, exc.detail)
        if config is not None:
            verdict = config.validate()
            reply = (Reply(verdict) if not verdict.ok
                     else self._flash_write("supervisors", n, flash_file.motion_entry(config)))
        return convert.answer(response, reply)

    def _on_axis_flash_get(self, k: int, response):
        """mpiAxisFlashConfigGet (MPI 002)."""
        reply, entry = self._flash_entry("axes", k)
        if entry is not None:
            master = dict(entry["master"])
            correction = master.pop("correction")
            convert.fill(response.in_position, rq.in_position_to_dict(rq.in_position(entry["in_position"])))
            convert.fill(response.master, rq.axis_master_to_dict(rq.axis_master(master, correction, AxisMaster())))
            response.master_correction = correction
        return convert.answer(response, reply)

    def _on_axis_flash_set(self, k: int, request, response):
        """mpiAxisFlashConfigSet (MPI 002): checked as mpiAxisConfigSet checks, then written."""
        try:
            in_position = rq.in_position(convert.to_dict(request.in_position))
            master = rq.axis_master(convert.to_dict(request.master), request.master_correction, AxisMaster())
            verdict = self.runner.read(lambda ctl: first_refusal((
                in_position.validate(), check_settling_reachable(in_position, ctl.axes[k].plant.config),
                ctl.axis_master_check(k, master).prefixed("master."))))
            reply = (Reply(verdict) if not verdict.ok
                     else self._flash_write("axes", k, flash_file.axis_entry(in_position, master)))
        except Refused as exc:
            reply = Reply.of(exc.message, exc.detail)
        return convert.answer(response, reply)


def _started_configs(ctl) -> dict[str, dict[int, dict]]:
    """Every supervisor's and axis' configuration now, in the flash's words."""
    return {"supervisors": {ms.number: flash_file.motion_entry(ms.config) for ms in ctl.supervisors},
            "axes": {a.number: flash_file.axis_entry(a.in_position, a.master) for a in ctl.axes}}
