"""The plot of a bag (mpi_ros/plot/bag.py) by its structure: panels, legends outside the
data, event labels that do not overprint, short states drawn wide enough, windows, titles;
and the field reader it uses, against the messages rclpy builds."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from mpi_ros.bag.reader import BagReader
from mpi_ros.plot import bag as plot

BAGS = Path(__file__).resolve().parents[1] / "fixtures" / "bags"


@pytest.fixture
def figures():
    """``draw(bag, **options)``: the figure, closed after the test."""
    import matplotlib.pyplot as plt

    made = []

    def draw(name: str, **options):
        made.append(plot.draw_bag(BAGS / name, **options))
        return made[-1]

    yield draw
    for fig in made:
        plt.close(fig)


def _strips(fig) -> list:
    return fig.axes[3:]


def _labels(ax) -> list:
    return [text for text in ax.texts if text.get_gid() == "event label"]


def test_a_panel_per_quantity_and_a_strip_per_busy_supervisor_named_in_the_title(figures):
    fig = figures("two_supervisors")
    assert len(fig.axes) == 5  # position, velocity, error, ms0, ms1
    assert [ax.get_ylabel() for ax in _strips(fig)] == ["ms0", "ms1"]
    title = fig.get_suptitle()
    assert title.startswith("bags/two_supervisors: recorded 2023-11-14 22:13:20 UTC, 3.0 s\n")
    assert title.endswith("supervisors ms0 (axes 0, 1), ms1 (axes 2, 3)")


def test_a_supervisor_that_stayed_idle_or_has_none_of_the_axes_gets_no_strip(figures):
    idle = figures("estop_reset")  # ms1 stayed IDLE, no event
    assert [ax.get_ylabel() for ax in _strips(idle)] == ["ms0"]
    assert "no strip for ms1 (idle, no events, or none of its axes shown)" in idle.get_suptitle()
    only_axis_2 = figures("two_supervisors", axes_wanted=[2])
    assert [ax.get_ylabel() for ax in _strips(only_axis_2)] == ["ms1"]
    assert [line.get_label() for line in only_axis_2.axes[0].lines] == ["axis2 command", "axis2 actual"]


def test_every_legend_lies_right_of_the_panels(figures):
    fig = figures("faults")
    renderer = fig.canvas.get_renderer()
    right = max(ax.get_window_extent(renderer).x1 for ax in fig.axes)
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + fig.legends
    assert len(legends) == 4  # position, velocity, error; the states' (the figure's)
    for legend in legends:
        assert legend.get_window_extent(renderer).x0 >= right


@pytest.mark.parametrize("name", ["faults", "two_supervisors", "estop_reset"])
def test_event_labels_do_not_overprint_and_the_unlabelled_are_counted(figures, name):
    fig = figures(name)
    renderer = fig.canvas.get_renderer()
    events = plot.read_recording(BAGS / name).events
    for ax, number in zip(_strips(fig), [int(ax.get_ylabel()[2:]) for ax in _strips(fig)], strict=True):
        boxes = [text.get_window_extent(renderer) for text in _labels(ax)]
        for a, b in itertools.combinations(boxes, 2):
            assert a.x1 <= b.x0 or b.x1 <= a.x0 or a.y1 <= b.y0 or b.y1 <= a.y0, "two labels overlap"
        panel = ax.get_window_extent(renderer)
        assert all(panel.x0 <= box.x0 and box.x1 <= panel.x1 + 0.5 for box in boxes)
        instants = {t for t, _, s in events if s == number}
        notes = [text.get_text() for text in ax.texts if text.get_gid() != "event label"]
        unlabelled = int(notes[0].split()[0]) if notes else 0
        assert len(boxes) + unlabelled == len(instants)  # one label per instant, or counted


def test_a_crowded_strip_labels_the_safety_actions_first():
    transitions = [(0.0, "MOVING")]
    events = [(t * 0.001, "MOTION_START", 0) for t in range(200)] + [(0.1005, "E_STOP", 0)]
    recording = plot.Recording(name="x/y", length=1.0, states={0: transitions}, events=sorted(events),
                               supervisor_axes={0: (0,)})
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    try:
        plot._label_events(fig, ax, [(t, kind) for t, kind, _ in recording.events], (0.0, 1.0))
        assert "E_STOP" in [text.get_text().strip() for text in _labels(ax)]
    finally:
        plt.close(fig)


def test_a_state_shorter_than_the_least_band_is_drawn_that_wide_over_its_neighbours():
    transitions = [(0.0, "MOVING"), (4.0, "STOPPING_ERROR"), (4.002, "ERROR"), (4.003, "IDLE")]
    drawn = plot.bands(transitions, (0.0, 10.0))
    least = plot.MIN_BAND * 10.0
    assert [state for _, _, state in drawn] == ["MOVING", "IDLE", "STOPPING_ERROR", "ERROR"]  # narrow ones last
    widths = {state: width for _, width, state in drawn}
    assert widths["STOPPING_ERROR"] == widths["ERROR"] == pytest.approx(least)
    assert widths["MOVING"] == pytest.approx(4.0)
    assert widths["IDLE"] == pytest.approx(10.0 - 4.003)
    # in a window of 0.2 s, 2 ms is wide enough on its own
    assert dict((s, w) for _, w, s in plot.bands(transitions, (3.9, 4.1)))["STOPPING_ERROR"] == pytest.approx(0.002)


def test_a_window_plots_that_part_and_the_title_says_which(figures):
    fig = figures("two_supervisors", start=0.5, end=1.25)
    assert fig.axes[0].get_xlim() == (0.5, 1.25)
    for line in fig.axes[0].lines:
        assert min(line.get_xdata()) >= 0.5
        assert max(line.get_xdata()) <= 1.25
    assert "; plotted 0.5 to 1.25 s\n" in fig.get_suptitle()


@pytest.mark.parametrize(("start", "end", "message"), [
    (2.0, 1.0, "--from 2 s is not before --to 1 s"),
    (5.0, None, "--from 5 s is past the end of the recording, which is 2.998 s long"),
    (-2.0, -1.0, "--to -1 s is before the recording's first message"),
])
def test_a_window_outside_the_recording_is_refused(start, end, message, capsys):
    with pytest.raises(ValueError, match=message):
        plot.draw_bag(BAGS / "two_supervisors", start=start, end=end)
    from mpi_ros.cli import main

    argv = ["plot", str(BAGS / "two_supervisors"), "--from", str(start)] + ([] if end is None else ["--to", str(end)])
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_the_field_reader_reads_what_rclpy_builds():
    from mpi_ros.bag import schema
    from mpi_ros.bag.fields import field_reader

    checked = 0
    for bag in sorted(BAGS.iterdir()):
        reader = BagReader(bag)
        for recorded, msg in reader.decoded([t for t, k in reader.topics().items() if k in plot.FIELDS]):
            if recorded.schema_text and recorded.schema_text != schema.ros2msg(recorded.type):
                continue  # recorded by an older definition: the plot builds those
            stamp = "header.stamp" if hasattr(msg, "header") else "stamp"
            wanted = (f"{stamp}.sec", f"{stamp}.nanosec", "header.frame_id" if stamp == "header.stamp" else "sample",
                      *plot.FIELDS[recorded.type])
            expected = tuple(tuple(v) if name == "axis_numbers" else v
                             for name, v in ((name, _get(msg, name)) for name in wanted))
            assert field_reader(schema.message_class(recorded.type), wanted)(recorded.data) == expected
            checked += 1
    assert checked > 1000


def _get(msg, dotted: str):
    for name in dotted.split("."):
        msg = getattr(msg, name)
    return msg


@pytest.mark.parametrize("name", ["two_supervisors", "faults", "streamed_path"])
def test_reading_in_stored_order_gives_what_mcap_gives(name):
    reader = BagReader(BAGS / name)
    topics = [topic for topic in reader.topics() if topic != "/mpi/configuration"]
    fast = list(reader.stored(topics))
    assert fast == list(reader.messages(topics, in_order=False))
    assert len(fast) > 100


def test_reading_a_bag_without_chunks_in_stored_order_gives_what_mcap_gives(unchunked_bag: Path):
    """Where the summary has no chunk indexes (an MCAP written without chunks), the records
    are read one by one from the start."""
    from mcap.reader import make_reader

    source = BagReader(BAGS / "two_supervisors")  # what unchunked_bag was written from
    path = unchunked_bag
    with open(path, "rb") as stream:
        assert not make_reader(stream).get_summary().chunk_indexes
    reader = BagReader(path)
    assert not reader.truncated
    topics = [topic for topic in reader.topics() if topic != "/mpi/configuration"]
    flat = list(reader.stored(topics))
    # written in log-time order: stored in it
    assert flat == list(reader.messages(topics, in_order=False)) == list(source.messages(topics))
