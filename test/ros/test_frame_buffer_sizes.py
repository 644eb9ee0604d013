"""Per-axis frame buffer sizes and the 32-bit positions through ROS (the supervisor node's services
and goals, in-process): what a user of a configured suite sees."""

from __future__ import annotations

import pytest

from .conftest import WAIT

HALF = 2.0**31


@pytest.fixture
def suite_config():
    from mpi_ros import config

    # ms1's axes with 256-frame buffers (MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "The axis frame buffer
    # sizes are configured" per axis); ms0's keep the controller's 128
    return config.load(overrides={"axes": {"overrides": {2: {"frame_buffer_size": 256},
                                                          3: {"frame_buffer_size": 256}}}})


def test_each_supervisor_reports_its_axes_buffer_and_a_mixed_list_is_refused(suite, probe, service):
    from mpi_ros.srv import AxisListEdit, AxisListGet, FrameBufferStatusGet

    for number, size in ((0, 128), (1, 256)):
        frames = service(probe, FrameBufferStatusGet, f"/mpi/ms{number}/frame_buffer_status",
                         FrameBufferStatusGet.Request())
        assert [f.size for f in frames.axes] == [size, size]
    # MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "All axes appended to a Motion object must have the same
    # frame buffer size"
    edit = service(probe, AxisListEdit, "/mpi/ms0/axis_list_edit", AxisListEdit.Request(operation="APPEND", axis=2))
    assert edit.message == "MPIMotionMessageAXIS_FRAME_COUNT"
    assert list(edit.axis_numbers) == [0, 1]
    listing = service(probe, AxisListGet, "/mpi/ms0/axis_list_get", AxisListGet.Request())
    assert list(listing.axis_numbers) == [0, 1]
    assert list(listing.mapped_axis_numbers) == [0, 1]


def test_positions_past_2_31_read_back_as_the_32_bit_controller_holds_them(suite, client, applied, drive,
                                                                            probe, service):
    from mpi_ros.srv import PositionGet, PositionSet

    # MPI 000, MPIMotionType, Example: 2^31 + 10 and -2^31 + 10 are "the same value" to the controller
    answer = service(probe, PositionSet, "/mpi/ms0/position_set",
                     PositionSet.Request(actual=[HALF - 100.0, 0.0], command=[HALF - 100.0, 0.0]))
    assert answer.message == "MPIMessageOK"
    goal = client.start({"type": "TRAPEZOIDAL", "position": [HALF + 100.0, 0.0],
                         "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0, "deceleration": 20000.0}]})
    applied.wait(2)
    drive(lambda: goal.done)
    result = goal.wait(WAIT)
    assert result.message == "MPIMessageOK"
    assert list(result.command_position) == [-HALF + 100.0, 0.0]
    position = service(probe, PositionGet, "/mpi/ms0/position_get", PositionGet.Request())
    assert list(position.command) == [-HALF + 100.0, 0.0]
    assert abs(position.actual[0] - (-HALF + 100.0)) < 10.0
