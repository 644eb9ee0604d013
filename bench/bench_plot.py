"""How long `mpi-ros plot BAG` takes on a 3-minute recording of the default configuration
(issue 36: it took 52 s; the target is under 5 s).

The recording: ``mpi-ros run --record`` (this tree, default configuration, real time) for
``--seconds`` while this process drives both supervisors through a cycle that leaves
every kind of mark on the plot (S-curve moves, a STOP and RESUME, an E_STOP and RESET, a
short E_STOP). ``--bag`` plots an existing recording instead.

The plotting: ``python -P -m mpi_ros.cli plot BAG -o PNG`` as a process (imports
included, as a user waits for it), this tree and ``--baseline`` (git archive) alternating,
``--runs`` each; wall time and CPU time of the process.

    python -P bench/bench_plot.py [--seconds 180] [--runs 3] [--baseline REV|none] [--bag BAG] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))  # run with -P: the sibling bench_controller
from bench_controller import compared_trees  # noqa: E402 - after the path it is found on

os.environ.setdefault("ROS_DOMAIN_ID", str(random.Random(os.getpid()).randint(150, 200)))
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH", "")) if p)
BASELINE = "e99f630"  # before issue 36
WAIT = 30.0


def record(bag: Path, seconds: float) -> None:
    """``seconds`` of the default configuration in real time, both supervisors busy."""
    import signal

    import rclpy

    from mpi_ros.client import MotionClient

    suite = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--record", str(bag)], cwd=REPO,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        clients = [MotionClient(n, context=context, timeout=WAIT, node_name=f"bench_plot_ms{n}") for n in (0, 1)]
        for client in clients:
            assert client.wait_for_server(WAIT), "the suite did not come up"
        end = time.monotonic() + seconds
        step = 0
        while time.monotonic() < end:
            _cycle(clients[step % 2], step)
            step += 1
        for client in clients:
            client.close()
    finally:
        suite.send_signal(signal.SIGINT)
        suite.wait(60)
        context.try_shutdown()


def _cycle(client, step: int) -> None:
    """One move, and every few moves a STOP/RESUME, an E_STOP/RESET or a short E_STOP."""
    sign = (-1) ** (step // 2)  # each supervisor (every other step) goes back and forth
    target = [sign * 20000.0, sign * 5000.0]
    goal = client.start({"type": "S_CURVE", "position": target,
                         "trajectory": [{"velocity": 20000.0, "acceleration": 100000.0, "deceleration": 100000.0,
                                         "jerk_percent": 50.0}]})
    if step % 3 == 1 and _moving(client) and client.action("STOP", raise_on_error=False).ok:
        client.wait_for_state("STOPPED", WAIT)
        client.resume()
    if step % 5 == 2 and _moving(client):
        client.e_stop()
        client.wait_for_state("ERROR", WAIT)
        client.reset()
        client.wait_for_state("IDLE", WAIT)
    goal.wait(WAIT, raise_on_error=False)
    if step % 7 == 3:  # an E_STOP while idle: a band of a few milliseconds
        client.e_stop()
        client.wait_for_state("ERROR", WAIT)
        client.reset()
        client.wait_for_state("IDLE", WAIT)


def _moving(client) -> bool:
    """Whether the move runs (a short one may be over before its status shows it)."""
    from mpi_ros.errors import NoResponse

    try:
        client.wait_for_state("MOVING", 2.0)
    except NoResponse:
        return False
    return True


def plot_once(tree: Path, bag: Path, png: Path) -> tuple[float, float]:
    """(wall s, CPU s) of `mpi-ros plot BAG -o PNG` run from ``tree``."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(tree), os.environ.get("PYTHONPATH", "")) if p))
    start = time.monotonic()
    process = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "plot", str(bag), "-o", str(png)],
                               cwd=tree, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.monotonic() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"plot from {tree} failed: {process.stderr.read().decode() if process.stderr else ''}")
    return wall, usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=180.0, help="length of the recording (default 180)")
    parser.add_argument("--runs", type=int, default=3, help="plots per tree (default 3)")
    parser.add_argument("--baseline", default=BASELINE, help=f"revision to compare with (default {BASELINE}), or none")
    parser.add_argument("--bag", type=Path, help="plot this recording instead of making one")
    parser.add_argument("--keep", type=Path, help="copy the recording and the PNGs into this directory")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_plot_") as scratch_name:
        scratch = Path(scratch_name)
        bag = args.bag
        if bag is None:
            bag = scratch / "three_minutes"
            record(bag, args.seconds)
        trees = compared_trees(args.baseline, scratch)
        times: dict[str, list[tuple[float, float]]] = {name: [] for _, name in trees}
        loads = [os.getloadavg()[0]]
        for run in range(args.runs):
            for tree, name in trees:
                times[name].append(plot_once(tree, bag, scratch / f"{name.replace(' ', '_')}_{run}.png"))
                loads.append(os.getloadavg()[0])
        size = sum(f.stat().st_size for f in Path(bag).rglob("*") if f.is_file())
        print(f"recording: {bag.name}, {size / 1e6:.1f} MB; 1-minute load average {min(loads):.1f} to "
              f"{max(loads):.1f} during the plots")
        print()
        print("| tree | runs | wall median | wall max | CPU median |")
        print("| --- | --- | --- | --- | --- |")
        for name, runs in times.items():
            print(f"| {name} | {len(runs)} | {statistics.median(w for w, _ in runs):.1f} s | "
                  f"{max(w for w, _ in runs):.1f} s | {statistics.median(c for _, c in runs):.1f} s |")
        if args.keep:
            args.keep.mkdir(parents=True, exist_ok=True)
            for png in scratch.glob("*.png"):
                shutil.copy(png, args.keep / png.name)
            if args.bag is None:
                shutil.copytree(bag, args.keep / bag.name, dirs_exist_ok=True)


if __name__ == "__main__":
    main()
