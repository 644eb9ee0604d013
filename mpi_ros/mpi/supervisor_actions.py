"""mpiMotionAction: STOP, RESUME, E_STOP, ABORT, E_STOP_ABORT, RESET and MEIActionMAP.

Each action answers per docs/state-machine.md; safety actions are never refused. Stops ramp
the supervisor's feedrate (clock.py); ABORT turns the amplifiers off.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .axis import CommandMode
from .events import MPIEventType
from .messages import STATE_MESSAGES, Message
from .status import StatusMode
from .types import ActionSource, MPIAction, MPIMotionType, MPIState

if TYPE_CHECKING:
    from .axis import Axis
    from .clock import ProfileClock
    from .control import Controller
    from .frames import Move
    from .params import MotionConfig

OK = Message.MPIMessageOK
# Actions that act on another supervisor's motion on shared axes (all but MAP).
_SHARED = (MPIAction.STOP, MPIAction.RESUME, MPIAction.E_STOP, MPIAction.ABORT, MPIAction.E_STOP_ABORT,
           MPIAction.RESET)
# The own states in which these act on this supervisor's own motion (None: always).
_OWN_STATES = {MPIAction.STOP: (MPIState.MOVING,), MPIAction.RESUME: (MPIState.STOPPED,),
               MPIAction.RESET: (MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR)}


class ActionsMixin:
    """The actions of MotionSupervisor."""

    if TYPE_CHECKING:
        # What this mixin uses of MotionSupervisor (motion.py) and AxisListMixin: declarations
        # for the type checker only.
        _ctl: Controller
        number: int
        valid: bool
        axis_list: list[int]
        mapped: list[int]
        config: MotionConfig
        own_state: MPIState
        current: Move | None
        clock: ProfileClock
        _stop_end: float
        _abort_after_stop: bool
        _error_at: int | None
        _aborted: bool

        @property
        def axes(self) -> list[Axis]: ...
        @property
        def state(self) -> MPIState: ...
        def _clock_of(self, axis: Axis) -> ProfileClock | None: ...
        def _emit(self, kind: MPIEventType, axis: int = -1, move: Move | None = None, detail: str = "",
                  sample: int | None = None) -> None: ...
        def _set_state(self, state: MPIState, action: str, source: ActionSource) -> None: ...
        def _rebase(self, t: float) -> None: ...
        def _drop_pending(self, message: Message, detail: str) -> None: ...
        def _notify_action(self, motion_type: MPIMotionType, action: str) -> None: ...
        def _map(self) -> Message: ...

    def action(self, action: MPIAction, source: ActionSource = ActionSource.USER) -> Message:
        """mpiMotionAction."""
        message, _ = self.action_detail(action, source)
        return message

    def action_detail(self, action: MPIAction, source: ActionSource = ActionSource.USER) -> tuple[Message, str]:
        """mpiMotionAction, with why in words."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, "invalid motion handle"
        handler = self._handlers.get(action)
        if handler is None:
            return Message.MPIMessagePARAM_INVALID, f"unknown action {action!r}"
        self._notify_action(self.current.type if self.current else MPIMotionType.INVALID, MPIAction(action).name)
        if not self.axis_list and not self.mapped:
            return Message.MEIMotionMessageNO_AXES_MAPPED, "no axes mapped to the motion supervisor"
        if action in _SHARED:
            return self._on_shared_axes(action, handler, source)
        return handler(source)

    def _sharing(self) -> list:
        """Other supervisors whose motion runs on one of this supervisor's mapped axes."""
        others = []
        for axis in self.axes:
            other = self._ctl.supervisor(axis.owner) if axis.owner not in (-1, self.number) else None
            if other is not None and other not in others and other.own_state is not MPIState.IDLE:
                others.append(other)
        return others

    def _on_shared_axes(self, action: MPIAction, handler, source: ActionSource) -> tuple[Message, str]:
        """STOP, RESUME, E_STOP, ABORT, E_STOP_ABORT and RESET act on the whole motion that
        holds this supervisor's axes (docs/decisions.md, "Supervisors and axes"), with that
        motion's own decel times, so a vector another supervisor runs stays on its path: the
        action goes to that supervisor as well. The answer is OK if the action did something
        anywhere, else the message of the state that refused it."""
        others = self._sharing()
        if not others:
            return handler(source)
        forwarded = [other.action_detail(action, source)[0].ok for other in others]
        allowed = _OWN_STATES.get(action)
        if allowed is None or (self.own_state in allowed and self.own_state is not MPIState.IDLE):
            return handler(source)
        if any(forwarded):
            return OK, "acted on the motion of the supervisor sharing its axes"
        return self._refusal(self.state)

    @property
    def _handlers(self):
        return {
            MPIAction.STOP: self._stop,
            MPIAction.RESUME: self._resume,
            MPIAction.E_STOP: self._e_stop,
            MPIAction.ABORT: self._abort,
            MPIAction.E_STOP_ABORT: self._e_stop_abort,
            MPIAction.RESET: self._reset,
            MPIAction.MAP: self._map_action,
        }

    def _refuse(self, allowed: tuple[MPIState, ...], own: bool = False) -> tuple[Message, str] | None:
        """None if the action may go on, else the message of the state that refuses it.
        ``own``: decide by this supervisor's own state (its own motion), not the state it
        shows (which includes the motions of supervisors sharing its axes)."""
        state = self.state
        if (self.own_state if own else state) in allowed:
            return None
        return self._refusal(state)

    @staticmethod
    def _refusal(state: MPIState) -> tuple[Message, str]:
        """The message of ``state``, which refuses an action."""
        return STATE_MESSAGES[state.name], f"supervisor is {state.name}"

    def _stop(self, source: ActionSource) -> tuple[Message, str]:
        refused = self._refuse(_OWN_STATES[MPIAction.STOP], own=True)
        if refused:
            return refused
        t = self._ctl.time
        self._rebase(t)
        self.clock = self.clock.ramp_to(t, self.config.pause_feedrate, self.config.decel_time.stop)
        self._stop_end = t + self.config.decel_time.stop
        self._set_status_mode(StatusMode.STOP)
        self._set_state(MPIState.STOPPING, "STOP", source)
        self._emit(MPIEventType.STOP)
        return OK, ""

    def _resume(self, source: ActionSource) -> tuple[Message, str]:
        refused = self._refuse(_OWN_STATES[MPIAction.RESUME], own=True)
        if refused:
            return refused
        t = self._ctl.time
        self._rebase(t)
        self.clock = self.clock.ramp_to(t, self.config.normal_feedrate, self.config.decel_time.stop)
        self._stop_end = math.inf
        for axis in self.axes:
            if axis.owner == self.number:
                plan = axis.plan
                velocity = plan is not None and plan.is_velocity
                axis.status_mode = StatusMode.VELOCITY if velocity else StatusMode.POINT_TO_POINT
        self._set_state(MPIState.MOVING, "RESUME", source)
        self._emit(MPIEventType.RESUME)
        return OK, ""

    def _e_stop(self, source: ActionSource, then_abort: bool = False, reason: str = "") -> tuple[Message, str]:
        self._map_if_unmapped()
        t = self._ctl.time
        if self.own_state is MPIState.ERROR:
            if then_abort and not self._aborted:
                self._disable_amps(t)
            return OK, "already in ERROR"
        if self.own_state is MPIState.STOPPING_ERROR:
            self._abort_after_stop |= then_abort
            return OK, "already stopping on error"
        self._rebase(t)
        e_stop = self.config.decel_time.e_stop
        self.clock = self.clock.ramp_to(t, 0.0, e_stop)
        self._stop_end = t + e_stop
        self._abort_after_stop = then_abort
        self._claim_axes()
        for axis in self._own_axes():
            axis.status_mode = StatusMode.E_STOP
            if axis.in_position.settle_on_estop_cmd_eq_act and axis.amp_enabled:
                axis.follow_actual(t, self.clock)
        self._set_state(MPIState.STOPPING_ERROR, "E_STOP_ABORT" if then_abort else "E_STOP", source)
        self._emit(MPIEventType.E_STOP, detail=reason)
        return OK, ""

    def _e_stop_abort(self, source: ActionSource) -> tuple[Message, str]:
        return self._e_stop(source, then_abort=True)

    def _abort(self, source: ActionSource) -> tuple[Message, str]:
        self._map_if_unmapped()
        t = self._ctl.time
        self._claim_axes()
        self._rebase(t)
        self._disable_amps(t)
        if self.own_state is not MPIState.ERROR:
            self._set_state(MPIState.STOPPING_ERROR, "ABORT", source)
            self._error_at = self._ctl.sample + 1
        self._emit(MPIEventType.ABORT)
        return OK, ""

    def _disable_amps(self, t: float) -> None:
        self._aborted = True
        for axis in self._own_axes():
            axis.disable(t, self._clock_of(axis))
            axis.status_mode = StatusMode.ABORT

    def _claim_axes(self) -> None:
        """A safety action takes over the mapped axes that no motion runs (their last
        commander is IDLE or in ERROR, or none). An axis another supervisor's motion runs
        stays with it: the action went to that supervisor (:meth:`_on_shared_axes`)."""
        t = self._ctl.time
        for axis in self.axes:
            if axis.owner != self.number and axis.plan is None and not axis.holding:
                other = self._ctl.supervisor(axis.owner) if axis.owner >= 0 else None
                if other is None or other.own_state in (MPIState.IDLE, MPIState.ERROR):
                    axis.rebase(t, self._clock_of(axis))
                    axis.owner = self.number

    def _own_axes(self) -> list:
        """The mapped axes this supervisor commands (or that no one commands)."""
        return [axis for axis in self.axes if axis.owner in (self.number, -1)]

    def _reset(self, source: ActionSource) -> tuple[Message, str]:
        state = self.state
        faults = self._ctl.faults
        if state is MPIState.IDLE and not faults.latched_on(self.mapped):
            self._map()
            return OK, "already IDLE"
        refused = self._refuse((MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR))
        if refused:
            return refused
        persisting = faults.persisting(self.mapped)
        if persisting:  # docs/faults.md: a fault is cleared by RESET once its condition is gone
            return Message.MPIMotionMessageERROR, "RESET refused: " + "; ".join(persisting) + ": clear it first"
        amp_faulted = faults.clear(self.mapped)
        t = self._ctl.time
        self._rebase(t)
        self._drop_pending(STATE_MESSAGES[state.name], f"dropped by RESET in {state.name}")
        for axis in self.axes:
            if axis.owner == self.number or axis.owner == -1:
                axis.unload(t, self._clock_of(axis))
                if not axis.amp_enabled or axis.mode is CommandMode.FOLLOW_ACTUAL:
                    # after an ABORT or an amplifier fault the motor coasted: the command is set to the actual
                    axis.enable(t, command_equals_actual=self._aborted or axis.mode is CommandMode.FOLLOW_ACTUAL
                                or axis.number in amp_faulted)
                axis.status_mode = StatusMode.POINT_TO_POINT
                axis.target = axis.rest
        self.clock = self.clock.ramp_to(t, self.config.normal_feedrate, 0.0)
        self._stop_end = math.inf
        self._aborted = False
        self._error_at = None
        self._abort_after_stop = False
        self._map()
        self._set_state(MPIState.IDLE, "RESET", source)
        self._emit(MPIEventType.RESET)
        return OK, ""

    def _map_action(self, source: ActionSource) -> tuple[Message, str]:
        refused = self._refuse((MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR))
        if refused:
            return refused
        if not self.axis_list:
            return Message.MEIMotionMessageNO_AXES_MAPPED, "the axis list is empty"
        message = self._map()
        if not message.ok:
            return message, "an axis that leaves the mapping still moves (pauseFeedrate); RESET first"
        return OK, ""

    def _map_if_unmapped(self) -> None:
        if not self.mapped:
            self._map()

    def _set_status_mode(self, mode: StatusMode) -> None:
        for axis in self.axes:
            if axis.owner == self.number:
                axis.status_mode = mode

