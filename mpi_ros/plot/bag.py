"""Plot a recorded bag: per axis, command and actual position, velocities, position error,
and each supervisor's state over time, with the events marked. Writes a PNG."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

from ..bag.reader import BagReader

STATE_COLOURS = {
    "IDLE": "#e8f5e9", "MOVING": "#bbdefb", "STOPPING": "#ffe0b2", "STOPPED": "#fff9c4",
    "STOPPING_ERROR": "#ffcdd2", "ERROR": "#ef9a9a",
}
MARKED_EVENTS = {"MOTION_START", "MOTION_DONE", "STOP", "E_STOP", "ABORT", "RESET", "RESUME", "HOLD_RELEASED"}


def _series(reader: BagReader):
    axes: dict[int, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    states: dict[int, list[tuple[float, str]]] = defaultdict(list)
    events: list[tuple[float, str, int]] = []
    t0: int | None = None  # stamps are wall-clock anchored: plot the time since the first one
    for item, msg in reader.decoded():
        stamp = _stamp(msg)
        if stamp is None:
            continue
        ns = stamp.sec * 1_000_000_000 + stamp.nanosec
        t0 = ns if t0 is None else t0
        t = (ns - t0) * 1e-9
        if item.type == "mpi_ros/msg/AxisStatus":
            series = axes[msg.number]
            series["t"].append(t)
            for key in ("command_position", "actual_position", "command_velocity", "actual_velocity",
                        "position_error"):
                series[key].append(getattr(msg, key))
        elif item.type == "mpi_ros/msg/MotionStatus":
            states[msg.number].append((t, msg.state_name))
        elif item.type == "mpi_ros/msg/MotionEvent" and msg.type in MARKED_EVENTS:
            events.append((t, msg.type, msg.supervisor))
    return axes, states, events


def _stamp(msg):
    """A recorded message's stamp: its header's, or the bare `stamp` of a bag recorded before
    the messages had a header (docs/recording.md); None for messages without one."""
    header = getattr(msg, "header", None)
    return header.stamp if header is not None else getattr(msg, "stamp", None)


def _state_bands(ax, states: list[tuple[float, str]]) -> None:
    for (t0, name), (t1, _) in zip(states, states[1:] + [states[-1]], strict=True):
        ax.axvspan(t0, t1 if t1 > t0 else t0, color=STATE_COLOURS.get(name, "#eeeeee"), lw=0)


def plot_bag(path: str | Path, output: str | Path, axes_wanted: list[int] | None = None) -> Path:
    """Draw the bag at ``path`` into the PNG ``output``; returns the output path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    axes, states, events = _series(BagReader(path))
    numbers = sorted(n for n in axes if axes_wanted is None or n in axes_wanted)
    if not numbers:
        raise ValueError(f"{path}: no axis status recorded")
    fig, rows = plt.subplots(3 + len(states), 1, figsize=(11, 2.6 * (3 + len(states))), sharex=True)
    pos_ax, vel_ax, err_ax, *state_axes = rows
    for n in numbers:
        s = axes[n]
        line, = pos_ax.plot(s["t"], s["command_position"], lw=1.2, label=f"axis{n} command")
        pos_ax.plot(s["t"], s["actual_position"], lw=1.0, ls="--", color=line.get_color(), label=f"axis{n} actual")
        vel_ax.plot(s["t"], s["command_velocity"], lw=1.2, color=line.get_color(), label=f"axis{n} command")
        vel_ax.plot(s["t"], s["actual_velocity"], lw=1.0, ls="--", color=line.get_color(), label=f"axis{n} actual")
        err_ax.plot(s["t"], s["position_error"], lw=1.0, color=line.get_color(), label=f"axis{n}")
    for ax, label in ((pos_ax, "position [counts]"), (vel_ax, "velocity [counts/s]"),
                      (err_ax, "position error [counts]")):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncol=2)
    for ax, (number, history) in zip(state_axes, sorted(states.items()), strict=True):
        _state_bands(ax, history)
        ax.set_yticks([])
        ax.set_ylabel(f"ms{number} state")
        for t, kind, supervisor in events:
            if supervisor == number:
                ax.axvline(t, color="k", lw=0.6)
                ax.text(t, 0.5, kind, rotation=90, fontsize=6, va="center", ha="right")
    handles = [Patch(color=c, label=s) for s, c in STATE_COLOURS.items()]
    if state_axes:
        state_axes[-1].legend(handles=handles, loc="lower right", fontsize=6, ncol=6)
    rows[-1].set_xlabel("time since the first message [s]")
    fig.suptitle(f"{Path(path).name}")
    fig.tight_layout()
    output = Path(output)
    fig.savefig(output, dpi=110)
    plt.close(fig)
    return output
