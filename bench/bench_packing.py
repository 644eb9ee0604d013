"""Packing a sample's statuses: what the status topics encode at each status sample.

At every status sample the controller node packs every axis' AxisStatus, each supervisor
node its MotionStatus (which holds its axes' again), and the controller node the JointState
and the clock (controller_node.py, supervisor_node.py; the CDR of mpi_ros/ros/wire.py). Timed
here without ROS, as the nodes' callbacks encode them, from the snapshots of samples new to
the packer (every axis in a VELOCITY move: bench_controller's _controller and _velocity; 8
axes in 4 supervisors, 32 in 16). A tree without ``convert.joint_readings`` reads the joints as
its node did (a dict of the snapshots, convert.joint_values), one without ``wire.clock`` builds
a rosgraph_msgs/Clock (the message only: rclpy converts it again when it publishes).

Each tree (this one and ``--baseline``, extracted with git archive) runs every case in a
fresh process, the trees alternating ``--rounds`` times; a figure is the best CPU time
(process_time) of a sample in its process, and the ratio compares the two trees' figures.

    python -P bench/bench_packing.py [--baseline main] [--rounds 3]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run with -P: the sibling bench_controller
from bench_controller import compared_trees, least_side_by_side

CASES = [(8, 4), (32, 16)]
PARTS = ("axis statuses", "motion statuses", "joint state", "clock", "a sample")
SAMPLES, REPEAT = 400, 7
EPOCH = 1_795_000_000_123_456_789


def _encoders(ctl) -> dict[str, Callable]:
    """Each part's encoding of one sample's snapshots (motions, axes), as this tree's nodes do."""
    from rosgraph_msgs.msg import Clock

    from mpi_ros.ros import convert, wire

    packer = wire.Packer(ctl.rate, EPOCH)
    names = convert.joint_names(ctl)

    def axes(motions, snaps):
        return [packer.axis_status(snap) for snap in snaps]

    def joints(motions, snaps):
        if hasattr(convert, "joint_readings"):
            values = convert.joint_readings(snaps)
        else:
            values = convert.joint_values(ctl, {snap.number: snap for snap in snaps})
        return wire.joint_state(snaps[0].sample, ctl.rate, EPOCH, names, *values)

    def clock(motions, snaps):
        if hasattr(wire, "clock"):
            return wire.clock(snaps[0].sample, ctl.rate, EPOCH)
        return Clock(clock=convert.stamp(snaps[0].sample, ctl.rate, EPOCH))

    return {"axis statuses": axes, "motion statuses": lambda motions, snaps: [
        packer.motion_status(snap) for snap in motions.values()], "joint state": joints, "clock": clock}


def measure(axes: int, supervisors: int) -> dict[str, float]:
    """Each of PARTS' best CPU time a sample, in microseconds (the axes' first: the motions
    find their bodies packed, as in the suite, where the controller node's callback runs first)."""
    from bench_controller import _controller, _velocity

    ctl = _controller(axes, supervisors)
    _velocity(ctl)
    batches = [list(ctl.step_snapshots(20, range(ctl.sample + 2, ctl.sample + 21, 2)).values())
               for _ in range(SAMPLES // 10)]
    samples = [taken for batch in batches for taken in batch]
    encoders = _encoders(ctl)
    best = dict.fromkeys(PARTS, float("inf"))
    for _ in range(REPEAT):
        spent = dict.fromkeys(encoders, 0.0)
        for motions, snaps in samples:
            for part, encode in encoders.items():
                start = time.process_time()
                encode(motions, snaps)
                spent[part] += time.process_time() - start
        for part, seconds in spent.items():
            best[part] = min(best[part], seconds / len(samples) * 1e6)
        best["a sample"] = min(best["a sample"], sum(spent.values()) / len(samples) * 1e6)
    return best


def main(baseline: str, rounds: int) -> list[str]:
    rows = [f"| axes / supervisors | part | this tree (us) | {baseline} (us) | {baseline} / this tree |",
            "| --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as scratch:
        trees = compared_trees(baseline, Path(scratch))
        for case in CASES:
            best = least_side_by_side(trees, case, "bench_packing", rounds)
            for part in PARTS:
                new = best["this tree"][part]
                old = best[baseline][part] if baseline in best else float("nan")
                rows.append(f"| {case[0]} / {case[1]} | {part} | {new:,.1f} | {old:,.1f} | {old / new:.2f}x |")
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="main", help="commit to measure side by side ('none': only this tree)")
    parser.add_argument("--rounds", type=int, default=3, help="processes of each case on each tree (best kept)")
    options = parser.parse_args()
    print("\n".join(main(options.baseline, options.rounds)))
