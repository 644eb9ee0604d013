"""A supervisor's axis list (mpi_ros/mpi/supervisor/axis_list.py; MPI 000, mpiMotionAxis*): pure list
logic, the state a change must respect given by the supervisor."""

from __future__ import annotations

from types import SimpleNamespace

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import ControllerConfig
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.mpi.supervisor.axis_list import AxisList

M = Message
MOVING = Outcome(M.MPIMotionMessageMOVING, "state: supervisor 0 is MOVING")  # what the supervisor passes


def axis_list(count: int = 4, disabled: tuple[int, ...] = (), sizes: dict[int, int] | None = None) -> AxisList:
    """An axis list over ``count`` axes (those in ``disabled`` not enabled; ``sizes``: frame
    buffer sizes of some axes, the others 128)."""
    axes = [SimpleNamespace(enabled=n not in disabled, valid=True) for n in range(count)]
    return AxisList(axes, ControllerConfig(axis_count=count, axis_frame_buffer_sizes=sizes or {}))


def test_append_insert_and_their_refusals():
    listed = axis_list(disabled=(3,))
    assert listed.append(1).ok
    assert listed.insert(None, 0).ok
    assert listed.insert(0, 2).ok
    assert listed.listed == [0, 2, 1]
    assert listed.append(1).message is M.MPIMessageOBJECT_ON_LIST
    assert listed.append(9).message is M.MPIMessageHANDLE_INVALID
    assert listed.append(3).message is M.MPIMessageOBJECT_NOT_ENABLED
    assert listed.insert(9, 3).message is M.MPIMessageOBJECT_NOT_ENABLED
    assert axis_list().insert(2, 1).message is M.MPIMotionMessageAXIS_NOT_FOUND
    assert listed.mapped == []  # nothing is mapped until the mapping is written


def test_remove_needs_the_axis_mapped_and_the_supervisor_idle_or_in_error():
    listed = axis_list()
    assert listed.set([0, 1], MPIState.IDLE, MOVING).ok
    assert listed.remove(1, MPIState.IDLE, MOVING).message is M.MPIAxisMessageNOT_MAPPED_TO_MS  # MPI 002
    assert listed.commit_mapping() == [0, 1]
    assert listed.remove(1, MPIState.MOVING, MOVING) is MOVING
    assert listed.listed == [0, 1]
    assert listed.remove(1, MPIState.ERROR, MOVING).ok
    assert listed.listed == [0]
    assert listed.remove(2, MPIState.IDLE, MOVING).message is M.MPIMotionMessageAXIS_NOT_FOUND


def test_list_set_replaces_the_list_whole_or_not_at_all():
    listed = axis_list(count=10)
    assert listed.set([3, 1], MPIState.STOPPED, MOVING).ok
    assert listed.listed == [3, 1]
    assert listed.set([0, 0], MPIState.IDLE, MOVING).message is M.MPIMessageOBJECT_ON_LIST
    assert listed.set(list(range(9)), MPIState.IDLE, MOVING).message is M.MPIMessageUNSUPPORTED  # MAX_COORD_AXES
    assert listed.set([0, 12], MPIState.IDLE, MOVING).message is M.MPIMessageHANDLE_INVALID
    assert listed.set([0], MPIState.MOVING, MOVING) is MOVING
    assert listed.listed == [3, 1]


def test_walking_the_list():
    listed = axis_list()
    assert listed.set([2, 0, 3], MPIState.IDLE, MOVING).ok
    assert listed.index(0) == 1
    assert listed.index(1) == -1
    assert listed.at(2) == (M.MPIMessageOK, 3)
    assert listed.at(3) == (M.MEIListMessageELEMENT_NOT_FOUND, None)
    assert listed.neighbour(0, +1) == (M.MPIMessageOK, 3)
    assert listed.neighbour(2, -1) == (M.MPIMessageOK, None)
    assert listed.neighbour(1, +1) == (M.MPIMessageHANDLE_INVALID, None)
    assert listed.leaving([0, 1, 2]) == [1]


def test_axes_of_different_frame_buffer_sizes_cannot_share_a_list():
    # MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "All axes appended to a Motion object must have the
    # same frame buffer size"
    listed = axis_list(sizes={2: 256, 3: 256})
    assert listed.append(0).ok
    assert listed.frame_buffer_size == 128
    assert listed.append(2).message is M.MPIMotionMessageAXIS_FRAME_COUNT
    assert listed.listed == [0]
    assert listed.set([2, 1], MPIState.IDLE, MOVING).message is M.MPIMotionMessageAXIS_FRAME_COUNT
    assert listed.set([2, 3], MPIState.IDLE, MOVING).ok
    assert listed.frame_buffer_size == 256
