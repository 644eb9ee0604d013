"""Recordings for the calibration tests: the twin's own controller run in-process (ROS-free)
with known plant parameters, and a plant the twin cannot represent (scipy.signal).

Fixtures: ``made`` (the controller's run, once per session: stepping it takes seconds),
``noisy`` and ``third_order`` (functions making an AxisRecording of it).

The controller is stepped a few samples at a time and its axes read after each step, as a
status recorder at ``rate / every`` would read them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from mpi_ros import config as suite_config
from mpi_ros.calibration.recording import AxisRecording
from mpi_ros.mpi import MotionParams, MPIMotionType, Trajectory

RATE = 2000.0
EVERY = 4  # samples between readings: a 500 Hz recording of a 2 kHz controller
# Per axis, far from the defaults (30 Hz, 0.7, 0.9, 0.0): what a fit must find again.
TRUE_PLANTS = {
    0: {"bandwidth_hz": 45.0, "damping": 0.55, "velocity_feedforward": 0.8, "acceleration_feedforward": 0.3},
    1: {"bandwidth_hz": 22.0, "damping": 0.85, "velocity_feedforward": 0.6, "acceleration_feedforward": 0.7},
}
# Vector moves of supervisor 0 (axes 0 and 1): targets, velocity, acceleration, jerk percent,
# samples to run. Different speeds, ramps and jerks, so that bandwidth, damping and both
# feed-forwards each leave their own mark on the following error.
MOVES = (
    ((20_000.0, -8_000.0), 20_000.0, 400_000.0, 50.0, 2400),
    ((4_000.0, 2_000.0), 30_000.0, 200_000.0, 0.0, 2400),
    ((14_000.0, 9_000.0), 10_000.0, 800_000.0, 80.0, 3000),
)


@dataclass(frozen=True)
class Made:
    """What the controller did: per axis, times, command and actual position."""

    time: np.ndarray
    command: dict[int, np.ndarray]
    actual: dict[int, np.ndarray]


def twin_run(every: int = 2, encoder_resolution: float = 0.0) -> Made:
    """The moves on a controller whose axes 0 and 1 have TRUE_PLANTS, read every ``every`` samples."""
    overrides = {n: {"plant": dict(p, encoder_resolution=encoder_resolution)} for n, p in TRUE_PLANTS.items()}
    ctl = suite_config.load(overrides={"axes": {"overrides": overrides}}).build_controller()
    ms = ctl.supervisor(0)
    assert ms is not None
    times: list[float] = []
    rows: list[tuple[float, float, float, float]] = []

    def record(samples: int) -> None:
        for _ in range(samples // every):
            ctl.step(every)
            a, b = ctl.axis_snapshots([0, 1])
            times.append(ctl.sample / ctl.rate)
            rows.append((a.command_position, a.actual_position, b.command_position, b.actual_position))

    record(20)
    for target, velocity, acceleration, jerk, samples in MOVES:
        params = MotionParams(trajectory=[Trajectory(velocity, acceleration, acceleration, jerk)],
                              position=list(target))
        assert ms.start(MPIMotionType.S_CURVE, params=params).ok
        record(samples)
    values = np.array(rows)
    return Made(np.array(times), {0: values[:, 0], 1: values[:, 2]}, {0: values[:, 1], 1: values[:, 3]})


def noisy(made: Made, axis: int, sigma: float, step: float, seed: int = 7) -> AxisRecording:
    """One axis of ``made`` as an encoder of ``step`` counts reads it, with white noise of
    ``sigma`` counts on the position before the encoder rounds it."""
    rng = np.random.default_rng(seed + axis)
    actual = made.actual[axis] + rng.normal(0.0, sigma, len(made.time))
    if step > 0.0:
        actual = np.floor(actual / step + 0.5) * step
    return AxisRecording(axis, made.time.copy(), made.command[axis].copy(), actual)


def third_order(made: Made, axis: int, extra_pole_hz: float, sigma: float, step: float,
                damping: float | None = None) -> AxisRecording:
    """The command of ``made``'s axis through a plant the twin cannot represent: the true
    second-order loop of TRUE_PLANTS[axis] (or with ``damping``) followed by a first-order lag (an extra pole),
    simulated with scipy.signal.lsim on the linearly interpolated command."""
    from scipy.signal import lsim

    p = TRUE_PLANTS[axis]
    w = 2.0 * np.pi * p["bandwidth_hz"]
    z = p["damping"] if damping is None else damping
    pole = 2.0 * np.pi * extra_pole_hz
    num = np.polymul([p["acceleration_feedforward"], 2.0 * z * w * p["velocity_feedforward"], w * w], [pole])
    den = np.polymul([1.0, 2.0 * z * w, w * w], [1.0, pole])
    t = made.time - made.time[0]
    fine = np.arange(round(t[-1] * RATE) + 1) / RATE
    command = np.interp(fine, t, made.command[axis])
    # Settled on the first command (at rest): the states of a plant at rest are its position only.
    _, out, _ = lsim((num, den), command - command[0], fine)
    actual = np.interp(t, fine, out + command[0])
    clean = Made(made.time, {axis: made.command[axis]}, {axis: actual})
    return noisy(clean, axis, sigma, step)


@pytest.fixture(scope="session")
def made() -> Made:
    return twin_run(every=EVERY)


@pytest.fixture
def make_noisy():
    return noisy


@pytest.fixture
def make_third_order():
    return third_order


@pytest.fixture
def true_plants() -> dict[int, dict[str, float]]:
    return TRUE_PLANTS


def write_csv(path, recordings: list[AxisRecording]) -> None:
    """``recordings`` (same times) as a CSV of this suite's layout."""
    columns = {"time": recordings[0].time}
    for r in recordings:
        columns[f"axis{r.number}_command_position"] = r.command
        columns[f"axis{r.number}_actual_position"] = r.actual
    rows = [",".join(columns)]
    rows += [",".join(repr(float(c[i])) for c in columns.values()) for i in range(len(recordings[0].time))]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


@pytest.fixture
def csv_of():
    return write_csv
