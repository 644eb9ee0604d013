"""Constant-jerk segments (mpi_ros/mpi/planning/profiles/segment.py, point_to_point.py)."""

from __future__ import annotations

import numpy as np
import pytest

from mpi_ros.mpi.planning.profiles.point_to_point import point_to_point, reverses, velocity_move
from mpi_ros.mpi.planning.profiles.segment import Segment, SegmentTable, chain, end_state, total_duration


def test_state_at_is_constant_jerk_motion():
    # MPI 000, Streaming Point Motion Type Calculations "all motion is specified by constant-jerk segments of motion"
    seg = Segment(2.0, 1.0, 2.0, 3.0, 6.0)
    assert seg.state_at(2.0) == (1.0 + 4.0 + 6.0 + 8.0, 2.0 + 6.0 + 12.0, 3.0 + 12.0)


def test_chain_is_contiguous_and_drops_empty_pieces():
    segments = chain(0.0, 0.0, 0.0, [(1.0, 6.0), (0.0, 100.0), (1.0, -6.0)])
    assert len(segments) == 2
    assert segments[1].p == segments[0].end_state()[0]
    assert segments[1].a == segments[0].end_state()[2]
    assert total_duration(segments) == 2.0
    assert end_state([], (1.0, 2.0, 3.0)) == (1.0, 2.0, 3.0)


def test_table_evaluates_like_the_segments():
    # segment.py SegmentTable: "A profile as arrays, for evaluating many sample times at once"
    segments = point_to_point(0.0, 0.0, 1234.0, 0.0, 1000.0, 8000.0, 5000.0, 60.0)
    table = SegmentTable(segments)
    t = np.linspace(0.0, total_duration(segments), 997)
    p, v, a, _ = table.evaluate(t)
    for ti, pi, vi, ai in zip(t[::50], p[::50], v[::50], a[::50], strict=True):
        i = min(int(np.searchsorted(table.end, ti, side="right")), len(segments) - 1)
        expected = segments[i].state_at(ti - table.start[i])
        assert (pi, vi, ai) == pytest.approx(expected)


def test_scaled_segment():
    # planner.py vector moves: each axis moves its share of the one profile
    seg = Segment(1.0, 0.0, 10.0, 2.0, 1.0).scaled(-0.5, 100.0)
    assert (seg.p, seg.v, seg.a, seg.j) == (100.0, -5.0, -1.0, -0.5)


def test_reverses():
    # MPI 000, MEIMotionAttrNO_REVERSAL NO_REVERSAL "prevents a motion profile from changing direction"
    forward = point_to_point(0.0, 500.0, 1000.0, 0.0, 1000.0, 1e4, 1e4, 0.0)
    back = point_to_point(0.0, 500.0, -1000.0, 0.0, 1000.0, 1e4, 1e4, 0.0)
    assert not reverses(forward, 500.0)
    assert reverses(back, 500.0)
    assert not reverses(point_to_point(0.0, 0.0, -10.0, 0.0, 1.0, 1.0, 1.0, 0.0), 0.0)


def test_velocity_move_segments():
    # MPI 000, MPIMotionTypeVELOCITY VELOCITY "S-Curve acceleration to a constant velocity ... jerkPercent"
    segments, ramp = velocity_move(0.0, 0.0, 500.0, 5000.0, 50.0, cruise=1.0)
    assert ramp == pytest.approx(0.1)
    assert segments[-1].v == pytest.approx(500.0)
    assert segments[-1].duration == 1.0
    assert max(abs(s.a) for s in segments) == pytest.approx(5000.0 / 0.75)
