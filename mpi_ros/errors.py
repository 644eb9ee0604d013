"""One exception class per MPI message, for the Python client API.

``mpi_ros.errors.MPIMotionMessageMOVING`` is raised when a start is refused because the
supervisor is moving, and so on for every message of :class:`mpi_ros.mpi.Message`.
All derive from :class:`MpiError` (``.message``, ``.code``, ``.detail``, ``.result``).
"""

from __future__ import annotations

from .mpi.messages import Message


class MpiError(Exception):
    """The controller refused or ended a command with a message other than MPIMessageOK."""

    message_name = ""

    def __init__(self, detail: str = "", result=None):
        super().__init__(f"{self.message_name}: {detail}" if detail else self.message_name)
        self.detail = detail
        self.result = result

    @property
    def message(self) -> Message:
        return Message[self.message_name]

    @property
    def code(self) -> int:
        return self.message.code


class NoResponse(TimeoutError):
    """No answer within the timeout: the ROS graph (not the controller) did not respond."""


_CLASSES: dict[str, type[MpiError]] = {}
for _member in Message:
    if _member is Message.MPIMessageOK:
        continue
    _cls = type(_member.name, (MpiError,), {"message_name": _member.name, "__doc__": f"{_member.name} (code {_member.code})."})
    _CLASSES[_member.name] = _cls
    globals()[_member.name] = _cls


def error_for(message_name: str) -> type[MpiError]:
    """The exception class of a message name (unknown names get a plain MpiError subclass)."""
    cls = _CLASSES.get(message_name)
    if cls is None:
        cls = type(message_name or "UnknownMessage", (MpiError,), {"message_name": message_name})
        _CLASSES[message_name] = cls
    return cls


def raise_for(message_name: str, detail: str = "", result=None) -> None:
    """Raise the exception of ``message_name`` unless it is MPIMessageOK."""
    if message_name != Message.MPIMessageOK.name:
        raise error_for(message_name)(detail, result)
