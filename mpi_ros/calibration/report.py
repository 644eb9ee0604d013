"""What `mpi-ros fit` and `mpi-ros compare` print, write and plot."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from mpi_ros.mpi.base.params import PlantConfig

from .fit import AxisFit, Residual
from .recording import AxisRecording
from .twin import AxisTwin

FITTED_KEYS = ("bandwidth_hz", "damping", "velocity_feedforward", "acceleration_feedforward")


def _row(label: str, residual: Residual) -> str:
    return f"    {label:<22}{residual.rms:>12.4f}{residual.max:>12.4f}{residual.at:>10.4f}"


def fit_text(fit: AxisFit) -> str:
    """One axis' fit: the recording, the residual before and after, the verdict."""
    c, f = fit.configured, fit.fitted
    lines = [
        f"axis {fit.axis}: {fit.samples} samples over {fit.duration:.3f} s, twin run at {fit.rate:g} Hz "
        f"({fit.starts} starts, {fit.evaluations} runs of the plant)",
        "    parameter                   configured      fitted",
        *(f"    {key:<26}{getattr(c, key):>12.5g}{getattr(f, key):>12.5g}" for key in FITTED_KEYS),
        f"    {'encoder_resolution':<26}{c.encoder_resolution:>12.5g}"
        + (f"{f.encoder_resolution:>12.5g}" if fit.resolution is not None else "   (no lattice: not fitted)"),
        "    counts                        RMS         max    at (s)",
        _row("recorded following err", fit.following_error),
        _row("residual, configured", fit.before),
        _row("residual, fitted", fit.after),
        f"    the fitted residual: white noise {fit.noise:.4f}, structured {fit.structured:.4f} RMS; "
        f"the twin reproduces {100.0 * fit.explained:.3f} % of the following error's power",
    ]
    if f == c:
        lines.append("    the configured plant fits this recording at least as well as any found: kept")
    if fit.matched:
        lines.append("    MATCH: what the fitted twin leaves is within the recording's noise")
    else:
        lines.append("    NO MATCH: the fitted twin leaves a structured error larger than the recording's noise "
                     "(the machine does something this plant model cannot; the fit is the closest it comes)")
    return "\n".join(lines)


def yaml_block(fits: list[AxisFit], source: str) -> str:
    """The fitted plants as a configuration fragment: axes.overrides.<k>.plant."""
    overrides = {}
    for fit in fits:
        plant = {key: _round(getattr(fit.fitted, key)) for key in FITTED_KEYS}
        if fit.resolution is not None:
            plant["encoder_resolution"] = fit.fitted.encoder_resolution
        overrides[fit.axis] = {"plant": plant}
    body = yaml.safe_dump({"axes": {"overrides": overrides}}, sort_keys=False)
    verdicts = ", ".join(f"axis {f.axis} {'matches' if f.matched else 'does NOT match'}" for f in fits)
    return f"# mpi-ros fit {source}: {verdicts}\n{body}"


def _round(value: float) -> float:
    return float(f"{value:.6g}")


def compare_text(recording: AxisRecording, rate: float, config: PlantConfig,
                 recorded: Residual, twin: Residual, difference: Residual) -> str:
    """How far the twin's following error is from the recording's, for one axis."""
    return "\n".join([
        f"axis {recording.number}: {len(recording.time)} samples over {recording.duration:.3f} s, twin run at "
        f"{rate:g} Hz with bandwidth_hz {config.bandwidth_hz:g}, damping {config.damping:g}, velocity_feedforward "
        f"{config.velocity_feedforward:g}, acceleration_feedforward {config.acceleration_feedforward:g}, "
        f"encoder_resolution {config.encoder_resolution:g}",
        "    counts                        RMS         max    at (s)",
        _row("recorded following err", recorded),
        _row("twin following error", twin),
        _row("twin - recorded", difference),
    ])


def plot(output: str | Path, rate: float, fits: list[tuple[AxisRecording, PlantConfig, PlantConfig]]) -> Path:
    """A PNG: per axis, recorded and twin actual position, and the following errors
    (recorded, twin as configured, twin as fitted)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, rows = plt.subplots(2 * len(fits), 1, figsize=(11, 5.0 * len(fits)), sharex=True, squeeze=False)
    for i, (recording, configured, fitted) in enumerate(fits):
        twin = AxisTwin(recording, rate)
        t = recording.time - recording.time[0]
        before, after = twin.actual(configured), twin.actual(fitted)
        position, error = rows[2 * i, 0], rows[2 * i + 1, 0]
        position.plot(t, recording.command, lw=0.8, color="0.6", label="command")
        position.plot(t, recording.actual, lw=1.2, label="recorded actual")
        position.plot(t, after, lw=1.0, ls="--", label="twin actual (fitted)")
        position.set_ylabel(f"axis {recording.number} position [counts]")
        error.plot(t, recording.command - recording.actual, lw=1.2, label="recorded")
        error.plot(t, recording.command - before, lw=0.8, ls=":", label="twin, configured")
        error.plot(t, recording.command - after, lw=1.0, ls="--", label="twin, fitted")
        error.plot(t, np.asarray(recording.actual - after), lw=0.6, label="recorded - twin (fitted)")
        error.set_ylabel(f"axis {recording.number} following error [counts]")
        for ax in (position, error):
            ax.grid(alpha=0.3)
            ax.legend(loc="upper right", fontsize=7)
    rows[-1, 0].set_xlabel("time since the recording's start [s]")
    figure.tight_layout()
    output = Path(output)
    figure.savefig(output, dpi=100)
    plt.close(figure)
    return output
