"""What a fit or a comparison starts from: the recorded axes, the rate the twin runs at, and
the plant each axis is configured with now.

The configuration: the file given (--config), else the one recorded with the bag, else the
packaged default. The rate: --rate, else the controller's as the recording says it, else the
configuration's controller.sample_rate.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mpi_ros import config as suite_config
from mpi_ros.mpi.base.params import PlantConfig

from .recording import AxisRecording, RecordingError, read


@dataclass(frozen=True, slots=True)
class Inputs:
    axes: list[AxisRecording]
    rate: float
    plants: dict[int, PlantConfig]  # the configured plant of each axis
    config_source: str
    skipped: list[int]  # axes left out because their command never moves (none named)


def gather(path: str | Path, axes: list[int] | None, config_path: str | None, rate: float | None) -> Inputs:
    """Read and check everything; RecordingError (or ConfigError) says what is wrong."""
    if rate is not None and not rate > 0.0:
        raise RecordingError(f"--rate must be positive, got {rate!r}")
    recording = read(path)
    chosen = recording.select(axes)
    if config_path is not None:
        config, source = suite_config.load(config_path), str(config_path)
    elif recording.config is not None:
        config = suite_config.parse(recording.config, f"{recording.source} (recorded)")
        source = f"the configuration recorded in {recording.source}"
    else:
        config, source = suite_config.load(), "the default configuration"
    plants = {axis.number: config.plant[axis.number] if axis.number < len(config.plant) else PlantConfig()
              for axis in chosen}
    used = rate or recording.sample_rate or config.controller.sample_rate
    skipped = [n for n in recording.still() if n not in {axis.number for axis in chosen}]
    return Inputs(chosen, float(used), plants, source, skipped)
