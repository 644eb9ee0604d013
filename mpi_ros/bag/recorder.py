"""Record a run: statuses, events, joint states and every command the controller received.

The recorder hooks into the controller runner in-process, so the bag holds exactly what
the controller did, sample for sample: commands with the sample at which they took effect
(``/mpi/commands``, mpi_ros/msg/Command), MotionStatus and AxisStatus at the status rate,
MotionEvent for every event, JointState. It also stores the configuration the run used,
which is what replay builds its fresh controller from, twice: as MCAP metadata ``mpi_ros``
and as the message a suite latches on ``/mpi/configuration`` (mpi_ros/msg/SuiteConfiguration),
so the bag looks like a recording of the graph too. (A bag of the graph made by any other
recorder has the commands and the configuration from the suite's topics, and replays alike.)

Time: the epoch is the wall-clock time of sample 0; every stamp and every log time is
``epoch + sample / rate``. Recording a suite, the epoch is the suite's (its stamps on the
graph are the same); a scenario uses a fixed epoch, so that recording it again gives the
same bytes.
"""

from __future__ import annotations

import time
from pathlib import Path

import yaml

from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.control import Controller

from .. import __version__
from .. import graph_names as gn
from ..commands import Command as ControllerCommand
from ..commands import Reply
from ..config import SuiteConfig
from ..joints import JointStates
from ..ros import convert
from ..runner import AtSample, ControllerRunner, Output
from .writer import BagWriter, TopicQos

COMMANDS_TOPIC = gn.COMMANDS.name()  # with the default namespace; in general commands_topic(namespace)
METADATA_NAME = "mpi_ros"
COMMAND_TYPE = gn.COMMANDS.type
CONFIGURATION_TYPE = gn.CONFIGURATION.type


def commands_topic(namespace: str) -> str:
    return gn.COMMANDS.name(namespace)


def configuration_topic(namespace: str) -> str:
    return gn.CONFIGURATION.name(namespace)


def offered(qos: gn.Qos) -> TopicQos:
    """The QoS a bag says a topic was offered with: the suite's (mpi_ros/graph_names.py)."""
    return TopicQos(reliable=qos.reliability is gn.Reliability.RELIABLE, depth=qos.depth,
                    transient_local=qos.durability is gn.Durability.TRANSIENT_LOCAL)


class Recorder:
    def __init__(self, runner: ControllerRunner, directory: str | Path, config: SuiteConfig,
                 epoch_ns: int | None = None, compress: bool = True):
        self.runner = runner
        ctl = runner.ctl
        self.rate = ctl.rate
        ns = config.ros.namespace.rstrip("/")
        self.ns = ns
        self.namespace = config.ros.namespace  # the headers' frame ids name their sources in it
        if epoch_ns is None:  # the suite's epoch when recording a suite (its stamps on the graph)
            epoch_ns = convert.epoch_of(ctl)
        if epoch_ns is None:
            epoch_ns = time.time_ns() - convert.sample_ns(ctl.sample, self.rate)
        self.epoch = int(epoch_ns)
        self.writer = BagWriter(directory, compress=compress)
        self.commands_topic = commands_topic(ns)
        self.events_topic = gn.EVENTS.name(ns)
        self._add(self.commands_topic, gn.COMMANDS)
        self._add(configuration_topic(ns), gn.CONFIGURATION)
        self._add(self.events_topic, gn.EVENTS)
        for spec in config.supervisors:
            self._add(gn.MOTION_STATUS.name(ns, spec.number), gn.MOTION_STATUS)
        for axis in ctl.axes:
            self._add(gn.AXIS_STATUS.name(ns, axis.number), gn.AXIS_STATUS)
        self.joint_states_topic, self.joints = gn.joint_states(ns), JointStates(config.axis_joints())
        self._add(self.joint_states_topic, gn.JOINT_STATES)
        self.writer.add_metadata(METADATA_NAME, {
            "config": yaml.safe_dump(config.raw, sort_keys=False),
            "sample_rate": repr(self.rate),
            "start_sample": str(ctl.sample),
            "epoch_ns": str(self.epoch),
            "stamp_epoch_ns": str(self.epoch),  # stamps are epoch + sample / rate (replay compares them)
            "namespace": config.ros.namespace,
            "mpi_ros_version": __version__,
        })
        self.writer.write(configuration_topic(ns), convert.configuration(config, self.rate, ctl.sample, self.epoch),
                          self.log_time(ctl.sample))
        # statuses: from the snapshots of their sample, which the runner may step past (runner.add_status)
        runner.add_status(config.ros.status_rate, self._collect_status)
        runner.add_status(config.ros.joint_states_rate, self._collect_joints)
        runner.on_event(self._on_event)
        runner.on_command(self._on_command)

    def _add(self, topic: str, endpoint: gn.Endpoint) -> None:
        self.writer.add_topic(topic, endpoint.type, offered(endpoint.qos))

    def log_time(self, sample: int) -> int:
        return convert.stamp_ns(sample, self.rate, self.epoch)

    # -- hooks (periodic collection under the runner lock, writing after it) --------------------------
    def _collect_status(self, ctl: Controller, at: AtSample) -> Output:
        t = self.log_time(at.sample)
        motions, axes = at.taken()  # every axis read once for both kinds of topic
        messages: list[tuple[str, object]] = [
            (gn.MOTION_STATUS.name(self.ns, number), convert.motion_status(snap, ctl.rate, self.epoch, self.namespace))
            for number, snap in motions.items()
        ]
        messages += [
            (gn.AXIS_STATUS.name(self.ns, snap.number), convert.axis_status(snap, ctl.rate, self.epoch, self.namespace))
            for snap in axes
        ]

        def write() -> None:
            for topic, msg in messages:
                self.writer.write(topic, msg, t)

        return write

    def _collect_joints(self, ctl: Controller, at: AtSample) -> Output:
        msg = convert.joint_state(ctl, self.epoch, self.joints, at.sample, {s.number: s for s in at.taken()[1]})
        t = self.log_time(at.sample)
        return lambda: self.writer.write(self.joint_states_topic, msg, t)

    def _on_event(self, event) -> None:
        self.writer.write(self.events_topic, convert.motion_event(event, self.rate, self.epoch, self.namespace),
                          self.log_time(event.sample))

    def _on_command(self, sample: int, command: ControllerCommand, reply: Reply) -> None:
        msg = convert.command(sample, command, reply, self.rate, self.epoch, self.namespace)
        self.writer.write(self.commands_topic, msg, self.log_time(sample))

    def close(self) -> None:
        self.writer.close()


# Events that are not the controller's own (they depend on optional monitors), left out of
# replay comparisons.
NOT_REPLAYED = {MPIEventType.CROSSCHECK.name}

