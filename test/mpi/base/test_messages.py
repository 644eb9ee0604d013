"""Message codes (mpi_ros/mpi/base/messages.py): every name of the spec, stable codes."""

from __future__ import annotations

import pytest

from mpi_ros.mpi.base.messages import OK, STATE_MESSAGES, Message
from mpi_ros.mpi.base.types import MPIState

# MPI 000, MPIMotionMessage, the MPIMotionMessage enum listing, in order (docs/decisions.md, "The ROS
# contract": the listing's "Type_INVALID" / "Attribute_INVALID" are typos for the descriptions' upper-case names).
MOTION_MESSAGES = [
    "MOTION_INVALID", "AXIS_NOT_FOUND", "AXIS_COUNT", "AXIS_FRAME_COUNT", "TYPE_INVALID",
    "ATTRIBUTE_INVALID", "IDLE", "MOVING", "STOPPING", "STOPPED", "STOPPING_ERROR", "ERROR",
    "AUTO_START", "ILLEGAL_DELAY", "PROFILE_ERROR", "PROFILE_NOT_SUPPORTED", "PATH_ERROR",
    "FRAMES_LOW", "FRAMES_EMPTY", "FRAME_BUFFER_TOO_SMALL",
]
# MPI 000, MEIMotionMessage, MEIMotionMessage.
MEI_MOTION_MESSAGES = ["RESERVED0", "RESERVED1", "RESERVED2", "NO_AXES_MAPPED", "BAD_PATH_DATA"]
# MPI 002, MPIAxisMessage, MPIAxisMessage.
AXIS_MESSAGES = ["AXIS_INVALID", "COMMAND_NOT_SET", "NOT_MAPPED_TO_MS"]


@pytest.mark.parametrize("name", MOTION_MESSAGES)
def test_every_motion_message_of_the_spec_exists(name):
    # MPI 000, MPIMotionMessage MPIMotionMessage enum
    assert Message[f"MPIMotionMessage{name}"].name == f"MPIMotionMessage{name}"


def test_motion_messages_keep_the_order_of_the_spec_listing():
    # MPI 000, MPIMotionMessage: codes follow the enum listing (one module base plus the position)
    codes = [Message[f"MPIMotionMessage{name}"].code for name in MOTION_MESSAGES]
    assert codes == list(range(codes[0], codes[0] + len(codes)))


def test_the_typo_spellings_of_the_enum_listing_are_not_names():
    # docs/decisions.md, "The ROS contract": MPIMotionMessageTYPE_INVALID and MPIMotionMessageATTRIBUTE_INVALID
    # (the enum listing's Type_INVALID/Attribute_INVALID is a typo)
    for typo in ("MPIMotionMessageType_INVALID", "MPIMotionMessageAttribute_INVALID"):
        with pytest.raises(KeyError):
            Message.from_name(typo)


@pytest.mark.parametrize("name", MEI_MOTION_MESSAGES)
def test_every_mei_motion_message_exists(name):
    # MPI 000, MEIMotionMessage MEIMotionMessage enum
    assert Message[f"MEIMotionMessage{name}"].name == f"MEIMotionMessage{name}"


@pytest.mark.parametrize("name", AXIS_MESSAGES)
def test_every_axis_message_exists(name):
    # MPI 002, MPIAxisMessage MPIAxisMessage enum
    assert Message[f"MPIAxisMessage{name}"].name == f"MPIAxisMessage{name}"


def test_list_message_element_not_found_exists():
    # MPI 000, mpiMotionAxis, return values mpiMotionAxis returns MEIListMessageELEMENT_NOT_FOUND
    assert Message.MEIListMessageELEMENT_NOT_FOUND.name == "MEIListMessageELEMENT_NOT_FOUND"


def test_ok_is_code_zero_and_the_only_ok():
    # docs/decisions.md, "The ROS contract": code is 0 for MPIMessageOK and a fixed number per message otherwise
    assert OK is Message.MPIMessageOK
    assert Message.MPIMessageOK.code == 0
    assert Message.MPIMessageOK.ok
    assert [m for m in Message if m.ok] == [Message.MPIMessageOK]
    assert all(m.code != 0 for m in Message if m is not Message.MPIMessageOK)


def test_codes_are_unique():
    # docs/decisions.md, "The ROS contract": one name per number (an IntEnum alias would hide a name)
    assert len({m.code for m in Message}) == len(Message.__members__)


def test_from_name_round_trips_every_message():
    # docs/decisions.md, "The ROS contract": message is the reference's name exactly; tools read the names
    for message in Message:
        assert Message.from_name(message.name) is message


@pytest.mark.parametrize("state", ["IDLE", "MOVING", "STOPPING", "STOPPED", "STOPPING_ERROR", "ERROR"])
def test_each_state_has_its_refusal_message(state):
    # MPI 000, MPIMotionMessageIDLE: a refused start/modify/action answers the message named after the state
    assert STATE_MESSAGES[state] is Message[f"MPIMotionMessage{state}"]
    assert MPIState[state].name == state
