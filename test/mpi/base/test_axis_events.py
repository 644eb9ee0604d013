"""mpiAxisEventNotifyGet/Set and mpiAxisEventReset (MPI 002, "Event Methods"): an axis' own
event mask and latched events, one implementation with the Motion's (events.EventNotify)."""

from __future__ import annotations

from mpi_ros.mpi import MPIMotionType, MPIState
from mpi_ros.mpi.base.events import MASK_AXIS, MPIEventType
from mpi_ros.mpi.base.messages import Message

E = MPIEventType


def _move(ctl, ms, params, run_to):
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=params((500.0, 300.0))).ok
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=100)


def test_an_axis_mask_notifies_what_its_supervisor_does_not(ctl, ms, params, run_to):
    # MPI 002, mpiAxisEventNotifySet; MPI 000, mpiMotionEventNotifySet: "Event notification is
    # disabled for event types that are not specified"
    assert ms.event_notify_set(E.MOTION_DONE).ok
    assert ctl.axis_event_notify_set(1, E.SETTLED).ok
    assert ctl.axis_event_notify_get(1) == (Message.MPIMessageOK, E.SETTLED)
    ctl.drain_events()
    _move(ctl, ms, params, run_to)
    events = ctl.drain_events()
    assert sorted({(e.type.name, e.axis) for e in events}) == [("MOTION_DONE", -1), ("SETTLED", 1)]


def test_an_event_both_ask_for_is_notified_once(ctl, ms, params, run_to):
    assert ms.event_notify_set(E.DONE).ok
    assert ctl.axis_event_notify_set(0, E.DONE).ok
    ctl.drain_events()
    _move(ctl, ms, params, run_to)
    assert [(e.axis, e.supervisor) for e in ctl.drain_events() if e.type is E.DONE] == [(0, 0), (1, 0)]


def test_axis_events_latch_on_the_axis_until_reset(ctl, ms, params, run_to):
    # MPI 002, mpiAxisEventReset ("Reset events specified in event mask"); motion events stay the Motion's
    _move(ctl, ms, params, run_to)
    latched = ctl.axes[0].events.latched
    assert latched & E.SETTLED
    assert latched & E.DONE
    assert not latched & E.MOTION_DONE
    assert ctl.axis_event_reset(0, E.SETTLED).ok
    assert not ctl.axes[0].events.latched & E.SETTLED
    assert ctl.axes[0].events.latched & E.DONE
    assert ctl.axes[1].events.latched & E.SETTLED  # the other axis keeps its own
    assert ctl.axis_event_reset(0, MASK_AXIS).ok
    assert ctl.axes[0].events.latched == E.NONE


def test_no_axis_mask_by_default_and_an_unknown_axis_is_refused(ctl):
    assert ctl.axis_event_notify_get(0) == (Message.MPIMessageOK, E.NONE)
    assert ctl.axis_event_notify_set(7, E.DONE).message is Message.MPIAxisMessageAXIS_INVALID
    assert ctl.axis_event_reset(-1, E.DONE).message is Message.MPIAxisMessageAXIS_INVALID
    assert ctl.axis_event_notify_get(7)[0] is Message.MPIAxisMessageAXIS_INVALID
