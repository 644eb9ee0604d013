"""The one outcome type (mpi_ros/mpi/base/outcome.py): what every layer answers with."""

from __future__ import annotations

import pytest

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, MoveEnd, Outcome, Refused


def test_an_outcome_is_ok_only_with_the_ok_message():
    assert VALID.ok
    assert Outcome(Message.MPIMessageOK, "why not").ok
    assert not Outcome(Message.MPIMessagePARAM_INVALID, "velocity: must be > 0").ok
    assert not Outcome(Message.MPIMotionMessageAUTO_START).ok  # accepted, but not OK


def test_prefixed_names_the_nested_field_and_leaves_ok_alone():
    refused = Outcome(Message.MPIMessagePARAM_INVALID, "velocity: must be > 0")
    assert refused.prefixed("trajectory[1].") == Outcome(Message.MPIMessagePARAM_INVALID,
                                                          "trajectory[1].velocity: must be > 0")
    assert VALID.prefixed("trajectory[1].") is VALID


def test_refused_carries_its_outcome_where_it_is_caught():
    with pytest.raises(Refused) as caught:
        raise Refused(Message.MPIMotionMessagePROFILE_ERROR, "cannot reach the target")
    assert caught.value.outcome == Outcome(Message.MPIMotionMessagePROFILE_ERROR, "cannot reach the target")
    assert (caught.value.message, caught.value.detail, str(caught.value)) == (
        Message.MPIMotionMessagePROFILE_ERROR, "cannot reach the target", "cannot reach the target")


def test_a_move_end_reads_through_to_its_outcome():
    end = MoveEnd(7, Outcome(Message.MPIMessageOK, "motion done"), 1200, (1.0, 2.0), (0.5, 2.0), supervisor=1)
    assert (end.message, end.detail, end.succeeded) == (Message.MPIMessageOK, "motion done", True)
    stopped = MoveEnd(7, Outcome(Message.MPIMotionMessageSTOPPED, "replaced by a modify"), 1300)
    assert not stopped.succeeded
    assert stopped.command_position == ()
    assert stopped.supervisor == -1
