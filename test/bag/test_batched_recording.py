"""A recording made with the statuses stepped in stretches (ros.publish_period; issue 35)
replays exactly: replay steps the statuses one by one (runner.ControllerRunner's default
publish_period 0), so every recorded status, joint state and event is compared with the one
stepped to its own sample."""

from __future__ import annotations

from mpi_ros import config
from mpi_ros.bag.recorder import Recorder
from mpi_ros.bag.replay import replay
from mpi_ros.bag.scenario import FIXED_EPOCH_NS
from mpi_ros.commands import Command
from mpi_ros.runner import ControllerRunner

GOAL = {"type": "S_CURVE", "position": [1500.0, 300.0],
        "trajectory": [{"velocity": 20000.0, "acceleration": 200000.0, "deceleration": 200000.0,
                        "jerk_percent": 50.0}]}


def test_a_recording_with_statuses_in_stretches_replays_with_zero_differences(tmp_path):
    raw = config.load().raw
    raw["ros"].update(status_rate=1000.0, joint_states_rate=1000.0)
    cfg = config.parse(raw)
    runner = ControllerRunner(cfg.build_controller(), time_scale=None, publish_period=0.005)
    stretches = []
    step_snapshots = runner.ctl.step_snapshots
    runner.ctl.step_snapshots = lambda samples, at: stretches.append(len(list(at))) or step_snapshots(samples, at)
    recorder = Recorder(runner, tmp_path / "run", cfg, epoch_ns=FIXED_EPOCH_NS)
    try:
        runner.step(9)
        runner.submit(Command("motion_start", 0, request=GOAL))
        runner.step(301)
        runner.submit(Command("action", 0, request={"action": "E_STOP"}))
        runner.step(700)
    finally:
        recorder.close()
    assert max(stretches) == 6  # statuses 10 samples apart at most: 6 of them at 1 kHz
    report = replay(tmp_path / "run")
    assert report.identical, report.summary()
    assert report.statuses >= 1010 // 2
