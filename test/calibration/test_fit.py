"""mpi-ros fit's core (issue: the twin matched to a real machine): the twin's own plant run on
a recorded command reproduces the controller; plants the twin made itself, with noise and an
encoder's rounding, are found again; a plant it cannot represent is reported as such."""

from __future__ import annotations

import numpy as np
import pytest

from mpi_ros.calibration.fit import encoder_step, fit_axis, split_noise
from mpi_ros.calibration.recording import AxisRecording
from mpi_ros.calibration.twin import AxisTwin
from mpi_ros.mpi.base.params import PlantConfig

RATE = 2000.0


def test_the_twin_run_on_the_recorded_command_is_the_controller(made, true_plants):
    # Noise-free, unrounded: what the controller's axis did, against the plant run here on its
    # recorded command (a 500 Hz reading of it). The difference is what the spline through the
    # samples misses of the command's jerk steps: hundredths of a count in tens.
    for axis, plant in true_plants.items():
        recording = AxisRecording(axis, made.time, made.command[axis], made.actual[axis])
        twin = AxisTwin(recording, RATE)
        following = np.abs(recording.command - recording.actual).max()
        same = np.abs(twin.actual(PlantConfig(**plant), read=False) - recording.actual).max()
        other = np.abs(twin.actual(PlantConfig(), read=False) - recording.actual).max()
        assert following > 20.0
        assert same < 0.05, same
        assert other > 1.0


def test_off_grid_times_read_the_twin_between_its_samples(made, true_plants):
    # Recorded times off the controller's grid (jittered by up to a third of a sample) are read
    # by Hermite interpolation; the command there is the recorded one, interpolated.
    rng = np.random.default_rng(3)
    t = made.time + rng.uniform(-1.0, 1.0, len(made.time)) / (3.0 * RATE)
    t[0] = made.time[0]
    command = np.interp(t, made.time, made.command[0])
    on_grid = AxisTwin(AxisRecording(0, made.time, made.command[0], made.actual[0]), RATE)
    off_grid = AxisTwin(AxisRecording(0, t, command, command), RATE)
    plant = PlantConfig(**true_plants[0])
    expected = np.interp(t, made.time, on_grid.actual(plant, read=False))
    assert np.abs(off_grid.actual(plant, read=False) - expected).max() < 0.5


@pytest.mark.parametrize("axis", [0, 1])
def test_fit_finds_the_plant_that_made_the_recording(made, make_noisy, true_plants, axis):
    recording = make_noisy(made, axis, sigma=0.2, step=0.5)
    fit = fit_axis(recording, RATE, PlantConfig())
    true = true_plants[axis]
    for key in ("bandwidth_hz", "velocity_feedforward", "acceleration_feedforward"):
        assert getattr(fit.fitted, key) == pytest.approx(true[key], rel=0.05), key
    assert fit.fitted.damping == pytest.approx(true["damping"], abs=0.05)
    assert fit.resolution == 0.5
    assert fit.fitted.encoder_resolution == 0.5
    assert fit.matched
    assert fit.before.max > 5.0
    assert fit.after.max <= 1.5
    assert fit.starts >= 3


def test_a_plant_the_twin_cannot_represent_is_not_claimed_a_match(made, make_third_order):
    # A lightly damped loop with an extra pole at 10 Hz (third order): the fit comes as close as
    # a second-order loop can, and says its error is well above the recording's noise.
    recording = make_third_order(made, 0, extra_pole_hz=10.0, sigma=0.05, step=0.1, damping=0.3)
    fit = fit_axis(recording, RATE, PlantConfig())
    assert not fit.matched
    assert fit.structured > 2.0 * fit.noise
    assert fit.after.rms > fit.structured > 0.1


def test_encoder_step_is_read_from_the_lattice_of_positions():
    rng = np.random.default_rng(1)
    positions = 1000.0 + rng.integers(-400, 400, 2000) * 0.25
    assert encoder_step(positions) == 0.25
    assert encoder_step(np.round(rng.normal(0.0, 50.0, 2000)) * 0.1) == pytest.approx(0.1)
    assert encoder_step(rng.normal(0.0, 50.0, 2000)) is None  # not rounded by any encoder
    assert encoder_step(np.array([1.0, 1.0, 1.0])) is None


def test_white_noise_is_told_from_a_smooth_error():
    rng = np.random.default_rng(2)
    noise = rng.normal(0.0, 0.3, 20_000)
    smooth = 0.5 * np.sin(np.linspace(0.0, 20.0, 20_000))
    white, structured = split_noise(noise)
    assert white == pytest.approx(0.3, rel=0.05)
    assert structured < 0.05
    white, structured = split_noise(noise + smooth)
    assert white == pytest.approx(0.3, rel=0.05)
    assert structured == pytest.approx(0.5 / np.sqrt(2.0), rel=0.1)
