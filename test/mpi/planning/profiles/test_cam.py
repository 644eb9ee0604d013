"""Cam tables (MPI 000, MPIMotionCam) against hand-computed values."""

from __future__ import annotations

import numpy as np
import pytest

from mpi_ros.mpi.planning.profiles.cam import CamTable


def at(table: CamTable, *u: float) -> list[float]:
    return table.position(np.array(u, dtype=float)).tolist()


def test_linear_cam_interpolates_between_segment_ends():
    # MPIMotionCam: masterDistance is the master's distance in each segment, slavePosition the slave's; a
    # linear cam goes straight between the segment ends. Segments: (100, +50), (200, -50), (100, +100):
    # knots at master 0, 100, 300, 400 with the slave at 0, 50, 0, 100.
    table = CamTable.build([100.0, 200.0, 100.0], [50.0, -50.0, 100.0], None, None)
    assert at(table, 0.0, 20.0, 100.0, 150.0, 200.0, 300.0, 350.0, 400.0) == [
        0.0, 10.0, 50.0, 37.5, 25.0, 0.0, 50.0, 100.0]
    # before the start the slave waits at its start, past the end it rests at the end
    assert at(table, -30.0, 450.0, 1e6) == [0.0, 100.0, 100.0]
    assert table.ratio(np.array([50.0, 250.0, 399.0])).tolist() == [0.5, -0.25, 1.0]


def test_cubic_cam_hand_computed_values():
    # One segment of 100 master counts moving the slave 100 counts, gear ratio 0 at both ends (the initial
    # one is zero by definition: "The initial gear ration is assumed to be zero"): the smoothstep
    # 100 (3 t^2 - 2 t^3).
    table = CamTable.build([100.0], [100.0], [0.0], None)
    assert at(table, 0.0, 25.0, 50.0, 75.0, 100.0) == [0.0, 15.625, 50.0, 84.375, 100.0]
    assert table.ratio(np.array([0.0, 50.0, 100.0 - 1e-12])).tolist() == pytest.approx([0.0, 1.5, 0.0], abs=1e-9)
    # With a gear ratio of 2 at the end: p(t) = 100 (3t^2 - 2t^3) + 100 * 2 (t^3 - t^2); at t = 0.5:
    # 50 + 200 (0.125 - 0.25) = 25; at t = 0.25: 15.625 + 200 (0.015625 - 0.0625) = 6.25.
    geared = CamTable.build([100.0], [100.0], [2.0], None)
    assert at(geared, 25.0, 50.0) == [6.25, 25.0]
    assert geared.ratio(np.array([100.0 - 1e-9]))[0] == pytest.approx(2.0, abs=1e-6)


def test_cubic_cam_position_and_gear_ratio_are_continuous_at_the_transitions():
    # MPIMotionCam gearRatio: the slope at "each of the transitions between cam segments".
    table = CamTable.build([100.0, 50.0, 200.0], [80.0, 60.0, -40.0], [1.2, 0.4, 0.0], None)
    eps = 1e-7
    for knot, ratio in ((100.0, 1.2), (150.0, 0.4)):
        below, above = at(table, knot - eps, knot + eps)
        assert below == pytest.approx(above, abs=1e-5)
        slopes = table.ratio(np.array([knot - eps, knot + eps]))
        assert slopes.tolist() == pytest.approx([ratio, ratio], abs=1e-5)
    # the knots themselves land exactly on the cumulative slave positions
    assert at(table, 100.0, 150.0, 350.0) == [80.0, 140.0, 100.0]


def test_repeat_runs_the_segments_from_repeat_from_again_without_drift():
    # MPIMotionAttributes.repeatFrom: "the first frame that is repeated. Any frames before this frame will act
    # as a run-in sequence." Run-in (100, +10), then the repeated (50, +20), (50, -5): each cycle 100 master
    # counts, +15 slave counts.
    table = CamTable.build([100.0, 50.0, 50.0], [10.0, 20.0, -5.0], None, 1)
    assert table.end is None
    assert at(table, 50.0, 100.0, 125.0, 200.0, 225.0, 300.0, 325.0) == [5.0, 10.0, 20.0, 25.0, 35.0, 40.0, 50.0]
    # the thousandth cycle is exactly where the first was plus 999 cycles: counted, not accumulated
    first = at(table, 137.5)[0]
    assert at(table, 137.5 + 999 * 100.0)[0] == first + 999 * 15.0
    cycles = np.arange(0, 5000, dtype=float)
    values = table.position(125.0 + cycles * 100.0)
    assert np.array_equal(values, 20.0 + cycles * 15.0)


def test_repeat_from_zero_repeats_the_whole_table():
    table = CamTable.build([100.0], [40.0], [0.0], 0)
    assert at(table, 50.0, 150.0, 250.0) == [20.0, 60.0, 100.0]


def test_frames_are_one_per_segment_and_the_final_frame():
    # MPIMotionMessageFRAME_BUFFER_TOO_SMALL: a cam's points must fit the frame buffer (see test_cams.py)
    assert CamTable.build([1.0] * 5, [0.0] * 5, None, None).frames == 6
