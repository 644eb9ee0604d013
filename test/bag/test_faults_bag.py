"""The faults fixture (test/fixtures/scenarios/faults.yaml, docs/faults.md): faults
configured in the YAML and injected by scenario steps are recorded as commands, and a
replay reproduces every trip, refusal and recovery at the same samples."""

from __future__ import annotations

from pathlib import Path

from mpi_ros.bag.reader import BagReader
from mpi_ros.bag.replay import replay

BAG = Path(__file__).resolve().parent.parent / "fixtures" / "bags" / "faults"
FAULTS = ("LIMIT_ERROR", "AMP_FAULT", "LIMIT_SW_POSITIVE", "ENCODER_FAULT", "FRAME_UNDERFLOW")


def _recorded(topic: str) -> list:
    return [msg for _, msg in BagReader(BAG).decoded([topic])]


def test_the_fixture_holds_every_fault_its_injections_and_the_refused_resets():
    events = _recorded("/mpi/events")
    tripped = [(e.type, e.axis) for e in events if e.type in FAULTS]
    assert tripped == [("LIMIT_ERROR", 0), ("AMP_FAULT", 1), ("LIMIT_SW_POSITIVE", 2), ("ENCODER_FAULT", 3),
                       ("FRAME_UNDERFLOW", 2), ("FRAME_UNDERFLOW", 3)]
    commands = _recorded("/mpi/commands")
    injected = [(c.operation, c.axis, c.message) for c in commands if c.operation.startswith("axis_fault")]
    assert injected == [("axis_fault_inject", 1, "MPIMessageOK"), ("axis_fault_inject", 1, "MPIMessageOK"),
                        ("axis_fault_config_set", 2, "MPIMessageOK"), ("axis_fault_inject", 3, "MPIMessageOK"),
                        ("axis_fault_inject", 3, "MPIMessageOK"), ("axis_fault_config_set", 3, "MPIMessageOK")]
    resets = [c.message for c in commands if c.request == '{"action":"RESET"}']
    assert resets.count("MPIMotionMessageERROR") == 2  # refused while the amplifier fault and the limit persist
    statuses = _recorded("/mpi/axis1/status")
    assert any(list(s.faults) == ["AMP_FAULT"] and not s.amp_enabled for s in statuses)
    assert not statuses[-1].faults


def test_the_fixture_replays_every_fault_with_zero_differences():
    report = replay(BAG)
    assert report.identical, report.summary()
    assert report.commands == 16
    assert report.events > 50


def test_a_changed_fault_limit_is_caught_as_a_divergence():
    # a looser following-error limit: the aggressive move no longer trips it
    report = replay(BAG, overrides={"axes": {"overrides": {0: {"faults": {"following_error_limit": 1000.0}}}}})
    assert not report.identical
    assert report.first is not None
    assert report.first.sample < 100
