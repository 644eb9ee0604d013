"""Replay steps through the statuses between two commands in one go and takes their
snapshots inside the controller's stretches (Controller.step_snapshots, issue 35). Over every
fixture, the snapshots are those of stepping to each status (every field of every supervisor
and axis, to the bit) and the report is the one that route gives, exact or diverged."""

from __future__ import annotations

from pathlib import Path

import pytest

from mpi_ros.bag import replay as replay_module
from mpi_ros.bag.replay import ReplayReport, replay

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures" / "bags"
BAGS = sorted(p for p in FIXTURES.iterdir() if p.is_dir())
CHANGED_PLANT = {"axes": {"defaults": {"plant": {"bandwidth_hz": 25.0}}}}


def _step_to_each_status(monkeypatch: pytest.MonkeyPatch) -> None:
    """Runs of one sample: the controller steps to each status's sample and takes
    motion_snapshots() there, as replay did before."""
    monkeypatch.setattr(replay_module, "RUN", 0)


def _figures(report: ReplayReport) -> tuple:
    return (report.commands, report.statuses, report.values, report.events, report.differences, report.first,
            report.largest, report.last_sample, report.summary())


def _snapshots_seen(monkeypatch: pytest.MonkeyPatch, bag: Path) -> dict[int, str]:
    """Every snapshot replay compares, by sample, every field (repr: a float's is exact)."""
    seen: dict[int, str] = {}
    take = replay_module._Statuses.take

    def recording_take(self, samples, until=-1):
        take(self, samples, until)
        seen.update({sample: repr(snapshots) for sample, snapshots in self.taken.items()})

    monkeypatch.setattr(replay_module._Statuses, "take", recording_take)
    assert replay(bag).identical
    monkeypatch.undo()
    return seen


@pytest.mark.parametrize("bag", BAGS, ids=[b.name for b in BAGS])
def test_the_snapshots_are_those_of_stepping_to_each_status(bag: Path, monkeypatch: pytest.MonkeyPatch):
    in_stretches = _snapshots_seen(monkeypatch, bag)
    _step_to_each_status(monkeypatch)
    stepped = _snapshots_seen(monkeypatch, bag)
    assert in_stretches.keys() == stepped.keys()
    different = [s for s in stepped if in_stretches[s] != stepped[s]]
    assert not different, f"{len(different)} samples differ, first at {different[:3]}"


@pytest.mark.parametrize("bag", BAGS, ids=[b.name for b in BAGS])
def test_the_report_is_that_of_stepping_to_each_status(bag: Path, monkeypatch: pytest.MonkeyPatch):
    in_stretches = replay(bag)
    assert in_stretches.identical, in_stretches.summary()
    _step_to_each_status(monkeypatch)
    assert _figures(in_stretches) == _figures(replay(bag))


@pytest.mark.parametrize("stop_at_first", [False, True])
def test_a_divergence_is_reported_as_stepping_to_each_status_reports_it(stop_at_first: bool,
                                                                      monkeypatch: pytest.MonkeyPatch):
    """Another plant: the first divergence, the largest ones, and where replay stopped (the
    controller may have stepped past it, the report says where the comparison was)."""
    in_stretches = replay(FIXTURES / "p2p_modify", overrides=CHANGED_PLANT, stop_at_first=stop_at_first)
    assert not in_stretches.identical
    _step_to_each_status(monkeypatch)
    stepped = replay(FIXTURES / "p2p_modify", overrides=CHANGED_PLANT, stop_at_first=stop_at_first)
    assert _figures(in_stretches) == _figures(stepped)
