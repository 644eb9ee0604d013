"""Scripted runs: a list of commands at given samples, run headless and recorded.

A scenario file (YAML):

    name: stop_resume
    samples: 6000               # how long the run lasts
    config: {}                  # overrides of the suite configuration (config/default.yaml)
    commands:
      - at: 10                  # the controller's sample when the command is given
        operation: motion_start # motion_start, motion_modify, action, config_set, gate_set, ...
        supervisor: 0
        request: {type: S_CURVE, position: [2000.0, 0.0], trajectory: [{velocity: 1000.0, ...}]}

This is how the regression fixtures in test/fixtures/bags are made
(``mpi-ros record --scenario FILE OUTPUT``); with a fixed epoch, recording a scenario again
gives the same bytes (the writer stores canonical CDR, padding zeroed: bag/cdr.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import yaml

from .. import config as suite_config
from ..commands import Command
from ..runner import ControllerRunner
from .recorder import Recorder

FIXED_EPOCH_NS = 1_700_000_000_000_000_000  # 2023-11-14T22:13:20Z, for reproducible bags


@dataclass(frozen=True, slots=True)
class Step:
    at: int
    command: Command


@dataclass(slots=True)
class Scenario:
    name: str
    samples: int
    config: dict = field(default_factory=dict)
    steps: list[Step] = field(default_factory=list)


def load(path: str | Path) -> Scenario:
    data = yaml.safe_load(Path(path).read_text(encoding="utf-8")) or {}
    steps = []
    for i, entry in enumerate(data.get("commands") or []):
        try:
            steps.append(Step(int(entry["at"]), Command(str(entry["operation"]), int(entry.get("supervisor", -1)),
                                                        int(entry.get("axis", -1)), dict(entry.get("request") or {}))))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: commands[{i}]: needs at, operation (and supervisor/axis/request): "
                             f"{exc}") from exc
    scenario = Scenario(str(data.get("name", Path(path).stem)), int(data.get("samples", 0)),
                        dict(data.get("config") or {}), sorted(steps, key=lambda s: s.at))
    if scenario.steps and scenario.steps[-1].at > scenario.samples:
        raise ValueError(f"{path}: a command at sample {scenario.steps[-1].at} is past the end ({scenario.samples})")
    return scenario


def record(scenario: Scenario, output: str | Path, epoch_ns: int = FIXED_EPOCH_NS) -> Path:
    """Run ``scenario`` as fast as possible and record it to the bag directory ``output``."""
    cfg = suite_config.parse(suite_config.merge(suite_config.load().raw, scenario.config), f"scenario {scenario.name}")
    runner = ControllerRunner(cfg.build_controller(), time_scale=None)
    recorder = Recorder(runner, output, cfg, epoch_ns=epoch_ns)
    try:
        for step in scenario.steps:
            runner.step(step.at - runner.ctl.sample)
            runner.submit(step.command)
        runner.step(scenario.samples - runner.ctl.sample)
    finally:
        recorder.close()
    return Path(output)
