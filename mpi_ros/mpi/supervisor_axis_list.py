"""The axis list of a motion supervisor (spec 000 mpiMotionAxis*): the coordinate system as
the host holds it, and the mapping written to the controller (MEIActionMAP)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .messages import Message
from .params import MAX_COORD_AXES
from .types import MPIState

if TYPE_CHECKING:
    from .axis import Axis
    from .control import Controller
    from .frames import Move
    from .params import MotionConfig
    from .types import ActionSource

OK = Message.MPIMessageOK


class AxisListMixin:
    """mpiMotionAxisAppend/Insert/Remove/ListSet/ListGet/Count/Index/First/Next/... of
    MotionSupervisor (which provides ``axis_list``, ``mapped``, ``config``, ``valid``,
    ``own_state``, ``_axis`` and ``_state_message``)."""

    if TYPE_CHECKING:
        # What this mixin uses of MotionSupervisor (motion.py): declarations for the type
        # checker only.
        _ctl: Controller
        valid: bool
        axis_list: list[int]
        mapped: list[int]
        config: MotionConfig
        own_state: MPIState
        action_source: ActionSource
        current: Move | None

        def _axis(self, number: int) -> Axis: ...
        def _state_message(self) -> Message: ...
        def _set_state(self, state: MPIState, action: str, source: ActionSource) -> None: ...
        def _rebase(self, t: float) -> None: ...
        def _drop_pending(self, message: Message, detail: str) -> None: ...

    def _check_axis(self, number: int) -> Message:
        if not 0 <= number < len(self._ctl.axes):
            return Message.MPIMessageHANDLE_INVALID
        if not self._axis(number).enabled:
            return Message.MPIMessageOBJECT_NOT_ENABLED
        return OK

    @property
    def frame_buffer_size(self) -> int:
        """The frame buffer size of the supervisor's axes (one size: see :meth:`_frame_sizes_differ`)."""
        config = self._ctl.config
        return config.frame_buffer_size_of(self.axis_list[0]) if self.axis_list else config.frame_buffer_size

    def _frame_sizes_differ(self, numbers: list[int]) -> bool:
        """MPI 000 MPIMotionMessageAXIS_FRAME_COUNT: "All axes appended to a Motion object must
        have the same frame buffer size". Answered where axes are appended (append, insert,
        list set), so a list never holds two sizes and MAP and the moves need not ask."""
        return len({self._ctl.config.frame_buffer_size_of(n) for n in numbers}) > 1

    def axis_append(self, number: int) -> Message:
        """mpiMotionAxisAppend."""
        return self.axis_insert(self.axis_list[-1] if self.axis_list else None, number)

    def axis_insert(self, after: int | None, number: int) -> Message:
        """mpiMotionAxisInsert: insert ``number`` just after axis ``after`` (None: first)."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        message = self._check_axis(number)
        if not message.ok:
            return message
        if number in self.axis_list:
            return Message.MPIMessageOBJECT_ON_LIST
        if len(self.axis_list) >= MAX_COORD_AXES:
            return Message.MPIMessageUNSUPPORTED
        if self._frame_sizes_differ([*self.axis_list, number]):
            return Message.MPIMotionMessageAXIS_FRAME_COUNT
        if after is None:
            self.axis_list.insert(0, number)
            return OK
        if after not in self.axis_list:
            return Message.MPIMotionMessageAXIS_NOT_FOUND
        self.axis_list.insert(self.axis_list.index(after) + 1, number)
        return OK

    def axis_remove(self, number: int) -> Message:
        """mpiMotionAxisRemove."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        message = self._check_axis(number)
        if not message.ok:
            return message
        if number not in self.axis_list:
            return Message.MPIMotionMessageAXIS_NOT_FOUND
        if number not in self.mapped:
            # spec 002 MPIAxisMessageNOT_MAPPED_TO_MS: on the list but not mapped.
            return Message.MPIAxisMessageNOT_MAPPED_TO_MS
        if self.own_state not in (MPIState.IDLE, MPIState.ERROR):
            return self._state_message()
        self.axis_list.remove(number)
        return OK

    def axis_list_set(self, numbers: list[int]) -> Message:
        """mpiMotionAxisListSet: the coordinate system is completely replaced."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        if len(numbers) > MAX_COORD_AXES:
            return Message.MPIMessageUNSUPPORTED
        if len(set(numbers)) != len(numbers):
            return Message.MPIMessageOBJECT_ON_LIST
        for number in numbers:
            message = self._check_axis(number)
            if not message.ok:
                return message
        if self._frame_sizes_differ(numbers):
            return Message.MPIMotionMessageAXIS_FRAME_COUNT
        if self.own_state not in (MPIState.IDLE, MPIState.ERROR, MPIState.STOPPED):
            return self._state_message()
        self.axis_list = list(numbers)
        return OK

    def axis_list_get(self) -> tuple[Message, list[int]]:
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, []
        return OK, list(self.axis_list)

    def axis_count(self) -> int:
        """mpiMotionAxisCount: -1 if the handle is invalid."""
        return len(self.axis_list) if self.valid else -1

    def axis_index(self, number: int) -> int:
        """mpiMotionAxisIndex: -1 if invalid or not on the list."""
        if not self.valid or number not in self.axis_list:
            return -1
        return self.axis_list.index(number)

    def axis_at(self, index: int) -> tuple[Message, int | None]:
        """mpiMotionAxis: the axis at ``index`` (None = MPIHandleVOID)."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, None
        if not 0 <= index < len(self.axis_list):
            return Message.MEIListMessageELEMENT_NOT_FOUND, None
        return OK, self.axis_list[index]

    def axis_first(self) -> tuple[Message, int | None]:
        return self.axis_at(0) if self.axis_list or not self.valid else (OK, None)

    def axis_last(self) -> tuple[Message, int | None]:
        return self.axis_at(len(self.axis_list) - 1) if self.axis_list or not self.valid else (OK, None)

    def axis_next(self, number: int) -> tuple[Message, int | None]:
        return self._neighbour(number, +1)

    def axis_previous(self, number: int) -> tuple[Message, int | None]:
        return self._neighbour(number, -1)

    def _neighbour(self, number: int, step: int) -> tuple[Message, int | None]:
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, None
        if number not in self.axis_list:
            return Message.MPIMessageHANDLE_INVALID, None
        index = self.axis_list.index(number) + step
        return OK, self.axis_list[index] if 0 <= index < len(self.axis_list) else None

    def _map(self) -> Message:
        """Write the axis list to the controller (MEIActionMAP).

        A stopped motion's pending profile belongs to the axes it was started on. Mapping a
        list that leaves out one of them drops that profile (the supervisor goes IDLE, as a
        RESET would take it): RESUME could not continue it, and the axes it leaves must not
        keep a plan no supervisor runs. Refused while such an axis still moves (a non-zero
        pauseFeedrate): it would stop dead."""
        move = self.current
        leaving = [p.axis for p in move.plans if p.axis not in self.axis_list] if move is not None else []
        if leaving and self.own_state is MPIState.STOPPED:
            moving = [n for n in leaving if self._axis(n).cmd_v != 0.0]
            if moving:
                return Message.MPIMotionMessageSTOPPED
            self._rebase(self._ctl.time)
            self._drop_pending(Message.MPIMotionMessageSTOPPED, "dropped: its axes were remapped")
            self._set_state(MPIState.IDLE, "MAP", self.action_source)
        self.mapped = list(self.axis_list)
        self.config.axis_numbers = list(self.mapped)
        return OK

