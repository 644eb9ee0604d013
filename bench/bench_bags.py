"""Bags (issue 10): how fast the fixtures replay, and how fast bags are written and read.

- replay: each fixture of test/fixtures/bags and a recording of ``--seconds`` (3 minutes)
  of the default configuration, made by this bench (:func:`three_minutes`, headless and
  the same every time), through mpi_ros.bag.replay.replay (what ``mpi-ros replay`` runs,
  less the interpreter's start), each in a fresh process, with this tree and with
  ``--baseline`` alternating: the recorded controller time (its last sample / the sample
  rate) over the replay's thread CPU time (and wall time), as a multiple of real time,
  best of ``--rounds``; every replay must be exact (zero differences). Also the whole
  ``mpi-ros replay BAG`` command on the long recording once, interpreter start included.
- parts (``--only parts``, not run otherwise): where this tree's replay of the long recording
  spends its thread CPU time: reading the bag, stepping with the snapshots (and the snapshots
  alone), packing and comparing the statuses, the commands.
- write: what a recording holds, MotionStatus, AxisStatus and JointState of a moving
  controller (2 supervisors of 2 axes, the default configuration), through
  mpi_ros.bag.writer.BagWriter: ``write`` (message -> canonical CDR -> MCAP) and
  ``write_raw`` (the CDR already made), zstd-compressed (the default) and not; messages/s
  and MB/s of CDR payload, the bag closed and on disk.
- read: the written bags through mpi_ros.bag.reader.BagReader: ``messages`` (CDR) and
  ``decoded`` (deserialized messages), messages/s and MB/s of CDR payload.

Load figures of the machine are printed with each table (the machine is shared).

    python -P bench/bench_bags.py [--rounds 3] [--messages 60000] [--seconds 180] [--baseline REV]
                                  [--only replay|write|parts]
"""

from __future__ import annotations

import argparse
import json
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
sys.path.insert(0, str(REPO / "bench"))  # run with -P: the sibling bench_controller
from bench_controller import compared_trees  # noqa: E402 - after the path it is found on

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
_MEASURE = """
import json, sys, time
sys.path.insert(0, sys.argv[1])
from mpi_ros.bag.replay import replay
wall, cpu = time.perf_counter(), time.thread_time()
report = replay(sys.argv[2])
wall, cpu = time.perf_counter() - wall, time.thread_time() - cpu
print(json.dumps({"wall": wall, "cpu": cpu, "identical": report.identical, "summary": report.summary(),
                  "last_sample": report.last_sample, "statuses": report.statuses, "values": report.values}))
"""


# Where a replay's thread CPU time goes: each phase's functions wrapped with a timer (the
# snapshots, their templates and the objects built from them, are inside the stepping's
# figure, and so is the garbage collector's time there; "the rest" is what no phase covers).
_PARTS = """
import json, sys, time
sys.path.insert(0, sys.argv[1])
from mpi_ros.bag import replay as R
from mpi_ros.mpi import snapshots
from mpi_ros.mpi.control import Controller
spent = {}
def timed(name, run):
    def wrapper(*args, **kwargs):
        start = time.thread_time()
        try:
            return run(*args, **kwargs)
        finally:
            spent[name] = spent.get(name, 0.0) + time.thread_time() - start
    return wrapper
R._timeline = timed("reading the bag (timeline)", R._timeline)
R._Statuses.take = timed("stepping with snapshots", R._Statuses.take)
for owner, name in ((Controller, "status_template"), (getattr(snapshots, "StatusTemplate", None), "at")):
    if hasattr(owner, name):  # where the snapshots of a stretch are made
        setattr(owner, name, timed("of which the snapshots", getattr(owner, name)))
R._Statuses.compare_run = timed("packing and comparing the statuses", R._Statuses.compare_run)
R._apply = timed("the commands (stepping to them, applying)", R._apply)
start = time.thread_time()
report = R.replay(sys.argv[2])
print(json.dumps({"total": time.thread_time() - start, "identical": report.identical, **spent}))
"""


def parts_rows(bag: Path, rounds: int) -> list[str]:
    """The phases of this tree's replay of ``bag`` (fresh processes, the run of least total
    CPU of ``rounds``): thread CPU time and share of the total."""
    best: dict = {}
    for _ in range(rounds):
        done = subprocess.run([sys.executable, "-P", "-c", _PARTS, str(REPO), str(bag)], check=True,
                              capture_output=True, text=True, env=_env())
        run = json.loads(done.stdout.splitlines()[-1])
        assert run.pop("identical")
        if not best or run["total"] < best["total"]:
            best = run
    total = best.pop("total")
    rows = [f"| phase ({bag.name}, this tree, best of {rounds}) | CPU | share |", "| --- | --- | --- |"]
    order = ["reading the bag (timeline)", "stepping with snapshots", "of which the snapshots",
             "packing and comparing the statuses", "the commands (stepping to them, applying)"]
    rows += [f"| {name} | {best[name] * 1e3:,.0f} ms | {best[name] / total:.0%} |" for name in order if name in best]
    covered = total - sum(v for k, v in best.items() if k != "of which the snapshots")
    rows += [f"| the rest | {covered * 1e3:,.0f} ms | {covered / total:.0%} |", f"| total | {total * 1e3:,.0f} ms | |"]
    return rows


def replay_in(tree: Path, bag: Path) -> dict:
    """Replay ``bag`` with the package in ``tree``, in a fresh process: wall and thread CPU
    time of the replay alone (imports and start-up left out), and its report."""
    done = subprocess.run([sys.executable, "-P", "-c", _MEASURE, str(tree), str(bag)], check=True,
                          capture_output=True, text=True, env=_env())
    result = json.loads(done.stdout.splitlines()[-1])
    assert result["identical"], result["summary"]
    return result


def replay_rows(bags: list[Path], trees: list[tuple[Path, str]], rounds: int) -> list[str]:
    """Each bag replayed by each tree, the trees alternating ``rounds`` times, best kept;
    "x real time" is the controller time over the replay's thread CPU time (wall in brackets)."""
    names = [name for _, name in trees]
    rows = ["| bag | controller time | statuses compared | " + " | ".join(
                f"{name}: CPU (wall), best of {rounds} | {name}: x real time, CPU (wall)" for name in names)
            + (f" | speed-up (CPU) over {names[1]} |" if len(trees) > 1 else " |"),
            "| --- | --- | --- |" + " --- | --- |" * len(trees) + (" --- |" if len(trees) > 1 else "")]
    for bag in bags:
        best: dict[str, dict] = {}
        for _ in range(rounds):
            for tree, name in trees:  # alternate, so both see the same load
                run = replay_in(tree, bag)
                if name not in best or run["cpu"] < best[name]["cpu"]:
                    best[name] = run
        first = best[names[0]]
        recorded = first["last_sample"] / 2000.0  # the default sample rate
        row = f"| {bag.name} | {recorded:.1f} s | {first['statuses']} ({first['values']} values) |"
        for name in names:
            run = best[name]
            row += (f" {run['cpu'] * 1e3:,.0f} ms ({run['wall'] * 1e3:,.0f} ms) | "
                    f"{recorded / run['cpu']:.1f} ({recorded / run['wall']:.1f}) |")
        if len(trees) > 1:
            row += f" {best[names[1]]['cpu'] / first['cpu']:.2f}x |"
        rows.append(row)
    return rows


def command_row(bag: Path) -> str:
    """The whole ``mpi-ros replay BAG`` command once, interpreter start and imports included."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-P", "-m", "mpi_ros.cli", "replay", str(bag)], capture_output=True,
                          text=True, env=_env())
    wall = time.perf_counter() - start
    assert done.returncode == 0 and "zero differences" in done.stdout, done.stdout + done.stderr
    return f"`mpi-ros replay {bag.name}` (this tree, start-up included): {wall:.2f} s wall"


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
    parser.add_argument("--seconds", type=float, default=180.0, help="the long recording's controller time")
    parser.add_argument("--baseline", default="none", help="a revision to replay with side by side (git archive)")
    parser.add_argument("--only", choices=("replay", "write", "parts"),
                        help="one part only (parts: where the long recording's replay spends its time)")
    args = parser.parse_args()
    print(f"Load before: {load_average()}")
    with tempfile.TemporaryDirectory(prefix="bench_bags_") as tmp:
        if args.only == "parts":
            long = three_minutes(Path(tmp) / f"recording_{args.seconds:.0f}s", args.seconds)
            print()
            print("\n".join(parts_rows(long, args.rounds)))
        elif args.only != "write":
            trees = compared_trees(args.baseline, Path(tmp))
            long = three_minutes(Path(tmp) / f"recording_{args.seconds:.0f}s", args.seconds)
            fixtures = sorted(p for p in FIXTURES.iterdir() if p.is_dir())
            print()
            print("\n".join(replay_rows([*fixtures, long], trees, args.rounds)))
            print()
            print(command_row(long))
        if args.only not in ("replay", "parts"):
            print()
            print("\n".join(write_read_rows(args.messages, args.rounds)))
    print()
    print(f"Load after: {load_average()}")


if __name__ == "__main__":
    main()
