"""Record a run: statuses, events, joint states and every command the controller received.

The recorder hooks into the controller runner in-process, so the bag holds exactly what
the controller did, sample for sample: commands with the sample at which they took effect
(``/mpi/commands``, mpi_ros/msg/Command), MotionStatus and AxisStatus at the status rate,
MotionEvent for every event, JointState. It also stores the configuration the run used
(MCAP metadata ``mpi_ros``), which is what replay builds its fresh controller from.
Log times are controller time after a fixed epoch (the wall time of sample 0), so a bag
plays back with the controller's timing.
"""

from __future__ import annotations

import time
from pathlib import Path

import yaml

from mpi_ros.msg import Command

from .. import __version__
from ..commands import Command as ControllerCommand
from ..commands import Reply
from ..config import SuiteConfig
from ..mpi.events import MPIEventType
from ..runner import ControllerRunner
from ..ros import convert
from .writer import BagWriter, TopicQos

COMMANDS_TOPIC = "/mpi/commands"
METADATA_NAME = "mpi_ros"


class Recorder:
    def __init__(self, runner: ControllerRunner, directory: str | Path, config: SuiteConfig,
                 epoch_ns: int | None = None, compress: bool = True):
        self.runner = runner
        ctl = runner.ctl
        self.rate = ctl.rate
        ns = config.ros.namespace.rstrip("/")
        self.ns = ns
        self.epoch = time.time_ns() - round(ctl.sample * 1e9 / self.rate) if epoch_ns is None else epoch_ns
        self.writer = BagWriter(directory, compress=compress)
        status, deep = TopicQos(depth=10), TopicQos(depth=1000)
        self.writer.add_topic(COMMANDS_TOPIC, "mpi_ros/msg/Command", deep)
        self.writer.add_topic(f"{ns}/events", "mpi_ros/msg/MotionEvent", deep)
        for spec in config.supervisors:
            self.writer.add_topic(f"{ns}/ms{spec.number}/status", "mpi_ros/msg/MotionStatus", status)
        for axis in ctl.axes:
            self.writer.add_topic(f"{ns}/axis{axis.number}/status", "mpi_ros/msg/AxisStatus", status)
        self.writer.add_topic("/joint_states", "sensor_msgs/msg/JointState", status)
        self.writer.add_metadata(METADATA_NAME, {
            "config": yaml.safe_dump(config.raw, sort_keys=False),
            "sample_rate": repr(self.rate),
            "start_sample": str(ctl.sample),
            "epoch_ns": str(self.epoch),
            "mpi_ros_version": __version__,
        })
        runner.add_periodic(config.ros.status_rate, self._collect_status)
        runner.add_periodic(config.ros.joint_states_rate, self._collect_joints)
        runner.on_event(self._on_event)
        runner.on_command(self._on_command)

    def log_time(self, sample: int) -> int:
        return self.epoch + round(sample * 1e9 / self.rate)

    # -- hooks (periodic collection under the runner lock, writing after it) --------------------------
    def _collect_status(self, ctl):
        t = self.log_time(ctl.sample)
        messages: list[tuple[str, object]] = [
            (f"{self.ns}/ms{ms.number}/status", convert.motion_status(ms.snapshot(), ctl.rate)) for ms in ctl.supervisors
        ]
        messages += [(f"{self.ns}/axis{a.number}/status", convert.axis_status(ctl.axis_snapshot(a.number), ctl.rate))
                     for a in ctl.axes]
        return lambda: [self.writer.write(topic, msg, t) for topic, msg in messages]

    def _collect_joints(self, ctl):
        msg = convert.joint_state(ctl)
        t = self.log_time(ctl.sample)
        return lambda: self.writer.write("/joint_states", msg, t)

    def _on_event(self, event) -> None:
        self.writer.write(f"{self.ns}/events", convert.motion_event(event, self.rate), self.log_time(event.sample))

    def _on_command(self, sample: int, command: ControllerCommand, reply: Reply) -> None:
        msg = Command()
        msg.stamp = convert.stamp(sample, self.rate)
        msg.sample = sample
        msg.operation = command.operation
        msg.supervisor = command.supervisor
        msg.axis = command.axis
        msg.request = command.to_json()
        msg.message = reply.message.name
        self.writer.write(COMMANDS_TOPIC, msg, self.log_time(sample))

    def close(self) -> None:
        self.writer.close()


# Events that are not the controller's own (they depend on optional monitors), left out of
# replay comparisons.
NOT_REPLAYED = {MPIEventType.CROSSCHECK.name}

