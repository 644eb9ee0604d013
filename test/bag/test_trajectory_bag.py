"""A recorded JointTrajectory run replays exactly: its chunks are commands recorded with the
sample each took effect at (/mpi/commands), so `mpi-ros replay` applies them at the same
samples and every status, event and joint state comes out the same (docs/trajectories.md)."""

from __future__ import annotations

import math

from mpi_ros import config
from mpi_ros.bag.recorder import Recorder
from mpi_ros.bag.replay import replay
from mpi_ros.bag.scenario import FIXED_EPOCH_NS
from mpi_ros.commands import Operation
from mpi_ros.runner import ControllerRunner
from mpi_ros.trajectory_feed import TrajectoryFeed

RATE = 2000.0  # config/gantry.yaml


def test_a_streamed_and_replaced_trajectory_run_replays_with_zero_differences(tmp_path):
    cfg = config.load("config/gantry.yaml")
    runner = ControllerRunner(cfg.build_controller(), time_scale=None)
    applied = []
    runner.on_command(lambda sample, command, reply: applied.append((sample, command.operation, reply.message.name)))
    recorder = Recorder(runner, tmp_path / "run", cfg, epoch_ns=FIXED_EPOCH_NS)
    warnings: list[str] = []
    feed = TrajectoryFeed(runner, 0, cfg.axis_joints(), FIXED_EPOCH_NS, warnings.append, chunk_points=64)
    try:
        runner.step(10)
        # 300 PVT points, 5 ms apart (5 chunks of at most 64 points, fed one ahead)
        points = [([0.05 * (1 - math.cos(0.5 * t)), 0.02 * t], [0.025 * math.sin(0.5 * t), 0.02], t)
                  for t in (0.005 * (i + 1) for i in range(300))]
        assert feed.receive(["y", "x"], [(p[::-1], v[::-1], t) for p, v, t in points], 0) is None
        runner.step(1000)
        # replaced from a stamp 0.25 s ahead (sample 1510): PT, two points
        stamp = FIXED_EPOCH_NS + round(1510 / RATE * 1e9)
        assert feed.receive(["x", "y"], [([0.01, 0.02], [], 0.5), ([0.0, 0.0], [], 1.0)], stamp) is None
        runner.step(4000)
        # and a refused one: nothing recorded, nothing moves
        assert not feed.receive(["x", "y"], [([0.0, 0.0], [], 0.1), ([5.0, 0.0], [], 0.2)], 0).ok
        runner.step(100)
    finally:
        recorder.close()
    assert warnings
    assert "over its max_velocity" in warnings[0]
    assert len(warnings) == 1
    # The first trajectory's chunks at the start (sample 10: chunks 0 and 1), then each as the
    # one before it begins (its predecessor's predecessor done: 10 + 0.32 s, 10 + 0.64 s); the
    # fifth (due at 10 + 0.96 s) was dropped by the replacement, which took effect at 1510.
    # Each is recorded with the sample after the one it was applied at.
    assert applied == [(s, Operation.JOINT_TRAJECTORY, "MPIMessageOK") for s in (11, 11, 651, 1291, 1511)]
    report = replay(tmp_path / "run")
    assert report.identical, report.summary()
    assert report.commands == len(applied)
    assert report.statuses > 100
