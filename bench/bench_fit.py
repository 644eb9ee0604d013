"""mpi-ros fit (issue 37): a fit of 60 s at 2 kHz for 4 axes, target under 30 s.

The recording: per axis a minute of point-to-point moves (quintic, so position, velocity and
acceleration are continuous; sizes, durations and pauses drawn at random), through a known
second-order loop with feed-forward simulated with scipy.signal.lsim (not the twin's code),
white noise of 0.2 counts added and the result read by a 1-count encoder. Written as a CSV of
the suite's layout, 120,001 rows x 4 axes.

Measured: the whole command, ``mpi-ros fit FILE.csv`` in a fresh interpreter (start, reading
the CSV, the four fits, printing), wall time best of ``--rounds``, with that process's CPU
time; and each axis' fit alone in this process (mpi_ros.calibration.fit.fit_axis: wall and
CPU time, runs of the plant, the parameters recovered). Load figures of the machine are
printed with the table (the machine is shared).

    python -P bench/bench_fit.py [--rounds 3] [--seconds 60] [--rate 2000]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

PLANTS = (  # bandwidth_hz, damping, velocity_feedforward, acceleration_feedforward
    (45.0, 0.55, 0.8, 0.3),
    (22.0, 0.85, 0.6, 0.7),
    (80.0, 0.4, 0.95, 0.1),
    (12.0, 0.7, 0.5, 0.5),
)


def load_average() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def command(seconds: float, rate: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Times and a command of quintic moves with pauses between them."""
    t = np.arange(round(seconds * rate) + 1) / rate
    u = np.zeros_like(t)
    start, position = 0.05, 0.0
    while start < seconds:
        duration = rng.uniform(0.08, 0.6)
        target = position + rng.uniform(-20_000.0, 20_000.0)
        tau = np.clip((t - start) / duration, 0.0, 1.0)
        u += (target - position) * (10 * tau**3 - 15 * tau**4 + 6 * tau**5) * (t >= start)
        position = target
        start += duration + rng.uniform(0.02, 0.4)
    return t, u


def machine(t: np.ndarray, u: np.ndarray, plant: tuple[float, float, float, float],
            rng: np.random.Generator) -> np.ndarray:
    from scipy.signal import lsim

    bandwidth, damping, kv, ka = plant
    w = 2.0 * np.pi * bandwidth
    _, y, _ = lsim(([ka, 2.0 * damping * w * kv, w * w], [1.0, 2.0 * damping * w, w * w]), u, t)
    return np.floor(y + rng.normal(0.0, 0.2, len(t)) + 0.5)


def write_csv(path: Path, seconds: float, rate: float) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(37)
    columns: dict[str, np.ndarray] = {}
    axes = {}
    for axis, plant in enumerate(PLANTS):
        t, u = command(seconds, rate, rng)
        y = machine(t, u, plant, rng)
        columns["time"] = t
        columns[f"axis{axis}_command_position"] = u
        columns[f"axis{axis}_actual_position"] = y
        axes[axis] = (t, u, y)
    table = np.column_stack(list(columns.values()))
    np.savetxt(path, table, delimiter=",", header=",".join(columns), comments="", fmt="%.10g")
    return axes


def cli_round(path: Path) -> tuple[float, float, str]:
    """Wall and CPU seconds of ``mpi-ros fit path`` in a fresh interpreter, and its output."""
    env = dict(os.environ, PYTHONPATH=str(REPO))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-P", "-m", "mpi_ros.cli", "fit", str(path)], env=env,
                          capture_output=True, text=True, timeout=600, check=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, done.stdout


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=2000.0)
    args = parser.parse_args()
    from mpi_ros.calibration.fit import fit_axis
    from mpi_ros.calibration.recording import AxisRecording
    from mpi_ros.mpi.base.params import PlantConfig

    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "machine.csv"
        axes = write_csv(path, args.seconds, args.rate)
        size = path.stat().st_size / 1e6
        print(f"recording: {args.seconds:g} s at {args.rate:g} Hz, {len(PLANTS)} axes, {size:.1f} MB CSV")
        print(f"load before: {load_average()}")
        rounds = [cli_round(path) for _ in range(args.rounds)]
        best = min(rounds, key=lambda r: r[0])
        print(f"load after the command: {load_average()}")
        print("| mpi-ros fit (4 axes, whole command) | wall s (best) | CPU s of that run | all rounds, wall s |")
        print("| --- | --- | --- | --- |")
        print(f"| {args.seconds:g} s at {args.rate:g} Hz | {best[0]:.1f} | {best[1]:.1f} | "
              f"{', '.join(f'{r[0]:.1f}' for r in rounds)} |")
        print()
        print("| axis | true (bw, zeta, kv, ka) | fitted | wall s | CPU s | plant runs | match |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
        for axis, (t, u, y) in axes.items():
            started, cpu = time.perf_counter(), time.process_time()
            fit = fit_axis(AxisRecording(axis, t, u, y), args.rate, PlantConfig())
            wall, cpu = time.perf_counter() - started, time.process_time() - cpu
            f = fit.fitted
            fitted = f"{f.bandwidth_hz:.3f}, {f.damping:.4f}, {f.velocity_feedforward:.4f}, " \
                     f"{f.acceleration_feedforward:.4f}"
            print(f"| {axis} | {', '.join(f'{x:g}' for x in PLANTS[axis])} | {fitted} | {wall:.1f} | {cpu:.1f} | "
                  f"{fit.evaluations} | {'yes' if fit.matched else 'no'} |")
        print(f"load at the end: {load_average()}")


if __name__ == "__main__":
    main()
