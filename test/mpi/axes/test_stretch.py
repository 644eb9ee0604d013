"""Every axis computed in rows, all at once, equals to the bit what the one-axis code computes.

The controller evaluates a stretch of samples for every axis together (axes/trace.py), with
shortcuts that claim to give the same bits (constant-velocity segments, a servo polynomial
without its zero leading coefficients, a transient that has underflowed to zeros, following
servo pieces as extra rows). Axis.trace, the one-axis code the controller keeps for coasting
axes, is the reference: here every stretch the controller computes is compared with it, axis
by axis and sample by sample, by the bits of each float (so -0.0 differs from 0.0).
"""

from __future__ import annotations

import random

import pytest

from mpi_ros.mpi import (
    AxisInPosition,
    Controller,
    ControllerConfig,
    Hold,
    HoldType,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    PlantConfig,
    Trajectory,
    control,
)
from mpi_ros.mpi.axes.plant import Plant

_VALUES = ("cmd_p", "cmd_v", "cmd_a", "act_p", "act_v", "rel")


@pytest.fixture
def compared(monkeypatch):
    """Wrap the controller's stretch computation: check every stretch against Axis.trace."""
    counts = {"stretches": 0, "axes": 0}
    trace = control.trace

    def checked(bank, axes, clock_of, k0, k1, rate, scratch, cam_inputs=None):
        stretch = trace(bank, axes, clock_of, k0, k1, rate, scratch, cam_inputs)
        for axis in axes:
            one = axis.trace(k0, k1, clock_of(axis))
            for name in _VALUES:
                rows, reference = getattr(stretch, name)[axis.number], getattr(one, name)
                assert rows.tobytes() == reference.tobytes(), (name, axis.number, k0, k1)
            counts["axes"] += 1
        counts["stretches"] += 1
        return stretch

    monkeypatch.setattr(control, "trace", checked)
    return counts


def _controller(rng: random.Random) -> tuple[Controller, list]:
    ctl = Controller(ControllerConfig(axis_count=4, supervisor_count=2))
    for axis in ctl.axes:
        axis.in_position = AxisInPosition(settle_on_stop=rng.random() < 0.5, settle_on_estop=rng.random() < 0.5)
    # a stiffer loop with an exact encoder beside the default ones
    ctl.axes[1].plant = Plant(PlantConfig(bandwidth_hz=60.0, damping=1.0, encoder_resolution=0.0))
    supervisors = []
    for n in range(2):
        _, ms = ctl.create_motion(n)
        ms.axis_list_set([2 * n, 2 * n + 1])
        ms.action(MPIAction.MAP)
        supervisors.append(ms)
    return ctl, supervisors


def _command(ctl: Controller, ms, rng: random.Random) -> None:
    x, y = rng.uniform(-3000.0, 3000.0), rng.uniform(-3000.0, 3000.0)
    trajectory = [Trajectory(rng.choice([800.0, 3000.0]), 20000.0, 15000.0, rng.choice([0.0, 50.0]))]
    kind = rng.choice(["s-curve", "trapezoid", "append", "modify", "velocity", "hold", "gate", "feedrate",
                       "STOP", "RESUME", "E_STOP", "RESET"])
    if kind in ("s-curve", "trapezoid", "append", "modify"):
        motion = MPIMotionType.S_CURVE if kind in ("s-curve", "modify") else MPIMotionType.TRAPEZOIDAL
        attrs = MotionAttr.APPEND if kind == "append" else MotionAttr.NONE
        command = ms.modify if kind == "modify" else ms.start
        command(motion, attrs, MotionParams(trajectory=trajectory, position=[x, y]))
    elif kind == "velocity":
        ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                 MotionParams(trajectory=[Trajectory(x / 4.0, 20000.0, 0.0, 30.0)]))
    elif kind == "hold":
        hold = Hold(HoldType.GATE, gate=1, timeout=0.05)
        ms.start(MPIMotionType.S_CURVE, MotionAttr.HOLD, MotionParams(trajectory=trajectory, position=[x, y],
                                                                       hold=[hold, hold]))
    elif kind == "gate":
        ctl.gate_set(1, x > 0.0)
    elif kind == "feedrate":
        _, config = ms.config_get()
        config.normal_feedrate = rng.choice([0.5, 1.0, 1.5])
        ms.config_set(config)
    else:
        ms.action(MPIAction[kind])


@pytest.mark.parametrize("seed", range(6))
def test_rows_equal_the_one_axis_code_under_random_commands(compared, seed):
    rng = random.Random(seed)
    ctl, supervisors = _controller(rng)
    for _ in range(150):
        if rng.random() < 0.3:
            _command(ctl, rng.choice(supervisors), rng)
        ctl.step(rng.choice([1, 7, 20, 20, 150, 900, 4096]))
    assert compared["stretches"] >= 150


def test_rows_equal_the_one_axis_code_over_a_long_cruise(compared):
    """Long enough (about 8 s past the ramp) for the servo's transient to underflow to zeros,
    with positions crossing zero on the way (axis 1 reads an exact encoder: y itself)."""
    ctl, supervisors = _controller(random.Random(1))
    for number, start in enumerate((600.0, 600.0, -400.0, -400.0)):
        assert ctl.axis_command_position_set(number, start).ok
    ctl.step(4000)  # settled there
    for ms, velocity in zip(supervisors, (-150.0, 90.0), strict=True):
        ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                 MotionParams(trajectory=[Trajectory(velocity, 2000.0, 0.0, 0.0)]))
    while ctl.sample < 24_000:
        ctl.step(4096 if ctl.sample < 20_000 else 20)
    assert compared["stretches"] > 10
    assert ctl.axes[1].cmd_p < 0.0 < ctl.axes[2].cmd_p  # both crossed zero
