"""MotionSupervisor: the Motion object of MPI 000 (mpiMotion*).

Every call that can be refused answers an :class:`Outcome` (the reference's message and why,
decided where it is refused); a getter answers a :class:`Message` and the value the C API
writes. A refused call changes nothing. State transitions follow
MPI 000 and docs/state-machine.md; the controller calls :meth:`scan`/:meth:`transition`
while it steps so motion-driven transitions (DONE, stop complete, hold release) happen at
the exact sample their condition is met.

The supervisor is a facade over collaborators, each owning one concept and given what it
needs: the axis list (axis_list.py), its moves (moves.py), its actions
(actions.py) and its transitions (stepping.py), sharing the
supervisor's state (state.py) and reaching the controller only through
SupervisorHost (host.py). Starting and modifying moves (planning them) is here.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from mpi_ros.mpi.axes.axis import Axis
from mpi_ros.mpi.axes.status import StretchStatus
from mpi_ros.mpi.axes.stretch import Stretch
from mpi_ros.mpi.base.clock import ProfileClock
from mpi_ros.mpi.base.events import EventNotify, MPIEventType
from mpi_ros.mpi.base.messages import STATE_MESSAGES, Message
from mpi_ros.mpi.base.outcome import VALID, MoveEnd, Outcome, Refused
from mpi_ros.mpi.base.params import AxisMaster, MotionConfig, MotionParams, check_position, first_refusal
from mpi_ros.mpi.base.snapshot import AxisSnapshot, FrameBufferStatus, MotionSnapshot
from mpi_ros.mpi.base.types import (
    HOLD_ATTRS,
    ActionSource,
    MotionAttr,
    MPIAction,
    MPIMotionType,
    MPIState,
)
from mpi_ros.mpi.host import SupervisorHost
from mpi_ros.mpi.planning import blend, cams, paths, validate
from mpi_ros.mpi.planning.families import FAMILIES, Kind
from mpi_ros.mpi.planning.frames import AxisPlan, Move
from mpi_ros.mpi.planning.planner import PlanNotes, compile_move
from mpi_ros.mpi.planning.start import AxisStart
from mpi_ros.mpi.supervisor.actions import Actions
from mpi_ros.mpi.supervisor.axis_list import AxisList
from mpi_ros.mpi.supervisor.log import MotionLog
from mpi_ros.mpi.supervisor.moves import Moves
from mpi_ros.mpi.supervisor.state import SupervisorState
from mpi_ros.mpi.supervisor.status import AxisSnapshots, MotionTemplate
from mpi_ros.mpi.supervisor.stepping import Transitions

OK = Message.MPIMessageOK
HANDLE_INVALID = Outcome(Message.MPIMessageHANDLE_INVALID, "motion: invalid handle (the supervisor was deleted)")
NO_AXES = Outcome(Message.MPIMotionMessageAXIS_COUNT, "the motion supervisor has no axes")
# Attributes that belong to a start, not to the on-the-fly modify of mpiMotionParamsSet.
# Bits read on every start and modify, as plain ints (an IntFlag's ``in`` is a Python call).
_APPEND, _AUTO_START, _DELAY = int(MotionAttr.APPEND), int(MotionAttr.AUTO_START), int(MotionAttr.DELAY)
_NO_WAIT, _NO_HANDSHAKE = int(MotionAttr.NO_WAIT), int(MotionAttr.NO_HANDSHAKE)
_START_ONLY = (MotionAttr.APPEND | MotionAttr.AUTO_START | MotionAttr.DELAY | MotionAttr.HOLD
               | MotionAttr.HOLD_LESS | MotionAttr.HOLD_GREATER)
# meiMotionActionFunction: called with (motion, motion type, action name) on every
# start ("START"), modify ("MODIFY") and action ("STOP", "E_STOP", ...).
ActionCallback = Callable[["MotionSupervisor", MPIMotionType, str], object]


@dataclass(slots=True)
class _Admitted:
    """How a start or modify was admitted: the state it found, whether a modify from IDLE
    starts (AUTO_START), whether it queues behind what runs or is pending (APPEND), and the
    open path it adds points to, if any."""

    state: MPIState
    auto_start: bool
    queued: bool
    open_path: Move | None


class MotionSupervisor:
    def __init__(self, host: SupervisorHost, number: int, config: MotionConfig):
        self._host = host
        self.number = number
        self.valid = True
        t = host.time
        self._state = SupervisorState(number, config.copy(),
                                      ProfileClock(t, t, config.normal_feedrate, config.normal_feedrate, t),
                                      host.clock_changed)
        self._axis_list = AxisList(host.axes, host.config)
        self._moves = Moves(host, self._state, self._axis_list)
        self._actions = Actions(host, self._state, self._moves, self._axis_list)
        self._transitions = Transitions(host, self._state, self._moves, self._actions)
        self.stored_params = MotionParams()
        self.stored_type = MPIMotionType.INVALID
        self.events = EventNotify(host.config.event_notify)  # (the Axis object has one too)
        self.log: MotionLog | None = None
        self.action_callback: ActionCallback | None = None

    # ================================================================= queries ====
    @property
    def notify_mask(self) -> MPIEventType:
        return self.events.mask

    @property
    def latched(self) -> MPIEventType:
        return self.events.latched

    @latched.setter
    def latched(self, latched: MPIEventType) -> None:
        self.events.latched = latched

    @property
    def config(self) -> MotionConfig:
        return self._state.config

    @property
    def clock(self) -> ProfileClock:
        """The feedrate clock this supervisor's axes read their plans through (clock.py)."""
        return self._state.clock

    @property
    def own_state(self) -> MPIState:
        """This supervisor's own state (without the motions of others on its axes)."""
        return self._state.own_state

    @property
    def last_action(self) -> str:
        return self._state.last_action

    @property
    def action_source(self) -> ActionSource:
        return self._state.action_source

    @property
    def axis_list(self) -> list[int]:
        """The axis list as the host holds it (a copy: change it with the axis calls)."""
        return list(self._axis_list.listed)

    @property
    def frame_buffer_size(self) -> int:
        """The frame buffer size of the supervisor's axes (they all have the same: AXIS_FRAME_COUNT)."""
        return self._axis_list.frame_buffer_size

    @property
    def mapped(self) -> list[int]:
        """The axes mapped to the supervisor (MEIActionMAP)."""
        return list(self._axis_list.mapped)

    @property
    def current(self) -> Move | None:
        """The move in progress."""
        return self._moves.current

    @property
    def queue(self) -> tuple[Move, ...]:
        """The moves appended behind it."""
        return tuple(self._moves.queue)

    @property
    def last_move(self) -> Move | None:
        """The last move that ran (the current one while one runs)."""
        return self._moves.last_move

    def move(self, serial: int) -> Move | None:
        """The current or queued move with ``serial``."""
        return self._moves.find(serial)

    def pending_serials(self) -> set[int]:
        """The serials of the current and queued moves (and of the points appended to them)."""
        return self._moves.pending_serials()

    def end_now(self, serial: int) -> MoveEnd | None:
        """How move ``serial`` stands ended now without an end of its own (moves.Moves.end_now)."""
        return self._moves.end_now(serial)

    def frames_queued(self, axis: int) -> int:
        """Frames axis ``axis`` holds for this supervisor beyond the plan it runs."""
        return self._moves.frames_queued(axis)

    def cruising(self) -> bool:
        """A FINAL_VEL move has reached its target and the axes go on at its final velocity."""
        return self._moves.cruising()

    def progress(self) -> float:
        """0..1 along the current move (profile time over its duration)."""
        return self._moves.progress()

    @property
    def element_id(self) -> int:
        """The element id status shows: the current (else last) move's; a path's, of the
        point it runs toward."""
        return self._moves.element_id(self._moves.current or self._moves.last_move)

    # ================================================================= handles ====
    def validate(self) -> Outcome:
        """mpiMotionValidate."""
        return VALID if self.valid else HANDLE_INVALID

    def _axis(self, number: int) -> Axis:
        return self._host.axes[number]

    @property
    def axes(self) -> list[Axis]:
        """The mapped axes."""
        return self._moves.axes

    # ================================================================= state ====
    @property
    def state(self) -> MPIState:
        """The most severe of this supervisor's state and the states of the supervisors
        commanding its axes (MPI 000: status is derived from each axis' status)."""
        return self._moves.shown_state()

    def _state_refusal(self) -> Outcome:
        """The answer of a call the state refuses: the message of the state shown."""
        state = self.state
        return Outcome(STATE_MESSAGES[state.name], f"state: supervisor {self.number} is {state.name}")

    # ================================================================= axis list ====
    def axis_append(self, number: int) -> Outcome:
        """mpiMotionAxisAppend."""
        return self._axis_list.append(number) if self.valid else HANDLE_INVALID

    def axis_insert(self, after: int | None, number: int) -> Outcome:
        """mpiMotionAxisInsert: insert ``number`` just after axis ``after`` (None: first)."""
        return self._axis_list.insert(after, number) if self.valid else HANDLE_INVALID

    def axis_remove(self, number: int) -> Outcome:
        """mpiMotionAxisRemove."""
        if not self.valid:
            return HANDLE_INVALID
        return self._axis_list.remove(number, self._state.own_state, self._state_refusal())

    def axis_list_set(self, numbers: list[int]) -> Outcome:
        """mpiMotionAxisListSet: the coordinate system is completely replaced."""
        if not self.valid:
            return HANDLE_INVALID
        return self._axis_list.set(numbers, self._state.own_state, self._state_refusal())

    def axis_list_get(self) -> tuple[Message, list[int]]:
        return (OK, self.axis_list) if self.valid else (Message.MPIMessageHANDLE_INVALID, [])

    def axis_count(self) -> int:
        """mpiMotionAxisCount: -1 if the handle is invalid."""
        return len(self._axis_list.listed) if self.valid else -1

    def axis_index(self, number: int) -> int:
        """mpiMotionAxisIndex: -1 if invalid or not on the list."""
        return self._axis_list.index(number) if self.valid else -1

    def axis_at(self, index: int) -> tuple[Message, int | None]:
        """mpiMotionAxis: the axis at ``index`` (None = MPIHandleVOID)."""
        return self._axis_list.at(index) if self.valid else (Message.MPIMessageHANDLE_INVALID, None)

    def axis_first(self) -> tuple[Message, int | None]:
        return self.axis_at(0) if self._axis_list.listed or not self.valid else (OK, None)

    def axis_last(self) -> tuple[Message, int | None]:
        listed = self._axis_list.listed
        return self.axis_at(len(listed) - 1) if listed or not self.valid else (OK, None)

    def axis_next(self, number: int) -> tuple[Message, int | None]:
        return self._axis_list.neighbour(number, +1) if self.valid else (Message.MPIMessageHANDLE_INVALID, None)

    def axis_previous(self, number: int) -> tuple[Message, int | None]:
        return self._axis_list.neighbour(number, -1) if self.valid else (Message.MPIMessageHANDLE_INVALID, None)

    # ================================================================= actions ====
    def action(self, action: MPIAction, source: ActionSource = ActionSource.USER) -> Outcome:
        """mpiMotionAction."""
        if not self.valid:
            return HANDLE_INVALID
        if not self._actions.knows(action):
            return Outcome(Message.MPIMessagePARAM_INVALID, f"unknown action {action!r}")
        current = self._moves.current
        self._notify_action(current.type if current else MPIMotionType.INVALID, MPIAction(action).name)
        return self._actions.act(action, source)

    def e_stop(self, source: ActionSource, reason: str) -> Outcome:
        """E_STOP with a reason in its event (the controller's own: a fault, a lost client)."""
        return self._actions.e_stop(source, reason=reason)

    # ================================================================= stepping ====
    def scan(self, stretch: Stretch, status: StretchStatus) -> int | None:
        """The first sample of ``stretch`` at which a transition of this supervisor happens."""
        return self._transitions.scan(stretch, status)

    def transition(self, index: int, samples: np.ndarray) -> None:
        """Apply what :meth:`scan` found at stretch sample ``index`` (the controller is there)."""
        self._transitions.transition(index, samples)

    def release_holds(self) -> None:
        """Release holds whose trigger is true now (after a gate or I/O change)."""
        self._moves.release_holds()

    # ================================================================= config ====
    def config_get(self) -> tuple[Message, MotionConfig]:
        config = self._state.config.copy()
        config.axis_numbers = list(self._axis_list.mapped)
        return (OK if self.valid else Message.MPIMessageHANDLE_INVALID), config

    def config_set(self, config: MotionConfig) -> Outcome:
        """mpiMotionConfigSet; a new normal feedrate applies on the fly (ramped over the
        stop time while moving)."""
        if not self.valid:
            return HANDLE_INVALID
        if not self._axis_list.listed:  # MPI 000 MPIMotionMessageAXIS_COUNT: "from mpiMotionConfigSet ... no axes"
            return NO_AXES
        verdict = config.validate()  # the one MotionConfig validator (params.py): YAML and services too
        if not verdict.ok:
            return verdict
        old_normal = self._state.config.normal_feedrate
        kept_axes = self._state.config.axis_numbers
        self._state.config = config.copy()
        self._state.config.axis_numbers = kept_axes
        if config.normal_feedrate != old_normal and self._state.own_state is MPIState.MOVING:
            t = self._host.time
            self._moves.rebase(t)
            self._state.clock = self._state.clock.ramp_to(t, config.normal_feedrate, config.decel_time.stop)
        elif self._state.own_state is MPIState.IDLE:
            t = self._host.time
            self._moves.rebase(t)
            self._state.clock = self._state.clock.ramp_to(t, config.normal_feedrate, 0.0)
        return VALID

    # ================================================================= params ====
    def params_get(self) -> tuple[Message, MotionParams]:
        """mpiMotionParamsGet: the parameters a start with null params uses."""
        return (OK if self.valid else Message.MPIMessageHANDLE_INVALID), self.stored_params.copy()

    def params_set(self, params: MotionParams) -> Outcome:
        """mpiMotionParamsSet. While a motion runs the parameters apply "on-the-fly" (MPI 000,
        mpiMotionParamsSet): a modify of the running move's type with its attributes (less
        those that only make sense at a start), refused as that modify would be, in which
        case nothing is stored either."""
        if not self.valid:
            return HANDLE_INVALID
        verdict = params.validate()  # stored for any later start: every value must be one it can hold
        if not verdict.ok:
            return verdict
        current = self._moves.current
        if self._state.own_state is MPIState.MOVING and current is not None:
            outcome = self._command(current.type, current.attributes & ~_START_ONLY, params, modify=True)
            if not outcome.ok:
                return outcome
        self.stored_params = params.copy()
        return VALID

    # ================================================================= positions ====
    def position_get(self) -> tuple[Message, list[float], list[float]]:
        """mpiMotionPositionGet: (actual, command), one value per axis."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, [], []
        axes = self._list_axes()
        return OK, [a.actual_position for a in axes], [a.command_position for a in axes]

    def position_set(self, actual: list[float], command: list[float]) -> Outcome:
        """mpiMotionPositionSet: both arrays one value per axis; each command position is set
        under the rule of mpiAxisCommandPositionSet (Axis.can_set_command), all or none."""
        if not self.valid:
            return HANDLE_INVALID
        axes = self._list_axes()
        if not axes:
            return NO_AXES
        verdict = first_refusal(self._check_positions(name, values, len(axes))
                                for name, values in (("actual", actual), ("command", command)))
        if not verdict.ok:
            return verdict
        # an axis is in the state of the supervisor commanding it (IDLE without one)
        states = [_or_idle(self._host.own_state_of(a.owner)) for a in axes]
        refused = [(a.number, s.name) for a, s in zip(axes, states, strict=True) if not a.can_set_command(s)]
        if refused:
            return Outcome(Message.MPIAxisMessageCOMMAND_NOT_SET,
                           f"command: axis {refused[0][0]} cannot take a command position while {refused[0][1]}")
        t = self._host.time
        for axis, act, cmd in zip(axes, actual, command, strict=True):
            axis.set_actual_position(act, t)
            axis.set_command_position(cmd, t)
        return VALID

    @staticmethod
    def _check_positions(name: str, values: list[float], count: int) -> Outcome:
        """One position per axis, each in range (params.check_position)."""
        if len(values) != count:
            return Outcome(Message.MPIMessagePARAM_INVALID, f"{name}: {len(values)} values for {count} axes")
        return first_refusal(check_position(f"{name}[{i}]", x) for i, x in enumerate(values))

    def _list_axes(self) -> list[Axis]:
        return [self._axis(n) for n in self._axis_list.listed]

    def trajectory(self) -> tuple[Message, list[tuple[float, float]]]:
        """mpiMotionTrajectory: (velocity, acceleration) per axis; deceleration,
        jerkPercent and the jerks cannot be read and are zero."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, []
        return OK, [(a.cmd_v, a.cmd_a) for a in self._list_axes()]

    # ================================================================= events ====
    def event_notify_get(self) -> tuple[Message, MPIEventType]:
        return (OK if self.valid else Message.MPIMessageHANDLE_INVALID), self.notify_mask

    def event_notify_set(self, mask: MPIEventType) -> Outcome:
        """mpiMotionEventNotifySet (also maps the axes, MPI 002 NOT_MAPPED_TO_MS)."""
        if not self.valid:
            return HANDLE_INVALID
        if self._state.own_state in (MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR):
            remapped = self._moves.remap()
            if not remapped.ok:
                return remapped
        self.events.notify_set(mask)
        return VALID

    def event_reset(self, mask: MPIEventType) -> Outcome:
        """mpiMotionEventReset: clear latched events."""
        if not self.valid:
            return HANDLE_INVALID
        self.events.reset(mask)
        return VALID

    def frame_buffer_status(self) -> tuple[Message, list[FrameBufferStatus]]:
        """meiMotionFrameBufferStatus for each mapped axis."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, []
        size = self._host.config.frame_buffer_size_of
        return OK, [FrameBufferStatus(a.number, size(a.number), self._host.frame_count(a.number)) for a in self.axes]

    # ================================================================= log ====
    def log_open(self, max_entries: int) -> Outcome:
        """meiMotionLogOpen."""
        if not self.valid:
            return HANDLE_INVALID
        if max_entries <= 0:
            return Outcome(Message.MPIMessagePARAM_INVALID, f"max_entries: must be > 0, got {max_entries}")
        self.log = MotionLog(max_entries)
        return VALID

    def log_print(self, filename: str) -> Outcome:
        """meiMotionLogPrint."""
        if self.log is None:
            return Outcome(Message.MPIMessageHANDLE_INVALID, "log: no log open (meiMotionLogOpen first)")
        return self.log.write(filename, self._axis_list.mapped)

    def log_close(self) -> Outcome:
        """meiMotionLogClose."""
        self.log = None
        return VALID

    def action_function(self, callback: ActionCallback | None) -> ActionCallback | None:
        """meiMotionActionFunction: returns the previous callback."""
        previous, self.action_callback = self.action_callback, callback
        return previous

    def _notify_action(self, motion_type: MPIMotionType, action: str) -> None:
        if self.action_callback is not None:
            self.action_callback(self, motion_type, action)

    # ================================================================= start/modify ====
    def start(self, motion_type: MPIMotionType, attrs: MotionAttr = MotionAttr.NONE,
              params: MotionParams | None = None) -> Outcome:
        """mpiMotionStart (params None: the parameters stored with params_set)."""
        return self.command(motion_type, attrs, params, modify=False)[0]

    def modify(self, motion_type: MPIMotionType, attrs: MotionAttr = MotionAttr.NONE,
               params: MotionParams | None = None) -> Outcome:
        """mpiMotionModify."""
        return self.command(motion_type, attrs, params, modify=True)[0]

    def command(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams | None,
                modify: bool) -> tuple[Outcome, int]:
        """Start or modify; returns the outcome and the serial of the move it made or changed."""
        bits = int(attrs)
        if bits & _NO_WAIT:
            # nothing to follow: the call did not wait for the move
            return self._command_no_wait(motion_type, attrs, params, modify), 0
        outcome = self._command(motion_type, attrs, params, modify)
        if outcome.ok and bits & (_NO_HANDSHAKE | _NO_WAIT):
            self._state.unacknowledged = self._host.sample  # status reads IDLE until the next sample
        current = self._moves.current
        serial = current.serial if current is not None else 0
        if outcome.message in (OK, Message.MPIMotionMessageAUTO_START) and bits & _APPEND:
            if self._moves.queue:
                serial = self._moves.queue[-1].serial
            elif current is not None and current.stream is not None and current.stream.chunks:
                serial = current.stream.chunks[-1][0]  # the points just appended to the open path
        return outcome, serial

    def _command(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams | None,
                 modify: bool) -> Outcome:
        """A start or modify, in five steps, each of which may refuse it (nothing changes then):
        admit (handle, axes, type, state), check (the request against what runs), plan,
        fit (the frame buffer, the mapping), commit."""
        if params is None:
            params = self.stored_params
        admitted = self._admit(motion_type, attrs, modify)
        if isinstance(admitted, Outcome):
            return admitted
        verdict = self._check(motion_type, attrs, params, modify, admitted)
        if not verdict.ok:
            return verdict
        if admitted.open_path is not None:
            return self._append_points(admitted.open_path, motion_type, attrs, params)
        planned = self._plan(motion_type, attrs, params, modify, admitted)
        if isinstance(planned, Outcome):
            return planned
        move, notes = planned
        verdict = self._fit(move, admitted.queued)
        if not verdict.ok:
            return verdict
        return self._commit(move, notes, params, modify, admitted)

    def _admit(self, motion_type: MPIMotionType, attrs: MotionAttr, modify: bool) -> Outcome | _Admitted:
        """May this supervisor take a start or modify of this type now, and how (behind what
        runs, into an open path, as an AUTO_START)?"""
        if not self.valid:
            return HANDLE_INVALID
        self._notify_action(motion_type, "MODIFY" if modify else "START")
        if not self._axis_list.listed:
            return NO_AXES
        axes = self._host.axes
        for n in self._axis_list.listed:
            if not axes[n].enabled:  # MPI 000, MPIMessageOBJECT_NOT_ENABLED: "axis is not an enabled axis"
                return Outcome(Message.MPIMessageOBJECT_NOT_ENABLED,
                               f"axis {n} is not enabled (its amplifier is off): enable it first")
        bits = int(attrs)
        append = bool(bits & _APPEND)
        verdict = validate.check_type(motion_type, modify, self._host.config.firmware_option_21, append=append)
        if not verdict.ok:
            return verdict
        held = self._moves.held_by_others(self._axis_list.listed)
        state = self._moves.state_with(held)
        if held:
            # A start or modify would take the axis out of the other supervisor's vector (its
            # motion, running or stopped, keeps it until it ends or is RESET): answered with the
            # state the axes show (docs/decisions.md, "Supervisors and axes": a supervisor's state
            # includes its axes' commanders).
            axis, other, other_state = held[0]
            return Outcome(STATE_MESSAGES[state.name], (f"axis {axis} is in the {other_state.name} motion of "
                                                        f"supervisor {other}: command it there, or RESET it"))
        auto_start = False
        if modify:
            if state is MPIState.IDLE:
                if not bits & _AUTO_START:
                    return Outcome(Message.MPIMotionMessageIDLE, "no motion in progress to modify")
                auto_start = True
            elif state is not MPIState.MOVING:
                return Outcome(STATE_MESSAGES[state.name], f"supervisor is {state.name}")
        elif state not in (MPIState.IDLE, MPIState.STOPPED) and not (append and state is MPIState.MOVING):
            return Outcome(STATE_MESSAGES[state.name], f"supervisor is {state.name}")
        # MPI 000, MPIMotionAttrAPPEND: the profile is "added to the end of a previous motion
        # profile"; STOPPED keeps the rest of its profile pending (RESUME continues it), so an
        # APPEND given while STOPPED queues behind it like one given while MOVING.
        behind = append and (state is MPIState.MOVING
                             or (state is MPIState.STOPPED and self._moves.current is not None))
        # APPEND queues behind the move in progress or pending; from STOPPED a start without it
        # drops what is pending (docs/state-machine.md), and behind a move already cruising at its
        # final velocity there is nothing to wait for: the new move starts from where the axes are.
        queued = behind and (bool(self._moves.queue) or not self._moves.cruising())
        open_path = self._moves.open_path() if behind else None
        return _Admitted(state, auto_start, queued, open_path)

    def _check(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, modify: bool,
               admitted: _Admitted) -> Outcome:
        """The request itself, and against the motion it would join or replace."""
        # (the type is known here: _admit checked it, validate.check_type)
        if admitted.open_path is not None and not FAMILIES[motion_type].kind.streamed:
            return Outcome(Message.MPIMotionMessagePATH_ERROR, "the path in progress is open (final false): append "
                                                               "its points, or close it with final true, first")
        replaces = modify and not admitted.auto_start
        running = self._moves.current
        if replaces and not admitted.queued and admitted.open_path is None and running is not None:
            verdict = validate.check_running_type(running.type)
            if not verdict.ok:
                return verdict
        verdict = self._check_request(motion_type, attrs, params, modify, append_to=admitted.open_path is not None)
        if not verdict.ok or admitted.open_path is not None:
            return verdict
        if replaces and int(attrs) & _DELAY and any(d != 0.0 for d in params.delay):
            # MPI 000, MPIMotionMessageILLEGAL_DELAY: a modify with a non-zero delay "while in
            # motion" (the supervisor's motion, even while its axes wait out a DELAY).
            return Outcome(Message.MPIMotionMessageILLEGAL_DELAY, "a modify in motion cannot be delayed")
        return VALID

    def _plan(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, modify: bool,
              admitted: _Admitted) -> Outcome | tuple[Move, PlanNotes]:
        """The move, from where each axis' new profile starts."""
        starts = self._starts(admitted.queued, admitted.state, modify and not admitted.auto_start)
        try:
            # (a cam also needs each slave's master; other moves are planned from the starts alone)
            cams_of = (self._cam_masters(),) if FAMILIES[motion_type].kind is Kind.CAM else ()
            move, notes = compile_move(self.number, motion_type, attrs, params, starts, self._host.rate, *cams_of)
        except Refused as exc:
            return exc.outcome
        move.serial = self._host.next_serial()  # (a modify keeps the serial of the move it changes: Moves.replace)
        if move.stream is not None:
            move.stream.low_count = self._low_count(attrs, params)
        return move, notes

    def _fit(self, move: Move, queued: bool) -> Outcome:
        """Does the move fit the frame buffer (with what it queues behind), and is the mapping
        the axes need in place?"""
        if queued:
            current = [self._moves.current] if self._moves.current else []
            verdict = self._check_frames(list(self._moves.queue) + current + [move])
        else:
            verdict = self._check_frames([move])
        return verdict if not verdict.ok else self._moves.remap()

    def _commit(self, move: Move, notes: PlanNotes, params: MotionParams, modify: bool,
                admitted: _Admitted) -> Outcome:
        """The move runs, replaces the one running, or queues; its notes are reported."""
        for kind, detail in notes.events:
            self._moves.emit(kind, detail=detail, move=move)
        if admitted.queued:
            ahead = self._moves.queue[-1] if self._moves.queue else self._moves.current
            if ahead is not None:
                move.blend = blend.overlap(ahead, move, self._state.config.blend_limit)
            self._moves.queue.append(move)
        elif modify and not admitted.auto_start:
            self._moves.replace(move)
        else:
            self._moves.begin(move)
        if admitted.auto_start or not modify:
            # MPI 000, mpiMotionParamsGet: the parameters are set by mpiMotionParamsSet "or
            # mpiMotionStart", so a start's parameters are the ones a later get returns.
            self.stored_params = params.copy()
        if admitted.auto_start:
            return Outcome(Message.MPIMotionMessageAUTO_START, "modify started a new motion (AUTO_START)")
        return VALID

    def params_validate(self, motion_type: MPIMotionType, attrs: MotionAttr = MotionAttr.NONE,
                        params: MotionParams | None = None, modify: bool = False) -> tuple[Outcome, int]:
        """meiMotionParamsValidate (MPI 000): "validates the type-specific motion parameters
        [...] using the coordinate system of motion", and the number of points they specify
        (0 for a point-to-point move). The checks are a start's (a modify's, with ``modify``)
        own: the handle, the axis count, the type, the attributes and the values against the
        axes; whatever depends on the motion in progress (the state, a running type) is the
        start's alone. Nothing changes (params None: the stored parameters)."""
        if not self.valid:
            return Outcome(Message.MPIMessageHANDLE_INVALID, "invalid motion handle"), 0
        if not self._axis_list.listed:
            return Outcome(Message.MPIMotionMessageAXIS_COUNT, "the motion supervisor has no axes"), 0
        params = self.stored_params if params is None else params
        verdict = validate.check_type(motion_type, modify, self._host.config.firmware_option_21,
                                      append=MotionAttr.APPEND in attrs)
        if verdict.ok:
            verdict = self._check_request(motion_type, attrs, params, modify, append_to=False)
        kind = FAMILIES[motion_type].kind if motion_type in FAMILIES else None  # an unknown type: refused above
        if kind is Kind.CAM:
            points = len(params.master_distance)  # (MPIMotionCam: pointCount segments)
        elif kind in (Kind.PATH, Kind.FRAME):
            points = paths.point_count(motion_type, params, len(self._axis_list.listed))
        else:
            points = 0
        return verdict, points

    def _check_request(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, modify: bool,
                       append_to: bool) -> Outcome:
        """The attributes and values of a start or modify (validate.py)."""
        # MPI 000, mpiMotionModify: HOLD is impossible with a modify "even when using the AUTO_START attribute"
        verdict = validate.check_attributes(motion_type, attrs, params, modify)
        if not verdict.ok:
            return verdict
        return validate.check_params(
            motion_type, attrs, params, len(self._axis_list.listed), self._host.config.io_words,
            self._host.config.motors, len(self._host.axes), sample_rate=self._host.rate,
            append_to=append_to, frame_buffer_size=self._axis_list.frame_buffer_size)

    def _command_no_wait(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams | None,
                         modify: bool) -> Outcome:
        """MPI 001 NO_WAIT: the MPI "does NOT wait for the controller to acknowledge the commanded
        move, does NOT wait for the controller to return an error code". What the library checks
        itself (type, attributes, values) is still answered; whatever the controller would
        refuse (its state, a profile it cannot load) is not: the call answers OK and a refused
        move shows only as a missing MOTION_START, as MPI 001 warns."""
        if not self.valid or not self._axis_list.listed:
            return self._command(motion_type, attrs, params, modify)
        params = self.stored_params if params is None else params
        verdict = validate.check_type(motion_type, modify, self._host.config.firmware_option_21,
                                      append=MotionAttr.APPEND in attrs)
        if verdict.ok:
            append_to = (MotionAttr.APPEND in attrs and self._state.own_state in (MPIState.MOVING, MPIState.STOPPED)
                         and self._moves.open_path() is not None)
            verdict = self._check_request(motion_type, attrs, params, modify, append_to)
        if not verdict.ok:
            return verdict
        if self._command(motion_type, attrs, params, modify).ok:
            self._state.unacknowledged = self._host.sample  # status reads IDLE until the next sample
        return Outcome(OK, "NO_WAIT: sent without waiting for the controller; MOTION_START shows whether the "
                           "move began")

    def _starts(self, queued: bool, state: MPIState, moving: bool) -> list[AxisStart]:
        """Where the new profile of each axis starts."""
        starts = []
        last = self._moves.queue[-1] if self._moves.queue else self._moves.current
        # The feedrate the axes' velocities are read through (the same for all of them): a modify
        # in motion goes on at the feedrate now, a start runs at the normal one from now on
        f = self._state.clock.feedrate(self._host.time) if moving else self._state.config.normal_feedrate
        for n in self._axis_list.listed:
            axis = self._axis(n)
            plan = last.plan_for(n) if queued and last is not None else None
            if plan is not None:
                starts.append(AxisStart(n, plan.target, plan.final_velocity, axis.turn_origin(plan.target)))
                continue
            position, cmd_v, cmd_a = axis.command_values()
            if moving:
                velocity = cmd_v / f if f > 0.0 else 0.0
                acceleration = cmd_a / (f * f) if f > 0.0 else 0.0
            else:
                # The axis may still move (STOPPED at a non-zero pauseFeedrate, or past a FINAL_VEL
                # move): the start goes on from that velocity.
                velocity, acceleration = cmd_v / f, cmd_a / (f * f)
            starts.append(AxisStart(n, position, velocity, axis.turn_origin(position), acceleration))
        return starts

    def _cam_masters(self) -> list[tuple[AxisMaster, float, float]]:
        """Each slave axis' master (MPIAxisConfig.master), the master's position now and the
        origins it is read less (the cam keeps them: masters.Sources.frame), for a cam on the
        axis list. Raises Refused if the masters would form a loop."""
        masters = [self._axis(n).master for n in self._axis_list.listed]
        running = {axis.number: axis.cam_reads() for axis in self._host.axes if axis.camming}
        loop = cams.master_loop(self._axis_list.listed, masters, running)
        if loop:
            raise Refused(Message.MPIMessagePARAM_INVALID, f"{loop} (MPIAxisConfig.master): a slave cannot follow "
                                                             "itself, directly or through other cams")
        now = self._host.master_sources()
        return [(master, float(now.position(master)[0]), now.frame(master)) for master in masters]

    def _check_frames(self, moves: list[Move]) -> Outcome:
        """Do the moves fit the frame buffer? A path's points need not: the library holds
        what does not fit and loads it as the buffer drains (MPI 001, LOW_COUNT)."""
        size = self._host.config.frame_buffer_size_of
        needs: dict[int, int] = {}  # frames per axis, over the moves
        for move in moves:
            if move.stream is None:
                for plan in move.plans:
                    needs[plan.axis] = needs.get(plan.axis, 0) + plan.frame_count
        for n in self._axis_list.listed:
            needed = needs.get(n, 0)
            if needed > size(n):
                return Outcome(Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL,
                               f"the move does not fit in the frame buffer: axis {n} needs {needed} frames "
                               f"of {size(n)}")
        return VALID

    def _low_count(self, attrs: MotionAttr, params: MotionParams) -> int:
        """MPI 001 LOW_COUNT: the given count, else a quarter of the frame buffer (32 of 128)."""
        if MotionAttr.LOW_COUNT in attrs:
            return params.low_count
        return self._axis_list.frame_buffer_size // 4

    def _append_points(self, move: Move, motion_type: MPIMotionType, attrs: MotionAttr,
                       params: MotionParams) -> Outcome:
        """APPEND to an open path: the points follow its last point (or start now, if it ran
        out of points), planned like a path of their own from there (docs/paths.md). The
        append is recorded as a chunk of the path: a command whose outcome comes when its last
        point is reached."""
        stream = move.stream
        plans = {plan.axis: plan for plan in move.plans}
        if attrs & HOLD_ATTRS:
            # A hold waits before a move begins; appended points continue one in progress.
            return Outcome(Message.MPIMotionMessageATTRIBUTE_INVALID,
                           "points appended to a path in motion cannot be held")
        if stream is None or sorted(plans) != sorted(self._axis_list.listed):
            return Outcome(Message.MPIMessagePARAM_INVALID, "the points' axes are not the axes of the open path")
        t = self._host.time
        tau = self._state.clock.tau_at(t)
        # Profile time into the path per axis (an axis still held has run none of it).
        listed = self._axis_list.listed
        nows = {n: -math.inf if n in self._moves.holds else tau - self._axis(n).tau_start for n in listed}
        if paths.point_count(motion_type, params, len(self._axis_list.listed)) == 0:
            # No points: it only closes (or keeps open) the path, and is done with its last point
            # (an open B-spline then runs the rest of its curve: docs/paths.md).
            if params.final and all(plans[n].spline is not None for n in listed):
                self._moves.rebase(t)
                ends = {n: self._close_spline(move, plans[n], nows[n], t) for n in listed}
            else:
                ends = {n: paths.last_point_time(plans[n]) for n in listed}
            stream.append(None, open_=not params.final)
            stream.chunks.append((self._host.next_serial(), ends))
            return Outcome(OK)
        starts = [AxisStart(n, *paths.end_state(plans[n], nows[n]), self._axis(n).origin) for n in listed]
        try:
            chunk, notes = compile_move(self.number, motion_type, attrs, params, starts, self._host.rate)
        except Refused as exc:
            return exc.outcome
        for kind, detail in notes.events:
            self._moves.emit(kind, detail=detail, move=move)
        self._moves.rebase(t)
        ends = {new.axis: self._extend_plan(move, plans[new.axis], new, nows[new.axis], t, params.final)
                for new in chunk.plans}
        stream.append(chunk.stream, open_=not params.final)
        if MotionAttr.LOW_COUNT in attrs:
            stream.low_count = params.low_count
        stream.chunks.append((self._host.next_serial(), ends))
        return Outcome(OK)

    def _extend_plan(self, move: Move, old: AxisPlan, new: AxisPlan, now: float, t: float, final: bool) -> float:
        """Put ``new``'s points after ``old``'s on its axis (B-spline points: on its curve, as
        one request of all the points would make it); returns when its last one is reached."""
        outputs = [(0.0, out) for out in new.outputs] + new.timed_outputs
        axis = self._axis(new.axis)
        values = new.feedforward[1][1:] if new.feedforward is not None else None
        assert new.point_times is not None  # the plan of a path (paths.compile_path)
        spline = paths.continued_spline(old, new, now, final)
        segments, times, target = ((new.segments, new.point_times, new.target) if spline is None
                                   else (spline.segments, spline.point_times, spline.target))
        extended = paths.extend(old, now, segments, times, new.element_ids, outputs, target,
                                values, axis.feedforward, spline)
        return self._install(move, old, extended, t)

    def _close_spline(self, move: Move, old: AxisPlan, now: float, t: float) -> float:
        """An open B-spline path closed without points: the rest of its curve, to its last
        point (paths.closed_spline); returns when that point is reached."""
        spline = paths.closed_spline(old, now)
        assert spline is not None  # (only for B-spline plans)
        extended = paths.extend(old, now, spline.segments, spline.point_times, (), [], spline.target,
                                None, self._axis(old.axis).feedforward, spline)
        return self._install(move, old, extended, t)

    def _install(self, move: Move, old: AxisPlan, extended: AxisPlan, t: float) -> float:
        """``extended`` replaces ``old`` in the move and on its axis; returns when its last
        point is reached."""
        move.plans[move.plans.index(old)] = extended
        wait = self._moves.holds.get(old.axis)
        if wait is not None:
            wait.plan = extended  # still held: the path begins, whole, when the hold releases
        else:
            self._axis(old.axis).extend(extended, t, self._state.clock)
        return paths.last_point_time(extended)

    # ================================================================= status ====
    def snapshot(self, axis_snapshots: Sequence[AxisSnapshot] | None = None) -> MotionSnapshot:
        """mpiMotionStatus; ``axis_snapshots``: every axis' at this sample, when already taken
        (Controller.motion_snapshots), else its axes' are taken here."""
        mapped = self._axis_list.mapped
        axes: AxisSnapshots = (dict(zip(mapped, self._host.axis_snapshots(mapped), strict=True))
                               if axis_snapshots is None else axis_snapshots)
        return self.status_template().at(self._host.sample, axes, lambda n: self._axis(n).rel, self.latched_events())

    def latched_events(self) -> tuple[str, ...]:
        """The names of the events latched now (what status shows)."""
        return tuple(self.latched.names())

    def status_template(self) -> MotionTemplate:
        """What this supervisor's mpiMotionStatus holds until its next discrete change
        (status.py): the snapshot of any sample up to then is built from it."""
        moves, state = self._moves, self._state
        move = moves.current or moves.last_move
        element_axis, element_id = moves.element_of(move)
        return MotionTemplate(
            number=self.number,
            state=self.state,
            own_moving=state.own_state is MPIState.MOVING,
            unacknowledged=state.unacknowledged,
            axis_numbers=tuple(self._axis_list.mapped),
            move_id=move.id if move else 0,
            element_axis=element_axis,
            element_id=element_id,
            motion_type=move.type.name if move else "",
            moves_pending=len(moves.queue),
            last_action=state.last_action,
            action_source=state.action_source.value,
            progress=moves.progress_of(),
            clock=state.clock,
            rate=self._host.rate,
        )



def _or_idle(state: MPIState | None) -> MPIState:
    """An axis is in the state of the supervisor commanding it, IDLE without one."""
    return MPIState.IDLE if state is None else state
