"""Axis objects made and removed while the controller runs: mpiAxisCreate, mpiAxisDelete,
mpiAxisValidate, mpiAxisControl (MPI 002) and mpiMotionControl (MPI 000)."""

from __future__ import annotations

from mpi_ros.commands import Command, Operation, apply
from mpi_ros.mpi import Controller, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.messages import Message


def test_create_out_of_range_is_axis_invalid(ctl: Controller):
    # MPI 002, MPIAxisMessageAXIS_INVALID: "returned by mpiAxisCreate(...) if the axis number is
    # less than zero or greater than or equal to MEIXmpMAX_Axes" (here the controller's 4 axes)
    for number in (-1, 4, 1000):
        outcome, axis = ctl.axis_create(number)
        assert outcome.message is Message.MPIAxisMessageAXIS_INVALID
        assert axis is None
        assert "MEIXmpMAX_Axes = 4" in outcome.detail
    assert ctl.valid_axes() == [0, 1, 2, 3]


def test_every_configured_axis_is_valid_at_the_start(ctl: Controller):
    # MPI 002, mpiAxisValidate: OK "if Axis is a handle to a valid object"
    assert all(ctl.axis_validate(n).ok for n in range(4))
    assert ctl.axis_validate(4).message is Message.MPIAxisMessageAXIS_INVALID


def test_delete_refuses_an_axis_on_a_supervisors_list(ctl: Controller, ms):
    # MPI 002, mpiAxisDelete remarks: objects are deleted in reverse order of creation, so the
    # motion that lists the axis goes first; the axis stays valid and moving is unaffected
    outcome = ctl.axis_delete(1)
    assert outcome.message is Message.MPIMessageOBJECT_ON_LIST
    assert "supervisor 0" in outcome.detail
    assert ctl.axis_validate(1).ok
    assert ms.axis_list == [0, 1]


def test_an_axis_removed_but_still_mapped_is_refused(ctl: Controller, ms):
    assert ms.axis_remove(1).ok  # off the list, still mapped until the next MAP (MPI 000)
    assert ctl.axis_delete(1).message is Message.MPIMessageOBJECT_ON_LIST
    assert ms.action(MPIAction.MAP).ok
    assert ctl.axis_delete(1).ok


def test_delete_then_create_while_running(ctl: Controller, ms, ms1, params, run_to):
    assert ms1.axis_remove(3).ok
    assert ms1.action(MPIAction.MAP).ok
    # a move runs while axis 3 comes and goes
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=params(position=(2000.0, 0.0))).ok
    ctl.step(100)
    assert ctl.axis_delete(3).ok
    # MPI 002, mpiAxisValidate / mpiAxisDelete: the handle is invalid from now on
    assert ctl.axis_validate(3).message is Message.MPIMessageHANDLE_INVALID
    assert ctl.axis_delete(3).message is Message.MPIMessageHANDLE_INVALID
    assert ctl.axis_control(3) is None  # mpiAxisControl: MPIHandleVOID "if axis is invalid"
    # MPI 000, mpiMotionAxisAppend: MPIMessageHANDLE_INVALID "Either motion or axis is an invalid handle"
    assert ms1.axis_append(3).message is Message.MPIMessageHANDLE_INVALID
    assert ms1.axis_list_set([2, 3]).message is Message.MPIMessageHANDLE_INVALID
    assert ms1.axis_list == [2]
    assert ctl.valid_axes() == [0, 1, 2]
    run_to(ctl, ms, MPIState.IDLE)  # the controller keeps stepping every axis
    outcome, axis = ctl.axis_create(3)
    assert outcome.ok
    assert axis is ctl.axes[3]
    assert ctl.axis_validate(3).ok
    assert ctl.axis_control(3) is ctl
    assert ms1.axis_append(3).ok
    assert ms1.action(MPIAction.MAP).ok
    assert ms1.start(MPIMotionType.TRAPEZOIDAL, params=params(position=(0.0, 500.0))).ok
    run_to(ctl, ms1, MPIState.IDLE)
    assert ctl.axis_snapshot(3).command_position == 500.0


def test_create_of_a_valid_axis_answers_the_same_object(ctl: Controller):
    outcome, axis = ctl.axis_create(2)
    assert outcome.ok
    assert axis is ctl.axes[2]
    assert ctl.valid_axes() == [0, 1, 2, 3]


def test_motion_control(ctl: Controller, ms):
    # MPI 000, mpiMotionControl: the Control of the motion, MPIHandleVOID if motion is invalid
    assert ctl.motion_control(ms) is ctl
    assert ctl.delete_motion(ms).ok
    assert ctl.motion_control(ms) is None


def test_create_and_delete_are_commands_a_replay_repeats(ctl: Controller, ms1):
    assert ms1.axis_list_set([2]).ok
    assert ms1.action(MPIAction.MAP).ok
    reply = apply(ctl, Command(Operation.AXIS_DELETE, axis=3))
    assert reply.message is Message.MPIMessageOK
    assert not ctl.axes[3].valid
    reply = apply(ctl, Command(Operation.AXIS_DELETE, axis=2))
    assert reply.message is Message.MPIMessageOBJECT_ON_LIST
    assert "supervisor 1" in reply.detail
    reply = apply(ctl, Command(Operation.AXIS_CREATE, axis=7))
    assert reply.message is Message.MPIAxisMessageAXIS_INVALID
    assert apply(ctl, Command(Operation.AXIS_CREATE, axis=3)).message is Message.MPIMessageOK
    assert ctl.axes[3].valid


def test_every_axis_call_on_a_deleted_axis_is_handle_invalid_and_changes_nothing(ctl: Controller, ms1):
    # MPI 002, mpiAxisValidate: a deleted Axis object is an invalid handle, so each mpiAxis* call
    # on it answers MPIMessageHANDLE_INVALID (a replayed or direct call as well as one over ROS)
    assert ms1.axis_remove(3).ok
    assert ms1.action(MPIAction.MAP).ok
    assert ctl.axis_delete(3).ok
    before = ctl.axis_snapshot(3)
    calls = {
        "command position": lambda: ctl.axis_command_position_set(3, 50.0),
        "actual position": lambda: ctl.axis_actual_position_set(3, 50.0),
        "origin": lambda: ctl.axis_origin_set(3, 50.0),
        "amplifier": lambda: ctl.axis_amp_enable_set(3, False),
        "event mask": lambda: ctl.axis_event_notify_set(3, ctl.axis_event_notify_get(0)[1]),
        "fault inject": lambda: ctl.axis_fault_inject(3, "AMP_FAULT"),
    }
    for name, call in calls.items():
        outcome = call()
        assert outcome.message is Message.MPIMessageHANDLE_INVALID, name
        assert "deleted" in outcome.detail, name
    assert ctl.axis_event_notify_get(3)[0] is Message.MPIMessageHANDLE_INVALID
    assert ctl.axis_fault_config_get(3)[0] is Message.MPIMessageHANDLE_INVALID
    after = ctl.axis_snapshot(3)
    assert (after.command_position, after.actual_position, after.origin, after.amp_enabled) == (
        before.command_position, before.actual_position, before.origin, before.amp_enabled)
    assert ctl.axis_create(3)[0].ok
    assert ctl.axis_origin_set(3, 50.0).ok
