"""Exact replay: feed a bag's commands into a fresh controller at the same samples and
compare every recorded status, event and command answer with the new run.

The fresh controller is built from the configuration stored in the bag (optionally with
overrides, to see what a changed parameter does). Statuses recorded at sample k are
compared once the new controller is at k; commands recorded with effective sample k are
applied when it is at k-1 (DESIGN.md: a command is applied at the first sample after the
controller's current one). Identical runs report zero differences; otherwise the report
names the first divergence: where, which field, by how much.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from .. import config as suite_config
from ..commands import Command, apply
from ..ros import convert
from .reader import BagReader
from .recorder import COMMANDS_TOPIC, METADATA_NAME, NOT_REPLAYED

_SKIPPED_FIELDS = {"stamp"}  # derived from the sample


@dataclass(frozen=True, slots=True)
class Divergence:
    sample: int
    topic: str
    field: str
    recorded: object
    replayed: object

    @property
    def difference(self) -> float | None:
        if isinstance(self.recorded, (int, float)) and isinstance(self.replayed, (int, float)):
            return abs(float(self.recorded) - float(self.replayed))
        return None

    def __str__(self) -> str:
        by = f" (by {self.difference:.6g})" if self.difference is not None else ""
        return (f"sample {self.sample}, {self.topic} {self.field}: recorded {self.recorded!r}, "
                f"replayed {self.replayed!r}{by}")


@dataclass(slots=True)
class ReplayReport:
    bag: str
    commands: int = 0
    statuses: int = 0
    values: int = 0
    events: int = 0
    differences: int = 0
    first: Divergence | None = None
    largest: dict[str, float] = field(default_factory=dict)  # field -> largest numeric difference
    last_sample: int = 0

    @property
    def identical(self) -> bool:
        return self.differences == 0

    def record(self, divergence: Divergence) -> None:
        self.differences += 1
        if self.first is None:
            self.first = divergence
        diff = divergence.difference
        if diff is not None and (math.isnan(diff) or diff > self.largest.get(divergence.field, -1.0)):
            self.largest[divergence.field] = diff

    def summary(self) -> str:
        head = (f"{self.bag}: {self.commands} commands, {self.statuses} statuses ({self.values} values), "
                f"{self.events} events compared up to sample {self.last_sample}")
        if self.identical:
            return f"{head}: zero differences"
        worst = ", ".join(f"{k} {v:.6g}" for k, v in sorted(self.largest.items(), key=lambda kv: -kv[1])[:5])
        return (f"{head}: {self.differences} differences; first at {self.first}"
                + (f"; largest: {worst}" if worst else ""))


def _flatten(data, prefix: str = ""):
    if isinstance(data, dict):
        for key, value in data.items():
            if key in _SKIPPED_FIELDS:
                continue
            yield from _flatten(value, f"{prefix}.{key}" if prefix else key)
    elif isinstance(data, list) and data and isinstance(data[0], dict):
        for i, value in enumerate(data):
            yield from _flatten(value, f"{prefix}[{i}]")
    else:
        yield prefix, data


def _compare(report: ReplayReport, sample: int, topic: str, recorded, replayed, tolerance: float) -> None:
    new = dict(_flatten(convert.to_dict(replayed)))
    for name, value in _flatten(convert.to_dict(recorded)):
        other = new.get(name)
        report.values += 1
        if isinstance(value, float) and isinstance(other, float):
            same = value == other or abs(value - other) <= tolerance or (math.isnan(value) and math.isnan(other))
        else:
            same = value == other
        if not same:
            report.record(Divergence(sample, topic, name, value, other))


def load_config(reader: BagReader, overrides: dict | None = None) -> suite_config.SuiteConfig:
    stored = reader.metadata(METADATA_NAME)
    if stored is None:
        raise ValueError(f"{reader.path}: no '{METADATA_NAME}' metadata: not recorded by mpi_ros")
    if int(stored.get("start_sample", "0")) != 0:
        raise ValueError(f"{reader.path}: recording did not start at sample 0; it cannot be replayed")
    raw = yaml.safe_load(stored["config"]) or {}
    return suite_config.parse(suite_config.merge(raw, overrides or {}), f"{reader.path} (recorded)")


def replay(path: str | Path, overrides: dict | None = None, tolerance: float = 0.0,
           stop_at_first: bool = False) -> ReplayReport:
    """Replay a bag; ``overrides`` change the recorded configuration (e.g. a plant gain)."""
    reader = BagReader(path)
    cfg = load_config(reader, overrides)
    ctl = cfg.build_controller()
    replayed_events = []
    ctl.listeners.append(lambda e: replayed_events.append(e) if e.type_name not in NOT_REPLAYED else None)
    report = ReplayReport(str(path))
    ns = cfg.ros.namespace.rstrip("/")
    recorded_events = []
    timeline = []  # (controller sample, 0 status / 1 command, order, topic, type, msg)
    for item, msg in reader.decoded():
        if item.topic == COMMANDS_TOPIC:
            # applied while the controller was one sample before the one it took effect at
            timeline.append((msg.sample - 1, 1, item.sequence, item.topic, item.type, msg))
        elif item.topic == f"{ns}/events":
            if msg.type not in NOT_REPLAYED:
                recorded_events.append((item.sequence, msg))
        elif item.type in ("mpi_ros/msg/MotionStatus", "mpi_ros/msg/AxisStatus"):
            # statuses at a sample were taken before commands given at that sample
            timeline.append((msg.sample, 0, item.sequence, item.topic, item.type, msg))
    timeline.sort(key=lambda entry: entry[:3])
    # the order they were written in, which ties in log time may not keep
    recorded_events = [msg for _, msg in sorted(recorded_events, key=lambda pair: pair[0])]
    for sample, kind, _, topic, msg_type, msg in timeline:
        _step_to(ctl, sample)
        if kind == 1:
            reply = apply(ctl, Command.from_json(msg.operation, msg.supervisor, msg.axis, msg.request))
            report.commands += 1
            if reply.message.name != msg.message:
                report.record(Divergence(msg.sample, topic, f"{msg.operation}.message", msg.message,
                                         reply.message.name))
        else:
            _compare(report, sample, topic, msg, _replayed_status(ctl, msg_type, msg.number), tolerance)
            report.statuses += 1
        if stop_at_first and report.first is not None:
            break
    report.last_sample = ctl.sample
    _compare_events(report, recorded_events, replayed_events, ctl.rate, tolerance)
    return report


def _step_to(ctl, sample: int) -> None:
    if sample > ctl.sample:
        ctl.step(sample - ctl.sample)


def _replayed_status(ctl, msg_type: str, number: int):
    if msg_type == "mpi_ros/msg/MotionStatus":
        return convert.motion_status(ctl.supervisor(number).snapshot(), ctl.rate)
    return convert.axis_status(ctl.axis_snapshot(number), ctl.rate)


def _compare_events(report: ReplayReport, recorded, replayed, rate: float, tolerance: float) -> None:
    """Events up to the last compared sample, in order."""
    horizon = report.last_sample
    replayed = [convert.motion_event(e, rate) for e in replayed if e.sample <= horizon]
    recorded = [e for e in recorded if e.sample <= horizon]
    for i, (old, new) in enumerate(zip(recorded, replayed)):
        report.events += 1
        _compare(report, old.sample, f"event[{i}]", old, new, tolerance)
    if len(recorded) != len(replayed):
        report.record(Divergence(horizon, "events", "count", len(recorded), len(replayed)))
