"""One exception class per MPI message, for the Python client and the ``mpi-ros`` console.

``mpi_ros.errors.MPIMotionMessageMOVING`` is raised when a start is refused because the
supervisor is moving, and so on for every message the controller can answer
(``mpi_ros.mpi.base.messages.Message``; a test keeps the two lists equal, names and codes).
All derive from :class:`MpiError` (``.message`` the spec's name, ``.code`` its number,
``.detail`` the controller's words, ``.result`` the reply or result that carried it); the
six refusals for the supervisor's state also derive from :class:`StateError`.

This module is written out (no classes made at import time) and imports nothing of the
simulated controller: a client on another machine needs only the generated interfaces
and rclpy. Tools should compare names, not codes.
"""

from __future__ import annotations

from typing import Any, ClassVar

OK = "MPIMessageOK"


class MpiError(Exception):
    """The controller refused or ended a command with a message other than MPIMessageOK."""

    message_name: ClassVar[str] = ""
    code: ClassVar[int] = -1

    def __init__(self, detail: str = "", result: Any = None):
        super().__init__(f"{self.message_name}: {detail}" if detail else self.message_name)
        self.detail = detail
        self.result = result

    @property
    def message(self) -> str:
        """The spec's message name (as ``result.message``)."""
        return self.message_name


class StateError(MpiError):
    """Refused because of the supervisor's state (the MPIMotionMessage<STATE> answers)."""


class NoResponse(TimeoutError):
    """No answer within the timeout: the ROS graph (not the controller) did not respond."""


class SuiteNotFound(NoResponse):
    """No supervisor of the suite appeared on the graph (wrong domain, namespace, or not running)."""


class NoSuchSupervisor(LookupError):
    """The suite is there but has no supervisor with that number; the message lists those it has."""


# -- MPIMessage: generic answers (MPI 000, "Return Values") ------------------------------
class MPIMessageARG_INVALID(MpiError):
    """An argument of the call is invalid."""
    message_name = "MPIMessageARG_INVALID"
    code = 0x0001


class MPIMessagePARAM_INVALID(MpiError):
    """A parameter of the request is invalid (a length, a limit, a value); nothing moved."""
    message_name = "MPIMessagePARAM_INVALID"
    code = 0x0002


class MPIMessageHANDLE_INVALID(MpiError):
    """The object handle is invalid."""
    message_name = "MPIMessageHANDLE_INVALID"
    code = 0x0003


class MPIMessageNO_MEMORY(MpiError):
    """The controller has no memory left for the request."""
    message_name = "MPIMessageNO_MEMORY"
    code = 0x0004


class MPIMessageOBJECT_NOT_ENABLED(MpiError):
    """The object is not enabled."""
    message_name = "MPIMessageOBJECT_NOT_ENABLED"
    code = 0x0005


class MPIMessageOBJECT_ON_LIST(MpiError):
    """The object is already on the list."""
    message_name = "MPIMessageOBJECT_ON_LIST"
    code = 0x0006


class MPIMessageUNSUPPORTED(MpiError):
    """The controller does not support the request (the detail says which part)."""
    message_name = "MPIMessageUNSUPPORTED"
    code = 0x0007


class MPIMessageFILE_OPEN_ERROR(MpiError):
    """A file could not be opened."""
    message_name = "MPIMessageFILE_OPEN_ERROR"
    code = 0x0008


# -- MPIAxisMessage (MPI 002) ---------------------------------------------------------------
class MPIAxisMessageAXIS_INVALID(MpiError):
    """The axis does not exist."""
    message_name = "MPIAxisMessageAXIS_INVALID"
    code = 0x0300


class MPIAxisMessageCOMMAND_NOT_SET(MpiError):
    """The command position was not set."""
    message_name = "MPIAxisMessageCOMMAND_NOT_SET"
    code = 0x0301


class MPIAxisMessageNOT_MAPPED_TO_MS(MpiError):
    """The axis is not mapped to a motion supervisor."""
    message_name = "MPIAxisMessageNOT_MAPPED_TO_MS"
    code = 0x0302


# -- MPIMotionMessage (MPI 000, in the order of its enum listing) ------------------------------
class MPIMotionMessageMOTION_INVALID(MpiError):
    """The motion supervisor does not exist."""
    message_name = "MPIMotionMessageMOTION_INVALID"
    code = 0x0900


class MPIMotionMessageAXIS_NOT_FOUND(MpiError):
    """The axis is not on the supervisor's axis list."""
    message_name = "MPIMotionMessageAXIS_NOT_FOUND"
    code = 0x0901


class MPIMotionMessageAXIS_COUNT(MpiError):
    """The supervisor has the wrong number of axes for the request."""
    message_name = "MPIMotionMessageAXIS_COUNT"
    code = 0x0902


class MPIMotionMessageAXIS_FRAME_COUNT(MpiError):
    """The axes' frame buffers do not agree for the request."""
    message_name = "MPIMotionMessageAXIS_FRAME_COUNT"
    code = 0x0903


class MPIMotionMessageTYPE_INVALID(MpiError):
    """The motion type is not a known MPIMotionType."""
    message_name = "MPIMotionMessageTYPE_INVALID"
    code = 0x0904


class MPIMotionMessageATTRIBUTE_INVALID(MpiError):
    """An attribute is not valid with this motion type or state."""
    message_name = "MPIMotionMessageATTRIBUTE_INVALID"
    code = 0x0905


class MPIMotionMessageIDLE(StateError):
    """Refused: the supervisor is IDLE (nothing to stop, resume or modify)."""
    message_name = "MPIMotionMessageIDLE"
    code = 0x0906


class MPIMotionMessageMOVING(StateError):
    """Refused: the supervisor is MOVING."""
    message_name = "MPIMotionMessageMOVING"
    code = 0x0907


class MPIMotionMessageSTOPPING(StateError):
    """Refused: the supervisor is STOPPING."""
    message_name = "MPIMotionMessageSTOPPING"
    code = 0x0908


class MPIMotionMessageSTOPPED(StateError):
    """Refused, or the goal ended: the supervisor is STOPPED (RESUME or RESET next)."""
    message_name = "MPIMotionMessageSTOPPED"
    code = 0x0909


class MPIMotionMessageSTOPPING_ERROR(StateError):
    """Refused: the supervisor is STOPPING_ERROR (after an E_STOP or ABORT)."""
    message_name = "MPIMotionMessageSTOPPING_ERROR"
    code = 0x090A


class MPIMotionMessageERROR(StateError):
    """Refused, or the goal ended: the supervisor is in ERROR (E_STOP/ABORT); RESET leaves it."""
    message_name = "MPIMotionMessageERROR"
    code = 0x090B


class MPIMotionMessageAUTO_START(MpiError):
    """A modify while IDLE with AUTO_START started a new move instead."""
    message_name = "MPIMotionMessageAUTO_START"
    code = 0x090C


class MPIMotionMessageILLEGAL_DELAY(MpiError):
    """DELAY is not allowed here (a move that starts in motion cannot be delayed)."""
    message_name = "MPIMotionMessageILLEGAL_DELAY"
    code = 0x090D


class MPIMotionMessagePROFILE_ERROR(MpiError):
    """The profile cannot be computed from the request."""
    message_name = "MPIMotionMessagePROFILE_ERROR"
    code = 0x090E


class MPIMotionMessagePROFILE_NOT_SUPPORTED(MpiError):
    """The profile needs a firmware option that is off (S_CURVE_JERK, VELOCITY_JERK)."""
    message_name = "MPIMotionMessagePROFILE_NOT_SUPPORTED"
    code = 0x090F


class MPIMotionMessagePATH_ERROR(MpiError):
    """The path cannot be computed."""
    message_name = "MPIMotionMessagePATH_ERROR"
    code = 0x0910


class MPIMotionMessageFRAMES_LOW(MpiError):
    """The frame buffer is running low."""
    message_name = "MPIMotionMessageFRAMES_LOW"
    code = 0x0911


class MPIMotionMessageFRAMES_EMPTY(MpiError):
    """The frame buffer ran empty."""
    message_name = "MPIMotionMessageFRAMES_EMPTY"
    code = 0x0912


class MPIMotionMessageFRAME_BUFFER_TOO_SMALL(MpiError):
    """The move needs more frames than the frame buffer holds; nothing was overwritten."""
    message_name = "MPIMotionMessageFRAME_BUFFER_TOO_SMALL"
    code = 0x0913


# -- MEIMotionMessage (MPI 000) -------------------------------------------------------------------
class MEIMotionMessageRESERVED0(MpiError):
    """Reserved by the spec."""
    message_name = "MEIMotionMessageRESERVED0"
    code = 0x0980


class MEIMotionMessageRESERVED1(MpiError):
    """Reserved by the spec."""
    message_name = "MEIMotionMessageRESERVED1"
    code = 0x0981


class MEIMotionMessageRESERVED2(MpiError):
    """Reserved by the spec."""
    message_name = "MEIMotionMessageRESERVED2"
    code = 0x0982


class MEIMotionMessageNO_AXES_MAPPED(MpiError):
    """No axes are mapped to the supervisor."""
    message_name = "MEIMotionMessageNO_AXES_MAPPED"
    code = 0x0983


class MEIMotionMessageBAD_PATH_DATA(MpiError):
    """The path data is inconsistent."""
    message_name = "MEIMotionMessageBAD_PATH_DATA"
    code = 0x0984


# -- MEIListMessage (MPI 000, mpiMotionAxis) -------------------------------------------------------
class MEIListMessageELEMENT_NOT_FOUND(MpiError):
    """The list element was not found."""
    message_name = "MEIListMessageELEMENT_NOT_FOUND"
    code = 0x1100


def _concrete(base: type[MpiError]) -> list[type[MpiError]]:
    """Every class below ``base`` that stands for one message."""
    found = []
    for cls in base.__subclasses__():
        if cls.message_name:
            found.append(cls)
        found.extend(_concrete(cls))
    return found


# name -> class, for every message but MPIMessageOK.
ERRORS: dict[str, type[MpiError]] = {cls.message_name: cls for cls in _concrete(MpiError)}
# name -> code, MPIMessageOK included (what ``mpi-ros`` prints beside a name).
CODES: dict[str, int] = {OK: 0, **{name: cls.code for name, cls in ERRORS.items()}}
_UNKNOWN: dict[str, type[MpiError]] = {}


def error_for(message_name: str) -> type[MpiError]:
    """The exception class of a message name.

    A name this client does not know (a newer suite) gets a plain MpiError subclass, made
    once and kept, so ``except`` on it works and the name still shows.
    """
    cls = ERRORS.get(message_name) or _UNKNOWN.get(message_name)
    if cls is None:
        cls = type(message_name or "UnknownMessage", (MpiError,), {"message_name": message_name or "UnknownMessage"})
        _UNKNOWN[message_name] = cls
    return cls


def raise_for(message_name: str, detail: str = "", result: Any = None) -> None:
    """Raise the exception of ``message_name`` unless it is MPIMessageOK."""
    if message_name != OK:
        raise error_for(message_name)(detail, result)
