"""The axis list of a Motion object (mpi_ros/mpi/supervisor/motion.py, MPI 000, mpiMotionAxis) and MAP."""

from __future__ import annotations

import pytest

from mpi_ros.mpi import Controller, ControllerConfig, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory
from mpi_ros.mpi.base.messages import Message

M = Message


@pytest.fixture
def big():
    """A controller with 10 axes (more than MEIXmpMAX_COORD_AXES = 8)."""
    return Controller(ControllerConfig(axis_count=10, supervisor_count=8))


@pytest.fixture
def empty(big):
    _, ms = big.create_motion(0)
    return ms


def test_append_builds_the_list_in_order(empty):
    # MPI 000, mpiMotionAxisAppend mpiMotionAxisAppend appends an Axis; MPI 000, mpiMotionAxisListGet ListGet writes the
    # list
    for n in (3, 1, 2):
        assert empty.axis_append(n).ok
    assert empty.axis_list_get() == (M.MPIMessageOK, [3, 1, 2])
    assert empty.axis_count() == 3  # MPI 000, mpiMotionAxisCount, return values


def test_append_an_axis_already_on_the_list(empty):
    # MPI 000, mpiMotionAxisAppend, return values MPIMessageOBJECT_ON_LIST "axis is already on the list"
    empty.axis_append(1)
    assert empty.axis_append(1).message is M.MPIMessageOBJECT_ON_LIST
    assert empty.axis_list_get()[1] == [1]


@pytest.mark.parametrize("number", [-1, 10, 1000])
def test_append_an_invalid_axis(empty, number):
    # MPI 000, mpiMotionAxisAppend, return values MPIMessageHANDLE_INVALID "Either motion or axis is an invalid handle"
    assert empty.axis_append(number).message is M.MPIMessageHANDLE_INVALID
    assert empty.axis_count() == 0


def test_append_past_max_coord_axes(empty):
    # MPI 000, mpiMotionAxisAppend, return values MPIMessageUNSUPPORTED "The list already contains the maximum number of
    # elements (MEIXmpMAX_COORD_AXES)" = 8
    for n in range(8):
        assert empty.axis_append(n).ok
    assert empty.axis_append(8).message is M.MPIMessageUNSUPPORTED
    assert empty.axis_insert(None, 9).message is M.MPIMessageUNSUPPORTED
    assert empty.axis_count() == 8


def test_list_set_past_max_coord_axes(empty):
    # MPI 000, mpiMotionAxisAppend, return values (the same limit for a list set at once)
    assert empty.axis_list_set(list(range(9))).message is M.MPIMessageUNSUPPORTED
    assert empty.axis_list_set(list(range(8))).ok


def test_append_a_disabled_axis(big, empty):
    # MPI 000, mpiMotionAxisAppend, return values MPIMessageOBJECT_NOT_ENABLED "axis is not an enabled axis"
    big.axes[4].enabled = False
    assert empty.axis_append(4).message is M.MPIMessageOBJECT_NOT_ENABLED
    assert empty.axis_list_set([4]).message is M.MPIMessageOBJECT_NOT_ENABLED


def test_insert_just_after_an_axis(empty):
    # MPI 000, mpiMotionAxisInsert mpiMotionAxisInsert "inserts an Axis (insert) ... just after the specified Axis"
    empty.axis_list_set([1, 2])
    assert empty.axis_insert(1, 5).ok
    assert empty.axis_insert(None, 7).ok  # first place (MPIHandleVOID)
    assert empty.axis_list_get()[1] == [7, 1, 5, 2]


def test_insert_after_an_axis_not_on_the_list(empty):
    # MPI 000, MPIMotionMessageAXIS_NOT_FOUND AXIS_NOT_FOUND "The specified axis object is not available"
    empty.axis_list_set([1])
    assert empty.axis_insert(3, 4).message is M.MPIMotionMessageAXIS_NOT_FOUND
    assert empty.axis_insert(1, 1).message is M.MPIMessageOBJECT_ON_LIST
    assert empty.axis_list_get()[1] == [1]


def test_remove_an_axis_not_on_the_list(big, empty):
    # MPI 000, MPIMotionMessageAXIS_NOT_FOUND AXIS_NOT_FOUND "returned from mpiMotionAxisRemove if the axis that is
    # being removed is not a member of the motion object"
    empty.axis_list_set([1])
    empty.action(MPIAction.MAP)
    assert empty.axis_remove(2).message is M.MPIMotionMessageAXIS_NOT_FOUND
    assert empty.axis_remove(99).message is M.MPIMessageHANDLE_INVALID


def test_remove_an_axis_not_mapped(empty):
    # MPI 002, MPIAxisMessageNOT_MAPPED_TO_MS NOT_MAPPED_TO_MS "returned by ... mpiMotionAxisRemove when an axis is
    # associated with a motion object, but not mapped to a motion supervisor"
    empty.axis_list_set([1, 2])
    assert empty.axis_remove(1).message is M.MPIAxisMessageNOT_MAPPED_TO_MS
    # MPI 002, MPIAxisMessageNOT_MAPPED_TO_MS "To correct this problem, map the axes"
    assert empty.action(MPIAction.MAP).ok
    assert empty.axis_remove(1).ok
    assert empty.axis_list_get()[1] == [2]


@pytest.mark.parametrize("mapper", ["MAP", "RESET", "start", "event_notify_set"])
def test_what_maps_the_axes(big, empty, mapper):
    # MPI 002, MPIAxisMessageNOT_MAPPED_TO_MS "map the axes ... by calling: mpiMotionAction with MEIActionMAP or
    # MPIActionRESET, mpiMotionStart, mpiMotionModify, or mpiMotionEventNotifySet"
    empty.axis_list_set([1])
    if mapper in ("MAP", "RESET"):
        assert empty.action(MPIAction[mapper]).ok
    elif mapper == "start":
        params = MotionParams(trajectory=[Trajectory(100.0, 1000.0, 1000.0)], position=[0.0])
        assert empty.start(MPIMotionType.TRAPEZOIDAL, params=params).ok
        big.step(100)
    else:
        assert empty.event_notify_set(empty.notify_mask).ok
    # MPI 000, MEIMotionConfig, axisNumber the mapping on the controller
    assert empty.config_get()[1].axis_numbers == [1]
    assert empty.axis_remove(1).ok


def test_delete_with_unmapped_axes(big, empty):
    # MPI 002, MPIAxisMessageNOT_MAPPED_TO_MS NOT_MAPPED_TO_MS "returned by mpiMotionDelete ..."
    empty.axis_list_set([1])
    assert big.delete_motion(empty).message is M.MPIAxisMessageNOT_MAPPED_TO_MS
    empty.action(MPIAction.MAP)
    assert big.delete_motion(empty).ok


def test_list_set_replaces_the_coordinate_system(empty):
    # MPI 000, mpiMotionAxisListSet "Any existing coordinate system is completely replaced"
    empty.axis_list_set([1, 2, 3])
    assert empty.axis_list_set([5]).ok
    assert empty.axis_list_get()[1] == [5]
    assert empty.axis_list_set([]).ok  # MPI 000, mpiMotionAxisListSet NULL list when axisCount is zero
    assert empty.axis_count() == 0


def test_list_set_with_duplicates(empty):
    # MPI 000, mpiMotionAxisAppend, return values OBJECT_ON_LIST (an axis twice)
    assert empty.axis_list_set([1, 1]).message is M.MPIMessageOBJECT_ON_LIST
    assert empty.axis_count() == 0


def test_list_set_while_moving_is_refused(ctl, ms, bring):
    # MPI 000, Motion Objects, introduction "Motion Supervisor to axis maps should NOT be changed when the axes are
    # moving"
    bring(MPIState.MOVING)
    assert ms.axis_list_set([0]).message is M.MPIMotionMessageMOVING
    assert ms.axis_remove(1).message is M.MPIMotionMessageMOVING
    assert ms.axis_list_get()[1] == [0, 1]


def test_axis_by_index(empty):
    # MPI 000, mpiMotionAxis mpiMotionAxis "returns the element at the position on the list indicated by
    # index"; MPI 000, mpiMotionAxis, return values MPIHandleVOID / ELEMENT_NOT_FOUND for index < 0 or >= count
    empty.axis_list_set([4, 6])
    assert empty.axis_at(1) == (M.MPIMessageOK, 6)
    assert empty.axis_at(2) == (M.MEIListMessageELEMENT_NOT_FOUND, None)
    assert empty.axis_at(-1) == (M.MEIListMessageELEMENT_NOT_FOUND, None)


def test_first_next_last_previous(empty):
    # MPI 000, mpiMotionAxisFirst First, MPI 000, mpiMotionAxisNext Next, MPI 000, mpiMotionAxisLast Last, MPI 000,
    # mpiMotionAxisPrevious Previous iterate the list; MPI 000, mpiMotionAxisNext, return values MPIHandleVOID after the
    # last axis
    empty.axis_list_set([4, 6, 8])
    forward, (message, axis) = [], empty.axis_first()
    while axis is not None:
        forward.append(axis)
        message, axis = empty.axis_next(axis)
        assert message.ok
    backward, (message, axis) = [], empty.axis_last()
    while axis is not None:
        backward.append(axis)
        message, axis = empty.axis_previous(axis)
    assert forward == [4, 6, 8]
    assert backward == [8, 6, 4]


def test_first_and_last_of_an_empty_list(empty):
    # MPI 000, mpiMotionAxisFirst, return values, MPI 000, mpiMotionAxisLast, return values MPIHandleVOID "if motion is
    # empty"
    assert empty.axis_first() == (M.MPIMessageOK, None)
    assert empty.axis_last() == (M.MPIMessageOK, None)


def test_next_of_an_axis_not_on_the_list(empty):
    # MPI 000, mpiMotionAxisNext, return values MPIMessageHANDLE_INVALID
    empty.axis_list_set([4])
    assert empty.axis_next(5) == (M.MPIMessageHANDLE_INVALID, None)
    assert empty.axis_previous(5) == (M.MPIMessageHANDLE_INVALID, None)


def test_index_of_an_axis(empty):
    # MPI 000, mpiMotionAxisIndex "returns the position of axis on the list"; MPI 000, mpiMotionAxisIndex, return values
    # -1 if not found
    empty.axis_list_set([4, 6])
    assert empty.axis_index(6) == 1
    assert empty.axis_index(5) == -1


def test_an_invalid_handle_everywhere(big, empty):
    # MPI 000, mpiMotionAxisCount, return values count -1 "if motion is invalid"; MPI 000, mpiMotionAxisIndex, return
    # values index -1; MPI 000, mpiMotionAxis, return values MPIHandleVOID; MPI 000, mpiMotionAxisAppend, return values
    # HANDLE_INVALID
    empty.axis_list_set([4])
    empty.action(MPIAction.MAP)
    assert big.delete_motion(empty).ok
    assert empty.validate().message is M.MPIMessageHANDLE_INVALID
    assert empty.axis_count() == -1
    assert empty.axis_index(4) == -1
    assert empty.axis_at(0) == (M.MPIMessageHANDLE_INVALID, None)
    assert empty.axis_first() == (M.MPIMessageHANDLE_INVALID, None)
    assert empty.axis_append(5).message is M.MPIMessageHANDLE_INVALID
    assert empty.axis_list_set([5]).message is M.MPIMessageHANDLE_INVALID
    assert empty.axis_list_get() == (M.MPIMessageHANDLE_INVALID, [])


def test_map_writes_the_mapping(empty):
    # MPI 000, MEIActionMAP MEIActionMAP "will write the axis mapping relationship of the motion supervisor
    # to the controller"; MPI 000, MEIMotionConfig, axisCount axisCount / axisNumber are the mapping on the controller
    empty.axis_list_set([3, 7])
    assert empty.config_get()[1].axis_numbers == []
    assert empty.action(MPIAction.MAP).ok
    config = empty.config_get()[1]
    assert config.axis_numbers == [3, 7]
    assert config.axis_count == 2


def test_map_with_an_empty_list(big, empty):
    # MPI 000, MEIMotionMessageNO_AXES_MAPPED NO_AXES_MAPPED for an action with no axes
    assert empty.action(MPIAction.MAP).message is M.MEIMotionMessageNO_AXES_MAPPED
    empty.axis_list_set([2])
    empty.action(MPIAction.MAP)
    empty.axis_list_set([])
    assert empty.action(MPIAction.MAP).message is M.MEIMotionMessageNO_AXES_MAPPED
    assert empty.config_get()[1].axis_numbers == [2]  # the mapping stays as it was


def test_create_with_an_initial_axis(big):
    # MPI 000, mpiMotionCreate "The axis parameter specifies the initial element in the list of Axis objects"
    message, ms = big.create_motion(3, axis=5)
    assert message.ok
    assert ms.axis_list_get()[1] == [5]
    message, none = big.create_motion(4, axis=99)
    assert message is M.MPIMessageHANDLE_INVALID
    assert none is None
