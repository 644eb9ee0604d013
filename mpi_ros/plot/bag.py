"""Plot a recorded bag: per axis, command and actual position, velocities and position error,
and a strip of each supervisor's state with its events labelled. Writes a PNG.

What the figure promises (issue 36; test/bag/test_plot.py checks each):
- every legend lies outside the data, right of its panel;
- event labels never overprint: each goes into the first of LANES rows of its strip where it
  has room (measured as drawn); those with none are counted beside the strip, and the
  safety actions (STOP, E_STOP, ABORT, RESET, RESUME) get their rows before the other events;
- a state shorter than MIN_BAND of the plotted time (a 2 ms E_STOP in 3 minutes) is drawn
  MIN_BAND wide, over its neighbours;
- a supervisor that stayed IDLE with no event in the window (or has none of the --axis axes)
  gets no strip; the title says so;
- the title names the recording (its last two path parts), when it started (UTC), how long it
  is, the window plotted, and the supervisors with their axes;
- ``window`` (seconds since the first message, as the x axis) plots part of it.

Reading: status messages are read field by field from their CDR (mpi_ros.bag.fields), not
built, when the bag's definition of the type is the installed one: a 3-minute recording of
the default configuration (about 110,000 statuses) is plotted in about 4 s on a busy 2-core machine
(bench/bench_plot.py).
"""

from __future__ import annotations

import datetime
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..bag import schema
from ..bag.fields import Unreadable, field_reader
from ..bag.reader import BagReader, Recorded
from ..graph_names import AXIS_STATUS, EVENTS, MOTION_STATUS

STATE_COLOURS = {
    "IDLE": "#e8f5e9", "MOVING": "#bbdefb", "STOPPING": "#ffe0b2", "STOPPED": "#fff9c4",
    "STOPPING_ERROR": "#ffcdd2", "ERROR": "#ef9a9a",
}
MARKED_EVENTS = {"MOTION_START", "MOTION_DONE", "STOP", "E_STOP", "ABORT", "RESET", "RESUME", "HOLD_RELEASED"}
SAFETY_EVENTS = ("E_STOP", "ABORT", "STOP", "RESET", "RESUME")  # labelled before the others
MIN_BAND = 0.004  # of the plotted time: the narrowest state band drawn (about 4 px at 1,000 px)
LANES = (0.8, 0.5, 0.2)  # rows of labels in a state strip (fraction of its height)
LABEL_GAP = 3.0  # px between two labels of a row
AXIS_FIELDS = ("command_position", "actual_position", "command_velocity", "actual_velocity", "position_error")
DPI = 110


@dataclass
class Recording:
    """What the plot needs of a bag, times in s since its first stamped message."""

    name: str
    start_ns: int = 0
    length: float = 0.0
    axes: dict[int, dict[str, np.ndarray]] = field(default_factory=dict)
    states: dict[int, list[tuple[float, str]]] = field(default_factory=dict)  # transitions only
    events: list[tuple[float, str, int]] = field(default_factory=list)  # (t, type, supervisor)
    supervisor_axes: dict[int, tuple[int, ...]] = field(default_factory=dict)


# -- reading ----------------------------------------------------------------------------------------
FIELDS = {AXIS_STATUS.type: ("number", *AXIS_FIELDS),
          MOTION_STATUS.type: ("number", "state_name", "axis_numbers"),
          EVENTS.type: ("type", "supervisor")}


def _rows(reader: BagReader) -> Iterator[tuple[str, tuple]]:
    """(type, (stamp ns, *its FIELDS)) of every message the plot reads, in one pass over the
    bag: read from the CDR when the bag's definition of the type is the installed one, else
    from the message built by the bag's definition."""
    topics = [topic for topic, type_name in reader.topics().items() if type_name in FIELDS]
    fast: dict[str, Any] = {}
    for recorded in reader.stored(topics):  # each topic in order is enough
        wanted = FIELDS[recorded.type]
        if recorded.topic not in fast:
            fast[recorded.topic] = _fast_reader(recorded, wanted)
        read = fast[recorded.topic]
        if read is not None:
            sec, nanosec, *values = read(recorded.data)
        else:
            msg = recorded.decode()
            stamp = msg.stamp if hasattr(msg, "stamp") else msg.header.stamp
            sec, nanosec, values = stamp.sec, stamp.nanosec, [getattr(msg, name) for name in wanted]
        yield recorded.type, (sec * 1_000_000_000 + nanosec, *values)


def _fast_reader(recorded: Recorded, wanted: tuple[str, ...]):
    if recorded.schema_text and recorded.schema_text != schema.ros2msg(recorded.type):
        return None  # recorded before the type changed: only its own definition reads it
    msg_class = schema.message_class(recorded.type)
    for stamp in ("stamp", "header.stamp"):
        try:
            return field_reader(msg_class, (f"{stamp}.sec", f"{stamp}.nanosec", *wanted))
        except Unreadable:
            continue
    return None


def read_recording(path: str | Path) -> Recording:
    """The axes' series, the supervisors' state transitions and the marked events of a bag."""
    reader = BagReader(path)
    recording = Recording(name="/".join(Path(path).resolve().parts[-2:]))
    raw_axes: dict[int, list[tuple]] = defaultdict(list)
    raw_states: dict[int, list[tuple[int, str]]] = defaultdict(list)
    raw_events: list[tuple[int, str, int]] = []
    for type_name, row in _rows(reader):
        if type_name == AXIS_STATUS.type:
            raw_axes[row[1]].append((row[0], *row[2:]))
        elif type_name == MOTION_STATUS.type:
            ns, number, state, axes = row
            history = raw_states[number]
            if not history or history[-1][1] != state:
                history.append((ns, state))
            recording.supervisor_axes[number] = tuple(axes)
        elif row[1] in MARKED_EVENTS:
            raw_events.append((row[0], row[1], row[2]))
    stamps = [rows[0][0] for rows in raw_axes.values()] + [h[0][0] for h in raw_states.values()]
    if not stamps:
        return recording
    start = min(stamps + [e[0] for e in raw_events])
    end = max([rows[-1][0] for rows in raw_axes.values()] + [h[-1][0] for h in raw_states.values()]
              + [e[0] for e in raw_events])
    recording.start_ns, recording.length = start, (end - start) * 1e-9
    for number, rows in raw_axes.items():
        table = np.array(rows, dtype=float)
        table = table[np.argsort(table[:, 0], kind="stable")]
        recording.axes[number] = {"t": (table[:, 0] - start) * 1e-9,
                                  **{key: table[:, k + 1] for k, key in enumerate(AXIS_FIELDS)}}
    recording.states = {n: [((ns - start) * 1e-9, s) for ns, s in h] for n, h in raw_states.items()}
    recording.events = sorted(((ns - start) * 1e-9, kind, supervisor) for ns, kind, supervisor in raw_events)
    return recording


# -- what is drawn ----------------------------------------------------------------------------------
def bands(transitions: list[tuple[float, str]], window: tuple[float, float]) -> list[tuple[float, float, str]]:
    """(start, width, state) of each state in ``window``, none narrower than MIN_BAND of it;
    the narrow ones last, so that they are drawn over their neighbours."""
    lo, hi = window
    least = MIN_BAND * (hi - lo)
    out = []
    for (t0, state), (t1, _) in zip(transitions, [*transitions[1:], (hi, "")], strict=True):
        a, b = max(t0, lo), min(max(t1, t0), hi)
        if b < a or (b == a and t1 > t0):
            continue  # outside the window
        out.append((a, max(b - a, least), state))
    return sorted(out, key=lambda band: band[1] <= least)


def busy(recording: Recording, number: int, window: tuple[float, float]) -> bool:
    """Whether a supervisor did anything in the window: a state other than IDLE, or an event."""
    return (any(state != "IDLE" for _, _, state in bands(recording.states.get(number, []), window))
            or any(s == number and window[0] <= t <= window[1] for t, _, s in recording.events))


def check_window(recording: Recording, start: float | None, end: float | None) -> tuple[float, float]:
    """The plotted time, [start, end] in s since the first message; ValueError says what is wrong."""
    lo = 0.0 if start is None else start
    hi = recording.length if end is None else end
    if lo >= recording.length:
        raise ValueError(f"--from {lo:g} s is past the end of the recording, which is {recording.length:.3f} s long")
    if hi <= lo:
        raise ValueError(f"--from {lo:g} s is not before --to {hi:g} s")
    if hi <= 0.0:
        raise ValueError(f"--to {hi:g} s is before the recording's first message (0 s)")
    return lo, hi


def _title(recording: Recording, window: tuple[float, float], shown: list[int], left_out: list[int]) -> str:
    start = datetime.datetime.fromtimestamp(recording.start_ns * 1e-9, tz=datetime.UTC)
    line = f"{recording.name}: recorded {start:%Y-%m-%d %H:%M:%S} UTC, {recording.length:.1f} s"
    if window != (0.0, recording.length):
        line += f"; plotted {window[0]:g} to {window[1]:g} s"
    supervisors = ", ".join(f"ms{n} (axes {', '.join(map(str, recording.supervisor_axes.get(n, ())))})"
                            for n in sorted(recording.supervisor_axes))
    line += f"\nsupervisors {supervisors}" if supervisors else ""
    if left_out:
        line += f"; no strip for {', '.join(f'ms{n}' for n in left_out)} (idle, no events, or none of its axes shown)"
    return line


def draw_bag(path: str | Path, axes_wanted: list[int] | None = None, start: float | None = None,
             end: float | None = None) -> Any:
    """The figure of the bag at ``path`` (matplotlib Figure; close it when done)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    recording = read_recording(path)
    numbers = sorted(n for n in recording.axes if axes_wanted is None or n in axes_wanted)
    if not numbers:
        raise ValueError(f"{path}: no axis status recorded" + (f" for axes {axes_wanted}" if axes_wanted else ""))
    window = check_window(recording, start, end)
    mine = [n for n in sorted(recording.states)
            if axes_wanted is None or set(recording.supervisor_axes.get(n, ())) & set(numbers)]
    shown = [n for n in mine if busy(recording, n, window)]
    left_out = [n for n in sorted(recording.states) if n not in shown]
    fig, rows = plt.subplots(3 + len(shown), 1, sharex=True, layout="constrained", squeeze=False,
                             figsize=(12, 2.4 * 3 + 0.9 * len(shown) + 0.6),
                             gridspec_kw={"height_ratios": [3, 3, 3] + [1] * len(shown)})
    data_axes, strips = list(rows[:3, 0]), list(rows[3:, 0])
    _draw_axes(data_axes, recording, numbers, window)
    for ax, number in zip(strips, shown, strict=True):
        _draw_states(ax, recording.states[number], window, number)
    if strips:  # the figure's, right of the panels, at the bottom beside the strips
        present = {state for number in shown for _, _, state in bands(recording.states[number], window)}
        fig.legend(handles=_state_handles(present), loc="outside right lower", fontsize=7, frameon=False,
                   title="supervisor state", title_fontsize=7)
    rows[-1, 0].set_xlabel("time since the first message [s]")
    rows[-1, 0].set_xlim(*window)
    fig.suptitle(_title(recording, window, shown, left_out), fontsize=10)
    layout = fig.get_layout_engine()
    assert layout is not None  # made with layout="constrained"
    layout.execute(fig)  # the layout, once (no drawing): labels go where the panels are now
    fig.set_layout_engine("none")
    for ax, number in zip(strips, shown, strict=True):
        _label_events(fig, ax, [(t, kind) for t, kind, s in recording.events if s == number], window)
    return fig


def plot_bag(path: str | Path, output: str | Path, axes_wanted: list[int] | None = None,
             start: float | None = None, end: float | None = None) -> Path:
    """Draw the bag at ``path`` into the PNG ``output``; returns the output path."""
    import matplotlib.pyplot as plt

    fig = draw_bag(path, axes_wanted, start, end)
    output = Path(output)
    try:
        fig.savefig(output, dpi=DPI)
    finally:
        plt.close(fig)
    return output


def _draw_axes(data_axes: list, recording: Recording, numbers: list[int], window: tuple[float, float]) -> None:
    pos_ax, vel_ax, err_ax = data_axes
    for n in numbers:
        s = recording.axes[n]
        inside = (s["t"] >= window[0]) & (s["t"] <= window[1])
        t = s["t"][inside]
        line, = pos_ax.plot(t, s["command_position"][inside], lw=1.2, label=f"axis{n} command")
        colour = line.get_color()
        pos_ax.plot(t, s["actual_position"][inside], lw=1.0, ls="--", color=colour, label=f"axis{n} actual")
        vel_ax.plot(t, s["command_velocity"][inside], lw=1.2, color=colour, label=f"axis{n} command")
        vel_ax.plot(t, s["actual_velocity"][inside], lw=1.0, ls="--", color=colour, label=f"axis{n} actual")
        err_ax.plot(t, s["position_error"][inside], lw=1.0, color=colour, label=f"axis{n}")
    for ax, label in ((pos_ax, "position [counts]"), (vel_ax, "velocity [counts/s]"),
                      (err_ax, "position error [counts]")):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=7, frameon=False)


def _draw_states(ax, transitions: list[tuple[float, str]], window: tuple[float, float], number: int) -> None:
    by_state: dict[str, list[tuple[float, float]]] = defaultdict(list)
    narrow: list[tuple[float, float, str]] = []
    least = MIN_BAND * (window[1] - window[0])
    for t0, width, state in bands(transitions, window):
        if width <= least:
            narrow.append((t0, width, state))
        else:
            by_state[state].append((t0, width))
    for state, spans in by_state.items():  # one collection per state: thousands of spans draw at once
        ax.broken_barh(spans, (0.0, 1.0), facecolors=STATE_COLOURS.get(state, "#eeeeee"), lw=0, zorder=1)
    for state in sorted({state for _, _, state in narrow}):  # over the wide ones, edged so a pale one shows too
        ax.broken_barh([(t0, width) for t0, width, s in narrow if s == state], (0.0, 1.0),
                       facecolors=STATE_COLOURS.get(state, "#eeeeee"), edgecolors="#555555", lw=0.4, zorder=2)
    ax.set_ylim(0.0, 1.0)
    ax.set_yticks([])
    ax.set_ylabel(f"ms{number}", rotation=0, ha="right", va="center")


def _state_handles(present: set[str]) -> list:
    from matplotlib.patches import Patch

    return [Patch(facecolor=colour, edgecolor="#999999", lw=0.4, label=state)
            for state, colour in STATE_COLOURS.items() if state in present]


def _label_events(fig, ax, events: list[tuple[float, str]], window: tuple[float, float]) -> None:
    """A tick per event; a label where a row has room (measured), the rest counted."""
    inside = [(t, kind) for t, kind in events if window[0] <= t <= window[1]]
    merged: dict[float, list[str]] = defaultdict(list)  # events of one instant share a label
    for t, kind in inside:
        if kind not in merged[t]:
            merged[t].append(kind)
    if inside:
        ax.vlines([t for t, _ in inside], 0.0, 1.0, colors="k", lw=0.5, zorder=3)
    renderer = fig.canvas.get_renderer()
    right_edge = ax.get_window_extent(renderer).x1
    widths: dict[str, float] = {}  # px per label text, measured once each
    rows: list[list[tuple[float, float]]] = [[] for _ in LANES]  # occupied pixel spans per row
    unlabelled = 0
    order = sorted(merged.items(), key=lambda item: (not any(k in SAFETY_EVENTS for k in item[1]), item[0]))
    for t, kinds in order:
        label = " " + "+".join(kinds)
        if label not in widths:
            widths[label] = _label(ax, 0.0, 0.0, label).get_window_extent(renderer).width
            ax.texts[-1].remove()
        at = ax.transData.transform((t, 0.0))[0]
        # right of its tick, or left of it where the panel ends
        x0, x1, align = (at, at + widths[label], "left") if at + widths[label] <= right_edge else \
            (at - widths[label], at, "right")
        lane = next((k for k, used in enumerate(rows)
                     if all(x1 + LABEL_GAP <= a or x0 >= b + LABEL_GAP for a, b in used)), None)
        if lane is None:
            unlabelled += 1
            continue
        rows[lane].append((x0, x1))
        _label(ax, t, LANES[lane], label if align == "left" else label.strip() + " ").set_horizontalalignment(align)
    if unlabelled:
        ax.text(1.005, 0.0, f"{unlabelled} of {len(merged)} events\nunlabelled: narrow the\nwindow (--from/--to)",
                transform=ax.transAxes, fontsize=6, va="bottom", ha="left")


def _label(ax, t: float, y: float, label: str):
    return ax.text(t, y, label, transform=ax.get_xaxis_transform(), fontsize=6, va="center", ha="left", zorder=4,
                   clip_on=True, gid="event label",
                   bbox={"boxstyle": "square,pad=0.1", "facecolor": "white", "alpha": 0.7, "lw": 0})
