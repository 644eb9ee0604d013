"""A 4 kHz controller through the runner, the recorder and replay (issue 35: the 2 kHz sample
rate stays the default, 4 kHz works as well). test/mpi/test_sample_rate.py has the core's side."""

from __future__ import annotations

from pathlib import Path

from mpi_ros.bag import scenario
from mpi_ros.bag.reader import BagReader
from mpi_ros.bag.replay import replay
from mpi_ros.ros import convert

SCENARIOS = Path(__file__).resolve().parent.parent / "fixtures" / "scenarios"


def test_a_run_at_4_khz_records_at_its_status_rate_and_replays_exactly(tmp_path):
    """Issue 35: a 4 kHz controller through the runner, the recorder and replay. The statuses
    come every 1/status_rate of controller time (twice the samples apart), stamped epoch +
    sample / 4000, and the run replays with zero differences."""
    plan = scenario.load(SCENARIOS / "two_supervisors.yaml")
    plan.config = {**plan.config, "controller": {"sample_rate": 4000.0}}
    bag = scenario.record(plan, tmp_path / "run")
    reader = BagReader(bag)
    epoch = int(reader.metadata("mpi_ros")["stamp_epoch_ns"])
    samples = []
    for _, msg in reader.decoded(["/mpi/ms0/status"]):
        assert convert.time_ns(msg.header.stamp) == epoch + round(msg.sample * 1e9 / 4000.0)
        samples.append(msg.sample)
    every = round(4000.0 / plan.config["ros"]["status_rate"])
    assert every == 80
    assert samples == list(range(every, plan.samples + 1, every))
    report = replay(bag)
    assert report.identical, report.summary()
    assert report.statuses > 0
    assert report.events > 0
