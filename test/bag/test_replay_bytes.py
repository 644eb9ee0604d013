"""Replay compares each status's canonical CDR first and its fields only where the bytes
differ (docs/recording.md, "Replay: bytes first, fields where they differ"): the report must
be the one a field-by-field comparison of every status gives, whether the run is the same or
has diverged."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpi_ros.bag import replay as replay_module
from mpi_ros.bag.replay import ReplayReport, replay

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

