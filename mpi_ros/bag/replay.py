"""Exact replay: feed a bag's commands into a fresh controller at the same samples and
compare every recorded status, event and command answer with the new run.

The fresh controller is built from the configuration stored in the bag (optionally with
overrides, to see what a changed parameter does): the MCAP metadata ``mpi_ros`` that
``mpi-ros record`` writes, or else the suite's latched <ns>/configuration message, which
any recorder of the graph (``ros2 bag record -a``) captures along with the commands on
<ns>/commands. A bag without one of them is refused with what it lacks (MissingInput).
Stamps are compared too when the bag knows the epoch they count from, and so are the headers'
frame ids (a bag recorded before the messages had a header holds a bare ``stamp``: it is
compared with the header's, and the frame id is not). Statuses recorded at sample k are
compared once the new controller is at k; commands recorded with effective sample k are
applied when it is at k-1 (docs/decisions.md, "Samples, commands and replay": a command is
applied at the first sample after the controller's current one). Identical runs report zero
differences; otherwise the report names the first divergence: where, which field, by how much.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from operator import attrgetter
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from mcap.exceptions import McapError

from .. import config as suite_config
from .. import graph_names as gn
from ..commands import Command, apply
from ..mpi.control import MAX_STRETCH
from ..ros import convert, wire
from . import fields, schema
from .reader import BagReader, Column, Source, load_yaml
from .recorder import COMMAND_TYPE, COMMANDS_TOPIC, CONFIGURATION_TYPE, METADATA_NAME, NOT_REPLAYED, commands_topic

_SKIPPED_FIELDS = frozenset({"stamp"})  # derived from the sample; compared when the bag has the epoch
_OLDER_STAMP = "header.stamp"  # where a bag recorded before the headers has its bare `stamp` compared
STATUS_TYPES = gn.STATUS_TYPES
# Samples a run of statuses spans at most: the controller's longest stretch (no longer one
# is any cheaper a sample), and the run's snapshots are all held until it is compared.
RUN = MAX_STRETCH


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
    truncated: str = ""  # the bag was cut short (BagReader.truncated): only what it holds was compared

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
        if self.truncated:
            head = f"{head} in a truncated bag (read up to its last complete record)"
        if self.identical:
            return f"{head}: zero differences"
        worst = ", ".join(f"{k} {v:.6g}" for k, v in sorted(self.largest.items(), key=lambda kv: -kv[1])[:5])
        return (f"{head}: {self.differences} differences; first at {self.first}"
                + (f"; largest: {worst}" if worst else ""))


def _flatten(data, prefix: str = "", skipped=_SKIPPED_FIELDS):
    if isinstance(data, dict):
        # a status or event recorded before the header (docs/recording.md, "Older recordings")
        older = "stamp" in data and "sample" in data
        for key, value in data.items():
            if key in skipped:
                continue
            name = _OLDER_STAMP if older and key == "stamp" else key
            yield from _flatten(value, f"{prefix}.{name}" if prefix else name, skipped)
    elif isinstance(data, list) and data and isinstance(data[0], dict):
        for i, value in enumerate(data):
            yield from _flatten(value, f"{prefix}[{i}]", skipped)
    else:
        yield prefix, data


def _compare(report: ReplayReport, sample: int, topic: str, recorded, replayed, tolerance: float,
             skipped=_SKIPPED_FIELDS) -> None:
    new = dict(_flatten(convert.to_dict(replayed), skipped=skipped))
    for name, value in _flatten(convert.to_dict(recorded), skipped=skipped):
        other = new.get(name)
        report.values += 1
        if isinstance(value, float) and isinstance(other, float):
            same = value == other or abs(value - other) <= tolerance or (math.isnan(value) and math.isnan(other))
        else:
            same = value == other
        if not same:
            report.record(Divergence(sample, topic, name, value, other))


class MissingInput(ValueError):
    """The bag lacks what replay needs (the configuration, the commands, any status)."""


@dataclass(frozen=True, slots=True)
class Recording:
    """What a bag says about the run it recorded: where the configuration came from and
    which topics hold the commands, events and statuses."""

    config: dict  # the configuration as recorded (YAML mapping)
    source: str  # "metadata" (mpi-ros record) or the configuration topic's name
    start_sample: int
    epoch_ns: int | None  # stamps are epoch + sample / rate (None: older bags, stamps not compared)
    namespace: str
    commands: list[str]  # topics
    events: str | None
    statuses: list[str]
    graph: bool  # a recording of the graph (any recorder): it may have started after the suite


def inspect(reader: BagReader, namespace: str | None = None) -> Recording:
    """The recording's configuration and topics; MissingInput names everything that is missing.

    A recording of a cell's graph holds several suites (one <ns>/configuration each):
    ``namespace`` chooses one; without it such a bag is refused with the namespaces named."""
    topics = reader.topics()
    stored = reader.metadata(METADATA_NAME)
    config_topics = sorted(t for t, k in topics.items() if k == CONFIGURATION_TYPE)
    missing = []
    setup = None
    if stored is not None:
        stored_epoch = stored.get("stamp_epoch_ns")
        setup = (load_yaml(stored["config"]) or {}, "metadata", int(stored.get("start_sample", "0")),
                 int(stored_epoch) if stored_epoch is not None else None, stored.get("namespace"))
        if namespace is not None and setup[4] not in (None, namespace):
            raise MissingInput(f"{reader.path}: the bag recorded the suite in {setup[4]}, not {namespace}")
    elif config_topics:
        config_topics = _chosen(reader, config_topics, namespace)
        found = next((msg for _, msg in reader.decoded(config_topics[:1])), None)
        if found is not None:
            setup = (load_yaml(found.config) or {}, config_topics[0], int(found.start_sample),
                     int(found.epoch_ns), found.ros_namespace or None)
    if setup is None:
        where = (f"the topic {config_topics[0]} is there but holds no message" if config_topics else
                 "no MCAP metadata 'mpi_ros' (what `mpi-ros record` writes) and no topic of type "
                 f"{CONFIGURATION_TYPE} (the suite latches it on /mpi/configuration)")
        missing.append(f"the configuration ({where})")
    raw, source, start, epoch, namespace = setup or ({}, "", 0, None, None)
    if namespace is None:
        namespace = (((raw.get("ros") or {}).get("namespace") if isinstance(raw, dict) else None)
                     or gn.DEFAULT_NAMESPACE)
    ns = namespace.rstrip("/")
    commands = [t for t, k in topics.items() if k == COMMAND_TYPE and t in (commands_topic(ns), COMMANDS_TOPIC)]
    if not commands:
        others = sorted(t for t, k in topics.items() if k == COMMAND_TYPE)
        missing.append(f"the commands (no topic {commands_topic(ns)} of type {COMMAND_TYPE}"
                       + (f"; only {', '.join(others)}" if others else "") + ")")
    statuses = sorted(t for t, k in topics.items() if k in STATUS_TYPES and t.startswith(ns + "/"))
    if not statuses:
        missing.append(f"the statuses to compare (no {ns}/ms<n>/status or {ns}/axis<k>/status topic)")
    if missing:
        raise MissingInput(f"{reader.path}: cannot replay, the bag lacks " + "; and ".join(missing))
    if start != 0:
        raise ValueError(f"{reader.path}: the suite did not start at sample 0 (it started at {start}); "
                         "it cannot be replayed")
    events = gn.EVENTS.name(ns) if topics.get(gn.EVENTS.name(ns)) == gn.EVENTS.type else None
    return Recording(raw, source, start, epoch, namespace, commands, events, statuses, source != "metadata")


def _chosen(reader: BagReader, config_topics: list[str], namespace: str | None) -> list[str]:
    """The configuration topic of the suite in ``namespace`` (or the only one)."""
    if namespace is not None:
        wanted = gn.CONFIGURATION.name(namespace)
        if wanted not in config_topics:
            raise MissingInput(f"{reader.path}: no suite in {namespace} (no topic {wanted}; "
                               f"the bag has {', '.join(config_topics)})")
        return [wanted]
    if len(config_topics) > 1:
        names = ", ".join(t.rsplit("/", 1)[0] for t in config_topics)
        raise MissingInput(f"{reader.path}: the bag holds several suites ({names}): choose one with --namespace")
    return config_topics


def load_config(reader: BagReader, overrides: dict | None = None) -> suite_config.SuiteConfig:
    """The configuration the bag's run used (from its metadata or its configuration topic)."""
    return _config(reader, inspect(reader), overrides)


def _config(reader: BagReader, recording: Recording, overrides: dict | None) -> suite_config.SuiteConfig:
    return suite_config.parse(suite_config.merge(recording.config, overrides or {}), f"{reader.path} (recorded)")


def replay(path: str | Path, overrides: dict | None = None, tolerance: float = 0.0,
           stop_at_first: bool = False, namespace: str | None = None) -> ReplayReport:
    """Replay a bag; ``overrides`` change the recorded configuration (e.g. a plant gain);
    ``namespace`` chooses the suite of a bag that recorded several (a cell).

    The bag may come from ``mpi-ros record`` (configuration in its metadata) or from any
    recorder of the graph (configuration from the latched <ns>/configuration topic).
    Raises MissingInput (a ValueError) naming what the bag lacks."""
    reader = BagReader(path)
    try:
        recording = inspect(reader, namespace)
    except McapError as exc:
        raise ValueError(f"{path}: not a readable MCAP file: {exc}") from exc
    cfg = _config(reader, recording, overrides)
    ctl = cfg.build_controller()
    replayed_events: list = []
    ctl.listeners.append(lambda e: replayed_events.append(e) if e.type_name not in NOT_REPLAYED else None)
    report = ReplayReport(str(path), truncated=reader.truncated)
    timeline = _timeline(reader, recording)
    statuses = _Statuses(ctl, recording, tolerance)
    report.last_sample = ctl.sample
    steps = list(_steps(timeline))
    for step, following in zip(steps, [*steps[1:], None], strict=True):
        if isinstance(step, _Command):
            _apply(ctl, report, step)
            # where stepping entry by entry would have left the controller
            report.last_sample = max(report.last_sample, step.sample)
        else:
            samples = timeline.statuses.sample[step]
            # on to where a command follows in the same go: a stretch fewer than stepping there apart
            until = following.sample if isinstance(following, _Command) else samples[-1]
            statuses.take(list(dict.fromkeys(samples)), until)
            statuses.compare_run(report, timeline.statuses, step, stop_at_first)
        if stop_at_first and report.first is not None:
            break
    # a recording of the graph holds the events from when it started; mpi-ros record has them all
    first = timeline.first_recorded
    since = (first if first is not None else report.last_sample + 1) if recording.graph else 0
    _compare_events(report, timeline.events, replayed_events, ctl.rate, tolerance, recording.epoch_ns,
                    statuses.skipped, since, recording.namespace)
    return report


# A status' sample and number, read from its CDR, by type: where wire.py lays them out, or,
# if the installed interfaces differ from its layouts, by the installed definition.
_STATUS_KEYS: dict[str, Callable[[bytes], tuple]] = {
    name: wire.sample_and_number if wire.AVAILABLE else fields.field_reader(schema.message_class(name),
                                                                             ("sample", "number"))
    for name in STATUS_TYPES}


# What replay reads of a recorded command: when it took effect, and what it asked and was answered
_COMMAND_FIELDS = ("sample", "operation", "supervisor", "axis", "request", "message")


class _Command(NamedTuple):
    """A recorded command, applied while the controller is at ``sample`` (the one before it
    took effect at); then what orders commands of the same sample: as they were written;
    its topic and its _COMMAND_FIELDS."""

    sample: int
    sequence: int
    log_time: int
    position: int
    topic: str
    fields: tuple


class _Event(NamedTuple):
    """A recorded event: its sample and type, every field of it (fields.field_names of the
    installed type; None where the bag's definition is another: compared field by field)
    and its CDR."""

    sample: int
    type: str
    values: tuple | None
    source: Source
    data: bytes

    def message(self):
        return self.source.recorded(0, self.data).decode()


def _reader(source: Source, names: Sequence[str]) -> Callable[[bytes], tuple | None]:
    """``names`` (dotted) of a message of ``source``, read from its CDR without building it
    (fields.field_reader: neither rclpy's serialization nor the type's support loaded);
    None where they cannot be read so (a bag recorded before the type changed)."""
    try:
        read = None if source.older else fields.field_reader(schema.message_class(source.type), names)
    except fields.Unreadable:
        read = None

    def values(data: bytes) -> tuple | None:
        try:
            return read(data) if read is not None else None
        except fields.Unreadable:  # big-endian CDR
            return None

    return values


def _command(source: Source, sequence: int, log_time: int, position: int, data: bytes,
             read: Callable[[bytes], tuple | None]) -> _Command:
    found = read(data)
    if found is None:
        found = attrgetter(*_COMMAND_FIELDS)(source.recorded(log_time, data, sequence).decode())
    return _Command(found[0] - 1, sequence, log_time, position, source.topic, found)


def _event(source: Source, data: bytes, read: Callable[[bytes], tuple | None], sample_and_type: tuple[int, int]
           ) -> _Event:
    """A recorded event; ``sample_and_type``: where its sample and type are among what ``read`` reads."""
    values = read(data)
    if values is None:
        msg = source.recorded(0, data).decode()
        return _Event(msg.sample, msg.type, None, source, data)
    return _Event(values[sample_and_type[0]], values[sample_and_type[1]], values, source, data)


@dataclass(frozen=True, slots=True)
class _Recorded:
    """The recorded statuses in the order they are compared, a list per field (no object a
    status: a recording's are many, and the garbage collector would go through each): the
    sample, whether a MotionStatus (else an AxisStatus), the supervisor's or axis' number,
    the CDR, the source (an index into ``sources``) and, for a status decoded to find its
    sample (a bag recorded before the type changed), the message by its index."""

    sample: list[int]
    motion: list[bool]
    number: list[int]
    data: list[bytes]
    source: list[int]
    sources: list[Source]
    decoded: dict[int, Any]

    def message(self, index: int):
        """The ``index``-th status, decoded."""
        found = self.decoded.get(index)
        return found if found is not None else self.sources[self.source[index]].recorded(0, self.data[index]).decode()


@dataclass(frozen=True, slots=True)
class _Timeline:
    """What replay compares and applies, each in order: the statuses by sample (those of a
    sample in the order written), the commands by the sample they are applied at, the
    recorded events as written, and the first sample the recording saw (a graph recording
    may start late)."""

    statuses: _Recorded
    commands: list[_Command]
    events: list
    first_recorded: int | None


def _timeline(reader: BagReader, recording: Recording) -> _Timeline:
    """The bag's statuses, commands and events, read a column per topic (BagReader.columns).

    Statuses are most of a recording: their sample and number are read from the CDR and the
    message is decoded only if the replayed bytes differ; they are sorted as arrays, by
    sample, then as they were written (sequence, log time, and where stored)."""
    columns = reader.columns([*recording.commands, *recording.statuses]
                             + ([recording.events] if recording.events else []))
    commands: list[_Command] = []
    recorded_events: list[tuple[tuple[int, int, int], _Event]] = []
    status_columns = []
    for column in columns:
        source = column.source
        rows = zip(column.sequence.tolist(), column.log_time.tolist(), column.position.tolist(), column.data,
                   strict=True)
        if source.topic in recording.commands:
            read = _reader(source, _COMMAND_FIELDS)
            commands += [_command(source, *row, read) for row in rows]
        elif source.topic == recording.events:
            names = fields.field_names(schema.message_class(source.type))
            read, at = _reader(source, names), (names.index("sample"), names.index("type"))
            recorded_events += [((sequence, log_time, position), _event(source, data, read, at))
                                for sequence, log_time, position, data in rows]
        else:
            status_columns.append(column)
    commands.sort()  # no two have the same position: the sort never compares what follows it
    statuses = _sorted_statuses(status_columns)
    seen = statuses.sample[:1] + [event.sample for _, event in recorded_events]
    # the order they were written in, which ties in log time may not keep
    events = [event for _, event in sorted(recorded_events, key=lambda pair: pair[0])
              if event.type not in NOT_REPLAYED]
    return _Timeline(statuses, commands, events, min(seen, default=None))


def _sorted_statuses(columns: list[Column]) -> _Recorded:
    """The statuses of ``columns`` (status topics), sorted by (sample, sequence, log time,
    position)."""
    keys, decoded = [], []
    for column in columns:
        source = column.source
        if source.older:
            msgs = [source.recorded(0, data).decode() for data in column.data]
            keys.append(np.array([(msg.sample, msg.number) for msg in msgs], np.int64).reshape(-1, 2))
            decoded += msgs
        else:
            keys.append(_status_keys(source.type, column.data))
            decoded += [None] * len(column.data)

    def joined(arrays: list[np.ndarray]) -> np.ndarray:
        return np.concatenate(arrays or [np.zeros(0, np.int64)])

    samples, numbers = joined([key[:, 0] for key in keys]), joined([key[:, 1] for key in keys])
    order = np.lexsort((joined([column.position for column in columns]),
                        joined([column.log_time for column in columns]),
                        joined([column.sequence for column in columns]), samples))
    which = np.repeat(np.arange(len(columns)), [len(column.data) for column in columns])[order]
    motion = np.array([column.source.type == STATUS_TYPES[0] for column in columns], bool)
    data = [x for column in columns for x in column.data]
    at = order.tolist()
    return _Recorded(samples[order].tolist(), motion[which].tolist(), numbers[order].tolist(),
                     [data[i] for i in at], which.tolist(), [column.source for column in columns],
                     {k: decoded[i] for k, i in enumerate(at) if decoded[i] is not None})


def _status_keys(type_name: str, data: list[bytes]) -> np.ndarray:
    """The (sample, number) of statuses of type ``type_name`` (CDR), as rows: read together
    where wire.sample_and_number reads one (after the header's stamp and frame_id, the
    uint64 sample 8-aligned, then the int32 number); one by one by _STATUS_KEYS where that
    does not hold (other interfaces, or bytes not laid out so: it says what is wrong)."""
    lengths = np.fromiter(map(len, data), np.int64, len(data))
    starts = np.cumsum(lengths) - lengths
    joined = np.frombuffer(b"".join(data), np.uint8)
    head = len(wire.HEADER)
    if wire.AVAILABLE and (lengths >= head + 12).all():
        frame = fields.gather(joined, starts + head + 8, "<u4").astype(np.int64)
        at = starts + head + ((12 + frame + 7) & -8)
        if (at + 12 <= starts + lengths).all() and (joined[starts + 1] == wire.HEADER[1]).all():
            return np.stack([fields.gather(joined, at, "<u8").astype(np.int64),
                             fields.gather(joined, at + 8, "<i4").astype(np.int64)], axis=1)
    return np.array(list(map(_STATUS_KEYS[type_name], data)), np.int64).reshape(-1, 2)


class _Statuses:
    """The replayed statuses at the controller's sample, compared with the recorded ones:
    their canonical CDR first (mpi_ros.ros.wire, the bytes the suite publishes and the
    recorder stores), field by field only where the bytes differ (or where they cannot be
    the same: a bag recorded before a type changed or without the stamps' epoch). Every
    axis is read once a sample, for all the topics (Controller.motion_snapshots), and packed
    once for its own status and the supervisor's that holds it (wire.Packer)."""

    def __init__(self, ctl, recording: Recording, tolerance: float):
        self.ctl = ctl
        self.epoch = recording.epoch_ns
        self.namespace = recording.namespace
        self.tolerance = tolerance
        self.skipped = _SKIPPED_FIELDS if self.epoch is None else frozenset()
        self.exact_bytes = wire.AVAILABLE and self.epoch is not None
        self.packer = wire.Packer(ctl.rate, self.epoch, self.namespace) if self.exact_bytes else None
        # the snapshots of the run being compared, by sample (the types are told apart by the message's)
        self.taken: dict[int, tuple[dict, list]] = {}
        self.leaves: dict[tuple[bool, int], int] = {}  # (motion status, axes) -> values a status compares

    def take(self, samples: Sequence[int], until: int = -1) -> None:
        """Step the controller to the last of ``samples`` (in order) or on to ``until``,
        keeping the snapshots of each sample; a sample the controller has passed is compared
        where it is (as stepping to each status did)."""
        ctl = self.ctl
        wanted = [max(sample, ctl.sample) for sample in samples]
        taken = ctl.step_snapshots(max(wanted[-1], until) - ctl.sample, wanted)
        self.taken = {sample: taken[at] for sample, at in zip(samples, wanted, strict=True)}

    def compare_run(self, report: ReplayReport, recorded: _Recorded, run: slice, stop_at_first: bool) -> None:
        """Compare a run of the recorded statuses (in order; their snapshots taken by
        :meth:`take`): their bytes, or their fields where the bytes differ; with
        ``stop_at_first``, up to the first difference."""
        packer = self.packer
        for index, sample, motion, number, data in zip(range(run.start, run.stop), recorded.sample[run],
                                                       recorded.motion[run], recorded.number[run], recorded.data[run],
                                                       strict=True):
            # where stepping status by status would have left the controller
            report.last_sample = max(report.last_sample, sample)
            report.statuses += 1
            snap = self._snapshot(sample, motion, number)
            if packer is not None and index not in recorded.decoded and data == (
                    packer.motion_status(snap) if motion else packer.axis_status(snap)):
                report.values += self._leaves(motion, snap)
                continue
            self._compare_fields(report, recorded, index, snap)
            if stop_at_first and report.first is not None:
                return

    def _compare_fields(self, report: ReplayReport, recorded: _Recorded, index: int, snap) -> None:
        """The ``index``-th recorded status and its snapshot, field by field."""
        motion = recorded.motion[index]
        replayed = (convert.motion_status if motion else convert.axis_status)(snap, self.ctl.rate, self.epoch or 0,
                                                                                self.namespace)
        _compare(report, recorded.sample[index], recorded.sources[recorded.source[index]].topic,
                 recorded.message(index), replayed, self.tolerance, self.skipped)

    def _snapshot(self, sample: int, motion: bool, number: int):
        """The replayed snapshot of supervisor or axis ``number`` at ``sample``."""
        motions, axes = self.taken[sample]
        snap = motions.get(number) if motion else (axes[number] if 0 <= number < len(axes) else None)
        if snap is None:  # what the controller answers for a supervisor or axis it does not have
            snap = self.ctl.supervisor(number).snapshot() if motion else self.ctl.axis_snapshot(number)
        return snap

    def _leaves(self, motion: bool, snap) -> int:
        """The values a field-by-field comparison of this status counts (fixed by its type
        and its number of axes)."""
        key = (motion, len(snap.axes) if motion else 0)
        found = self.leaves.get(key)
        if found is None:
            convert_ = convert.motion_status if motion else convert.axis_status
            built = convert_(snap, self.ctl.rate, self.epoch or 0, self.namespace)
            found = self.leaves[key] = sum(1 for _ in _flatten(convert.to_dict(built), skipped=self.skipped))
        return found


def _step_to(ctl, sample: int) -> None:
    if sample > ctl.sample:
        ctl.step(sample - ctl.sample)


def _apply(ctl, report: ReplayReport, command: _Command) -> None:
    """A recorded command, applied at the sample before the one it took effect at."""
    sample, operation, supervisor, axis, request, message = command.fields
    _step_to(ctl, command.sample)
    reply = apply(ctl, Command.from_json(operation, supervisor, axis, request))
    report.commands += 1
    if reply.message.name != message:
        report.record(Divergence(sample, command.topic, f"{operation}.message", message, reply.message.name))


def _steps(timeline: _Timeline) -> Iterator[_Command | slice]:
    """The timeline in steps: each command alone, and the statuses between two commands
    (slices of timeline.statuses) in runs of at most RUN samples. A run of statuses is
    stepped through at once, its snapshots taken inside the controller's stretches
    (Controller.step_snapshots): a stretch costs about the same whatever its length, and
    was cut at every status (issue 35)."""
    samples = timeline.statuses.sample
    start = 0
    for command in [*timeline.commands, None]:
        # the statuses before a command: those of samples up to the one it is applied at
        stop = len(samples) if command is None else bisect.bisect_right(samples, command.sample, lo=start)
        while start < stop:
            end = bisect.bisect_right(samples, samples[start] + RUN, start, stop)
            yield slice(start, end)
            start = end
        if command is not None:
            yield command


def _compare_events(report: ReplayReport, recorded, replayed, rate: float, tolerance: float,
                    epoch: int | None = None, skipped=_SKIPPED_FIELDS, since: int = 0,
                    namespace: str = suite_config.DEFAULT_NAMESPACE) -> None:
    """Events from ``since`` up to the last compared sample, in order."""
    horizon = report.last_sample
    if report.truncated:
        # the cut may fall among the writes of the last sample: events are written as they
        # happen, before the statuses of any later sample, so those before it are all there
        horizon -= 1
    replayed = [convert.motion_event(e, rate, epoch or 0, namespace) for e in replayed if since <= e.sample <= horizon]
    recorded = [e for e in recorded if e.sample <= horizon]
    if replayed:
        # an event has no sequence of messages: as many values each, counted once
        leaves = sum(1 for _ in _flatten(convert.to_dict(replayed[0]), skipped=skipped))
        values = attrgetter(*fields.field_names(type(replayed[0])))
    # pairs up to the shorter list: a difference in count is a divergence of its own (below)
    for i, (old, new) in enumerate(zip(recorded, replayed, strict=False)):
        report.events += 1
        if old.values is not None and old.values == values(new):  # every field exact (false for a NaN)
            report.values += leaves
        else:
            _compare(report, old.sample, f"event[{i}]", old.message(), new, tolerance, skipped)
    if len(recorded) != len(replayed):
        report.record(Divergence(horizon, "events", "count", len(recorded), len(replayed)))
