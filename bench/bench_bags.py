"""Bags (issue 10): how fast the fixtures replay, and how fast bags are written and read.

- replay: each fixture of test/fixtures/bags through mpi_ros.bag.replay.replay (what
  ``mpi-ros replay`` runs, less the interpreter's start): the recorded controller time
  (its last sample / the sample rate) over the wall time of the replay, as a multiple of
  real time, best of ``--rounds``; every replay must be exact (zero differences). Also
  the whole ``mpi-ros replay BAG`` command once, interpreter start included.
- write: what a recording holds, MotionStatus, AxisStatus and JointState of a moving
  controller (2 supervisors of 2 axes, the default configuration), through
  mpi_ros.bag.writer.BagWriter: ``write`` (message -> canonical CDR -> MCAP) and
  ``write_raw`` (the CDR already made), zstd-compressed (the default) and not; messages/s
  and MB/s of CDR payload, the bag closed and on disk.
- read: the written bags through mpi_ros.bag.reader.BagReader: ``messages`` (CDR) and
  ``decoded`` (deserialized messages), messages/s and MB/s of CDR payload.

Load figures of the machine are printed with each table (the machine is shared).

    python -P bench/bench_bags.py [--rounds 3] [--messages 60000]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# This source tree, not a stale installed copy (the installed package still supplies the
# generated interfaces: mpi_ros/__init__.py).
REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

FIXTURES = REPO / "test" / "fixtures" / "bags"
EPOCH = 1_700_000_000_000_000_000


def load_average() -> str:
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


def _best(run, rounds: int) -> tuple[float, object]:
    """(the least wall time of ``rounds`` runs, the last run's result)."""
    best, result = float("inf"), None
    for _ in range(rounds):
        start = time.perf_counter()
        result = run()
        best = min(best, time.perf_counter() - start)
    return best, result


# -- replay ----------------------------------------------------------------------------------------
def replay_rows(rounds: int) -> list[str]:
    from mpi_ros.bag.replay import replay

    rows = ["| fixture | controller time | statuses compared | replay (wall, best of "
            f"{rounds}) | x real time | `mpi-ros replay` (wall, with start-up) |",
            "| --- | --- | --- | --- | --- | --- |"]
    total_recorded = total_wall = 0.0
    for bag in sorted(p for p in FIXTURES.iterdir() if p.is_dir()):
        wall, report = _best(lambda bag=bag: replay(bag), rounds)
        assert report.identical, report.summary()
        recorded = report.last_sample / 2000.0  # the fixtures run at the default sample rate
        command = _command_wall(bag)
        total_recorded, total_wall = total_recorded + recorded, total_wall + wall
        rows.append(f"| {bag.name} | {recorded:.2f} s | {report.statuses} ({report.values} values) | "
                    f"{wall * 1e3:.0f} ms | {recorded / wall:.1f} | {command:.2f} s |")
    rows.append(f"| all {len(rows) - 2} | {total_recorded:.2f} s | | {total_wall * 1e3:.0f} ms | "
                f"{total_recorded / total_wall:.1f} | |")
    return rows


def _command_wall(bag: Path) -> float:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-P", "-m", "mpi_ros.cli", "replay", str(bag)], capture_output=True,
                          text=True, env=_env())
    wall = time.perf_counter() - start
    assert done.returncode == 0 and "zero differences" in done.stdout, done.stdout + done.stderr
    return wall


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH", "")) if p)}


# -- a long recording -------------------------------------------------------------------------------
def cycle_commands(samples: int, rate: float = 2000.0) -> list:
    """Both supervisors of the default configuration busy for ``samples``: S-curve moves
    back and forth (one every 1.5 s each, the two out of phase), and in turn a STOP and
    RESUME, an E_STOP and RESET, and a modify of a move in progress; what bench_plot.py's
    recording does through ROS, here at fixed samples so that the bag is the same every time."""
    from mpi_ros.bag.scenario import Step
    from mpi_ros.commands import Command

    period = int(1.5 * rate)
    steps = []
    for k, at in enumerate(range(5, samples - period, period // 2)):
        ms = k % 2
        sign = (-1) ** (k // 2)
        move = {"type": "S_CURVE", "position": [sign * 20000.0, sign * 5000.0],
                "trajectory": [{"velocity": 20000.0, "acceleration": 100000.0, "deceleration": 100000.0,
                                "jerk_percent": 50.0}]}
        steps.append(Step(at, Command("motion_start", ms, -1, move)))
        later = at + period // 5
        if k % 3 == 1:
            steps += [Step(later, Command("action", ms, -1, {"action": "STOP"})),
                      Step(later + 400, Command("action", ms, -1, {"action": "RESUME"}))]
        elif k % 5 == 2:
            steps += [Step(later, Command("action", ms, -1, {"action": "E_STOP"})),
                      Step(later + 300, Command("action", ms, -1, {"action": "RESET"}))]
        elif k % 7 == 4:
            modified = {**move, "position": [sign * 15000.0, sign * 3000.0]}
            steps.append(Step(later, Command("motion_modify", ms, -1, modified)))
    return sorted(steps, key=lambda step: step.at)


def three_minutes(directory: Path, seconds: float = 180.0) -> Path:
    """A recording of the default configuration (status and joint states at 100 Hz) of
    ``seconds`` of controller time, made headless (mpi_ros.bag.scenario, as the fixtures
    are): the same bag every time."""
    from mpi_ros.bag import scenario

    samples = int(seconds * 2000)
    return scenario.record(scenario.Scenario("three_minutes", samples, {}, cycle_commands(samples)), directory)


# -- write and read ----------------------------------------------------------------------------------
def recording(count: int) -> list[tuple[str, object, int]]:
    """``count`` (topic, message, log time) as the recorder makes them: every status and the
    joint states of the default configuration at 100 Hz, the axes moving (S-curves back
    and forth, so states, flags and values change)."""
    from mpi_ros import config
    from mpi_ros.mpi import MotionAttr, MotionParams, MPIMotionType, MPIState, Trajectory
    from mpi_ros.ros import convert

    ctl = config.load().build_controller()
    out: list[tuple[str, object, int]] = []
    flip = 1.0
    while len(out) < count:
        for ms in ctl.supervisors:
            if ms.state is MPIState.IDLE:
                flip = -flip
                ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE, MotionParams(
                    trajectory=[Trajectory(5000.0, 50000.0, 50000.0, 50.0)], position=[2000.0 * flip, -700.0 * flip]))
        ctl.step(20)
        t = convert.stamp_ns(ctl.sample, ctl.rate, EPOCH)
        out += [(f"/mpi/ms{ms.number}/status", convert.motion_status(ms.snapshot(), ctl.rate, EPOCH), t)
                for ms in ctl.supervisors]
        out += [(f"/mpi/axis{a.number}/status", convert.axis_status(ctl.axis_snapshot(a.number), ctl.rate, EPOCH), t)
                for a in ctl.axes]
        out.append(("/joint_states", convert.joint_state(ctl, EPOCH), t))
    return out[:count]


def write_read_rows(count: int, rounds: int) -> list[str]:
    from mpi_ros.bag import cdr, schema
    from mpi_ros.bag.reader import BagReader
    from mpi_ros.bag.writer import BagWriter

    messages = recording(count)
    raw = [(topic, schema.full_name(type(msg)), cdr.serialize(msg), t) for topic, msg, t in messages]
    payload = sum(len(data) for _, _, data, _ in raw) / 1e6
    rows = [f"{count} messages ({payload:.1f} MB of CDR, {payload * 1e6 / count:.0f} bytes each on average: "
            "MotionStatus, AxisStatus and JointState); best of " + str(rounds),
            "", "| operation | compression | wall | messages/s | MB/s (CDR) | bag on disk |",
            "| --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory(prefix="bench_bags_") as tmp:
        for compress in (True, False):
            label = "zstd" if compress else "none"
            bags = []
            for how in ("write", "write_raw"):
                def run(how=how, compress=compress, label=label):
                    directory = Path(tmp) / f"{how}_{label}_{time.perf_counter_ns()}"
                    with BagWriter(directory, compress=compress) as bag:
                        if how == "write":
                            for topic, msg, t in messages:
                                bag.write(topic, msg, t)
                        else:
                            for topic, kind, data, t in raw:
                                bag.write_raw(topic, kind, data, t)
                    return directory
                wall, directory = _best(run, rounds)
                bags.append(directory)
                size = sum(f.stat().st_size for f in directory.iterdir()) / 1e6
                rows.append(f"| BagWriter.{how} | {label} | {wall:.2f} s | {count / wall:,.0f} | "
                            f"{payload / wall:.1f} | {size:.1f} MB |")
            for how in ("messages", "decoded"):
                reader = BagReader(bags[0])
                wall, read = _best(lambda how=how, reader=reader: sum(1 for _ in getattr(reader, how)()), rounds)
                assert read == count, (read, count)
                rows.append(f"| BagReader.{how} | {label} | {wall:.2f} s | {count / wall:,.0f} | "
                            f"{payload / wall:.1f} | |")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--messages", type=int, default=60_000)
    args = parser.parse_args()
    print(f"Load before: {load_average()}")
    print()
    print("\n".join(replay_rows(args.rounds)))
    print()
    print("\n".join(write_read_rows(args.messages, args.rounds)))
    print()
    print(f"Load after: {load_average()}")


if __name__ == "__main__":
    main()
