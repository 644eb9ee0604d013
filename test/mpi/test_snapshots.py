"""Status snapshots built from templates (mpi_ros/mpi/snapshots.py, supervisor/status.py): the
snapshots Controller.step_snapshots takes inside its stretches equal, every field of every
supervisor and axis to the bit (NaN equal to NaN, -0.0 told from 0.0), what stepping to each
sample and calling motion_snapshots() there gives, whatever the motion: paths with element ids
(PT, PVT) and feedforward (PTF), cams, velocity moves, appended moves, STOP, E_STOP, ABORT,
RESET, injected amplifier faults and amplifiers turned off, in several supervisors (MPI 000,
mpiMotionStatus and mpiAxisStatus)."""

from __future__ import annotations

import dataclasses
import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mpi_ros.mpi import (
    AxisMaster,
    AxisMasterType,
    Controller,
    ControllerConfig,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    Trajectory,
)
from mpi_ros.mpi.axes.plant import Plant, servo_effort
from mpi_ros.mpi.base.params import PlantConfig

SAMPLES = 1600
TRAJ = Trajectory(4000.0, 40000.0, 30000.0, 40.0)
KINDS = ["s_curve", "append", "pt", "pvt", "ptf", "velocity", "cam", "STOP", "E_STOP", "ABORT", "RESET",
         "RESUME", "fault", "fault_clear", "amp_off", "amp_on"]
ACTIONS = {"STOP": MPIAction.STOP, "E_STOP": MPIAction.E_STOP, "ABORT": MPIAction.ABORT,
           "RESET": MPIAction.RESET, "RESUME": MPIAction.RESUME}


def _controller() -> Controller:
    """Three supervisors: ms0 on axes 0 and 1 (moves and paths), ms1 on axis 2 (velocity),
    ms2 on axis 3 (a cam following axis 0's command)."""
    ctl = Controller(ControllerConfig(axis_count=4, supervisor_count=3))
    for number, axes in enumerate(([0, 1], [2], [3])):
        _, ms = ctl.create_motion(number)
        assert ms is not None
        assert ms.axis_list_set(axes).ok
        ms.action(MPIAction.MAP)
    assert ctl.axis_master_set(3, AxisMaster(AxisMasterType.AXIS_COMMANDED_POSITION, 0)).ok
    return ctl


def _path(kind: MPIMotionType, x: float, y: float) -> MotionParams:
    """Four points toward (x, y) with element ids, velocities (PVT) and feedforward (PTF)."""
    points = [(x * i / 4.0, y * i / 4.0) for i in range(1, 5)]
    params = MotionParams(position=[p for point in points for p in point], time=[0.05] * 4,
                          element_id=[11, 12, 13, 14])
    if kind is MPIMotionType.PVT:
        params.point_velocity = [x, y] * 4
    if kind is MPIMotionType.PTF:
        params.feedforward = [100.0 * i for i in range(8)]
    return params


def _apply(ctl: Controller, kind: str, who: int, x: float, y: float) -> None:
    """One command; a refused one changes nothing (both routes see the same refusals)."""
    ms, ms0, axis = ctl.supervisor(who % 3), ctl.supervisor(0), who % 4
    assert ms is not None
    assert ms0 is not None
    if kind == "s_curve":
        ms0.start(MPIMotionType.S_CURVE, MotionAttr.NONE, MotionParams(trajectory=[TRAJ], position=[x, y]))
    elif kind == "append":
        ms0.start(MPIMotionType.TRAPEZOIDAL, MotionAttr.APPEND, MotionParams(trajectory=[TRAJ], position=[y, x]))
    elif kind in ("pt", "pvt", "ptf"):
        kind_type = MPIMotionType[kind.upper()]
        ms0.start(kind_type, MotionAttr.ELEMENT_ID, _path(kind_type, x, y))
    elif kind == "velocity":
        ctl.supervisor(1).start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                                MotionParams(trajectory=[Trajectory(x / 2.0, 20000.0, 0.0, 30.0)]))
    elif kind == "cam":
        ctl.supervisor(2).start(MPIMotionType.CAM_LINEAR, MotionAttr.NONE,
                                MotionParams(master_distance=[abs(x) + 100.0], slave_position=[y]))
    elif kind in ACTIONS:
        ms.action(ACTIONS[kind])
    elif kind in ("fault", "fault_clear"):
        ctl.axis_fault_inject(axis, "AMP_FAULT", kind == "fault")
    else:
        ctl.axis_amp_enable_set(axis, kind == "amp_on")


def _stepped(script, wanted: list[int], ctl: Controller | None = None) -> tuple[dict[int, object], list]:
    """Step to each wanted sample and take motion_snapshots() there (before the commands
    given at that sample), on ``ctl`` (a new _controller() by default)."""
    ctl, pending, taken = ctl or _controller(), list(script), {}
    for sample in [*wanted, SAMPLES]:
        while pending and pending[0][0] < sample:
            ctl.step(max(0, pending[0][0] - ctl.sample))
            _apply(ctl, *pending.pop(0)[1:])
        ctl.step(max(0, sample - ctl.sample))
        taken[sample] = ctl.motion_snapshots()
    return {s: taken[s] for s in wanted}, _events(ctl)


def _in_stretches(script, wanted: list[int], ctl: Controller | None = None) -> tuple[dict[int, object], list]:
    """From command to command, one step_snapshots for the samples between (on ``ctl``, a
    new _controller() by default)."""
    ctl, pending, taken = ctl or _controller(), list(script), {}
    while True:
        end = pending[0][0] if pending else SAMPLES
        at = [s for s in wanted if ctl.sample <= s <= end and s not in taken]
        taken.update(ctl.step_snapshots(end - ctl.sample, at))
        if not pending:
            break
        _apply(ctl, *pending.pop(0)[1:])
    return {s: taken[s] for s in wanted}, _events(ctl)


def _events(ctl: Controller) -> list:
    return [(e.sample, e.type, e.supervisor, e.axis, e.move_id, e.element_id, e.detail) for e in ctl.drain_events()]


def _same(a: object, b: object) -> bool:
    """Equal to the bit: NaN equals NaN, -0.0 differs from 0.0, and the types agree."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return math.copysign(1.0, a) == math.copysign(1.0, b) and (a == b or (math.isnan(a) and math.isnan(b)))
    return a == b


def differences(new: object, old: object, where: str = "") -> list[str]:
    """Every field (nested: snapshots, their axes, tuples, dicts) where ``new`` and ``old``
    differ, by its path."""
    if dataclasses.is_dataclass(old) and type(new) is type(old):
        return [d for f in dataclasses.fields(old)
                for d in differences(getattr(new, f.name), getattr(old, f.name), f"{where}.{f.name}")]
    if isinstance(old, (tuple, list)) and type(new) is type(old) and len(new) == len(old):
        return [d for i, (x, y) in enumerate(zip(new, old, strict=True)) for d in differences(x, y, f"{where}[{i}]")]
    if isinstance(old, dict) and isinstance(new, dict) and new.keys() == old.keys():
        return [d for k in old for d in differences(new[k], old[k], f"{where}[{k}]")]
    return [] if _same(new, old) else [f"{where}: {new!r} != {old!r}"]


def _compare(script, wanted: list[int]) -> None:
    old, old_events = _stepped(script, wanted)
    new, new_events = _in_stretches(script, wanted)
    assert new_events == old_events
    for sample in wanted:
        found = differences(new[sample], old[sample], f"sample {sample}")
        assert not found, found[:5]


@settings(max_examples=20, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(script=st.lists(st.tuples(st.integers(0, SAMPLES - 1), st.sampled_from(KINDS), st.integers(0, 11),
                                 st.integers(-3000, 3000), st.integers(-3000, 3000)), min_size=1, max_size=12),
       gaps=st.lists(st.integers(1, 60), min_size=1, max_size=8))
def test_snapshots_inside_stretches_are_those_of_stepping_there(script, gaps):
    script = sorted(((s, kind, who, float(x), float(y)) for s, kind, who, x, y in script), key=lambda c: c[0])
    wanted, sample = [], 0
    while sample < SAMPLES:  # status at irregular intervals, the commands' samples among them
        wanted.append(sample)
        sample += gaps[len(wanted) % len(gaps)]
    _compare(script, sorted(set(wanted) | {c[0] for c in script}))


def test_a_path_with_feedforward_and_a_cam_at_every_sample():
    """The fields that follow a path's points (element id, frame count, feedforward) and a
    cam's master, at every sample, across a STOP, a RESET and an amplifier fault."""
    script = [(0, "ptf", 0, 1200.0, -800.0), (0, "cam", 2, 500.0, 300.0), (0, "velocity", 1, 900.0, 0.0),
              (260, "STOP", 0, 0.0, 0.0), (700, "RESET", 0, 0.0, 0.0), (710, "pvt", 0, -600.0, 400.0),
              (900, "fault", 2, 0.0, 0.0), (1200, "append", 0, 300.0, 200.0)]
    _compare(script, list(range(SAMPLES)))


def test_the_differences_helper_finds_a_changed_field():
    """The comparison above can fail: one bit of one axis' field is found, by its path."""
    motions, axes = _controller().motion_snapshots()
    changed = dataclasses.replace(axes[1], feedforward=-0.0)
    assert differences({0: changed}, {0: axes[1]}) == ["[0].feedforward: -0.0 != 0.0"]
    assert differences(dataclasses.replace(motions[2], feedrate=math.nan), motions[2]) == [".feedrate: nan != 1.0"]


def test_the_live_snapshots_are_one_definition():
    """A supervisor's own snapshot and an axis' are those of motion_snapshots()."""
    ctl = _controller()
    for kind, who in (("ptf", 0), ("velocity", 1), ("cam", 2)):
        _apply(ctl, kind, who, 700.0, -300.0)
    ctl.step(123)
    motions, axes = ctl.motion_snapshots()
    assert not differences([ctl.supervisor(n).snapshot() for n in range(3)], [motions[n] for n in range(3)])
    assert not differences([ctl.axis_snapshot(n) for n in range(4)], axes)
    assert [ctl.frame_count(n) for n in range(4)] == [a.frame_count for a in axes]
    assert axes[0].element_id in (11, 12, 13, 14)
    assert axes[0].feedforward != 0.0


def test_the_servo_effort_computed_for_a_stretch_at_once_is_each_axis_own():
    """A stretch's axis snapshots are computed for every sample and axis at once, the servo
    effort together for the axes whose plants are alike: each equals plant.servo_effort of
    its own plant and values, one at a time, whatever its plant (three kinds here, one of
    them twice) and its amplifier (0 once off)."""
    ctl = _controller()
    plants = [PlantConfig(bandwidth_hz=45.0, damping=0.9), PlantConfig(), PlantConfig(bandwidth_hz=45.0, damping=0.9),
              PlantConfig(velocity_feedforward=0.5, acceleration_feedforward=0.25)]
    for axis, plant in zip(ctl.axes, plants, strict=True):
        axis.plant = Plant(plant)
    for kind, who in (("s_curve", 0), ("velocity", 1), ("cam", 2)):
        _apply(ctl, kind, who, 700.0, -300.0)
    ctl.step(150)
    taken = ctl.step_snapshots(20, range(ctl.sample + 1, ctl.sample + 21))
    assert ctl.axis_amp_enable_set(3, False).ok
    taken |= ctl.step_snapshots(20, range(ctl.sample + 1, ctl.sample + 21))
    assert len(taken) == 40
    for _, axes in taken.values():
        for snap, plant in zip(axes, plants, strict=True):
            effort = servo_effort(plant, snap.position_error, snap.command_velocity, snap.actual_velocity,
                                  snap.command_acceleration, snap.feedforward) if snap.amp_enabled else 0.0
            assert _same(snap.servo_effort, effort), (snap.number, snap.servo_effort, effort)
    first = next(iter(taken.values()))[1]
    assert all(a.amp_enabled and a.servo_effort != 0.0 for a in first)
    assert [a.amp_enabled for a in axes] == [True, True, True, False]



def test_snapshots_in_stretches_across_the_32_bit_wrap_are_those_of_stepping_there():
    """Feedforward, a cam, a fault and an amplifier turned off, with axis 2's reported
    position crossing the 32-bit wrap (its origin puts its velocity move across 2^31):
    every snapshot taken inside stretches is the one stepping there gives, to the bit."""
    script = [(0, "ptf", 0, 1200.0, -800.0), (0, "cam", 2, 500.0, 300.0), (0, "velocity", 1, 900.0, 0.0),
              (260, "STOP", 0, 0.0, 0.0), (700, "RESET", 0, 0.0, 0.0), (710, "pvt", 0, -600.0, 400.0),
              (900, "fault", 2, 0.0, 0.0), (1000, "amp_off", 3, 0.0, 0.0), (1200, "append", 0, 300.0, 200.0)]
    wanted = list(range(SAMPLES))

    def across_the_wrap() -> Controller:
        ctl = _controller()
        assert ctl.axis_origin_set(2, -(2.0**31) + 100.0).ok  # a command past 100 reads across the wrap
        return ctl

    stretches, stretch_events = _in_stretches(script, wanted, across_the_wrap())
    stepped, stepped_events = _stepped(script, wanted, across_the_wrap())
    assert stretch_events == stepped_events
    assert not [d for s in wanted for d in differences(stretches[s], stepped[s], f"sample {s}")][:5]
    reported = [axes[2].command_position for _, axes in stretches.values()]
    assert max(reported) > 2.0**31 - 1000.0
    assert min(reported) < -(2.0**31) + 1000.0
    assert any(not a.amp_enabled for _, axes in stretches.values() for a in axes)
