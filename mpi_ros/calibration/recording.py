"""A recording of a real (or simulated) controller: per axis, command and actual position
against time, read from an MCAP bag in this suite's layout or from a CSV file.

CSV: a header row, then one row per sample. ``time`` (seconds) and, per axis k,
``axis<k>_command_position`` and ``axis<k>_actual_position``; a recording of one axis may
name its columns ``command_position`` and ``actual_position`` (axis 0). Samples need not be
uniform in time. An axis recorded for less time than others leaves its last cells empty.

MCAP: the AxisStatus topics (``<ns>/axis<k>/status``), each message one sample with
``command_position`` and ``actual_position``. Its time is ``sample / sample rate`` when the
bag says the rate (the MCAP metadata ``mpi_ros`` that ``mpi-ros record`` writes, or the suite's
latched ``<ns>/configuration``), else the message's log time.

Everything wrong with the input raises :class:`RecordingError` with a message for the user.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from .. import graph_names

MIN_SAMPLES = 50  # fewer say too little about a loop of two states and four parameters
AXIS_STATUS_TYPE = graph_names.AXIS_STATUS.type
CONFIGURATION_TYPE = graph_names.CONFIGURATION.type
_AXIS_COLUMN = re.compile(r"^axis(\d+)_(command_position|actual_position)$")


class RecordingError(ValueError):
    """The recording cannot be fitted or compared: the message says why."""


@dataclass(frozen=True, slots=True)
class AxisRecording:
    """One axis' samples: times (s, increasing), command and actual position (counts)."""

    number: int
    time: np.ndarray
    command: np.ndarray
    actual: np.ndarray

    def validate(self) -> None:
        """Raise RecordingError naming the first problem (lengths, length, numbers, time, motion)."""
        name = f"axis {self.number}"
        n_t, n_c, n_a = len(self.time), len(self.command), len(self.actual)
        if n_c != n_a:
            raise RecordingError(f"{name}: {n_c} command positions but {n_a} actual positions "
                                 "(command and actual must be recorded at the same samples)")
        if n_t != n_c:
            raise RecordingError(f"{name}: {n_t} times but {n_c} positions")
        if n_t < MIN_SAMPLES:
            raise RecordingError(f"{name}: only {n_t} samples; a fit needs at least {MIN_SAMPLES}")
        for label, values in (("time", self.time), ("command_position", self.command),
                              ("actual_position", self.actual)):
            bad = np.flatnonzero(~np.isfinite(values))
            if len(bad):
                raise RecordingError(f"{name}: {label} is not a finite number at sample {int(bad[0])} "
                                     f"({values[bad[0]]!r}; {len(bad)} such samples)")
        steps = np.diff(self.time)
        if np.any(steps <= 0.0):
            i = int(np.flatnonzero(steps <= 0.0)[0]) + 1
            raise RecordingError(f"{name}: time does not increase at sample {i} "
                                 f"({self.time[i - 1]!r} then {self.time[i]!r})")
        if np.ptp(self.command) == 0.0:
            raise RecordingError(f"{name}: the command never moves (constant {self.command[0]!r}): "
                                 "a recording without motion says nothing about the servo")

    @property
    def duration(self) -> float:
        return float(self.time[-1] - self.time[0])


@dataclass(frozen=True, slots=True)
class Recording:
    """Every axis of a recording, with what it says about the controller that made it."""

    source: str
    axes: dict[int, AxisRecording]
    sample_rate: float | None = None  # the controller's, when the recording says it
    config: dict | None = field(default=None)  # the configuration recorded with it (YAML mapping)

    def still(self) -> list[int]:
        """The axes whose command never moves (nothing to fit on them)."""
        return [n for n, axis in sorted(self.axes.items()) if len(axis.command) and np.ptp(axis.command) == 0.0]

    def select(self, wanted: list[int] | None) -> list[AxisRecording]:
        """The axes asked for, each validated; if none are named, every axis whose command
        moves (a recording of a machine with an axis at rest fits the others), or, when none
        does, every axis (and the first one's error says so)."""
        moving = [n for n in sorted(self.axes) if n not in self.still()]
        numbers = (moving or sorted(self.axes)) if not wanted else list(dict.fromkeys(wanted))
        missing = [n for n in numbers if n not in self.axes]
        if missing:
            have = ", ".join(str(n) for n in sorted(self.axes)) or "none"
            raise RecordingError(f"{self.source}: axis {missing[0]} is not in the recording (it has axes {have})")
        chosen = [self.axes[n] for n in numbers]
        for axis in chosen:
            axis.validate()
        return chosen


def read(path: str | Path) -> Recording:
    """A recording from a bag (directory or .mcap file) or a CSV file."""
    path = Path(path)
    if not path.exists():
        raise RecordingError(f"{path}: no such file or directory")
    if path.is_dir() or path.suffix == ".mcap":
        return read_bag(path)
    return read_csv(path)


# -- CSV -------------------------------------------------------------------------------------
def read_csv(path: str | Path) -> Recording:
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            rows = list(csv.reader(stream))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise RecordingError(f"{path}: cannot read as CSV ({exc})") from exc
    if not rows:
        raise RecordingError(f"{path}: empty (expected a header row: time, command_position, actual_position)")
    header = [name.strip() for name in rows[0]]
    columns = {name: _column(path, rows, i, name) for i, name in enumerate(header)}
    if "time" not in columns:
        raise RecordingError(f"{path}: no column 'time' (the header is {', '.join(header)})")
    axes = _csv_axes(path, header)
    time = columns["time"]
    recorded = {}
    for number, (command_name, actual_name) in axes.items():
        command, actual = columns[command_name], columns[actual_name]
        if len(command) > len(time) or len(actual) > len(time):
            raise RecordingError(f"{path}: axis {number} has more samples than the time column")
        recorded[number] = AxisRecording(number, time[:max(len(command), len(actual))], command, actual)
    return Recording(str(path), recorded)


def _csv_axes(path: Path, header: list[str]) -> dict[int, tuple[str, str]]:
    """axis -> (command column, actual column), from the header."""
    if "command_position" in header or "actual_position" in header:
        if "command_position" not in header or "actual_position" not in header:
            raise RecordingError(f"{path}: a single axis needs both command_position and actual_position columns")
        return {0: ("command_position", "actual_position")}
    found: dict[int, dict[str, str]] = {}
    for name in header:
        match = _AXIS_COLUMN.match(name)
        if match:
            found.setdefault(int(match.group(1)), {})[match.group(2)] = name
    if not found:
        raise RecordingError(f"{path}: no position columns (expected axis<k>_command_position and "
                             "axis<k>_actual_position, or command_position and actual_position)")
    for number, kinds in found.items():
        for kind in ("command_position", "actual_position"):
            if kind not in kinds:
                raise RecordingError(f"{path}: axis {number} has no column axis{number}_{kind}")
    return {n: (kinds["command_position"], kinds["actual_position"]) for n, kinds in sorted(found.items())}


def _column(path: Path, rows: list[list[str]], index: int, name: str) -> np.ndarray:
    """Column ``index`` as floats, up to its trailing empty cells; an empty cell before a
    value, or text that is not a number, is an error naming the row (1: the header)."""
    cells = [row[index].strip() if index < len(row) else "" for row in rows[1:]]
    end = len(cells)
    while end and not cells[end - 1]:
        end -= 1
    try:
        return np.array(cells[:end], dtype=float)
    except ValueError:
        pass  # (some cell is not a number: found below, by row)
    for i in range(end):
        try:
            float(cells[i])
        except ValueError:
            where = "empty" if not cells[i] else f"{cells[i]!r} is not a number"
            raise RecordingError(f"{path}: row {i + 2}, column {name}: {where}") from None
    raise AssertionError("unreachable: numpy refused a column whose every cell float() reads")


# -- MCAP --------------------------------------------------------------------------------------
def read_bag(path: str | Path) -> Recording:
    from mpi_ros.bag.reader import BagReader

    try:
        reader = BagReader(path)
        topics = reader.topics()
    except (OSError, ValueError) as exc:
        raise RecordingError(f"{path}: cannot read the bag ({exc})") from exc
    statuses = sorted(t for t, kind in topics.items() if kind == AXIS_STATUS_TYPE)
    if not statuses:
        raise RecordingError(f"{path}: no {AXIS_STATUS_TYPE} topic (<ns>/axis<k>/status): nothing to fit")
    rate, config = _bag_setup(reader, topics)
    samples: dict[int, dict[float, tuple[float, float]]] = {}
    for item, msg in reader.decoded(statuses):
        t = msg.sample / rate if rate else item.log_time * 1e-9
        # The first of two messages of one sample (a status published again) is kept.
        samples.setdefault(int(msg.number), {}).setdefault(t, (msg.command_position, msg.actual_position))
    axes = {}
    for number, series in samples.items():
        times = np.array(sorted(series))
        values = np.array([series[t] for t in times.tolist()]).reshape(-1, 2)
        axes[number] = AxisRecording(number, times - times[0] if len(times) else times,
                                     values[:, 0].copy(), values[:, 1].copy())
    return Recording(str(path), axes, rate, config)


def _bag_setup(reader, topics: dict[str, str]) -> tuple[float | None, dict | None]:
    """The controller's sample rate and configuration as the bag records them (None: not recorded)."""
    stored = reader.metadata("mpi_ros")
    if stored is not None:
        rate = float(stored["sample_rate"]) if "sample_rate" in stored else None
        return _finite_rate(rate), (yaml.safe_load(stored.get("config", "")) or None)
    for topic in sorted(t for t, kind in topics.items() if kind == CONFIGURATION_TYPE)[:1]:
        for _, msg in reader.decoded([topic]):
            return _finite_rate(float(msg.sample_rate)), (yaml.safe_load(msg.config) or None)
    return None, None


def _finite_rate(rate: float | None) -> float | None:
    return rate if rate is not None and math.isfinite(rate) and rate > 0.0 else None
