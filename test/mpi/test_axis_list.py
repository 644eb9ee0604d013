"""A supervisor's axis list (mpi_ros/mpi/axis_list.py; MPI 000, mpiMotionAxis*): pure list
logic, the state a change must respect given by the supervisor."""

from __future__ import annotations

from types import SimpleNamespace

from mpi_ros.mpi.axis_list import AxisList
from mpi_ros.mpi.messages import Message
from mpi_ros.mpi.types import MPIState

M = Message
MOVING = M.MPIMotionMessageMOVING


def axes(count: int = 4, disabled: tuple[int, ...] = ()):
    return [SimpleNamespace(enabled=n not in disabled) for n in range(count)]


def test_append_insert_and_their_refusals():
    listed = AxisList(axes(disabled=(3,)))
    assert listed.append(1).ok and listed.insert(None, 0).ok and listed.insert(0, 2).ok
    assert listed.listed == [0, 2, 1]
    assert listed.append(1) is M.MPIMessageOBJECT_ON_LIST
    assert listed.append(9) is M.MPIMessageHANDLE_INVALID
    assert listed.append(3) is M.MPIMessageOBJECT_NOT_ENABLED
    assert listed.insert(9, 3) is M.MPIMessageOBJECT_NOT_ENABLED
    assert AxisList(axes()).insert(2, 1) is M.MPIMotionMessageAXIS_NOT_FOUND
    assert listed.mapped == []  # nothing is mapped until the mapping is written


def test_remove_needs_the_axis_mapped_and_the_supervisor_idle_or_in_error():
    listed = AxisList(axes())
    assert listed.set([0, 1], MPIState.IDLE, MOVING).ok
    assert listed.remove(1, MPIState.IDLE, MOVING) is M.MPIAxisMessageNOT_MAPPED_TO_MS  # MPI 002
    assert listed.commit_mapping() == [0, 1]
    assert listed.remove(1, MPIState.MOVING, MOVING) is MOVING and listed.listed == [0, 1]
    assert listed.remove(1, MPIState.ERROR, MOVING).ok and listed.listed == [0]
    assert listed.remove(2, MPIState.IDLE, MOVING) is M.MPIMotionMessageAXIS_NOT_FOUND


def test_list_set_replaces_the_list_whole_or_not_at_all():
    listed = AxisList(axes(count=10))
    assert listed.set([3, 1], MPIState.STOPPED, MOVING).ok and listed.listed == [3, 1]
    assert listed.set([0, 0], MPIState.IDLE, MOVING) is M.MPIMessageOBJECT_ON_LIST
    assert listed.set(list(range(9)), MPIState.IDLE, MOVING) is M.MPIMessageUNSUPPORTED  # MAX_COORD_AXES
    assert listed.set([0, 12], MPIState.IDLE, MOVING) is M.MPIMessageHANDLE_INVALID
    assert listed.set([0], MPIState.MOVING, MOVING) is MOVING
    assert listed.listed == [3, 1]


def test_walking_the_list():
    listed = AxisList(axes())
    assert listed.set([2, 0, 3], MPIState.IDLE, MOVING).ok
    assert listed.index(0) == 1 and listed.index(1) == -1
    assert listed.at(2) == (M.MPIMessageOK, 3) and listed.at(3) == (M.MEIListMessageELEMENT_NOT_FOUND, None)
    assert listed.neighbour(0, +1) == (M.MPIMessageOK, 3) and listed.neighbour(2, -1) == (M.MPIMessageOK, None)
    assert listed.neighbour(1, +1) == (M.MPIMessageHANDLE_INVALID, None)
    assert listed.leaving([0, 1, 2]) == [1]
