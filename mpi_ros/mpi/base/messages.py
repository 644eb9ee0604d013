"""Message codes: every MPI/MEI message the simulated controller can answer.

Member names are the spec's names exactly (``MPIMotionMessageIDLE``, ...). The enum
listing in MPI 000 spells two of them ``Type_INVALID`` and ``Attribute_INVALID``; the
descriptions spell them upper case, which is what is used here (docs/decisions.md, "The ROS
contract: names, numbers, arrays").

Codes are stable numbers: 0 for ``MPIMessageOK``, and for the others a module base
(as the MPI groups messages by module) plus the position in the spec's enum listing.
Tools should compare names, not codes.
"""

from __future__ import annotations

from enum import IntEnum

_MPI = 0x0000
_AXIS = 0x0300
_MOTION = 0x0900
_MEI_MOTION = 0x0980
_MEI_LIST = 0x1100


class Message(IntEnum):
    """The answer of every controller call: OK or why nothing was done."""

    # Generic messages (MPI 000 "Return Values" of the methods).
    MPIMessageOK = _MPI + 0
    MPIMessageARG_INVALID = _MPI + 1
    MPIMessagePARAM_INVALID = _MPI + 2
    MPIMessageHANDLE_INVALID = _MPI + 3
    MPIMessageNO_MEMORY = _MPI + 4
    MPIMessageOBJECT_NOT_ENABLED = _MPI + 5
    MPIMessageOBJECT_ON_LIST = _MPI + 6
    MPIMessageUNSUPPORTED = _MPI + 7
    MPIMessageFILE_OPEN_ERROR = _MPI + 8

    # MPIAxisMessage (MPI 002).
    MPIAxisMessageAXIS_INVALID = _AXIS + 0
    MPIAxisMessageCOMMAND_NOT_SET = _AXIS + 1
    MPIAxisMessageNOT_MAPPED_TO_MS = _AXIS + 2

    # MPIMotionMessage (MPI 000, in the order of its enum listing).
    MPIMotionMessageMOTION_INVALID = _MOTION + 0
    MPIMotionMessageAXIS_NOT_FOUND = _MOTION + 1
    MPIMotionMessageAXIS_COUNT = _MOTION + 2
    MPIMotionMessageAXIS_FRAME_COUNT = _MOTION + 3
    MPIMotionMessageTYPE_INVALID = _MOTION + 4
    MPIMotionMessageATTRIBUTE_INVALID = _MOTION + 5
    MPIMotionMessageIDLE = _MOTION + 6
    MPIMotionMessageMOVING = _MOTION + 7
    MPIMotionMessageSTOPPING = _MOTION + 8
    MPIMotionMessageSTOPPED = _MOTION + 9
    MPIMotionMessageSTOPPING_ERROR = _MOTION + 10
    MPIMotionMessageERROR = _MOTION + 11
    MPIMotionMessageAUTO_START = _MOTION + 12
    MPIMotionMessageILLEGAL_DELAY = _MOTION + 13
    MPIMotionMessagePROFILE_ERROR = _MOTION + 14
    MPIMotionMessagePROFILE_NOT_SUPPORTED = _MOTION + 15
    MPIMotionMessagePATH_ERROR = _MOTION + 16
    MPIMotionMessageFRAMES_LOW = _MOTION + 17
    MPIMotionMessageFRAMES_EMPTY = _MOTION + 18
    MPIMotionMessageFRAME_BUFFER_TOO_SMALL = _MOTION + 19

    # MEIMotionMessage (MPI 000).
    MEIMotionMessageRESERVED0 = _MEI_MOTION + 0
    MEIMotionMessageRESERVED1 = _MEI_MOTION + 1
    MEIMotionMessageRESERVED2 = _MEI_MOTION + 2
    MEIMotionMessageNO_AXES_MAPPED = _MEI_MOTION + 3
    MEIMotionMessageBAD_PATH_DATA = _MEI_MOTION + 4

    # MEIListMessage (MPI 000, mpiMotionAxis).
    MEIListMessageELEMENT_NOT_FOUND = _MEI_LIST + 0

    @property
    def code(self) -> int:
        """The stable number of the message (0 for MPIMessageOK)."""
        return int(self)

    @property
    def ok(self) -> bool:
        return self is Message.MPIMessageOK

    @classmethod
    def from_name(cls, name: str) -> Message:
        return cls[name]


OK = Message.MPIMessageOK

# The message a refused start/modify/action answers for each supervisor state
# (MPI 000 MPIMotionMessageIDLE ... MPIMotionMessageERROR descriptions).
STATE_MESSAGES = {
    "IDLE": Message.MPIMotionMessageIDLE,
    "MOVING": Message.MPIMotionMessageMOVING,
    "STOPPING": Message.MPIMotionMessageSTOPPING,
    "STOPPED": Message.MPIMotionMessageSTOPPED,
    "STOPPING_ERROR": Message.MPIMotionMessageSTOPPING_ERROR,
    "ERROR": Message.MPIMotionMessageERROR,
}
