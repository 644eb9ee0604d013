"""Blending of appended point-to-point moves (mpi_ros/mpi/planning/blend.py): MEIMotionConfig.blendLimit,
MPI 000: "If cosine (turn angle defined above) is greater than the blendLimit, the motion will be blended. A
blend limit value of 0 exclude turns sharper than 90 degrees. 1.0 causes all moves to be blended. -1.0 allows no
blending", and "180 degrees = acceleration*2.0". Decisions: docs/decisions.md, "blendLimit". Everything steps
the controller by samples."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mpi_ros.mpi import Controller, MotionAttr, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory

A, T = MotionAttr, MPIMotionType
RATE = 2000.0
V, ACC = 1000.0, 10_000.0
CORNER = (1000.0, 0.0)


def _second(degrees: float) -> tuple[float, float]:
    """The target of a move of 1000 counts from CORNER, turned ``degrees`` from the first move's direction."""
    turn = math.radians(degrees)
    return CORNER[0] + 1000.0 * math.cos(turn), CORNER[1] + 1000.0 * math.sin(turn)


def _run(limit: float, second, kind=T.TRAPEZOIDAL, jerk_percent=0.0, append=True):
    """Command positions per sample of a move to CORNER with a move to ``second`` appended."""
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    _, config = ms.config_get()
    config.blend_limit = limit
    assert ms.config_set(config).ok
    trajectory = [Trajectory(V, ACC, ACC, jerk_percent)]
    assert ms.start(kind, A.NONE, MotionParams(trajectory=trajectory, position=list(CORNER))).ok
    if append:
        assert ms.start(kind, A.APPEND, MotionParams(trajectory=trajectory, position=list(second))).ok
    trace = []
    while ms.state is not MPIState.IDLE:
        ctl.step(1)
        trace.append((ctl.axes[0].cmd_p, ctl.axes[1].cmd_p))
        assert len(trace) < 40_000
    return np.array(trace), ctl


def _speed_and_acceleration(trace):
    v = np.diff(np.vstack([[0.0, 0.0], trace]), axis=0) * RATE
    a = np.diff(v, axis=0) * RATE
    return np.hypot(*v.T), np.hypot(*a.T)


CASES = [  # (blendLimit, turn in degrees, blended?)
    (1.0, 90.0, True), (1.0, 180.0, True), (1.0, 30.0, True),
    (-1.0, 90.0, False), (-1.0, 0.0, False), (-1.0, 30.0, False),
    (0.0, 45.0, True), (0.0, 90.0, True), (0.0, 135.0, False),
    (0.5, 120.0, True), (0.5, 121.0, False),
]


@pytest.mark.parametrize(("limit", "degrees", "blended"), CASES, ids=[f"{c[0]}-{c[1]:g}deg" for c in CASES])
def test_blend_limit_decides_which_turns_blend(limit, degrees, blended):
    # MEIMotionConfig.blendLimit: 1.0 blends all, -1.0 none, 0 excludes turns sharper than 90 degrees (the
    # cosine of the turn compared with -blendLimit: docs/decisions.md)
    trace, _ = _run(limit, _second(degrees))
    unblended, _ = _run(-1.0, _second(degrees))
    speed, _ = _speed_and_acceleration(trace)
    corner = int(np.argmin(np.hypot(*(trace - CORNER).T)))
    if blended:
        assert len(trace) < len(unblended)  # the second move began before the first had stopped
        assert speed[corner] > 0.1 * V or degrees == 180.0
    else:
        assert np.array_equal(trace, unblended)  # bit-identical: no blend
        assert speed[corner - 2:corner + 3].min() < 1e-6  # the axes stop at the corner
    assert trace[-1] == pytest.approx(_second(degrees), abs=1e-9)


@pytest.mark.parametrize(("kind", "jerk_percent"), [(T.TRAPEZOIDAL, 0.0), (T.S_CURVE, 50.0), (T.S_CURVE, 100.0)])
@pytest.mark.parametrize("degrees", [30.0, 90.0, 150.0, 180.0])
def test_a_blended_corner_keeps_the_velocity_and_at_most_doubles_the_acceleration(kind, jerk_percent, degrees):
    # MEIMotionConfig.blendLimit: "the acceleration resulting from the blending can exceed the acceleration limit
    # specified in the motion parameters (180 degrees = acceleration*2.0)": the two profiles add up, so the
    # vector acceleration is at most |a1 - a2| <= peak * sqrt(2 - 2 cos(turn)), twice the peak at an about-face,
    # and the speed never exceeds the velocity limit
    trace, _ = _run(1.0, _second(degrees), kind, jerk_percent)
    speed, acceleration = _speed_and_acceleration(trace)
    peak = ACC / (1.0 - jerk_percent / 200.0)  # an S-curve's peak acceleration (jerk percent of the ramp)
    bound = peak * math.sqrt(2.0 - 2.0 * math.cos(math.radians(degrees)))
    assert speed.max() <= V * (1 + 1e-9)
    assert acceleration.max() <= max(bound, peak) * (1 + 1e-6) + 1e-3
    if degrees == 180.0:
        assert acceleration.max() > 1.9 * peak  # "180 degrees = acceleration*2.0"


@pytest.mark.parametrize(("kind", "jerk_percent"), [(T.TRAPEZOIDAL, 0.0), (T.S_CURVE, 50.0)])
def test_a_blended_corner_is_the_sum_of_the_two_profiles(kind, jerk_percent):
    # The blend shape (docs/decisions.md, "blendLimit"): the second move's profile, as it runs alone from the
    # corner, starts while the first decelerates, and the two add up; each alone is the profile the ruckig and
    # limits checks cover (test/crosscheck), so a blended corner consists of checked profiles
    trace, _ = _run(1.0, _second(90.0), kind, jerk_percent)
    first, _ = _run(1.0, None, kind, jerk_percent, append=False)
    alone, _ = _run(-1.0, _second(90.0), kind, jerk_percent)
    corner = np.array(CORNER)
    # the second move alone: from its first sample off the corner, after the first move reached it
    reached = int(np.argmax(np.all(alone == corner, axis=1)))
    second = alone[reached + int(np.argmax(np.any(alone[reached:] != corner, axis=1))):]
    # the blend begins where the blended trace leaves the first move's own profile
    begins = int(np.argmax(np.any(trace[:len(first)] != first, axis=1)))
    assert 0 < begins < reached
    expected = np.concatenate([first, np.repeat(first[-1:], len(trace), axis=0)])[:len(trace)].copy()
    end = min(len(trace), begins + len(second))
    expected[begins:end] += second[:end - begins] - corner
    expected[end:] += second[-1] - corner
    assert np.allclose(trace, expected, rtol=0.0, atol=1e-9)
