"""Path (streaming point) moves run by the controller (mpi_ros/mpi/planning/paths.py, motion.py,
stepping.py, frames.py): PT, PTF, PVT, PVTF, SPLINE, BESSEL, BSPLINE, BSPLINE2 and
FRAME through the one executor; streaming with APPEND and the frame buffer (FRAMES_LOW,
FRAMES_EMPTY, the emptyCount E_STOP); ELEMENT_ID and OUTPUT per point; the shortest-path rule;
validation; STOP/RESUME and E_STOP on a path.

The per-type mathematics (profiles/path.py) is tested against scipy in
test/mpi/planning/profiles/test_path.py; here the expected path is path_segments() of the points the
controller was given, evaluated at the sample times, and everything goes through the public API
(start/modify/command, step, snapshots, events, the move log, the I/O image). Nothing sleeps.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from mpi_ros.mpi import (
    Controller,
    ControllerConfig,
    IoSpace,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Output,
    OutputType,
    Trajectory,
)
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import UserFrame
from mpi_ros.mpi.planning.profiles.path import PathKind, path_segments
from mpi_ros.mpi.planning.profiles.segment import Segment, SegmentTable, chain
from mpi_ros.mpi.planning.validate import MAX_PATH_VALUES

A = MotionAttr
T = MPIMotionType
E = MPIEventType
M = Message
RATE = 2000.0  # the default sample rate
NOTIFY = E.FRAMES_LOW | E.FRAMES_EMPTY | E.E_STOP | E.MOTION_DONE
TOL = 1e-9  # counts: the controller evaluates the same polynomials; only rounding differs

KIND = {T.PT: PathKind.PT, T.PTF: PathKind.PT, T.PVT: PathKind.PVT, T.PVTF: PathKind.PVT,
        T.SPLINE: PathKind.SPLINE, T.BESSEL: PathKind.BESSEL, T.BSPLINE: PathKind.BSPLINE,
        T.BSPLINE2: PathKind.BSPLINE2}
PATH_TYPES = list(KIND)
WITH_VELOCITY = (T.PVT, T.PVTF)
WITH_FEEDFORWARD = (T.PTF, T.PVTF)
INTERPOLATING = (T.PT, T.PTF, T.PVT, T.PVTF, T.SPLINE, T.BESSEL)  # pass through every point

# Five points of two axes; every time a whole number of samples (20, 40, 30, 50, 20).
POINTS = np.array([[40.0, -10.0], [100.0, 30.0], [150.0, 90.0], [120.0, 60.0], [200.0, 0.0]])
TIMES = [0.01, 0.02, 0.015, 0.025, 0.01]
VELOCITIES = np.array([[3000.0, 0.0], [2000.0, 2500.0], [0.0, 1000.0], [1500.0, -2000.0], [0.0, 0.0]])
ORIGINS = (100.0, -7.0)
START_USER = (25.0, -40.0)
# 1/16 s = 125 samples, exact in binary: cumulative point times land on the sample grid exactly
EXACT_DT = 0.0625


# ------------------------------------------------------------------ helpers ----
def new_supervisor(config: ControllerConfig | None = None, notify: MPIEventType | None = NOTIFY):
    """Controller and its supervisor 0 on axes [0, 1], mapped; notified of ``notify``."""
    ctl = Controller(config)
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    if notify is not None:
        assert ms.event_notify_set(notify).ok
    ctl.drain_events()
    return ctl, ms


def place(ctl, user=START_USER, origins=ORIGINS):
    """Axes 0 and 1 at rest at user positions ``user`` with ``origins`` (raw = user + origin)."""
    for n, (x, origin) in enumerate(zip(user, origins, strict=True)):
        assert ctl.axis_origin_set(n, origin).ok
        assert ctl.axis_command_position_set(n, x).ok
        assert ctl.axis_actual_position_set(n, x).ok
    return np.array(user) + np.array(origins)


def path_params(kind, points, times, velocities=None, **fields) -> MotionParams:
    """MotionParams of a path: positions (and point velocities) interleaved by axis."""
    points = np.asarray(points, dtype=float)
    params = MotionParams(position=list(points.ravel()), time=list(times), **fields)
    if kind in WITH_VELOCITY:
        v = np.zeros_like(points) if velocities is None else np.asarray(velocities, dtype=float)
        params.point_velocity = list(v.ravel())
    if kind in WITH_FEEDFORWARD:
        params.feedforward = [0.0] * points.size
    return params


class Expected:
    """The path each axis must follow: path_segments of the raw points, in profile time."""

    def __init__(self, segments_per_axis: list[list[Segment]]):
        self.segments = segments_per_axis
        self.tables = [SegmentTable(s) for s in segments_per_axis]
        self.duration = max(float(t.end[-1]) for t in self.tables)

    @classmethod
    def of(cls, kind, start_raw, raw_points, times, velocities=None, start_velocity=(0.0, 0.0)):
        raw_points = np.asarray(raw_points, dtype=float)
        return cls([
            path_segments(KIND[kind], start_raw[k], start_velocity[k], raw_points[:, k], times,
                          None if velocities is None else np.asarray(velocities, dtype=float)[:, k])
            for k in range(raw_points.shape[1])
        ])

    def at(self, t: float) -> np.ndarray:
        """Raw positions at profile time ``t`` (the end position from the end on)."""
        out = []
        for table in self.tables:
            tt = np.array([min(t, float(table.end[-1]))])
            out.append(table.evaluate(tt)[0][0])
        return np.array(out)

    def peaks(self) -> list[tuple[float, float]]:
        """Per axis (max |v|, max |a|), by sampling every segment densely (both ends included)."""
        out = []
        for segments in self.segments:
            v = a = 0.0
            for seg in segments:
                _, sv, sa = seg.state_at(np.linspace(0.0, seg.duration, 801))
                v, a = max(v, float(np.abs(sv).max())), max(a, float(np.abs(sa).max()))
            out.append((v, a))
        return out


def raw(ctl) -> np.ndarray:
    return np.array([ctl.axes[0].cmd_p, ctl.axes[1].cmd_p])


def samples_of(times) -> list[int]:
    """Sample offset (from the start) at which each point is reached: whole samples."""
    return [round(x * RATE) for x in np.cumsum(times)]


def of_type(events, *kinds):
    return [e for e in events if e.type in kinds]


def run_idle(ctl, ms, limit=20_000, chunk=10):
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, limit, chunk=chunk), ms.state


def ends_of(ctl, serial):
    return list(ctl.move_log.ends(serial))


PEAK_RE = re.compile(r"axis (\d+): \|v\| ([0-9.e+-]+) counts/s, \|a\| ([0-9.e+-]+) counts/s\^2")


# ------------------------------------------------------------------ 1. the executor ----
@pytest.mark.parametrize("relative", [False, True], ids=["absolute", "relative"])
@pytest.mark.parametrize("kind", PATH_TYPES, ids=[k.name for k in PATH_TYPES])
def test_every_path_type_runs_its_segments_at_every_sample(kind, relative):
    # MPI 000, Streaming Point Motion Type Calculations: "Any given dt defining a point also specifies how
    # long it will take to arrive at that point" (the first dt from the start); MPI 000, MPIMotionPT,
    # position: "The positions are interleaved in the array by the axis index", time: "one time value per
    # point"; MPI 000, MPIMotionAttrRELATIVE: relative to the starting value; user positions = raw - origin
    ctl, ms = new_supervisor()
    start = place(ctl)
    ctl.step(3)
    params = path_params(kind, POINTS, TIMES, VELOCITIES)
    assert ms.start(kind, A.RELATIVE if relative else A.NONE, params).ok
    s0 = ctl.sample
    raw_points = POINTS + (start if relative else np.array(ORIGINS))
    expected = Expected.of(kind, start, raw_points, TIMES, VELOCITIES if kind in WITH_VELOCITY else None)
    assert np.allclose(raw(ctl), start, rtol=0.0, atol=TOL)  # the path starts where the axes are
    point_samples = samples_of(TIMES)
    for k in range(1, point_samples[-1] + 40):
        ctl.step(1)
        assert np.allclose(raw(ctl), expected.at(k / RATE), rtol=0.0, atol=TOL), k
        if k <= point_samples[-1]:
            assert ms.state is MPIState.MOVING, k
        if kind in INTERPOLATING and k in point_samples:
            assert np.allclose(raw(ctl), raw_points[point_samples.index(k)], rtol=0.0, atol=TOL), k
    user = [ctl.axes[n].command_position for n in (0, 1)]
    assert np.allclose(user, raw_points[-1] - np.array(ORIGINS), rtol=0.0, atol=TOL)
    # MOTION_DONE and IDLE once the axes settle on the last point
    run_idle(ctl, ms)
    events = ctl.drain_events()
    assert [e.type for e in events] == [E.MOTION_DONE]
    assert not ms.current
    assert len(ctl.move_log.recent(ms.number)) == 1
    end = ctl.move_log.recent(ms.number)[0]
    assert end.message is M.MPIMessageOK
    assert end.sample == events[0].sample > s0 + point_samples[-1]
    assert end.detail.startswith("motion done; path peaks")
    reported = {int(n): (float(v), float(a)) for n, v, a in PEAK_RE.findall(end.detail)}
    assert sorted(reported) == [0, 1]
    for n, (v, a) in enumerate(expected.peaks()):
        assert reported[n][0] == pytest.approx(v, rel=1e-4, abs=1e-6)
        assert reported[n][1] == pytest.approx(a, rel=1e-4, abs=1e-6)


def _frame_pieces():
    """Per axis: (duration, jerk) pieces of a rest-to-rest S move (a -> +, -, 0; v back to 0)."""
    return [[(0.01, 1e6), (0.02, -1e6), (0.01, 1e6)],  # 0.04 s
            [(0.005, -4e6), (0.01, 4e6), (0.005, -4e6)]]  # 0.02 s: frames need not share times


def test_frame_move_runs_the_user_frames_as_given():
    # MPI 000, MEIMotionFrame, frame: "This structure contains the frame data for each frame" (MEIXmpFrame:
    # position, velocity, acceleration, jerk, time), one constant-jerk segment each, interleaved by axis;
    # positions are user positions (raw = user + origin)
    ctl, ms = new_supervisor()
    start = place(ctl)
    per_axis = [chain(START_USER[k], 0.0, 0.0, pieces) for k, pieces in enumerate(_frame_pieces())]
    frames = [UserFrame(s.p, s.v, s.a, s.j, s.duration) for pair in zip(*per_axis, strict=True) for s in pair]
    assert ms.start(T.FRAME, A.NONE, MotionParams(frames=frames)).ok
    expected = Expected([[s.scaled(1.0, ORIGINS[k]) for s in segs] for k, segs in enumerate(per_axis)])
    assert np.allclose(raw(ctl), start, rtol=0.0, atol=TOL)
    for k in range(1, 121):
        ctl.step(1)
        assert np.allclose(raw(ctl), expected.at(k / RATE), rtol=0.0, atol=TOL), k
    ends = [s.end_state()[0] for s in (segs[-1] for segs in per_axis)]
    assert np.allclose([ctl.axes[n].command_position for n in (0, 1)], ends, rtol=0.0, atol=TOL)
    run_idle(ctl, ms)
    assert [e.type for e in ctl.drain_events()] == [E.MOTION_DONE]
    assert ctl.move_log.recent(ms.number)[-1].message is M.MPIMessageOK


def _frames_of(per_axis) -> list[UserFrame]:
    """MEIXmpFrame values of per-axis segments, interleaved by axis (MEIMotionFrame, frame)."""
    return [UserFrame(s.p, s.v, s.a, s.j, s.duration) for pair in zip(*per_axis, strict=True) for s in pair]


def _stepped(per_axis, axis, **change):
    """``per_axis`` with the first frame of ``axis`` changed by ``change`` (a step at the start)."""
    first = per_axis[axis][0]
    values = {"p": first.p, "v": first.v, "a": first.a, "j": first.j, "duration": first.duration} | change
    moved = Segment(values["duration"], values["p"], values["v"], values["a"], values["j"])
    return [[moved, *segs[1:]] if k == axis else segs for k, segs in enumerate(per_axis)]


FRAME_STEPS = [("position at the start", 0, {"p": START_USER[0] - 5.0}),
               ("velocity at the start", 1, {"v": 300.0})]


@pytest.mark.parametrize(("name", "axis", "change"), FRAME_STEPS, ids=[s[0] for s in FRAME_STEPS])
def test_a_frame_move_that_would_step_the_command_at_its_start_is_refused(name, axis, change):
    # MPI 000, MEIMotionFrame / MEIXmpFrame: a frame is a constant-jerk segment from its own position and
    # velocity, so frames that do not begin where the axis is would make the command jump (a position
    # step, or a velocity step: an unbounded acceleration). MPIMotionMessagePATH_ERROR: "The specified
    # multi-point motion path is not valid"; docs/paths.md, "FRAME moves"
    ctl, ms = new_supervisor()
    start = place(ctl)
    per_axis = [chain(START_USER[k], 0.0, 0.0, pieces) for k, pieces in enumerate(_frame_pieces())]
    outcome, _ = ms.command(T.FRAME, A.NONE, MotionParams(frames=_frames_of(_stepped(per_axis, axis, **change))), False)
    assert outcome.message is M.MPIMotionMessagePATH_ERROR
    assert f"axis {axis}" in outcome.detail
    assert ms.state is MPIState.IDLE
    ctl.step(20)
    assert np.array_equal(raw(ctl), start)  # nothing moved: no step, no motion


def test_frames_that_do_not_join_are_refused():
    # MPI 000, MEIMotionFrame: each frame runs on from where the one before it ends; a gap between two
    # frames of an axis is a step of the command in the middle of the move (docs/paths.md, "FRAME moves")
    ctl, ms = new_supervisor()
    place(ctl)
    per_axis = [chain(START_USER[k], 0.0, 0.0, pieces) for k, pieces in enumerate(_frame_pieces())]
    second = per_axis[1][1]
    per_axis[1][1] = Segment(second.duration, second.p + 1.0, second.v, second.a, second.j)
    outcome, _ = ms.command(T.FRAME, A.NONE, MotionParams(frames=_frames_of(per_axis)), False)
    assert outcome.message is M.MPIMotionMessagePATH_ERROR
    assert "axis 1" in outcome.detail
    assert "frame 1" in outcome.detail


def test_appended_frames_begin_where_the_frames_before_them_end():
    # MPI 000, MPIMotionAttrMaskAPPEND (FRAME: APPEND and ID only) and MEIMotionFrame: appended frames run
    # on from the end state of the frames loaded before them; ones that do not are refused, nothing changes
    ctl, ms = new_supervisor()
    place(ctl)
    per_axis = [chain(START_USER[k], 0.0, 0.0, pieces) for k, pieces in enumerate(_frame_pieces())]
    assert ms.start(T.FRAME, A.NONE, MotionParams(frames=_frames_of(per_axis), final=False, empty_count=0)).ok
    ctl.step(10)
    ends = [segs[-1].end_state() for segs in per_axis]
    apart = [[Segment(0.01, p + 1.0, v, a, 0.0)] for p, v, a in ends]  # one count past where they end
    refused, _ = ms.command(T.FRAME, A.APPEND, MotionParams(frames=_frames_of(apart)), False)
    assert refused.message is M.MPIMotionMessagePATH_ERROR
    joined = [[Segment(0.01, p, v, a, 0.0)] for p, v, a in ends]
    assert ms.command(T.FRAME, A.APPEND, MotionParams(frames=_frames_of(joined)), False)[0].ok
    run_idle(ctl, ms)
    assert ctl.move_log.recent(ms.number)[-1].message is M.MPIMessageOK


# ------------------------------------------------------------------ 3. batching ----
def _batching_script():
    """(sample, command) of a streamed PVT path: appends by start and modify, outputs, element
    ids, a STOP while points run out, RESUME, a last append that resumes the resting path."""
    rng = np.random.default_rng(7)

    def chunk(count, base):
        pts = base + np.cumsum(rng.uniform(-40.0, 80.0, size=(count, 2)), axis=0)
        return pts, rng.uniform(-3000.0, 3000.0, size=(count, 2))

    p1, v1 = chunk(6, 0.0)
    p2, v2 = chunk(4, p1[-1])
    p3, v3 = chunk(3, p2[-1])
    p4, _ = chunk(2, p3[-1])
    outputs = [Output(type=OutputType.OUTPUT, address=4, on_mask=1, point_index=0),
               Output(type=OutputType.OUTPUT, address=4, on_mask=2, point_index=3)]
    first = path_params(T.PVT, p1, [0.01] * 6, v1, final=False, empty_count=0, element_id=[1, 2, 3, 4, 5, 6],
                        output=outputs)
    second = path_params(T.PVT, p2, [0.005, 0.01, 0.015, 0.01], v2, final=False, empty_count=0, element_id=[7])
    third = path_params(T.PVT, p3, [0.01] * 3, v3, final=False, empty_count=0, element_id=[8, 9, 10])
    last = path_params(T.PVT, p4, [0.02, 0.01], np.zeros((2, 2)), final=True, element_id=[11])
    return [
        (0, lambda ms: ms.start(T.PVT, A.ELEMENT_ID | A.OUTPUT, first)),
        (37, lambda ms: ms.start(T.PVT, A.APPEND | A.ELEMENT_ID, second)),
        (90, lambda ms: ms.modify(T.PVT, A.APPEND | A.ELEMENT_ID, third)),
        (150, lambda ms: ms.action(MPIAction.STOP)),
        (1300, lambda ms: ms.action(MPIAction.RESUME)),
        (1500, lambda ms: ms.start(T.PVT, A.APPEND | A.ELEMENT_ID, last)),
    ]


def _run_batched(batch: int, end: int = 2200):
    ctl, ms = new_supervisor(notify=None)  # every event
    pending = _batching_script()
    seen = {}
    while ctl.sample < end:
        while pending and pending[0][0] <= ctl.sample:
            assert pending.pop(0)[1](ms).ok
        upcoming = pending[0][0] if pending else end
        ctl.step(max(1, min(batch, upcoming - ctl.sample)))
        seen[ctl.sample] = (ms.state, ms.snapshot().element_id, ctl.io_get(IoSpace.IO, 4)[1],
                            tuple((a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v) for a in ctl.axes))
    events = [(e.sample, e.type, e.axis, e.move_id, e.element_id, e.detail) for e in ctl.drain_events()]
    ends = [(m.message, m.sample, m.detail, m.command_position, m.actual_position)
            for m in ctl.move_log.recent(ms.number)]
    return seen, events, ends


def test_a_path_gives_bit_identical_samples_however_it_is_batched():
    # docs/decisions.md, "Samples, commands and replay": every command takes effect at a sample boundary,
    # which is what makes replay exact (as test_batching.py for point-to-point moves)
    fine, fine_events, fine_ends = _run_batched(1)
    assert fine[2200][0] is MPIState.IDLE  # the script ran to its end
    assert any(t is E.FRAMES_EMPTY for _, t, *_ in fine_events)  # the path ran out, and resumed
    for batch in (7, 100_000):
        coarse, events, ends = _run_batched(batch)
        different = [s for s, values in coarse.items() if fine[s] != values]
        assert not different, f"batch {batch}: {len(different)} samples differ, first at {different[:3]}"
        assert events == fine_events
        assert ends == fine_ends


# ------------------------------------------------------------------ 4. streaming ----
def _smooth(count, t0=0.0, dt=0.01):
    """Points and velocities of x = 2000 sin(2 pi t), y = 800 (1 - cos(2 pi t)) at t0 + dt, ..."""
    t = t0 + dt * np.arange(1, count + 1)
    w = 2.0 * np.pi
    points = np.stack([2000.0 * np.sin(w * t), 800.0 * (1.0 - np.cos(w * t))], axis=1)
    velocities = np.stack([2000.0 * w * np.cos(w * t), 800.0 * w * np.sin(w * t)], axis=1)
    return points, velocities


def test_append_extends_an_open_pvt_path_without_a_gap():
    # MPI 000, MPIMotionPoint, final: "If final=0, more points can be loaded using mpiMotionModify(...)
    # with the MPIMotionAttrMaskAPPEND attribute mask"; MPI 000, MPIMotionAttrAPPEND (start or modify);
    # the appended points follow the last point: PVT's velocity is continuous across the seam
    ctl, ms = new_supervisor()
    points, velocities = _smooth(13)
    velocities[-1] = 0.0  # the path ends at rest (from its end on the command holds the last point)
    first = path_params(T.PVT, points[:6], [0.01] * 6, velocities[:6], final=False, empty_count=0)
    outcome, path_serial = ms.command(T.PVT, A.NONE, first, False)
    message = outcome.message
    assert message.ok
    s0 = ctl.sample
    ctl.step(30)
    second = path_params(T.PVT, points[6:10], [0.01] * 4, velocities[6:10], final=False, empty_count=0)
    outcome, serial_1 = ms.command(T.PVT, A.APPEND, second, False)  # mpiMotionStart with APPEND
    message = outcome.message
    assert message.ok
    ctl.step(10)
    third = path_params(T.PVT, points[10:], [0.01] * 3, velocities[10:], final=True)
    outcome, serial_2 = ms.command(T.PVT, A.APPEND, third, True)  # mpiMotionModify with APPEND
    message = outcome.message
    assert message.ok
    assert len({path_serial, serial_1, serial_2}) == 3
    # one path from the start through all 13 points: PVT pieces depend only on their two points
    whole = Expected.of(T.PVT, (0.0, 0.0), points, [0.01] * 13, velocities)
    point_samples = samples_of([0.01] * 13)
    last_v = np.zeros(2)
    bound = max(a for _, a in whole.peaks()) / RATE * (1 + 1e-9)
    for k in range(41, point_samples[-1] + 1):
        ctl.step(1)
        assert np.allclose(raw(ctl), whole.at(k / RATE), rtol=0.0, atol=1e-8), k
        v = np.array([ctl.axes[0].cmd_v, ctl.axes[1].cmd_v])
        if k > 41:
            assert np.all(np.abs(v - last_v) <= bound), k  # no step in velocity anywhere
        last_v = v
        if k in point_samples:
            i = point_samples.index(k)
            assert np.allclose(raw(ctl), points[i], rtol=0.0, atol=1e-8)
            assert np.allclose(v, velocities[i], rtol=0.0, atol=1e-6)
        # each append is done when its last point is reached; the path goes on
        assert [e.sample for e in ends_of(ctl, serial_1)] == ([s0 + 200] if k >= 200 else [])
        assert [e.sample for e in ends_of(ctl, serial_2)] == ([s0 + 260] if k >= 260 else [])
    for serial in (serial_1, serial_2):
        (end,) = ends_of(ctl, serial)
        assert (end.message, end.detail) == (M.MPIMessageOK, "points executed")
    assert not ends_of(ctl, path_serial)
    assert ms.state is MPIState.MOVING
    run_idle(ctl, ms)
    (end,) = ends_of(ctl, path_serial)
    assert end.message is M.MPIMessageOK
    assert end.detail.startswith("motion done; path peaks")
    assert of_type(ctl.drain_events(), E.FRAMES_EMPTY, E.E_STOP) == []  # fed in time: never starved


def test_an_append_of_zero_points_with_final_closes_the_path():
    # MPI 000, MPIMotionPoint, final: "If final=1, no more points will be loaded"; the path then ends
    # with its last point, and being closed, never signals a low or empty buffer nor E-stops
    ctl, ms = new_supervisor()
    n = round(EXACT_DT * RATE)
    points = np.stack([np.arange(1.0, 41.0), -np.arange(1.0, 41.0)], axis=1)
    outcome, path_serial = ms.command(T.PT, A.NONE, path_params(T.PT, points, [EXACT_DT] * 40, final=False),
                                         False)
    message = outcome.message
    assert message.ok
    s0 = ctl.sample
    ctl.step(4)
    outcome, serial = ms.command(T.PT, A.APPEND, MotionParams(final=True), False)
    message = outcome.message
    assert message.ok
    assert serial != path_serial
    run_idle(ctl, ms, limit=10_000, chunk=50)
    assert [e.type for e in ctl.drain_events()] == [E.MOTION_DONE]
    assert [ctl.axes[n].command_position for n in (0, 1)] == pytest.approx([40.0, -40.0], abs=TOL)
    (closing,) = ends_of(ctl, serial)
    assert (closing.message, closing.detail) == (M.MPIMessageOK, "points executed")
    assert closing.sample == s0 + 40 * n  # done with the path's last point
    assert ends_of(ctl, path_serial)[0].detail.startswith("motion done")


def test_a_closed_path_of_fewer_points_than_empty_count_runs_to_its_end():
    # MPI 000, MPIMotionPoint, emptyCount: "If the number of points in the buffer is below emptyCount,
    # an E_STOP action will occur"; MPI 001, MPIMotionPathAttrMask, EMPTY_COUNT: only "if there are still
    # points to be downloaded"; a closed (final) path has none
    ctl, ms = new_supervisor()
    closed = path_params(T.PT, POINTS, TIMES, empty_count=5)  # 5 points: soon fewer than 5
    assert ms.start(T.PT, A.NONE, closed).ok
    run_idle(ctl, ms)
    assert [e.type for e in ctl.drain_events()] == [E.MOTION_DONE]
    assert ctl.move_log.recent(ms.number)[-1].message is M.MPIMessageOK


def test_a_10000_point_path_streamed_in_chunks_of_50_runs_without_a_gap():
    # MPI 001, MPIMotionPathAttrMask, LOW_COUNT: points are fetched into the buffer as it drains; a path fed
    # in time never starves (MPI 000, MPIMotionPoint, emptyCount, default 5) and runs without a gap:
    # x = 1 count per 1 ms point, so 1000 counts/s from the first sample to the last point
    ctl, ms = new_supervisor()
    total, size = 10_000, 50

    def chunk(a, b, final):
        x = np.arange(a + 1, b + 1, dtype=float)
        return path_params(T.PT, np.stack([x, -0.5 * x], axis=1), [0.001] * (b - a), final=final)

    outcome, path_serial = ms.command(T.PT, A.NONE, chunk(0, size, False), False)
    message = outcome.message
    assert message.ok
    s0 = ctl.sample
    sent, appends = size, []  # (serial, number of its last point)
    while ms.state is MPIState.MOVING:
        assert ctl.frame_count(0) <= 128
        if sent < total and ctl.frame_count(0) < 64:
            b = min(total, sent + size)
            outcome, serial = ms.command(T.PT, A.APPEND, chunk(sent, b, b == total), False)
            message = outcome.message
            assert message.ok
            appends.append((serial, b))
            sent = b
        ctl.step(10)
        k = ctl.sample - s0
        if k < 2 * total:
            assert ctl.axes[0].command_position == pytest.approx(k / 2.0, abs=1e-6), k
            assert ctl.axes[0].cmd_v == pytest.approx(1000.0, abs=1e-6), k
        assert ctl.sample - s0 < 2 * total + 2000, "the path never ended"
    assert ms.state is MPIState.IDLE
    assert sent == total
    assert [ctl.axes[n].command_position for n in (0, 1)] == pytest.approx([10_000.0, -5_000.0], abs=TOL)
    events = ctl.drain_events()
    assert of_type(events, E.E_STOP, E.FRAMES_EMPTY) == []
    assert of_type(events, E.MOTION_DONE)
    assert len(appends) == total // size - 1
    assert len({s for s, _ in appends} | {path_serial}) == total // size
    (end,) = ends_of(ctl, path_serial)
    assert end.message is M.MPIMessageOK
    assert end.detail.startswith("motion done")
    # every append ends (OK, "points executed") at the sample its last point is reached: 2 per point
    late = []
    for serial, last_point in appends:
        (done,) = ends_of(ctl, serial)
        assert (done.message, done.detail) == (M.MPIMessageOK, "points executed")
        if done.sample != s0 + 2 * last_point:
            late.append((last_point, done.sample - s0))
    assert not late, f"{len(late)} appends end off their last point's sample, e.g. (point, sample) {late[:3]}"


# ------------------------------------------------------------------ 5. frame buffer ----
@pytest.mark.parametrize("buffer", [128, 64])
def test_the_frame_count_never_exceeds_the_buffer_for_a_1000_point_request(buffer):
    # MPI 000, mpiMotionStart: "Each axis has a 128 frame buffer (FIFO)"; MPI 001, MPIMotionPathAttrMask,
    # LOW_COUNT: "If all of the points will not fit into the buffer" they are fetched as it drains;
    # "FrameBufferSize is configurable"
    ctl, ms = new_supervisor(ControllerConfig(frame_buffer_size=buffer))
    count = 1000
    x = np.arange(1.0, count + 1)
    assert ms.start(T.PT, A.NONE, path_params(T.PT, np.stack([x, 2 * x], axis=1), [0.001] * count)).ok
    seen = []
    while ms.state is MPIState.MOVING:
        counts = [ctl.frame_count(0), ctl.frame_count(1), ctl.axis_snapshot(1).frame_count]
        counts += [status.frame_count for status in ms.frame_buffer_status()[1]]
        seen.append(max(counts))
        ctl.step(1)
    assert max(seen) == buffer
    assert seen[0] == buffer
    assert seen[-1] < buffer
    assert ctl.axes[0].command_position == count


@pytest.mark.parametrize("dt", [EXACT_DT, 0.01, 0.001], ids=["dt=1/16s", "dt=10ms", "dt=1ms"])
def test_frames_low_then_empty_count_e_stop_at_their_exact_samples(dt):
    # MPI 001, MPIMotionPathAttrMask, LOW_COUNT: "if no changes are made, LOW_COUNT default is 32" (128 // 4):
    # FRAMES_LOW when fewer than 32 points are left; MPI 000, MPIMotionPoint, emptyCount (default 5,
    # MPI 001, EMPTY_COUNT): E_STOP when fewer than 5 are left while the path is open. 40 points dt apart:
    # point i (1-based) is reached at i * dt (MPI 000, Streaming Point Motion Type Calculations), a whole
    # number n of samples each; 9 reached leaves 31, 36 reached leaves 4.
    ctl, ms = new_supervisor()
    n = round(dt * RATE)
    points = np.stack([np.arange(1.0, 41.0), np.zeros(40)], axis=1)
    outcome, serial = ms.command(T.PT, A.ELEMENT_ID, path_params(T.PT, points, [dt] * 40, final=False,
                                                                  element_id=list(range(1, 41))), False)
    message = outcome.message
    assert message.ok
    s0 = ctl.sample
    ctl.step(36 * n - 1)
    assert ms.state is MPIState.MOVING
    ctl.step(1)
    events = ctl.drain_events()
    assert [(e.sample - s0, e.type) for e in events] == [(9 * n, E.FRAMES_LOW), (36 * n, E.E_STOP)]
    low, stop = events
    assert "32" in low.detail
    assert low.element_id == 10
    assert "emptyCount" in stop.detail
    assert stop.element_id == 37
    assert ms.state is MPIState.STOPPING_ERROR
    assert ms.snapshot().last_action == "E_STOP"
    assert ctl.run_until(lambda c: ms.state is MPIState.ERROR, 400)
    (end,) = ends_of(ctl, serial)
    assert end.message is M.MPIMotionMessageERROR


def test_low_count_follows_the_configured_frame_buffer_size():
    # MPI 001, MPIMotionPathAttrMask, LOW_COUNT: "FrameBufferSize is configurable" (lowCount = size // 4:
    # 64 -> 16; 25 of 40 points reached leaves 15)
    ctl, ms = new_supervisor(ControllerConfig(frame_buffer_size=64))
    n = round(EXACT_DT * RATE)
    points = np.stack([np.arange(1.0, 41.0), np.zeros(40)], axis=1)
    assert ms.start(T.PT, A.NONE, path_params(T.PT, points, [EXACT_DT] * 40, final=False, empty_count=0)).ok
    s0 = ctl.sample
    ctl.step(30 * n)
    assert [(e.sample - s0, e.type) for e in ctl.drain_events()] == [(25 * n, E.FRAMES_LOW)]


@pytest.mark.parametrize("empty_count", [0, -1])
def test_without_empty_count_the_path_rests_on_its_last_point_and_an_append_resumes_it(empty_count):
    # MPI 000, MPIMotionPoint, emptyCount: "When emptyCount is (-1), the buffer low trigger is disabled";
    # MPI 001, MPIMotionPathAttrMask, EMPTY_COUNT: "To disable path-based deceleration, set the value to
    # zero". Out of points the open path rests on its last point (FRAMES_EMPTY, still MOVING: more points
    # are expected) and points appended later run from there.
    ctl, ms = new_supervisor()
    n = round(EXACT_DT * RATE)
    points = np.stack([10.0 * np.arange(1.0, 9.0), -5.0 * np.arange(1.0, 9.0)], axis=1)
    params = path_params(T.PT, points, [EXACT_DT] * 8, final=False, empty_count=empty_count,
                         element_id=list(range(51, 59)))
    assert ms.start(T.PT, A.ELEMENT_ID, params).ok
    s0 = ctl.sample
    ctl.step(8 * n + 500)
    events = ctl.drain_events()
    empty = of_type(events, E.FRAMES_EMPTY)
    assert [e.sample - s0 for e in empty] == [8 * n]
    assert empty[0].element_id == 58
    assert of_type(events, E.E_STOP, E.MOTION_DONE) == []
    assert ms.state is MPIState.MOVING
    assert raw(ctl) == pytest.approx(points[-1], abs=TOL)
    assert ctl.axes[0].cmd_v == 0.0
    resumed = ctl.sample
    more = np.array([[90.0, -45.0], [130.0, -25.0]])
    assert ms.start(T.PT, A.APPEND, path_params(T.PT, more, [EXACT_DT, EXACT_DT], final=True)).ok
    expected = Expected.of(T.PT, points[-1], more, [EXACT_DT] * 2)
    for k in range(1, 2 * n + 1):
        ctl.step(1)
        assert np.allclose(raw(ctl), expected.at(k / RATE), rtol=0.0, atol=TOL), k
    assert ctl.sample == resumed + 2 * n
    assert raw(ctl) == pytest.approx(more[-1], abs=TOL)
    run_idle(ctl, ms)
    assert [e.type for e in of_type(ctl.drain_events(), E.MOTION_DONE, E.E_STOP, E.FRAMES_EMPTY)] == [E.MOTION_DONE]
    assert ctl.move_log.recent(ms.number)[-1].message is M.MPIMessageOK


def test_a_closed_path_never_signals_the_buffer_nor_e_stops():
    # MPI 001, MPIMotionPathAttrMask, EMPTY_COUNT: the E_STOP needs "points to be downloaded" and LOW_COUNT
    # "fetching of new points": a final path has none to fetch
    ctl, ms = new_supervisor()
    points = np.stack([np.arange(1.0, 41.0), np.zeros(40)], axis=1)
    assert ms.start(T.PT, A.NONE, path_params(T.PT, points, [0.001] * 40, final=True, empty_count=5)).ok
    run_idle(ctl, ms)
    assert [e.type for e in ctl.drain_events()] == [E.MOTION_DONE]


# ------------------------------------------------------------------ 6. ELEMENT_ID ----
ID_TIMES = {
    "mixed": ([0.01, 0.02, 0.015, 0.005], [0.01, 0.005, 0.02]),
    "1ms": ([0.001] * 12, [0.001] * 8),
}


@pytest.mark.parametrize("times", list(ID_TIMES), ids=list(ID_TIMES))
def test_element_id_is_the_id_of_the_point_the_path_runs_toward(times):
    # MPI 000, MPIMotionAttributes, elementId: "This array defines the identity for each element of a path
    # motion"; the status (mpiMotionStatus, mpiAxisStatus) and the events report the current element
    first_times, more_times = ID_TIMES[times]
    ctl, ms = new_supervisor(notify=E.MOTION_DONE)
    first_ids = [100 + i for i in range(len(first_times))]
    more_ids = [200 + i for i in range(len(more_times))]
    def pts(count, base):
        return np.stack([base + np.arange(1.0, count + 1), np.zeros(count)], axis=1)
    first = path_params(T.PT, pts(len(first_times), 0.0), first_times, final=False, empty_count=0,
                        element_id=first_ids)
    assert ms.start(T.PT, A.ELEMENT_ID, first).ok
    more = path_params(T.PT, pts(len(more_times), len(first_times)), more_times, final=True, element_id=more_ids)
    assert ms.start(T.PT, A.APPEND | A.ELEMENT_ID, more).ok  # appended at once, with their own ids
    s0 = ctl.sample
    reached = samples_of(first_times + more_times)
    ids = first_ids + more_ids
    wrong = []
    for k in range(0, reached[-1] + 10):
        toward = ids[min(sum(1 for r in reached if r <= k), len(ids) - 1)]
        seen = (ms.snapshot().element_id, ctl.axis_snapshot(0).element_id, ctl.axis_snapshot(1).element_id)
        if seen != (toward,) * 3:
            wrong.append((k, toward, seen))
        ctl.step(1)
    assert not wrong, f"{len(wrong)} samples off, first (sample, expected, seen): {wrong[:3]}"
    run_idle(ctl, ms)
    (done,) = ctl.drain_events()
    assert done.type is E.MOTION_DONE
    assert done.element_id == ids[-1]
    assert done.sample > s0


def test_one_element_id_for_all_points():
    # MPI 000, MPIMotionAttributes, elementId (one value: the identity of every element)
    ctl, ms = new_supervisor()
    assert ms.start(T.PVT, A.ELEMENT_ID, path_params(T.PVT, POINTS, TIMES, VELOCITIES, element_id=[42])).ok
    for _ in range(samples_of(TIMES)[-1] + 5):
        assert ms.snapshot().element_id == 42
        assert ctl.axis_snapshot(1).element_id == 42
        ctl.step(1)


def test_points_appended_without_element_ids_leave_the_later_ids_in_place():
    # MPI 000, MPIMotionAttributes, elementId: the identity "for each element"; an append without
    # ELEMENT_ID gives its points none, and the points appended after it with ids keep theirs
    ctl, ms = new_supervisor()
    n = round(EXACT_DT * RATE)
    def pts(base, count):
        return np.stack([base + np.arange(1.0, count + 1), np.zeros(count)], axis=1)
    first = path_params(T.PT, pts(0.0, 4), [EXACT_DT] * 4, final=False, empty_count=0, element_id=[1, 2, 3, 4])
    assert ms.start(T.PT, A.ELEMENT_ID, first).ok
    s0 = ctl.sample
    unlabeled = path_params(T.PT, pts(4.0, 2), [EXACT_DT] * 2, final=False, empty_count=0)
    assert ms.start(T.PT, A.APPEND, unlabeled).ok
    labeled = path_params(T.PT, pts(6.0, 2), [EXACT_DT] * 2, final=True, element_id=[7, 8])
    assert ms.start(T.PT, A.APPEND | A.ELEMENT_ID, labeled).ok
    seen = {}
    for k in range(0, 8 * n + 1):
        seen[k] = ms.snapshot().element_id
        ctl.step(1)
    assert [seen[k] for k in (1, n + 1, 2 * n + 1, 3 * n + 1)] == [1, 2, 3, 4]
    assert [seen[k] for k in (6 * n + 1, 7 * n + 1, 8 * n)] == [7, 8, 8]
    run_idle(ctl, ms)
    assert raw(ctl) == pytest.approx([8.0, 0.0], abs=TOL)
    assert ctl.sample > s0


@pytest.mark.parametrize("batch", [1, 1000])
def test_axis_events_carry_the_element_id_of_their_sample(batch):
    # MPI 000, MPIMotionAttributes, elementId: every event of the path carries the element it runs toward
    # at the event's sample (IN_COARSE_POSITION, AT_TARGET, ... of MPI 002 included), however the
    # controller's samples are batched (docs/decisions.md, "Samples, commands and replay")
    ctl, ms = new_supervisor(notify=E.IN_COARSE_POSITION | E.AT_TARGET | E.DONE | E.MOTION_DONE)
    points = [[100.0, 50.0], [3000.0, 10.0], [3100.0, 30.0], [3200.0, 40.0]]
    times = [0.01] * 4
    assert ms.start(T.PT, A.ELEMENT_ID, path_params(T.PT, points, times, element_id=[1, 2, 3, 4])).ok
    s0 = ctl.sample
    while ctl.sample < s0 + 400:
        ctl.step(batch)
    reached = samples_of(times)
    events = ctl.drain_events()
    assert len(events) >= 4
    assert events[-1].type is E.MOTION_DONE
    wrong = [(e.sample - s0, e.type.name, e.axis, e.element_id) for e in events
             if e.element_id != 1 + min(sum(1 for r in reached if r <= e.sample - s0), 3)]
    assert not wrong, f"events with the element id of another sample (sample, type, axis, id): {wrong}"


# ------------------------------------------------------------------ 7. OUTPUT ----
OUTPUT_TIMES = {
    "mixed": ([0.01, 0.02, 0.015, 0.005], [0, 1, 2, 3], [0.01, 0.005, 0.02], [0, 2]),
    "1ms": ([0.001] * 20, [0, 5, 10, 15], [0.001] * 10, [0, 5]),
}


@pytest.mark.parametrize("times", list(OUTPUT_TIMES), ids=list(OUTPUT_TIMES))
def test_output_by_point_index_is_applied_as_the_segment_toward_that_point_begins(times):
    # MPI 000, MEIMotionAttrOutput, pointIndex: "an index to a point, when multiple point motion is used";
    # MPI 000, MEIMotionAttrOUTPUT "as a move begins": the output of point i is applied as the segment toward
    # point i begins (index 0 at the start, index i when point i-1 is reached), appended points alike
    first_times, first_indices, more_times, more_indices = OUTPUT_TIMES[times]
    ctl, ms = new_supervisor()
    bit = iter(range(32))
    first_out = [Output(type=OutputType.OUTPUT, address=5, on_mask=1 << next(bit), point_index=i)
                 for i in first_indices]
    more_out = [Output(type=OutputType.OUTPUT, address=5, on_mask=1 << next(bit), point_index=i)
                for i in more_indices]
    def pts(count):
        return np.stack([np.arange(1.0, count + 1), np.zeros(count)], axis=1)
    assert ctl.io_get(IoSpace.IO, 5)[1] == 0
    first = path_params(T.PT, pts(len(first_times)), first_times, final=False, empty_count=0, output=first_out)
    assert ms.start(T.PT, A.OUTPUT, first).ok
    more = path_params(T.PT, 100 + pts(len(more_times)), more_times, final=True, output=more_out)
    assert ms.start(T.PT, A.APPEND | A.OUTPUT, more).ok
    reached = [0, *samples_of(first_times)]
    begin = reached[-1]
    due = [(reached[out.point_index], out.on_mask) for out in first_out]
    due += [(begin + ([0, *samples_of(more_times)])[out.point_index], out.on_mask) for out in more_out]
    wrong = []
    for k in range(0, begin + samples_of(more_times)[-1] + 5):
        expected = sum(mask for when, mask in due if when <= k)
        word = ctl.io_get(IoSpace.IO, 5)[1]
        if word != expected:
            wrong.append((k, bin(expected), bin(word)))
        ctl.step(1)
    assert not wrong, f"{len(wrong)} samples off, first (sample, expected, word): {wrong[:3]}"


# ------------------------------------------------------------------ 8. shortest path ----
def test_the_first_point_is_taken_the_short_way_and_the_others_keep_their_distances():
    # MPI 000, MPIMotionType, Example: current 2147483638 (2^31 - 10), first point -2147483638: "With the
    # shortest path algorithm, -2147483638 is converted to 2147483658"; "It DOES NOT apply to points
    # within the points list": they keep their distances to the first point
    ctl, ms = new_supervisor()
    here = 2.0**31 - 10
    assert ctl.axis_command_position_set(0, here).ok
    assert ctl.axis_actual_position_set(0, here).ok
    given = [-2147483638.0, -2147483628.0, 2147483600.0]
    times = [0.01, 0.01, 1.0]
    assert ms.start(T.PT, A.NONE, path_params(T.PT, np.stack([given, np.zeros(3)], axis=1), times)).ok
    for k in range(1, 21):
        ctl.step(1)
        assert abs(ctl.axes[0].unwrapped_command - here) <= 20.0 * (1 + 1e-12), k  # the short 20 counts
    # the MPI's (continuous) view, and the controller's 32-bit one (docs/paths.md)
    taken = [2147483658.0, 2147483668.0, 2147483600.0 + 2.0**32]
    assert ctl.axes[0].unwrapped_command == pytest.approx(taken[0], abs=1e-6)
    assert ctl.axes[0].command_position == pytest.approx(given[0], abs=1e-6)
    ctl.step(20)
    assert ctl.axes[0].unwrapped_command == pytest.approx(taken[1], abs=1e-6)
    assert ctl.axes[0].command_position == pytest.approx(given[1], abs=1e-6)
    ctl.step(2000)
    assert ctl.axes[0].unwrapped_command == pytest.approx(taken[2], abs=1e-3)
    assert ctl.axes[0].command_position == pytest.approx(given[2], abs=1e-3)


# ------------------------------------------------------------------ 9. validation ----
def _idle(ctl, ms):
    place(ctl)


def _open_path(ctl, ms):
    """An open PT path of 200 points, running."""
    place(ctl)
    x = np.arange(1.0, 201.0)
    params = path_params(T.PT, np.stack([x, -x], axis=1), [0.005] * 200, final=False, empty_count=0)
    assert ms.start(T.PT, A.RELATIVE, params).ok
    ctl.step(100)


def _twins(setup):
    out = []
    for _ in range(2):
        ctl, ms = new_supervisor(notify=None)
        setup(ctl, ms)
        ctl.drain_events()
        out.append((ctl, ms))
    return out


def _observe(ctl, ms, samples=600):
    """What a refused command must not change: the motion from now on, state, events, outcomes."""
    trace = []
    for _ in range(samples // 50):
        ctl.step(50)
        trace.append((ms.state, ms.snapshot().element_id, tuple((a.cmd_p, a.act_p) for a in ctl.axes)))
    events = [(e.sample, e.type, e.supervisor, e.axis, e.move_id, e.element_id) for e in ctl.drain_events()]
    ends = [(m.message, m.sample, m.detail) for m in ctl.move_log.recent(ms.number)]
    return trace, events, ends, len(ms.queue), ms.stored_params


NAN, INF = float("nan"), float("inf")
P3 = np.array([[10.0, 5.0], [20.0, 10.0], [30.0, 0.0]])
T3 = [0.01, 0.01, 0.01]
REST = [UserFrame(0.0, 0.0, 0.0, 0.0, 0.01)] * 2  # a frame per axis, at rest


def _with(kind, **changes) -> MotionParams:
    params = path_params(kind, P3, T3, np.ones((3, 2)))
    for name, value in changes.items():
        setattr(params, name, value)
    return params


def _output(index):
    return [Output(type=OutputType.OUTPUT, address=0, on_mask=1, point_index=index)]


def _too_many() -> MotionParams:
    points = (MAX_PATH_VALUES + 2) // 2
    return MotionParams(position=[1.0] * (2 * points), time=[0.01] * points)


BAD_DATA = M.MEIMotionMessageBAD_PATH_DATA
PARAM = M.MPIMessagePARAM_INVALID
PATH = M.MPIMotionMessagePATH_ERROR
ATTR = M.MPIMotionMessageATTRIBUTE_INVALID
UNSUPPORTED = M.MPIMessageUNSUPPORTED
# (name, setup, modify, type, attributes, params, expected)
REFUSED = [
    # MPI 000, MEIMotionMessageBAD_PATH_DATA: "If any of the motion parameters passed to the MPI for path
    # motion are infinite or NAN, the MPI will return MEIMotionMessageBAD_PATH_DATA and will not load the move"
    ("nan position", _idle, False, T.PT, A.NONE, _with(T.PT, position=[10.0, NAN, 20.0, 10.0, 30.0, 0.0]), BAD_DATA),
    ("inf time appended", _open_path, False, T.PT, A.APPEND, _with(T.PT, time=[0.01, INF, 0.01]), BAD_DATA),
    ("nan point velocity", _idle, False, T.PVT, A.NONE, _with(T.PVT, point_velocity=[0.0] * 5 + [NAN]), BAD_DATA),
    ("inf feedforward", _idle, False, T.PTF, A.NONE, _with(T.PTF, feedforward=[INF] + [0.0] * 5), BAD_DATA),
    ("nan frame", _idle, False, T.FRAME, A.NONE,
     MotionParams(frames=[UserFrame(0.0, 0.0, 0.0, NAN, 0.01), REST[1]]), BAD_DATA),
    ("nan appended pvtf", _open_path, True, T.PVTF, A.APPEND, _with(T.PVTF, point_velocity=[NAN] * 6), BAD_DATA),
    # MPI 000, MPIMotionPT, position: "The length of the array must be equal to pointCount multiplied by the
    # number of axes"; time: "The length of the time array must be equal to pointCount"
    ("position not points x axes", _idle, False, T.PT, A.NONE, _with(T.PT, position=[1.0] * 5), PARAM),
    ("position of an append", _open_path, False, T.PT, A.APPEND, _with(T.PT, position=[1.0] * 8), PARAM),
    ("pvt velocity not points x axes", _idle, False, T.PVT, A.NONE, _with(T.PVT, point_velocity=[0.0] * 4), PARAM),
    ("ptf feedforward not points x axes", _idle, False, T.PTF, A.NONE, _with(T.PTF, feedforward=[0.0] * 3),
     PARAM),  # MPI 000, MPIMotionPTF, feedforward
    ("pvtf feedforward not points x axes", _open_path, True, T.PVTF, A.APPEND,
     _with(T.PVTF, feedforward=[0.0] * 7), PARAM),
    ("frames not per axis", _idle, False, T.FRAME, A.NONE, MotionParams(frames=REST + REST[:1]), PARAM),
    # MPI 000, MPIMotionAttributes, elementId: "the identity for each element": one per point (or one)
    ("element_id of 2 for 3 points", _idle, False, T.PT, A.ELEMENT_ID, _with(T.PT, element_id=[1, 2]), PARAM),
    ("element_id of 4 for 3 points", _open_path, False, T.PT, A.APPEND | A.ELEMENT_ID,
     _with(T.PT, element_id=[1, 2, 3, 4]), PARAM),
    # MPI 000, MEIMotionAttrOutput, pointIndex: "an index to a point" of the move
    ("output past the points", _idle, False, T.PT, A.OUTPUT, _with(T.PT, output=_output(3)), PARAM),
    ("output negative index", _idle, False, T.PT, A.OUTPUT, _with(T.PT, output=_output(-1)), PARAM),
    ("zero points on a start", _idle, False, T.PT, A.NONE, MotionParams(), PARAM),
    ("more than MAX_PATH_VALUES", _idle, False, T.PT, A.NONE, _too_many(), PARAM),
    # MPI 000, MPIMotionMessagePATH_ERROR: "when the final point is not specified or the time slice is less
    # than one controller sample"
    ("time slice below a sample", _idle, False, T.PT, A.NONE, _with(T.PT, time=[0.01, 0.0004, 0.01]), PATH),
    ("appended slice below a sample", _open_path, True, T.PVT, A.APPEND, _with(T.PVT, time=[0.0004] * 3), PATH),
    ("zero frame time", _idle, False, T.FRAME, A.NONE, MotionParams(frames=[REST[0], UserFrame()]), PATH),
    ("spline without final point", _idle, False, T.SPLINE, A.NONE, _with(T.SPLINE, final=False), PATH),
    ("point-to-point onto an open path", _open_path, False, T.TRAPEZOIDAL, A.APPEND,
     MotionParams(trajectory=[Trajectory(1000.0, 1e4, 1e4)], position=[0.0, 0.0]), PATH),
    ("velocity onto an open path", _open_path, True, T.VELOCITY, A.APPEND,
     MotionParams(trajectory=[Trajectory(100.0, 1e4, 1e4)]), PATH),
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID: SPLINE may not carry APPEND; FRAME only APPEND and ID; the
    # path types only APPEND RELATIVE ID ELEMENT_ID HOLD HOLD_LESS HOLD_GREATER OUTPUT
    ("spline with append", _idle, False, T.SPLINE, A.APPEND, _with(T.SPLINE), ATTR),
    ("frame relative", _idle, False, T.FRAME, A.RELATIVE, MotionParams(frames=REST), ATTR),
    ("frame element id", _idle, False, T.FRAME, A.ELEMENT_ID, MotionParams(frames=REST, element_id=[1]), ATTR),
    ("frame output", _idle, False, T.FRAME, A.OUTPUT, MotionParams(frames=REST, output=_output(0)), ATTR),
    ("pt with sync start", _idle, False, T.PT, A.SYNC_START, _with(T.PT), ATTR),
    ("pvt with delay", _open_path, False, T.PVT, A.APPEND | A.DELAY, _with(T.PVT, delay=[0.0, 0.0]), ATTR),
] + [
    # MPI 000, mpiMotionModify: "The types of motion whose parameters can be modified while moving are
    # TRAPEZOIDAL, S_CURVE, VELOCITY, PT and PVT": without APPEND the other path types are refused
    (f"modify {kind.name} without append", _open_path, True, kind, A.NONE, _with(kind), UNSUPPORTED)
    for kind in (T.PTF, T.PVTF, T.BESSEL, T.BSPLINE, T.BSPLINE2, T.SPLINE, T.FRAME)
]


@pytest.mark.parametrize(("name", "setup", "modify", "kind", "attrs", "params", "expected"), REFUSED,
                         ids=[r[0] for r in REFUSED])
def test_a_refused_path_command_changes_nothing(name, setup, modify, kind, attrs, params, expected):
    # MPI 000, Returns for mpiMotionStart and mpiMotionModify; docs/quality.md, "Robust": bad input gets
    # the reference's message and changes nothing (as test_validate.py, test_a_refused_command_changes_nothing)
    (ctl_a, ms_a), (ctl_b, ms_b) = _twins(setup)
    outcome, _ = ms_b.command(kind, attrs, params, modify)
    message = outcome.message
    assert message is expected
    assert _observe(ctl_a, ms_a) == _observe(ctl_b, ms_b)


def test_a_time_slice_of_one_sample_is_accepted():
    # MPI 000, MPIMotionMessagePATH_ERROR: only "less than one controller sample" is refused
    ctl, ms = new_supervisor()
    assert ms.start(T.PT, A.NONE, path_params(T.PT, P3, [1.0 / RATE] * 3)).ok
    ctl.step(3)
    assert raw(ctl) == pytest.approx(P3[-1], abs=TOL)


def _running(kind):
    """A long closed path of ``kind`` (or FRAME moves) in progress: 40 points, 2 s."""
    def setup(ctl, ms):
        if kind is T.FRAME:
            # from rest where the axes are (user 0), accelerating: a FRAME move may not step the command
            frames = [UserFrame(0.0, 0.0, 100.0, 0.0, 2.0), UserFrame(0.0, 0.0, -50.0, 0.0, 2.0)]
            assert ms.start(T.FRAME, A.NONE, MotionParams(frames=frames)).ok
        else:
            t = np.arange(1.0, 41.0)
            points = np.stack([10.0 * t + 5.0 * np.sin(t), -7.0 * t], axis=1)
            assert ms.start(kind, A.RELATIVE, path_params(kind, points, [0.05] * 40, np.ones((40, 2)))).ok
        ctl.step(200)
        assert ms.state is MPIState.MOVING
    return setup


UNMODIFIABLE = [T.SPLINE, T.BSPLINE, T.BSPLINE2, T.BESSEL, T.PTF, T.PVTF, T.FRAME]
MODIFYING = [(T.TRAPEZOIDAL, MotionParams(trajectory=[Trajectory(500.0, 1e4, 1e4)], position=[0.0, 0.0])),
             (T.VELOCITY, MotionParams(trajectory=[Trajectory(500.0, 1e4, 1e4)])),
             (T.PT, path_params(T.PT, P3, T3))]


@pytest.mark.parametrize("running", UNMODIFIABLE, ids=[k.name for k in UNMODIFIABLE])
@pytest.mark.parametrize(("kind", "params"), MODIFYING, ids=[k.name for k, _ in MODIFYING])
def test_the_running_motions_type_decides_whether_it_can_be_modified(running, kind, params):
    # MPI 000, mpiMotionModify: "The types of motion whose parameters can be modified while moving are
    # MPIMotionTypeTRAPEZOIDAL, MPIMotionTypeS_CURVE, MPIMotionTypeVELOCITY, MPIMotionTypePT and
    # MPIMotionTypePVT": a modify of a modifiable type does not replace a motion that cannot be modified
    (ctl_a, ms_a), (ctl_b, ms_b) = _twins(_running(running))
    outcome, _ = ms_b.command(kind, A.NONE, params, True)
    assert outcome.message is M.MPIMessageUNSUPPORTED
    assert running.name in outcome.detail
    assert _observe(ctl_a, ms_a) == _observe(ctl_b, ms_b)


APPENDABLE = [T.PT, T.PTF, T.PVT, T.PVTF, T.BESSEL, T.BSPLINE, T.BSPLINE2]
BSPLINES = [T.BSPLINE, T.BSPLINE2]


@pytest.mark.parametrize("kind", APPENDABLE, ids=[k.name for k in APPENDABLE])
def test_a_modify_with_append_adds_points_and_modifies_nothing(kind):
    # MPI 000, MPIMotionPoint, final: more points are loaded "using mpiMotionModify(...) with the
    # MPIMotionAttrMaskAPPEND attribute mask" (docs/paths.md: for every type that may carry APPEND; the
    # points already given run unchanged; a B-spline's run on the one curve of all the points, which its
    # first points settle only in part: four settle none of a cubic's, so it starts when the rest come)
    ctl, ms = new_supervisor()
    first = np.array([[20.0, 10.0], [50.0, 30.0], [60.0, 70.0], [90.0, 80.0]])
    outcome, path_serial = ms.command(kind, A.NONE, path_params(kind, first, [EXACT_DT] * 4, final=False,
                                                                   empty_count=0), False)
    message = outcome.message
    assert message.ok
    more = np.array([[120.0, 60.0], [150.0, 40.0], [170.0, 20.0]])
    late = 10 if kind is T.BSPLINE else 0
    if kind in BSPLINES:
        expected = Expected.of(kind, (0.0, 0.0), np.concatenate([first, more]), [EXACT_DT] * 7)
    else:
        expected = Expected.of(kind, (0.0, 0.0), first, [EXACT_DT] * 4,
                               np.zeros((4, 2)) if kind in WITH_VELOCITY else None)
    ctl.step(10)
    outcome, serial = ms.command(kind, A.APPEND, path_params(kind, more, [EXACT_DT] * 3, final=True), True)
    message = outcome.message
    assert message.ok
    assert serial != path_serial
    n = round(EXACT_DT * RATE)
    for k in range(11, 4 * n + 1):
        ctl.step(1)
        assert np.allclose(raw(ctl), expected.at((k - late) / RATE), rtol=0.0, atol=1e-6 if late else TOL), k
    run_idle(ctl, ms)
    assert raw(ctl) == pytest.approx(more[-1], abs=TOL)
    (done,) = ends_of(ctl, serial)
    assert (done.message, done.detail, done.sample) == (M.MPIMessageOK, "points executed", 7 * n + late)
    assert ends_of(ctl, path_serial)[0].message is M.MPIMessageOK


@pytest.mark.parametrize("kind", BSPLINES, ids=[k.name for k in BSPLINES])
@pytest.mark.parametrize("chunks", [(6, 5), (6, 1, 1, 3), (7, 2, 2, 0)], ids=["6+5", "6+1+1+3", "7+2+2+close"])
def test_a_streamed_b_spline_is_the_one_request_b_spline(kind, chunks):
    # MPI 000, MPIMotionPoint.final: "If final=0, more points can be loaded using mpiMotionModify(...) with the
    # MPIMotionAttrMaskAPPEND attribute" (APPEND is among the BSPLINE, BSPLINE2 attributes); MPIMotionTypeBSPLINE
    # fits one B spline "through a list of position and time points", and the reference warns of a velocity step
    # at an appended seam for the cubic SPLINE only (Streaming Point Motion Type Calculations): points streamed in
    # time make the same curve as the same points given in one request
    ctl, ms = new_supervisor()
    count = sum(chunks)
    t = np.arange(1.0, count + 1.0)
    points = np.stack([40.0 * t + 30.0 * np.sin(t), 25.0 * np.cos(0.7 * t) - 10.0 * t], axis=1)
    times = [EXACT_DT * (1 + (i % 3)) for i in range(count)]
    expected = Expected.of(kind, (0.0, 0.0), points, times)
    n = round(EXACT_DT * RATE)
    first = 0
    trace = []
    for index, size in enumerate(chunks):
        final = index == len(chunks) - 1
        params = path_params(kind, points[first:first + size], times[first:first + size], final=final,
                             empty_count=0)
        outcome, _ = ms.command(kind, A.APPEND if index else A.NONE, params, bool(index))
        assert outcome.ok
        first += size
        for _ in range(n // 5):  # each chunk comes in good time, while the path runs well inside what it has
            ctl.step(1)
            trace.append(raw(ctl))
    while ms.state is not MPIState.IDLE:
        ctl.step(1)
        trace.append(raw(ctl))
    trace = np.array(trace)
    wanted = np.array([expected.at(k / RATE) for k in range(1, len(trace) + 1)])
    assert np.allclose(trace, wanted, rtol=0.0, atol=1e-6)
    assert trace[-1] == pytest.approx(points[-1], abs=TOL)


@pytest.mark.parametrize("kind", BSPLINES, ids=[k.name for k in BSPLINES])
def test_a_b_spline_that_runs_out_waits_where_its_points_settle_it_then_runs_the_same_curve(kind):
    # MPI 000, mpiMotionStart: a path whose points come too late underflows ("the axis jumps on a frame
    # underflow"): an open B-spline runs only as far as its points settle the curve (docs/paths.md), two
    # points of a BSPLINE2 (three of a BSPLINE) settle none of it; the points that come later run the rest of
    # the same curve, later by the wait
    ctl, ms = new_supervisor()
    t = np.arange(1.0, 10.0)
    points = np.stack([30.0 * t, 20.0 * np.sin(t)], axis=1)
    times = [EXACT_DT] * 9
    early = 2 if kind is T.BSPLINE2 else 3
    assert ms.command(kind, A.NONE, path_params(kind, points[:early], times[:early], final=False, empty_count=0),
                      False)[0].ok
    ctl.drain_events()
    ctl.step(40)
    assert np.array_equal(raw(ctl), [0.0, 0.0])
    assert [e.sample for e in ctl.drain_events() if e.type is E.FRAMES_EMPTY] == [1]  # it ran out at once
    assert ms.command(kind, A.APPEND, path_params(kind, points[early:], times[early:]), True)[0].ok
    expected = Expected.of(kind, (0.0, 0.0), points, times)
    for k in range(1, round(9 * EXACT_DT * RATE) + 10):
        ctl.step(1)
        assert np.allclose(raw(ctl), expected.at(k / RATE), rtol=0.0, atol=1e-6), k
    run_idle(ctl, ms)


@pytest.mark.parametrize("kind", [T.PT, T.PVT], ids=["PT", "PVT"])
def test_a_pt_or_pvt_modify_replaces_the_path_from_the_command_position(kind):
    # MPI 000, mpiMotionModify: PT and PVT "can be modified while moving": the new points run from where
    # the axes are (PVT: from their velocity too), the move keeps its identity
    ctl, ms = new_supervisor()
    outcome, serial = ms.command(kind, A.NONE, path_params(kind, [[100.0, 50.0], [200.0, 100.0], [300.0, 150.0]],
                                                              [0.02] * 3, [[5000.0, 2000.0]] * 2 + [[0.0, 0.0]]),
                                    False)
    message = outcome.message
    assert message.ok
    ctl.step(15)
    here = raw(ctl)
    velocity = (ctl.axes[0].cmd_v, ctl.axes[1].cmd_v)
    assert abs(velocity[0]) > 100.0
    new_points, new_times, new_velocities = [[150.0, 0.0], [160.0, -10.0]], [0.01, 0.02], [[0.0, -500.0], [0.0, 0.0]]
    outcome, modified = ms.command(kind, A.NONE, path_params(kind, new_points, new_times, new_velocities), True)
    message = outcome.message
    assert message.ok
    assert modified == serial
    expected = Expected.of(kind, here, new_points, new_times, new_velocities if kind is T.PVT else None,
                           start_velocity=velocity)
    for k in range(1, 80):
        ctl.step(1)
        assert np.allclose(raw(ctl), expected.at(k / RATE), rtol=0.0, atol=TOL), k
    run_idle(ctl, ms)
    assert [(e.serial, e.message) for e in ctl.move_log.recent(ms.number)] == [(serial, M.MPIMessageOK)]


# ------------------------------------------------------------------ 10. STOP, RESUME, E_STOP ----
def _line_and_curve(kind, count):
    """x = 2000 counts/s exactly (evenly spaced points from 0, every kind reproduces a line), y a curve:
    the path parameter is x / 2000, so (x, y) is on the path iff y = Y(x / 2000)."""
    dt = 0.05
    t = dt * np.arange(1, count + 1)
    points = np.stack([2000.0 * t, 300.0 * np.sin(9.0 * t) + 100.0 * t], axis=1)
    return points, [dt] * count, Expected.of(kind, (0.0, 0.0), points, [dt] * count)


def _off_the_curve(ctl, expected) -> float:
    x, y = raw(ctl)
    return abs(y - expected.at(x / 2000.0)[1])


def test_stop_decelerates_along_the_path_and_resume_continues_it():
    # MPI 000, MPIMotionConfig, pauseFeedrate: "the feed speed rate for the Stop action" (0 by default):
    # the path's time slows to a stop; its positions stay on the path's curve, and RESUME goes on from there
    ctl, ms = new_supervisor()
    points, times, expected = _line_and_curve(T.SPLINE, 20)
    outcome, serial = ms.command(T.SPLINE, A.NONE, path_params(T.SPLINE, points, times), False)
    message = outcome.message
    assert message.ok
    ctl.step(300)
    assert ms.action(MPIAction.STOP).ok
    worst, slowed = 0.0, []
    while ms.state is MPIState.STOPPING:
        ctl.step(1)
        worst = max(worst, _off_the_curve(ctl, expected))
        slowed.append(ctl.axes[0].cmd_v)
    assert ms.state is MPIState.STOPPED
    assert worst < 1e-6
    assert slowed[0] > 1000.0
    assert abs(slowed[-1]) < 1e-9
    assert ms.snapshot().feedrate == 0.0
    stopped_at = raw(ctl)
    assert 0.0 < stopped_at[0] < points[-1][0]  # mid-path
    ctl.step(300)
    assert np.array_equal(raw(ctl), stopped_at)
    assert ms.action(MPIAction.RESUME).ok
    while ms.state is MPIState.MOVING and raw(ctl)[0] < points[-1][0] - 1e-6:
        ctl.step(1)
        worst = max(worst, _off_the_curve(ctl, expected))
    assert worst < 1e-6
    run_idle(ctl, ms)
    assert raw(ctl) == pytest.approx(points[-1], abs=TOL)
    assert [(e.serial, e.message) for e in ctl.move_log.recent(ms.number)] == [(serial, M.MPIMessageOK)]


def _open_pvt_stopped_then_resumed(append_when_stopped: bool):
    """An open PVT path (200 counts/s on axis 0), STOP at sample 101, RESUME 100 samples after it
    is STOPPED; more points appended at sample 100 (MOVING) or once STOPPED. The command per sample."""
    ctl, ms = new_supervisor(notify=None)
    t = np.arange(1.0, 11.0)
    first = np.stack([10.0 * t, -5.0 * t], axis=1)
    more = np.stack([100.0 + 10.0 * t, -50.0 - 5.0 * t], axis=1)
    velocity = np.tile([200.0, -100.0], (10, 1))
    assert ms.start(T.PVT, A.NONE, path_params(T.PVT, first, [0.05] * 10, velocity, final=False,
                                                empty_count=0)).ok
    ctl.step(100)
    appended = path_params(T.PVT, more, [0.05] * 10, velocity, final=True)
    if not append_when_stopped:
        assert ms.command(T.PVT, A.APPEND, appended, False)[0].ok
    ctl.step(1)
    assert ms.action(MPIAction.STOP).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 10_000)
    if append_when_stopped:
        assert ms.command(T.PVT, A.APPEND, appended, False)[0].ok
        assert ms.state is MPIState.STOPPED
    trace = []
    for _ in range(100):
        ctl.step(1)
        trace.append(raw(ctl))
    assert ms.action(MPIAction.RESUME).ok
    while ms.state is not MPIState.IDLE and len(trace) < 20_000:
        ctl.step(1)
        trace.append(raw(ctl))
    return np.array(trace)


def test_points_appended_while_stopped_follow_the_stopped_path_and_resume_runs_them():
    # MPI 000, MPIMotionPoint, final: "If final=0, more points can be loaded using mpiMotionModify(...) with the
    # MPIMotionAttrMaskAPPEND attribute"; MPIMotionAttrMaskAPPEND adds "to the end of a previous motion
    # profile": a STOP leaves the rest of the path pending, so the points follow it, as if appended in motion
    stopped = _open_pvt_stopped_then_resumed(append_when_stopped=True)
    moving = _open_pvt_stopped_then_resumed(append_when_stopped=False)
    # the end time is the same sum of point times taken from another base: it may round to the next
    # sample (both then rest on the last point), so the shorter run is padded with its last position
    assert abs(len(stopped) - len(moving)) <= 1
    length = max(len(stopped), len(moving))
    stopped, moving = (np.concatenate([x, np.repeat(x[-1:], length - len(x), axis=0)]) for x in (stopped, moving))
    assert np.allclose(stopped, moving, rtol=0.0, atol=TOL)
    assert stopped[-1] == pytest.approx([200.0, -100.0], abs=TOL)
    assert np.max(np.abs(np.diff(stopped[:, 0]))) * RATE <= 200.0 * (1 + 1e-6)


def test_e_stop_decelerates_along_the_path_and_ends_its_goals_with_error():
    # MPI 000, mpiMotionStart: "The axis will E-stop along the path of the last frames in the buffer";
    # MPI 000, MPIMotionMessageERROR: the motion (and every append to it) ends in error
    ctl, ms = new_supervisor()
    points, times, expected = _line_and_curve(T.PT, 30)
    outcome, serial = ms.command(T.PT, A.NONE, path_params(T.PT, points[:20], times[:20], final=False), False)
    message = outcome.message
    assert message.ok
    outcome, appended = ms.command(T.PT, A.APPEND, path_params(T.PT, points[20:], times[20:], final=False),
                                      False)
    message = outcome.message
    assert message.ok
    ctl.step(500)
    assert ms.action(MPIAction.E_STOP).ok
    worst = 0.0
    while ms.state is MPIState.STOPPING_ERROR:
        ctl.step(1)
        worst = max(worst, _off_the_curve(ctl, expected))
    assert ms.state is MPIState.ERROR
    assert worst < 1e-6
    assert sorted((e.serial, e.message) for e in ctl.move_log.recent(ms.number)) == [(serial, M.MPIMotionMessageERROR),
                                                                    (appended, M.MPIMotionMessageERROR)]
    assert all(e.detail.startswith("E_STOP") for e in ctl.move_log.recent(ms.number))
