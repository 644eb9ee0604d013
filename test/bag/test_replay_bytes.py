"""Replay compares each status's canonical CDR first and its fields only where the bytes
differ (docs/recording.md, "Replay: bytes first, fields where they differ"): the report must
be the one a field-by-field comparison of every status gives, whether the run is the same or
has diverged."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpi_ros.bag import cdr
from mpi_ros.bag import replay as replay_module
from mpi_ros.bag.reader import BagReader
from mpi_ros.bag.recorder import METADATA_NAME
from mpi_ros.bag.replay import ReplayReport, replay
from mpi_ros.bag.writer import BagWriter

BAGS = Path(__file__).resolve().parent.parent / "fixtures" / "bags"
CHANGED_PLANT = {"axes": {"defaults": {"plant": {"bandwidth_hz": 25.0}}}}


def _fields_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """Replay as it was before the bytes were compared: every status field by field."""
    monkeypatch.setattr(replay_module.wire, "AVAILABLE", False)


def _figures(report: ReplayReport) -> tuple:
    return (report.commands, report.statuses, report.values, report.events, report.differences, report.first,
            report.largest, report.last_sample)


@pytest.mark.parametrize("bag", ["two_supervisors", "cams"])
def test_an_exact_replay_reports_what_the_fields_report(bag: str, monkeypatch: pytest.MonkeyPatch):
    by_bytes = replay(BAGS / bag)
    assert by_bytes.identical, by_bytes.summary()
    _fields_only(monkeypatch)
    assert _figures(by_bytes) == _figures(replay(BAGS / bag))


def test_a_divergence_is_reported_as_the_fields_report_it(monkeypatch: pytest.MonkeyPatch):
    by_bytes = replay(BAGS / "p2p_modify", overrides=CHANGED_PLANT)
    assert not by_bytes.identical
    _fields_only(monkeypatch)
    assert _figures(by_bytes) == _figures(replay(BAGS / "p2p_modify", overrides=CHANGED_PLANT))


def test_bytes_that_differ_within_the_tolerance_are_the_same(monkeypatch: pytest.MonkeyPatch):
    """The statuses' bytes differ (another plant), their fields not beyond the tolerance: what
    is left are the events' samples (integers, compared exactly), one a sample later."""
    report = replay(BAGS / "p2p_modify", overrides=CHANGED_PLANT, tolerance=1e9)
    assert report.first is not None
    assert report.first.topic.startswith("event"), report.summary()
    _fields_only(monkeypatch)
    assert _figures(report) == _figures(replay(BAGS / "p2p_modify", overrides=CHANGED_PLANT, tolerance=1e9))



def _with_one_status_changed(tmp_path: Path, bag: str, topic: str, index: int, change) -> tuple[Path, int]:
    """A copy of a fixture (its messages in the order they were written, its metadata) in
    which the ``index``-th message of ``topic`` was changed by ``change(msg)``; and the
    sample of that message."""
    reader = BagReader(BAGS / bag)
    copy = tmp_path / bag
    sample = -1
    with BagWriter(copy) as writer:
        writer.add_metadata(METADATA_NAME, reader.metadata(METADATA_NAME) or {})
        seen = 0
        for recorded in reader.messages():
            data = recorded.data
            if recorded.topic == topic:
                if seen == index:
                    msg = recorded.decode()
                    change(msg)
                    data, sample = cdr.serialize(msg), msg.sample
                seen += 1
            writer.write_raw(recorded.topic, recorded.type, data, recorded.log_time)
    return copy, sample


def test_a_copy_with_nothing_changed_replays_exactly(tmp_path: Path):
    copy, _ = _with_one_status_changed(tmp_path, "two_supervisors", "/mpi/axis1/status", -1, lambda msg: None)
    assert _figures(replay(copy)) == _figures(replay(BAGS / "two_supervisors"))


@pytest.mark.parametrize("stop_at_first", [False, True])
def test_a_changed_axis_status_is_reported_at_its_sample_topic_and_field(tmp_path: Path, stop_at_first: bool,
                                                                        monkeypatch: pytest.MonkeyPatch):
    def moved(msg) -> None:
        msg.actual_position += 0.5

    copy, sample = _with_one_status_changed(tmp_path, "two_supervisors", "/mpi/axis1/status", 70, moved)
    report = replay(copy, stop_at_first=stop_at_first)
    assert report.differences == 1, report.summary()
    first = report.first
    assert (first.sample, first.topic, first.field) == (sample, "/mpi/axis1/status", "actual_position")
    assert first.difference == pytest.approx(0.5)
    _fields_only(monkeypatch)
    assert _figures(report) == _figures(replay(copy, stop_at_first=stop_at_first))


def test_a_changed_axis_inside_a_motion_status_is_reported_there_only(tmp_path: Path):
    """wire.Packer packs an axis once for its own status and the supervisor's that holds it:
    a difference in one of the two is still found in that one."""
    def flagged(msg) -> None:
        msg.axes[1].settled = not msg.axes[1].settled

    copy, sample = _with_one_status_changed(tmp_path, "two_supervisors", "/mpi/ms0/status", 40, flagged)
    report = replay(copy)
    assert report.differences == 1, report.summary()
    first = report.first
    assert (first.sample, first.topic, first.field) == (sample, "/mpi/ms0/status", "axes[1].settled")
    assert first.recorded != first.replayed


def test_a_changed_event_is_reported_at_its_sample_and_field(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """Events equal as messages are counted without comparing their fields one by one: one
    that differs is still reported, as the field-by-field comparison of every event did."""
    def renumbered(msg) -> None:
        msg.move_id += 1

    copy, sample = _with_one_status_changed(tmp_path, "two_supervisors", "/mpi/events", 3, renumbered)
    report = replay(copy)
    assert report.differences == 1, report.summary()
    first = report.first
    assert (first.sample, first.topic, first.field) == (sample, "event[3]", "move_id")
    assert first.difference == 1
    monkeypatch.setattr(replay_module.convert.MotionEvent, "__eq__", lambda self, other: False)
    assert _figures(report) == _figures(replay(copy))
    assert _figures(replay(BAGS / "two_supervisors"))[2] == _figures(replay(copy))[2]  # the values counted
