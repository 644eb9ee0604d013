"""JointTrajectory commands without ROS (mpi_ros/trajectory.py, trajectory_feed.py, the
``joint_trajectory`` command, the runner's scheduled commands): names, units, times, speed
limits, chunks, and the motion checked against MPI 000's PVT equations (Streaming Point Motion
Type Calculations, PVT Moves: the cubic Hermite between points) in SI units."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from mpi_ros import config, trajectory
from mpi_ros.commands import Command, Operation, apply
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.types import MPIAction, MPIState
from mpi_ros.runner import ControllerRunner
from mpi_ros.trajectory_feed import TrajectoryFeed

GANTRY = "config/gantry.yaml"
RATE = 2000.0  # config/gantry.yaml: controller.sample_rate


@pytest.fixture
def gantry():
    return config.load(GANTRY)


@pytest.fixture
def joints(gantry):
    return gantry.axis_joints()


def ms0(joints):
    return joints[:2]  # x, y


def ms1(joints):
    return joints[2:]  # z, c


def read(joints, names, points):
    return trajectory.read(names, points, joints)


# -- reading: names and shapes ---------------------------------------------------------
def test_names_in_any_order_map_to_the_supervisor_axes(joints):
    t = read(ms0(joints), ["y", "x"], [([0.2, 0.1], [], 1.0)])
    assert t.positions.tolist() == [[0.1, 0.2]]
    assert t.velocities is None


@pytest.mark.parametrize(("names", "words"), [
    (["x", "q"], "unknown joint 'q'"),
    (["x"], "y missing"),
    (["x", "z"], "unknown joint 'z'"),  # an axis of the other supervisor
    (["x", "x"], "x named twice"),
])
def test_names_that_are_not_exactly_the_supervisor_joints_are_refused(joints, names, words):
    with pytest.raises(Refused) as refused:
        read(ms0(joints), names, [([0.0] * len(names), [], 1.0)])
    assert refused.value.message is Message.MPIMessagePARAM_INVALID
    assert words in refused.value.detail


def test_points_of_the_wrong_size_or_with_velocities_on_some_points_only_are_refused(joints):
    with pytest.raises(Refused, match="positions: 1 values for 2 joints"):
        read(ms0(joints), ["x", "y"], [([0.0], [], 1.0)])
    with pytest.raises(Refused, match="all points give velocities"):
        read(ms0(joints), ["x", "y"], [([0.0, 0.0], [0.0, 0.0], 1.0), ([0.1, 0.0], [], 2.0)])


# -- checks ----------------------------------------------------------------------------
@pytest.mark.parametrize(("points", "message", "words"), [
    ([([math.nan, 0.0], [], 1.0)], Message.MEIMotionMessageBAD_PATH_DATA, "NaN"),
    ([([0.0, 0.0], [math.inf, 0.0], 1.0)], Message.MEIMotionMessageBAD_PATH_DATA, "NaN"),
    ([([0.0, 0.0], [], math.nan)], Message.MEIMotionMessageBAD_PATH_DATA, "NaN"),
    ([([0.1, 0.0], [], 1.0), ([0.2, 0.0], [], 1.0)], Message.MPIMotionMessagePATH_ERROR,
     "points[1] at 1 s is not after points[0]"),
    ([([0.1, 0.0], [], 0.0)], Message.MPIMotionMessagePATH_ERROR, "not after the start"),
    ([([0.1, 0.0], [], 1.0), ([0.2, 0.0], [], 0.5)], Message.MPIMotionMessagePATH_ERROR, "must increase"),
    # x's max_velocity is 0.5 m/s: a chord of 0.6 m/s (PT)
    ([([0.1, 0.0], [], 1.0), ([0.7, 0.0], [], 2.0)], Message.MPIMessagePARAM_INVALID,
     "joint x: 0.6 m/s between points[0] and points[1], over its max_velocity 0.5 m/s"),
    # a point's velocity over it (PVT)
    ([([0.1, 0.0], [0.6, 0.0], 1.0)], Message.MPIMessagePARAM_INVALID, "joint x: 0.6 m/s at points[0]"),
    # y: both ends at 0.45 m/s but the Hermite cubic between them peaks at 1.5 dx/dt - v/2 = 0.675 m/s (midway)
    ([([0.0, 0.1], [0.0, 0.45], 1.0), ([0.0, 0.7], [0.0, 0.45], 2.0)], Message.MPIMessagePARAM_INVALID,
     "joint y: 0.675 m/s between points[0] and points[1]"),
])
def test_bad_points_are_refused_with_the_message_and_the_reason(joints, points, message, words):
    verdict = read(ms0(joints), ["x", "y"], points).validate()
    assert verdict.message is message
    assert words in verdict.detail


def test_the_first_interval_is_judged_from_where_the_path_starts(joints):
    chunk = read(ms0(joints), ["x", "y"], [([0.3, 0.0], [], 0.5)]).chunks()[0]
    assert chunk.check([(0.0, 0.0), (0.0, 0.0)]).message is Message.MPIMessagePARAM_INVALID  # 0.6 m/s
    assert "from the start to points[0]" in chunk.check([(0.0, 0.0), (0.0, 0.0)]).detail
    assert chunk.check([(100_000.0, 0.0), (0.0, 0.0)]).ok  # from x = 0.1 m: 0.4 m/s


def test_a_speed_at_the_limit_is_accepted(joints):
    assert read(ms0(joints), ["x", "y"], [([0.5, 0.0], [], 1.0)]).chunks()[0].check([(0.0, 0.0)] * 2).ok


# -- conversion ------------------------------------------------------------------------
def test_points_become_counts_and_time_from_start_becomes_intervals(joints):
    # z: counts_per_unit -1e6, offset 0.3 m (count 0 is z = 0.3 m); c: 10,000 counts a turn
    t = read(ms1(joints), ["c", "z"], [([math.pi, 0.25], [0.0, -0.05], 0.5), ([0.0, 0.2], [0.0, 0.0], 1.25)])
    request = t.chunks()[0].motion_request()
    assert request["type"] == "PVT"
    assert request["final"] is True
    assert request["attributes"] == []
    assert request["position"] == pytest.approx([50_000.0, 5_000.0, 100_000.0, 0.0])
    assert request["point_velocity"] == pytest.approx([50_000.0, 0.0, 0.0, 0.0])
    assert request["time"] == pytest.approx([0.5, 0.75])
    assert "point_velocity" not in read(ms1(joints), ["z", "c"], [([0.25, 0.0], [], 1.0)]).chunks()[0].motion_request()


def test_chunks_cover_the_trajectory_and_read_back_as_they_were(joints):
    n = 300
    times = np.arange(1, n + 1) * 0.01
    t = read(ms0(joints), ["x", "y"], [([0.001 * i, 0.0], [0.1, 0.0], float(times[i])) for i in range(n)])
    chunks = t.chunks(128)
    assert [len(c.times) for c in chunks] == [128, 128, 44]
    assert [(c.append, c.final) for c in chunks] == [(False, False), (True, False), (True, True)]
    for chunk in chunks:
        again = trajectory.Chunk.from_request(chunk.to_request())
        assert again.motion_request() == chunk.motion_request()
    stitched = np.concatenate([c.motion_request()["time"] for c in chunks])
    assert stitched == pytest.approx(np.diff(times, prepend=0.0))


def test_chunks_are_fed_one_ahead_of_the_path():
    t = trajectory.Trajectory((), np.zeros((5, 0)), None, np.array([1.0, 2.0, 3.0, 4.0, 5.0]))
    chunks = t.chunks(2)  # points (1, 2), (3, 4), (5)
    assert trajectory.feed_samples(100, chunks, RATE) == [100, 100, 100 + 2 * 2000]


def test_the_start_is_the_first_sample_at_or_after_the_stamp():
    epoch = 1_000_000_000_000
    assert trajectory.start_sample(0, epoch, RATE, now=50) == 50  # zero: now
    assert trajectory.start_sample(epoch + 10_000_000, epoch, RATE, now=50) == 50  # past: now
    assert trajectory.start_sample(epoch + 1_000_000_000, epoch, RATE, now=50) == 2000
    assert trajectory.start_sample(epoch + 1_000_000_001, epoch, RATE, now=50) == 2001


# -- the command -----------------------------------------------------------------------
def command(chunk, supervisor=0) -> Command:
    return Command(Operation.JOINT_TRAJECTORY, supervisor, request=chunk.to_request())


def si_positions(ctl, joints, axes):
    return [joints[n].position(ctl.axis_snapshot(n).command_position) for n in axes]


def test_a_pvt_trajectory_follows_the_hermite_cubic_in_si_units(gantry, joints):
    ctl = gantry.build_controller()
    points = [([0.10, 0.05], [0.20, 0.0], 0.5), ([0.25, 0.20], [0.10, 0.3], 1.0), ([0.30, 0.30], [0.0, 0.0], 1.6)]
    t = read(ms0(joints), ["x", "y"], points)
    reply = apply(ctl, command(t.chunks()[0]))
    assert reply.message is Message.MPIMessageOK, reply.detail
    begin = ctl.sample  # the path runs from this sample's time on
    knots = [0.0] + [p[2] for p in points]
    expected = [CubicHermiteSpline(knots, [0.0] + [p[0][i] for p in points], [0.0] + [p[1][i] for p in points])
                for i in range(2)]
    for _ in range(32):
        ctl.step(100)
        elapsed = (ctl.sample - begin) / RATE
        got = si_positions(ctl, joints, (0, 1))
        want = [float(e(min(elapsed, 1.6))) for e in expected]
        assert got == pytest.approx(want, abs=1e-9), elapsed  # 1e-9 m = 1e-3 count
    assert si_positions(ctl, joints, (0, 1)) == pytest.approx([0.30, 0.30], abs=1e-12)


def test_a_pt_trajectory_runs_straight_lines_from_the_command_position(gantry, joints):
    ctl = gantry.build_controller()
    t = read(ms1(joints), ["z", "c"], [([0.2, 1.0], [], 1.0)])  # z from 0.3 to 0.2 m, c 0 to 1 rad
    assert apply(ctl, command(t.chunks()[0], 1)).message is Message.MPIMessageOK
    begin = ctl.sample
    ctl.step(1000)
    assert si_positions(ctl, joints, (2, 3)) == pytest.approx([0.3 - 0.1 * (ctl.sample - begin) / RATE,
                                                               (ctl.sample - begin) / RATE], abs=1e-9)


def test_a_new_trajectory_replaces_the_one_in_progress_from_now(gantry, joints):
    ctl = gantry.build_controller()
    first = read(ms0(joints), ["x", "y"], [([0.4, 0.0], [], 1.0)])
    assert apply(ctl, command(first.chunks()[0])).message is Message.MPIMessageOK
    ctl.step(1000)  # halfway: x = 0.2 m
    assert si_positions(ctl, joints, (0,))[0] == pytest.approx(0.2, abs=1e-9)
    second = read(ms0(joints), ["x", "y"], [([0.1, 0.1], [], 0.5)])
    reply = apply(ctl, command(second.chunks()[0]))  # a modify of the PT path (MPI 000, mpiMotionModify)
    assert reply.message is Message.MPIMessageOK, reply.detail
    begin, x0 = ctl.sample, si_positions(ctl, joints, (0,))[0]
    ctl.step(250)  # a quarter of the way along the new line, from where x was
    assert si_positions(ctl, joints, (0, 1)) == pytest.approx([x0 + (0.1 - x0) * (ctl.sample - begin) / 1000,
                                                               0.1 * (ctl.sample - begin) / 1000], abs=1e-9)
    ctl.step(750)
    assert si_positions(ctl, joints, (0, 1)) == pytest.approx([0.1, 0.1], abs=1e-12)


def test_an_empty_trajectory_stops_and_error_refuses(gantry, joints):
    ctl = gantry.build_controller()
    t = read(ms0(joints), ["x", "y"], [([0.4, 0.0], [], 1.0)])
    apply(ctl, command(t.chunks()[0]))
    ctl.step(100)
    assert apply(ctl, Command(Operation.JOINT_TRAJECTORY, 0, request={})).message is Message.MPIMessageOK
    assert ctl.supervisor(0).state is MPIState.STOPPING
    ctl.supervisor(0).action(MPIAction.E_STOP)
    ctl.step(200)
    moved = si_positions(ctl, joints, (0, 1))
    reply = apply(ctl, command(t.chunks()[0]))
    assert reply.message is Message.MPIMotionMessageERROR
    ctl.step(200)
    assert si_positions(ctl, joints, (0, 1)) == moved


def test_a_chunk_for_other_axes_is_refused(gantry, joints):
    ctl = gantry.build_controller()
    chunk = read(ms1(joints), ["z", "c"], [([0.2, 1.0], [], 1.0)]).chunks()[0]
    reply = apply(ctl, command(chunk, supervisor=0))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert "not supervisor 0's axes" in reply.detail


# -- the runner's scheduled commands and the feed ----------------------------------------
def test_a_scheduled_command_applies_at_its_sample_however_the_steps_are_batched(gantry):
    for batch in (1, 7, 1000):
        runner = ControllerRunner(gantry.build_controller(), time_scale=None)
        seen = []
        runner.on_command(lambda sample, command, reply, seen=seen: seen.append(sample))
        runner.schedule(123, Command("action", 0, request={"action": "STOP"}))
        runner.schedule(50, Command("action", 0, request={"action": "STOP"}), tag="dropped")
        assert runner.unschedule(lambda sample, tag: tag == "dropped") == 1
        while runner.ctl.sample < 1000:
            runner.step(batch)
        assert seen == [124], batch  # applied at sample 123, effective (and recorded) at 124


def feed(gantry, number=0, chunk_points=trajectory.CHUNK_POINTS):
    runner = ControllerRunner(gantry.build_controller(), time_scale=None)
    warnings: list[str] = []
    return runner, TrajectoryFeed(runner, number, gantry.axis_joints(), 0, warnings.append, chunk_points), warnings


def test_a_10000_point_trajectory_is_streamed_through_the_frame_buffer(gantry, joints):
    runner, trajectories, warnings = feed(gantry)
    events, frames = [], []
    runner.on_event(lambda event: events.append(event.type_name))
    n = 10_000
    times = (np.arange(n) + 1) * 0.002  # 4 samples a point: 20 s
    w = math.pi / 20.0  # x from 0 at rest (where the path starts) to 0.6 m at rest, within its limits
    x = 0.3 * (1.0 - np.cos(w * times))
    points = [([float(x[i]), 0.0], [float(0.3 * w * math.sin(w * times[i])), 0.0], float(times[i]))
              for i in range(n)]
    assert trajectories.receive(["x", "y"], points, 0) is None
    while runner.ctl.sample < 41_000:
        runner.step(500)
        frames.append(runner.ctl.axis_snapshot(0).frame_count)
    assert warnings == []
    assert trajectories.snapshot().accepted == 1
    assert "FRAMES_EMPTY" not in events
    assert "FRAMES_LOW" not in events
    assert "E_STOP" not in events
    assert 0 < max(frames) <= 128
    assert runner.ctl.supervisor(0).state is MPIState.IDLE
    assert si_positions(runner.ctl, joints, (0, 1)) == pytest.approx([x[-1], 0.0], abs=1e-12)


def test_the_feed_refuses_and_counts(gantry):
    runner, trajectories, warnings = feed(gantry)
    assert trajectories.receive(["x", "q"], [([0.1, 0.0], [], 1.0)], 0).message is Message.MPIMessagePARAM_INVALID
    assert trajectories.receive(["x", "y"], [([0.9, 0.0], [], 1.0)], 0) is None  # 0.9 m/s from x = 0: at apply
    runner.step(10)
    counts = trajectories.snapshot()
    assert counts.refused == {"MPIMessagePARAM_INVALID": 2}
    assert counts.accepted == 0
    assert "unknown joint 'q'" in warnings[0]
    assert "over its max_velocity" in warnings[1]
    assert runner.ctl.supervisor(0).state is MPIState.IDLE
    assert runner.scheduled() == 0
