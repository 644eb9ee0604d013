"""Property tests (hypothesis, derandomized) over random moves of the simulated controller.

Over random TRAPEZOIDAL / S_CURVE / VELOCITY moves (random limits, distances, jerk percent,
modifies from motion to random targets): the command never exceeds the velocity asked; the
acceleration stays within acceleration/(1 - f/2) while speeding up and deceleration/(1 - f/2)
while slowing down (f = jerkPercent/100; exactly A and D for TRAPEZOIDAL); the S-curve jerk
stays within 4 A^2/(f (2 - f) w) for the velocity w the ramp reaches (w = velocity when the
move cruises); moves end exactly on target; STOP / E_STOP reach zero command velocity within
decelTime.stop / decelTime.eStop; nothing is ever NaN; and stepping one sample at a time or in
random batches gives bit-identical motion and identical events.

Limits come from two independent places: the samples (the motion log: command position and
velocity of every sample; acceleration and jerk as finite differences, which are averages
of the true values and so bounded by them) and the planned constant-jerk segments.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from mpi_ros.mpi import (
    Controller,
    ControllerConfig,
    DecelTime,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Trajectory,
)
from mpi_ros.mpi.base.messages import Message

T = MPIMotionType
RATE = 2000.0
DT = 1.0 / RATE
TOL = 1e-9

SETTINGS = dict(derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

velocities = st.floats(50.0, 5000.0)
accelerations = st.floats(500.0, 100_000.0)
jerk_percents = st.one_of(st.just(0.0), st.just(100.0), st.floats(0.0, 100.0))
distances = st.floats(-5000.0, 5000.0).filter(lambda d: abs(d) > 1e-3)


@st.composite
def trajectories(draw, kind):
    return Trajectory(draw(velocities), draw(accelerations), draw(accelerations),
                      draw(jerk_percents) if kind is T.S_CURVE else 0.0)


def rig(axes=1, **config):
    ctl = Controller(ControllerConfig(axis_count=axes, supervisor_count=1, **config))
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set(list(range(axes))).ok
    assert ms.action(MPIAction.MAP).ok
    ms.log_open(50_000_000)
    return ctl, ms


def run_idle(ctl, ms):
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000_000, chunk=1 << 14)


def logged(ms) -> np.ndarray:
    """(samples, 3 x axes): command position, actual position, command velocity of each axis."""
    log = np.concatenate(ms.log.columns)
    assert np.all(np.isfinite(log))  # no NaN anywhere
    return log


def peak(rate: float, jerk_percent: float) -> float:
    """Peak acceleration of an S-curve ramp of average rate ``rate`` (docs/profiles.md: A/(1 - f/2))."""
    return rate / (1.0 - jerk_percent / 200.0)


def check_sampled_limits(velocity: np.ndarray, v_max: float, up: float, down: float) -> None:
    """Velocity and acceleration of the samples (the command starts at rest)."""
    v = np.concatenate(([0.0], velocity))
    assert np.max(np.abs(velocity)) <= v_max * (1 + TOL)
    acc = np.diff(v) / DT
    before, after = v[:-1], v[1:]
    same = before * after >= 0.0
    speeding = same & (np.abs(after) > np.abs(before))
    slowing = same & (np.abs(after) < np.abs(before))
    through_zero = ~same  # part slowing, part speeding within the sample
    slack = 1 + 1e-6
    assert np.all(np.abs(acc[speeding]) <= up * slack)
    assert np.all(np.abs(acc[slowing]) <= down * slack)
    assert np.all(np.abs(acc[through_zero]) <= max(up, down) * slack)


def speeding_up(seg, v_max: float):
    """True if the segment raises |v|, False if it lowers it, None when it is at rest up to
    rounding (a ramp never crosses zero velocity, ramps.py, so the middle tells)."""
    _, v_mid, a_mid = seg.state_at(0.5 * seg.duration)
    if abs(v_mid) <= 1e-9 * v_max:
        return None
    return v_mid * a_mid > 0.0


def check_segment_limits(plan, v_max: float, up: float, down: float) -> None:
    """The same limits from the planned constant-jerk segments (MPI 000, Streaming Point Motion Type
    Calculations: the extremes of the acceleration are at the segment ends)."""
    for seg in plan.segments:
        p1, v1, a1 = seg.end_state()
        assert all(math.isfinite(x) for x in (seg.p, seg.v, seg.a, seg.j, p1, v1, a1))
        assert max(abs(seg.v), abs(v1)) <= v_max * (1 + TOL)
        limit = {True: up, False: down, None: max(up, down)}[speeding_up(seg, v_max)]
        assert max(abs(seg.a), abs(a1)) <= limit * (1 + 1e-9) + 1e-9


# ------------------------------------------------------------------ point to point ----
@settings(max_examples=150, **SETTINGS)
@given(kind=st.sampled_from([T.TRAPEZOIDAL, T.S_CURVE]), data=st.data(), distance=distances)
def test_point_to_point_limits_and_target(kind, data, distance):
    # docs/quality.md, "Correct motion": limits never exceeded (|v| <= velocity, |a| <= acceleration/
    # deceleration, jerk as configured, within float tolerance); MPI 002, Configuration of IN_POSITION and DONE Events
    # after STOP or E-STOP Events, AT_TARGET "command = target"
    traj = data.draw(trajectories(kind))
    ctl, ms = rig()
    assert ms.start(kind, params=MotionParams(trajectory=[traj], position=[distance])).ok
    plan = ctl.axes[0].plan
    up, down = peak(traj.acceleration, traj.jerk_percent), peak(traj.deceleration, traj.jerk_percent)
    check_segment_limits(plan, traj.velocity, up, down)
    run_idle(ctl, ms)
    log = logged(ms)
    check_sampled_limits(log[:, 2], traj.velocity, up, down)
    assert ctl.axes[0].command_position == distance
    assert log[-1, 0] == distance


@settings(max_examples=100, **SETTINGS)
@given(data=st.data(), distance=distances)
def test_s_curve_jerk_within_the_profile_jerk(data, distance):
    # docs/profiles.md, "The cross-check against ruckig": max_jerk = 4*A^2/(f*(2-f)*w), w the peak
    # velocity the move actually reaches (short moves never reach v)
    traj = data.draw(trajectories(T.S_CURVE))
    f = traj.jerk_percent / 100.0
    ctl, ms = rig()
    ms.start(T.S_CURVE, params=MotionParams(trajectory=[traj], position=[distance]))
    plan = ctl.axes[0].plan
    reached = max(max(abs(s.v), abs(s.end_state()[1])) for s in plan.segments)
    if f == 0.0:
        assert all(s.j == 0.0 for s in plan.segments)
        return
    bound_up = 4.0 * traj.acceleration ** 2 / (f * (2.0 - f) * reached)
    bound_down = 4.0 * traj.deceleration ** 2 / (f * (2.0 - f) * reached)
    for seg in plan.segments:
        bound = {True: bound_up, False: bound_down, None: max(bound_up, bound_down)}[speeding_up(seg, traj.velocity)]
        assert abs(seg.j) <= bound * (1 + 1e-9)
    run_idle(ctl, ms)
    v = np.concatenate(([0.0], logged(ms)[:, 2], [0.0]))
    sampled_jerk = np.abs(np.diff(v, 2)) / DT ** 2  # bounded by the largest jerk (a is continuous)
    assert np.max(sampled_jerk) <= max(bound_up, bound_down) * (1 + 1e-6)


@settings(max_examples=150, **SETTINGS)
@given(kind=st.sampled_from([T.TRAPEZOIDAL, T.S_CURVE]), data=st.data(), distance=distances,
       new_distance=distances, when=st.floats(0.02, 0.95))
def test_modify_from_motion_keeps_the_limits(kind, data, distance, new_distance, when):
    # issue 3: "Modify on the fly from the current position, velocity and acceleration (including
    # reversal)"; the limits of both requests hold throughout, and the move ends on the new target
    first, second = data.draw(trajectories(kind)), data.draw(trajectories(kind))
    ctl, ms = rig()
    ms.start(kind, params=MotionParams(trajectory=[first], position=[distance]))
    ctl.step(max(1, int(when * ctl.axes[0].plan.duration * RATE)))
    assert ms.state is MPIState.MOVING
    assert ms.modify(kind, params=MotionParams(trajectory=[second], position=[new_distance])).ok
    v_max = max(first.velocity, second.velocity)
    up = max(peak(first.acceleration, first.jerk_percent), peak(second.acceleration, second.jerk_percent))
    down = max(peak(first.deceleration, first.jerk_percent), peak(second.deceleration, second.jerk_percent))
    check_segment_limits(ctl.axes[0].plan, v_max, peak(second.acceleration, second.jerk_percent),
                         max(down, peak(second.deceleration, second.jerk_percent)))
    run_idle(ctl, ms)
    check_sampled_limits(logged(ms)[:, 2], v_max, up, down)
    assert ctl.axes[0].command_position == new_distance


@settings(max_examples=80, **SETTINGS)
@given(kind=st.sampled_from([T.TRAPEZOIDAL, T.S_CURVE]), data=st.data(),
       target=st.tuples(distances, distances), back=st.floats(-1.5, 1.5), when=st.floats(0.05, 0.9))
def test_vector_moves_along_the_line(kind, data, target, back, when):
    # MPI 000, MPIMotionSCurve "the first trajectory structure will be applied as the vector trajectory for all
    # the axes": the path speed and acceleration obey the limits; a modify along the same line
    # (incl. back past the start) keeps the axes on it
    traj = data.draw(trajectories(kind))
    ctl, ms = rig(axes=2)
    ms.start(kind, params=MotionParams(trajectory=[traj], position=list(target)))
    ctl.step(max(1, int(when * ctl.axes[0].plan.duration * RATE)))
    new_target = [back * x for x in target]
    assert ms.modify(kind, params=MotionParams(trajectory=[traj], position=new_target)).ok
    run_idle(ctl, ms)
    log = logged(ms)
    up, down = peak(traj.acceleration, traj.jerk_percent), peak(traj.deceleration, traj.jerk_percent)
    speed = np.hypot(log[:, 2], log[:, 5])
    direction = np.array(target) / np.hypot(*target)
    along = log[:, 2] * direction[0] + log[:, 5] * direction[1]  # signed path velocity
    assert np.max(speed) <= traj.velocity * (1 + TOL)
    check_sampled_limits(along, traj.velocity, up, down)
    across = log[:, 0] * direction[1] - log[:, 3] * direction[0]
    assert np.max(np.abs(across)) <= 1e-6 * (1.0 + np.max(np.abs(log[:, [0, 3]])))
    assert [a.command_position for a in ms.axes] == new_target


# ------------------------------------------------------------------ velocity ----
@settings(max_examples=60, **SETTINGS)
@given(first=st.floats(-3000.0, 3000.0), second=st.floats(-3000.0, 3000.0), acc=accelerations,
       dec=accelerations, jerk=jerk_percents, when=st.floats(0.0, 0.3))
def test_velocity_moves(first, second, acc, dec, jerk, when):
    # MPI 000, MPIMotionTypeVELOCITY VELOCITY "S-Curve acceleration to a constant velocity ... acceleration, velocity,
    # and jerkPercent"; MPI 000, MPIMotionVelocity "deceleration is ignored": every ramp uses the acceleration
    ctl, ms = rig()
    ms.start(T.VELOCITY, params=MotionParams(trajectory=[Trajectory(first, acc, dec, jerk)]))
    ctl.step(1 + int(when * RATE))
    # a first velocity of 0 ends at once: the modify then starts anew (MPI 000, MPIMotionMessageAUTO_START AUTO_START)
    again = MotionParams(trajectory=[Trajectory(second, acc, dec, jerk)])
    message = ms.modify(T.VELOCITY, MotionAttr.AUTO_START, again).message
    assert message in (Message.MPIMessageOK, Message.MPIMotionMessageAUTO_START)
    ctl.step(int((abs(first) + abs(second)) / acc * RATE) + 20)
    log = logged(ms)
    check_sampled_limits(log[:, 2], max(abs(first), abs(second)), peak(acc, jerk), peak(acc, jerk))
    assert ctl.axes[0].cmd_v == second


# ------------------------------------------------------------------ STOP / E_STOP ----
@settings(max_examples=80, **SETTINGS)
@given(kind=st.sampled_from([T.TRAPEZOIDAL, T.S_CURVE, T.VELOCITY]), data=st.data(),
       action=st.sampled_from([MPIAction.STOP, MPIAction.E_STOP]), stop=st.floats(0.01, 1.0),
       e_stop=st.floats(0.001, 0.2), when=st.floats(0.0, 0.9), distance=distances)
def test_stop_and_e_stop_reach_zero_within_their_time(kind, data, action, stop, e_stop, when, distance):
    # MPI 000, MPIActionSTOP STOP "decelerates the axis (or axes) to a stop in the time specified by the stop
    # time"; MPI 000, MPIActionE_STOP E_STOP likewise in the eStop time; MPI 000, MPIMotionDecelTime, stop
    # MPIMotionDecelTime
    traj = data.draw(trajectories(kind if kind is not T.VELOCITY else T.S_CURVE))
    ctl, ms = rig()
    config = ms.config_get()[1]
    config.decel_time = DecelTime(stop, e_stop)
    assert ms.config_set(config).ok
    ms.start(kind, params=MotionParams(trajectory=[traj], position=[distance]))
    ctl.step(1 + int(when * (ctl.axes[0].plan.duration if kind is not T.VELOCITY else 1.0) * RATE))
    assume(ms.state is MPIState.MOVING)
    assert ms.action(action).ok
    limit = math.ceil((stop if action is MPIAction.STOP else e_stop) * RATE - 1e-9)
    ctl.step(limit)
    assert abs(ctl.axes[0].cmd_v) <= 1e-9 * traj.velocity  # zero within float tolerance (the ramp's
    assert ms.state is (MPIState.STOPPED if action is MPIAction.STOP else MPIState.ERROR)  # end time)
    ctl.step(1)
    assert ctl.axes[0].cmd_v == 0.0
    ctl.step(500)
    assert ctl.axes[0].cmd_v == 0.0
    log = logged(ms)
    assert np.max(np.abs(log[:, 2])) <= traj.velocity * (1 + TOL)


# ------------------------------------------------------------------ chunk invariance ----
ACTIONS = [MPIAction.STOP, MPIAction.RESUME, MPIAction.E_STOP, MPIAction.RESET, MPIAction.ABORT]


@st.composite
def scenarios(draw):
    kind = draw(st.sampled_from([T.TRAPEZOIDAL, T.S_CURVE, T.VELOCITY]))
    fast = st.builds(Trajectory, st.floats(100.0, 3000.0), st.floats(20_000.0, 200_000.0),
                     st.floats(20_000.0, 200_000.0), jerk_percents if kind is not T.TRAPEZOIDAL else st.just(0.0))
    position = st.lists(st.floats(-500.0, 500.0), min_size=2, max_size=2)
    ops = [("start", draw(fast), draw(position), 0)]
    for _ in range(draw(st.integers(0, 4))):
        wait = draw(st.integers(1, 300))
        choice = draw(st.integers(0, 2))
        if choice < 2:
            ops.append((("modify", "start")[choice], draw(fast), draw(position), wait))
        else:
            ops.append((draw(st.sampled_from(ACTIONS)).name, None, None, wait))
    return kind, ops


def play(kind, ops, batches, tail=1500):
    ctl, ms = rig(axes=2)
    answers = []

    def advance(n):
        while n > 0:
            k = min(n, next(batches))
            ctl.step(k)
            n -= k

    for name, traj, position, wait in ops:
        advance(wait)
        if name in ("start", "modify"):
            params = MotionParams(trajectory=[traj], position=position)
            answers.append((ms.start if name == "start" else ms.modify)(kind, params=params))
        else:
            answers.append(ms.action(MPIAction[name]))
    advance(tail)
    events = [(e.sample, e.type, e.supervisor, e.axis, e.move_id, e.detail) for e in ctl.drain_events()]
    status = [(a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v, a.status) for a in ctl.axes]
    return logged(ms), events, answers, status, ms.state


@settings(max_examples=25, **SETTINGS)
@given(scenario=scenarios(), sizes=st.lists(st.integers(1, 700), min_size=1, max_size=20))
def test_stepping_is_chunk_invariant(scenario, sizes):
    # controller: "the result does not depend on how the samples are batched"; docs/decisions.md,
    # "Samples, commands and replay": replay reproduces a run exactly. One sample at a time vs
    # random batches: bit-identical.
    kind, ops = scenario

    def ones():
        while True:
            yield 1

    def cycle():
        while True:
            yield from sizes

    log_one, *rest_one = play(kind, ops, ones())
    log_batched, *rest_batched = play(kind, ops, cycle())
    assert np.array_equal(log_one, log_batched)
    assert rest_one == rest_batched
