"""MotionSupervisor: the Motion object of spec 000 (mpiMotion*).

Every method answers a :class:`Message` (and a value where the C API writes one). A
refused call changes nothing. State transitions follow spec 000 and the table in
DESIGN.md; the controller calls :meth:`scan`/:meth:`transition` while it steps so
motion-driven transitions (DONE, stop complete, hold release) happen at the exact
sample their condition is met.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from . import cams, paths, validate
from .axis import Axis, CommandMode
from .clock import ProfileClock
from .events import MPIEventType
from .frames import AxisPlan, Move, frames_needed, next_serial
from .holds import HoldWait
from .log import MotionLog
from .messages import STATE_MESSAGES, Message
from .params import AxisMaster, MotionConfig, MotionParams, Output, Verdict, check_position
from .planner import AxisStart, PlanError, compile_move
from .snapshot import FrameBufferStatus, MotionSnapshot
from .status import StatusMode
from .supervisor_actions import ActionsMixin
from .supervisor_axis_list import AxisListMixin
from .supervisor_stepping import SteppingMixin
from .types import (
    CAM_TYPES,
    HOLD_ATTRS,
    STATE_SEVERITY,
    ActionSource,
    HoldType,
    IoSpace,
    MotionAttr,
    MPIMotionType,
    MPIState,
    OutputType,
)

if TYPE_CHECKING:
    from .control import Controller

OK = Message.MPIMessageOK
# Attributes that belong to a start, not to the on-the-fly modify of mpiMotionParamsSet.
_START_ONLY = (MotionAttr.APPEND | MotionAttr.AUTO_START | MotionAttr.DELAY | MotionAttr.HOLD
               | MotionAttr.HOLD_LESS | MotionAttr.HOLD_GREATER)
# meiMotionActionFunction: called with (motion, motion type, action name) on every
# start ("START"), modify ("MODIFY") and action ("STOP", "E_STOP", ...).
ActionCallback = Callable[["MotionSupervisor", MPIMotionType, str], object]


@dataclass(frozen=True, slots=True)
class MoveEnd:
    """An outcome of a move, with the supervisor's axis positions at its sample: how the move
    ended, or (a VELOCITY move) that it reached its velocity, which is what its goals wait for.
    A modify keeps the move's serial: an outcome before the modify's sample is not its own."""

    serial: int
    message: Message
    sample: int
    detail: str
    command_position: tuple[float, ...]
    actual_position: tuple[float, ...]


class MotionSupervisor(AxisListMixin, ActionsMixin, SteppingMixin):
    def __init__(self, controller: Controller, number: int, config: MotionConfig):
        self._ctl = controller
        self.number = number
        self.valid = True
        self.axis_list: list[int] = []
        self.mapped: list[int] = []
        self.config = config.copy()
        self.stored_params = MotionParams()
        self.stored_type = MPIMotionType.INVALID
        self.notify_mask = controller.config.event_notify
        self.latched = MPIEventType.NONE
        t = controller.time
        self.clock = ProfileClock(t, t, self.config.normal_feedrate, self.config.normal_feedrate, t)
        self.own_state = MPIState.IDLE
        self.last_action = "NONE"
        self.action_source = ActionSource.USER
        self.current: Move | None = None
        self.queue: deque[Move] = deque()
        self.last_move: Move | None = None
        self._stop_end = math.inf  # time at which the stop/e-stop ramp ends
        self._abort_after_stop = False
        self._error_at: int | None = None  # sample at which an ABORT completes
        self._aborted = False
        self._holds: dict[int, HoldWait] = {}
        self._conditions: dict = {}
        self._at_velocity_sent = False
        self.log: MotionLog | None = None
        self.action_callback: ActionCallback | None = None
        self.move_ends: list[MoveEnd] = []  # how each move ended, in order (drained by the owner)
        # NO_HANDSHAKE / NO_WAIT (MPI 001): the sample of a start not yet acknowledged, at
        # which status still reads IDLE ("until the controller begins the profile execution").
        self._unacknowledged: int | None = None

    @property
    def clock(self) -> ProfileClock:
        """The feedrate clock this supervisor's axes read their plans through (clock.py)."""
        return self._clock

    @clock.setter
    def clock(self, clock: ProfileClock) -> None:
        self._clock = clock
        self._ctl.bank.clock_changed(self.number, clock)

    # ================================================================= handles ====
    def validate(self) -> Message:
        """mpiMotionValidate."""
        return OK if self.valid else Message.MPIMessageHANDLE_INVALID

    def _axis(self, number: int) -> Axis:
        return self._ctl.axes[number]

    @property
    def axes(self) -> list[Axis]:
        return [self._axis(n) for n in self.mapped]

    # ================================================================= state ====
    @property
    def state(self) -> MPIState:
        """The most severe of this supervisor's state and the states of the supervisors
        commanding its axes (spec 000: status is derived from each axis' status)."""
        states = [self.own_state]
        for number in self.mapped:
            owner = self._axis(number).owner
            if owner not in (-1, self.number):
                other = self._ctl.supervisor(owner)
                if other is not None:
                    states.append(other.own_state)
        return max(states, key=STATE_SEVERITY.__getitem__)

    def _state_message(self) -> Message:
        return STATE_MESSAGES[self.state.name]

    def _set_state(self, state: MPIState, action: str, source: ActionSource) -> None:
        self.own_state = state
        self.last_action = action
        self.action_source = source

    # ================================================================= config ====
    def config_get(self) -> tuple[Message, MotionConfig]:
        config = self.config.copy()
        config.axis_numbers = list(self.mapped)
        return (OK if self.valid else Message.MPIMessageHANDLE_INVALID), config

    def config_set(self, config: MotionConfig) -> Message:
        """mpiMotionConfigSet; a new normal feedrate applies on the fly (ramped over the
        stop time while moving)."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        if not self.axis_list:  # spec 000 MPIMotionMessageAXIS_COUNT: "from mpiMotionConfigSet ... no axes"
            return Message.MPIMotionMessageAXIS_COUNT
        verdict = config.validate()  # the one MotionConfig validator (params.py): YAML and services too
        if not verdict.ok:
            return verdict.message
        old_normal = self.config.normal_feedrate
        kept_axes = self.config.axis_numbers
        self.config = config.copy()
        self.config.axis_numbers = kept_axes
        if config.normal_feedrate != old_normal and self.own_state is MPIState.MOVING:
            t = self._ctl.time
            self._rebase(t)
            self.clock = self.clock.ramp_to(t, config.normal_feedrate, config.decel_time.stop)
        elif self.own_state is MPIState.IDLE:
            t = self._ctl.time
            self._rebase(t)
            self.clock = self.clock.ramp_to(t, config.normal_feedrate, 0.0)
        return OK

    # ================================================================= params ====
    def params_get(self) -> tuple[Message, MotionParams]:
        """mpiMotionParamsGet: the parameters a start with null params uses."""
        return (OK if self.valid else Message.MPIMessageHANDLE_INVALID), self.stored_params.copy()

    def params_set(self, params: MotionParams) -> Message:
        """mpiMotionParamsSet. While a motion runs the parameters apply "on-the-fly" (MPI 000,
        mpiMotionParamsSet): a modify of the running move's type with its attributes (less
        those that only make sense at a start), refused as that modify would be, in which
        case nothing is stored either."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        if self.own_state is MPIState.MOVING and self.current is not None:
            message, _ = self._command(self.current.type, self.current.attributes & ~_START_ONLY, params,
                                       modify=True)
            if not message.ok:
                return message
        self.stored_params = params.copy()
        return OK

    # ================================================================= positions ====
    def position_get(self) -> tuple[Message, list[float], list[float]]:
        """mpiMotionPositionGet: (actual, command), one value per axis."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, [], []
        axes = self._list_axes()
        return OK, [a.actual_position for a in axes], [a.command_position for a in axes]

    def position_set(self, actual: list[float], command: list[float]) -> Message:
        """mpiMotionPositionSet: both arrays one value per axis; each command position is set
        under the rule of mpiAxisCommandPositionSet (Axis.can_set_command), all or none."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        axes = self._list_axes()
        if not axes:
            return Message.MPIMotionMessageAXIS_COUNT
        if len(actual) != len(axes) or len(command) != len(axes):
            return Message.MPIMessagePARAM_INVALID
        if not all(check_position("position", x).ok for x in list(actual) + list(command)):
            return Message.MPIMessagePARAM_INVALID
        # an axis is in the state of the supervisor commanding it (IDLE without one)
        owners = [self._ctl.supervisor(a.owner) for a in axes]
        states = [o.own_state if o is not None else MPIState.IDLE for o in owners]
        if not all(a.can_set_command(state) for a, state in zip(axes, states, strict=True)):
            return Message.MPIAxisMessageCOMMAND_NOT_SET
        t = self._ctl.time
        for axis, act, cmd in zip(axes, actual, command, strict=True):
            axis.set_actual_position(act, t)
            axis.set_command_position(cmd, t)
        return OK

    def _list_axes(self) -> list[Axis]:
        return [self._axis(n) for n in self.axis_list]

    def trajectory(self) -> tuple[Message, list[tuple[float, float]]]:
        """mpiMotionTrajectory: (velocity, acceleration) per axis; deceleration,
        jerkPercent and the jerks cannot be read and are zero."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, []
        return OK, [(a.cmd_v, a.cmd_a) for a in self._list_axes()]

    # ================================================================= events ====
    def event_notify_get(self) -> tuple[Message, MPIEventType]:
        return (OK if self.valid else Message.MPIMessageHANDLE_INVALID), self.notify_mask

    def event_notify_set(self, mask: MPIEventType) -> Message:
        """mpiMotionEventNotifySet (also maps the axes, spec 002 NOT_MAPPED_TO_MS)."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        if self.own_state in (MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR):
            message = self._map()
            if not message.ok:
                return message
        self.notify_mask = MPIEventType(mask)
        return OK

    def event_reset(self, mask: MPIEventType) -> Message:
        """mpiMotionEventReset: clear latched events."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        self.latched &= ~MPIEventType(mask)
        return OK

    def frame_buffer_status(self) -> tuple[Message, list[FrameBufferStatus]]:
        """meiMotionFrameBufferStatus for each mapped axis."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, []
        size = self._ctl.config.frame_buffer_size_of
        return OK, [FrameBufferStatus(a.number, size(a.number), self._ctl.frame_count(a.number)) for a in self.axes]

    # ================================================================= log ====
    def log_open(self, max_entries: int) -> Message:
        """meiMotionLogOpen."""
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID
        if max_entries <= 0:
            return Message.MPIMessagePARAM_INVALID
        self.log = MotionLog(max_entries)
        return OK

    def log_print(self, filename: str) -> Message:
        """meiMotionLogPrint."""
        if self.log is None:
            return Message.MPIMessageHANDLE_INVALID
        return self.log.write(filename, self.mapped)

    def log_close(self) -> Message:
        """meiMotionLogClose."""
        self.log = None
        return OK

    def action_function(self, callback: ActionCallback | None) -> ActionCallback | None:
        """meiMotionActionFunction: returns the previous callback."""
        previous, self.action_callback = self.action_callback, callback
        return previous

    def _notify_action(self, motion_type: MPIMotionType, action: str) -> None:
        if self.action_callback is not None:
            self.action_callback(self, motion_type, action)

    # ================================================================= start/modify ====
    def start(self, motion_type: MPIMotionType, attrs: MotionAttr = MotionAttr.NONE,
              params: MotionParams | None = None) -> Message:
        """mpiMotionStart (params None: the parameters stored with params_set)."""
        message, _, _ = self.command(motion_type, attrs, params, modify=False)
        return message

    def modify(self, motion_type: MPIMotionType, attrs: MotionAttr = MotionAttr.NONE,
               params: MotionParams | None = None) -> Message:
        """mpiMotionModify."""
        message, _, _ = self.command(motion_type, attrs, params, modify=True)
        return message

    def command(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams | None,
                modify: bool) -> tuple[Message, str, int]:
        """Start or modify; returns (message, detail, serial of the move it made or changed)."""
        if MotionAttr.NO_WAIT in attrs:
            message, detail = self._command_no_wait(motion_type, attrs, params, modify)
            return message, detail, 0  # nothing to follow: the call did not wait for the move
        message, detail = self._command(motion_type, attrs, params, modify)
        if message.ok and attrs & (MotionAttr.NO_HANDSHAKE | MotionAttr.NO_WAIT):
            self._unacknowledged = self._ctl.sample  # status reads IDLE until the next sample
        serial = self.current.serial if self.current is not None else 0
        if message in (OK, Message.MPIMotionMessageAUTO_START) and attrs & MotionAttr.APPEND:
            if self.queue:
                serial = self.queue[-1].serial
            elif self.current is not None and self.current.stream is not None and self.current.stream.chunks:
                serial = self.current.stream.chunks[-1][0]  # the points just appended to the open path
        return message, detail, serial

    def _command(self, motion_type, attrs, params, modify) -> tuple[Message, str]:
        if not self.valid:
            return Message.MPIMessageHANDLE_INVALID, "invalid motion handle"
        self._notify_action(motion_type, "MODIFY" if modify else "START")
        if params is None:
            params = self.stored_params
        if not self.axis_list:
            return Message.MPIMotionMessageAXIS_COUNT, "the motion supervisor has no axes"
        verdict = validate.check_type(motion_type, modify, self._ctl.config.firmware_option_21,
                                      append=MotionAttr.APPEND in attrs)
        if not verdict.ok:
            return verdict.message, verdict.detail
        state = self._state_for(self.axis_list)
        held = self._held_by_others(self.axis_list)
        if held:
            # A start or modify would take the axis out of the other supervisor's vector (its
            # motion, running or stopped, keeps it until it ends or is RESET): answered with the
            # state the axes show (DESIGN: a supervisor's state includes its axes' commanders).
            axis, other = held[0]
            return STATE_MESSAGES[state.name], (f"axis {axis} is in the {other.own_state.name} motion of "
                                                f"supervisor {other.number}: command it there, or RESET it")
        append = MotionAttr.APPEND in attrs
        auto_start = False
        if modify:
            if state is MPIState.IDLE:
                if MotionAttr.AUTO_START not in attrs:
                    return Message.MPIMotionMessageIDLE, "no motion in progress to modify"
                auto_start = True
            elif state is not MPIState.MOVING:
                return STATE_MESSAGES[state.name], f"supervisor is {state.name}"
        elif state not in (MPIState.IDLE, MPIState.STOPPED) and not (append and state is MPIState.MOVING):
            return STATE_MESSAGES[state.name], f"supervisor is {state.name}"
        open_path = self._open_path() if append and state is MPIState.MOVING else None
        if open_path is not None and motion_type not in paths.STREAMED_TYPES:
            return Message.MPIMotionMessagePATH_ERROR, ("the path in progress is open (final false): append its "
                                                        "points, or close it with final true, first")
        verdict = self._check_request(motion_type, attrs, params, modify, append_to=open_path is not None)
        if not verdict.ok:
            return verdict.message, verdict.detail
        if open_path is not None:
            return self._append_points(open_path, motion_type, attrs, params)
        if modify and not auto_start and MotionAttr.DELAY in attrs and any(d != 0.0 for d in params.delay):
            # MPI 000, MPIMotionMessageILLEGAL_DELAY: a modify with a non-zero delay "while in
            # motion" (the supervisor's motion, even while its axes wait out a DELAY).
            return Message.MPIMotionMessageILLEGAL_DELAY, "a modify in motion cannot be delayed"
        # APPEND queues behind the move in progress; from STOPPED a start drops what is pending
        # (docs/state-machine.md), and behind a move already cruising at its final velocity there
        # is nothing to wait for: the new move starts from where the axes are (a modify).
        queued = append and state is MPIState.MOVING and (bool(self.queue) or not self.cruising())
        starts = self._starts(queued, state, modify and not auto_start)
        try:
            # (a cam also needs each slave's master; other moves are planned from the starts alone)
            cams_of = (self._cam_masters(),) if motion_type in CAM_TYPES else ()
            move, notes = compile_move(self.number, motion_type, attrs, params, starts, self._ctl.rate, *cams_of)
        except PlanError as exc:
            return exc.message, exc.detail
        if move.stream is not None:
            move.stream.low_count = self._low_count(attrs, params)
        if queued:
            message = self._check_frames(list(self.queue) + ([self.current] if self.current else []) + [move])
        else:
            message = self._check_frames([move])
        if not message.ok:
            return message, "the move does not fit in the frame buffer"
        message = self._map()
        if not message.ok:
            return message, "an axis that leaves the mapping still moves (pauseFeedrate); RESET first"
        for kind, detail in notes.events:
            self._emit(kind, detail=detail, move=move)
        if queued:
            self.queue.append(move)
        elif modify and not auto_start:
            self._replace(move)
        else:
            self._begin(move)
        if auto_start or not modify:
            # MPI 000, mpiMotionParamsGet: the parameters are set by mpiMotionParamsSet "or
            # mpiMotionStart", so a start's parameters are the ones a later get returns.
            self.stored_params = params.copy()
        if auto_start:
            return Message.MPIMotionMessageAUTO_START, "modify started a new motion (AUTO_START)"
        return OK, ""

    def _check_request(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, modify: bool,
                       append_to: bool) -> Verdict:
        """The attributes and values of a start or modify (validate.py)."""
        # MPI 000, mpiMotionModify: HOLD is impossible with a modify "even when using the AUTO_START attribute"
        verdict = validate.check_attributes(motion_type, attrs, params, modify)
        if not verdict.ok:
            return verdict
        return validate.check_params(
            motion_type, attrs, params, len(self.axis_list), self._ctl.config.io_words,
            self._ctl.config.motors, len(self._ctl.axes), sample_rate=self._ctl.rate,
            append_to=append_to, frame_buffer_size=self.frame_buffer_size)

    def _command_no_wait(self, motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams | None,
                         modify: bool) -> tuple[Message, str]:
        """MPI 001 NO_WAIT: the MPI "does NOT wait for the controller to acknowledge the commanded
        move, does NOT wait for the controller to return an error code". What the library checks
        itself (type, attributes, values) is still answered; whatever the controller would
        refuse (its state, a profile it cannot load) is not: the call answers OK and a refused
        move shows only as a missing MOTION_START, as MPI 001 warns."""
        if not self.valid or not self.axis_list:
            return self._command(motion_type, attrs, params, modify)
        params = self.stored_params if params is None else params
        verdict = validate.check_type(motion_type, modify, self._ctl.config.firmware_option_21,
                                      append=MotionAttr.APPEND in attrs)
        if verdict.ok:
            append_to = (MotionAttr.APPEND in attrs and self.own_state is MPIState.MOVING
                         and self._open_path() is not None)
            verdict = self._check_request(motion_type, attrs, params, modify, append_to)
        if not verdict.ok:
            return verdict.message, verdict.detail
        message, _ = self._command(motion_type, attrs, params, modify)
        if message.ok:
            self._unacknowledged = self._ctl.sample  # status reads IDLE until the next sample
        return OK, "NO_WAIT: sent without waiting for the controller; MOTION_START shows whether the move began"

    def _state_for(self, numbers: list[int]) -> MPIState:
        """State as a command on ``numbers`` sees it (other supervisors' axes included)."""
        states = [self.own_state] + [other.own_state for _, other in self._held_by_others(numbers)]
        return max(states, key=STATE_SEVERITY.__getitem__)

    def _held_by_others(self, numbers: list[int]) -> list[tuple[int, MotionSupervisor]]:
        """(axis, supervisor) for each axis of ``numbers`` in another supervisor's motion."""
        held = []
        for n in numbers:
            owner = self._axis(n).owner
            if owner not in (-1, self.number):
                other = self._ctl.supervisor(owner)
                if other is not None and other.own_state is not MPIState.IDLE:
                    held.append((n, other))
        return held

    def _starts(self, queued: bool, state: MPIState, moving: bool) -> list[AxisStart]:
        """Where the new profile of each axis starts."""
        starts = []
        last = self.queue[-1] if self.queue else self.current
        for n in self.axis_list:
            axis = self._axis(n)
            plan = last.plan_for(n) if queued and last is not None else None
            if plan is not None:
                starts.append(AxisStart(n, plan.target, plan.final_velocity, axis.turn_origin(plan.target)))
            elif moving:
                f = self.clock.feedrate(self._ctl.time)
                velocity = axis.cmd_v / f if f > 0.0 else 0.0
                acceleration = axis.cmd_a / (f * f) if f > 0.0 else 0.0
                starts.append(AxisStart(n, axis.cmd_p, velocity, axis.turn_origin(axis.cmd_p), acceleration))
            else:
                # A start runs at the normal feedrate from now on. The axis may still move (STOPPED
                # at a non-zero pauseFeedrate, or past a FINAL_VEL move): start from that velocity.
                f = self.config.normal_feedrate
                starts.append(AxisStart(n, axis.cmd_p, axis.cmd_v / f, axis.turn_origin(axis.cmd_p),
                                        axis.cmd_a / (f * f)))
        return starts

    def _cam_masters(self) -> list[tuple[AxisMaster, float]]:
        """Each slave axis' master (MPIAxisConfig.master) and the master's position now, for a
        cam on the axis list. Raises PlanError if the masters would form a loop."""
        masters = [self._axis(n).master for n in self.axis_list]
        running = {axis.number: axis.cam_reads() for axis in self._ctl.axes if axis.camming}
        loop = cams.master_loop(self.axis_list, masters, running)
        if loop:
            raise PlanError(Message.MPIMessagePARAM_INVALID, f"{loop} (MPIAxisConfig.master): a slave cannot follow "
                                                             "itself, directly or through other cams")
        now = self._ctl.master_sources()
        return [(master, float(now.position(master)[0])) for master in masters]

    def _check_frames(self, moves: list[Move]) -> Message:
        """Do the moves fit the frame buffer? A path's points need not: the library holds
        what does not fit and loads it as the buffer drains (MPI 001, LOW_COUNT)."""
        size = self._ctl.config.frame_buffer_size_of
        loaded = [move for move in moves if move.stream is None]
        for n in self.axis_list:
            if frames_needed(loaded, n) > size(n):
                return Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL
        return OK

    def _low_count(self, attrs: MotionAttr, params: MotionParams) -> int:
        """MPI 001 LOW_COUNT: the given count, else a quarter of the frame buffer (32 of 128)."""
        if MotionAttr.LOW_COUNT in attrs:
            return params.low_count
        return self.frame_buffer_size // 4

    def _open_path(self) -> Move | None:
        """The path in progress, if it is open (more points are expected)."""
        move = self.current
        if move is None or move.stream is None or not move.stream.open or self.queue:
            return None
        return move

    def _append_points(self, move: Move, motion_type: MPIMotionType, attrs: MotionAttr,
                       params: MotionParams) -> tuple[Message, str]:
        """APPEND to an open path: the points follow its last point (or start now, if it ran
        out of points), planned like a path of their own from there (docs/paths.md). The
        append is recorded as a chunk of the path: a command whose outcome comes when its last
        point is reached."""
        stream = move.stream
        plans = {plan.axis: plan for plan in move.plans}
        if attrs & HOLD_ATTRS:
            # A hold waits before a move begins; appended points continue one in progress.
            return Message.MPIMotionMessageATTRIBUTE_INVALID, "points appended to a path in motion cannot be held"
        if stream is None or sorted(plans) != sorted(self.axis_list):
            return Message.MPIMessagePARAM_INVALID, "the points' axes are not the axes of the open path"
        t = self._ctl.time
        tau = self.clock.tau_at(t)
        # Profile time into the path per axis (an axis still held has run none of it).
        nows = {n: -math.inf if n in self._holds else tau - self._axis(n).tau_start for n in self.axis_list}
        if paths.point_count(motion_type, params, len(self.axis_list)) == 0:
            # No points: it only closes (or keeps open) the path, and is done with its last point.
            stream.append(None, open_=not params.final)
            stream.chunks.append((next_serial(), {n: paths.last_point_time(plans[n]) for n in self.axis_list}))
            return OK, ""
        starts = [AxisStart(n, *paths.end_state(plans[n], nows[n]), self._axis(n).origin) for n in self.axis_list]
        try:
            chunk, notes = compile_move(self.number, motion_type, attrs, params, starts, self._ctl.rate)
        except PlanError as exc:
            return exc.message, exc.detail
        for kind, detail in notes.events:
            self._emit(kind, detail=detail, move=move)
        self._rebase(t)
        ends = {new.axis: self._extend_plan(move, plans[new.axis], new, nows[new.axis], t) for new in chunk.plans}
        stream.append(chunk.stream, open_=not params.final)
        if MotionAttr.LOW_COUNT in attrs:
            stream.low_count = params.low_count
        stream.chunks.append((chunk.serial, ends))
        return OK, ""

    def _extend_plan(self, move: Move, old: AxisPlan, new: AxisPlan, now: float, t: float) -> float:
        """Put ``new``'s points after ``old``'s on its axis; returns when its last one is reached."""
        outputs = [(0.0, out) for out in new.outputs] + new.timed_outputs
        axis = self._axis(new.axis)
        values = new.feedforward[1][1:] if new.feedforward is not None else None
        assert new.point_times is not None  # the plan of a path (paths.compile_path)
        extended = paths.extend(old, now, new.segments, new.point_times, new.element_ids, outputs, new.target,
                                values, axis.feedforward)
        move.plans[move.plans.index(old)] = extended
        wait = self._holds.get(new.axis)
        if wait is not None:
            wait.plan = extended  # still held: the path begins, whole, when the hold releases
        else:
            axis.extend(extended, t, self.clock)
        return paths.last_point_time(extended)

    def _rebase(self, t: float) -> None:
        for axis in self.axes:
            if axis.owner == self.number:
                axis.rebase(t, self.clock)

    def _end_move(self, move: Move, message: Message, detail: str) -> None:
        """Record how ``move`` ended (with the appends to it still pending)."""
        if move.stream is not None:
            detail = f"{detail}; {move.stream.describe_peaks(move.plan_axes)}"
            for serial, _ in move.stream.chunks:
                self._end_serial(serial, message, detail)
            move.stream.chunks.clear()
        self._end_serial(move.serial, message, detail)

    def _end_serial(self, serial: int, message: Message, detail: str) -> None:
        axes = [self._axis(n) for n in self.mapped]
        self.move_ends.append(MoveEnd(serial, message, self._ctl.sample, detail,
                                      tuple(a.command_position for a in axes),
                                      tuple(a.actual_position for a in axes)))

    def _drop_pending(self, message: Message, detail: str) -> None:
        """End the move in progress and the queued ones. Every axis that runs (or waits to
        run) a plan of the dropped move is released where its command is now, whether or
        not it is still mapped: no axis keeps motion that no supervisor owns."""
        for move in list(self.queue):
            self._end_move(move, message, detail)
        self.queue.clear()
        if self.current is not None:
            self._release_axes(self.current)
            self._end_move(self.current, message, detail)
            self.last_move = self.current
            self.current = None
        self._holds.clear()

    def _release_axes(self, move: Move) -> None:
        t = self._ctl.time
        for plan in move.plans:
            axis = self._axis(plan.axis)
            if axis.owner == self.number and (axis.plan is plan or axis.holding):
                axis.unload(t, self.clock)

    def _begin(self, move: Move) -> None:
        """A start: whatever is pending is dropped and ``move`` runs from now."""
        t = self._ctl.time
        self._rebase(t)
        self._drop_pending(Message.MPIMotionMessageSTOPPED, "replaced by a new start")
        self.clock = self.clock.ramp_to(t, self.config.normal_feedrate, 0.0)
        self._stop_end = math.inf
        self._set_state(MPIState.MOVING, "START", ActionSource.USER)
        self._load(move)

    def _replace(self, move: Move) -> None:
        """A modify: the move in progress (and anything appended) becomes ``move``."""
        t = self._ctl.time
        self._rebase(t)
        previous = self.current
        for queued in list(self.queue):
            self._end_move(queued, Message.MPIMotionMessageSTOPPED, "replaced by a modify")
        self.queue.clear()
        self._holds.clear()
        if previous is not None:
            move.serial = previous.serial
            if not MotionAttr.ID & move.attributes:
                move.id = previous.id
            if previous.stream is not None:  # points appended to the path are replaced too
                for serial, _ in previous.stream.chunks:
                    self._end_serial(serial, Message.MPIMotionMessageSTOPPED, "replaced by a modify")
        self._load(move, announce=False)

    def _load(self, move: Move, announce: bool = True) -> None:
        """Put ``move`` on its axes now (held axes wait for their trigger)."""
        t, sample = self._ctl.time, self._ctl.sample
        self.current = move
        self.last_move = move
        self._at_velocity_sent = False
        tau = self.clock.tau_at(t)
        for plan in move.plans:
            axis = self._axis(plan.axis)
            axis.rebase(t, self._clock_of(axis))
            axis.owner = self.number
            axis.move_id = move.id
            axis.element_id = move.element_id
            axis.mode = CommandMode.SERVO if axis.amp_enabled else axis.mode
            axis.status_mode = StatusMode.VELOCITY if plan.is_velocity else StatusMode.POINT_TO_POINT
            if plan.hold is not None:
                axis.unload(t, self._clock_of(axis))
                axis.holding = True
                axis.target = axis.rest
                self._holds[plan.axis] = HoldWait.begin(
                    plan, move.attributes, sample, self._ctl.rate,
                    self._position_of(plan.hold) if HoldWait.watches(plan.hold) else 0.0)
            else:
                axis.load(plan, tau, t, self.clock)
                self._fire_outputs(plan)
        if announce:
            self._emit(MPIEventType.MOTION_START, move=move)
        self.release_holds(self._ctl.io)

    def _clock_of(self, axis: Axis) -> ProfileClock | None:
        owner = self._ctl.supervisor(axis.owner) if axis.owner >= 0 else None
        return owner.clock if owner is not None else None

    def _position_of(self, hold) -> float:
        """The position (user units) a position hold watches: actual or command."""
        axis = self._axis(hold.number)
        return axis.unwrapped_actual if hold.type is HoldType.AXIS_POSITION_ACTUAL else axis.unwrapped_command

    def _fire_outputs(self, plan) -> None:
        for output in plan.outputs:
            self._fire_output(output)

    def _fire_output(self, output: Output) -> None:
        if output.type is OutputType.MOTOR:
            self._ctl.io.apply_masks(IoSpace.MOTOR_GENERAL_IO, output.motor, output.on_mask, output.off_mask)
        elif output.type is OutputType.OUTPUT:
            self._ctl.io.apply_masks(IoSpace.IO, output.address, output.on_mask, output.off_mask)

    # ================================================================= status ====
    def _at_velocity_reached(self) -> None:
        """The velocity move is at velocity (the controller is at that sample): the event,
        and the outcome a goal on this move waits for."""
        assert self.current is not None  # scan found the current move at its velocity
        self._at_velocity_sent = True
        self._emit(MPIEventType.MOTION_AT_VELOCITY)
        self._end_move(self.current, OK, "at velocity")

    def snapshot(self) -> MotionSnapshot:
        """mpiMotionStatus."""
        axes = tuple(self._ctl.axis_snapshot(n) for n in self.mapped)
        move = self.current or self.last_move
        done = all(a.done for a in axes) if axes else True
        return MotionSnapshot(
            sample=self._ctl.sample,
            number=self.number,
            state=self._reported_state(),
            axis_numbers=tuple(self.mapped),
            axes=axes,
            done=done and self.own_state is not MPIState.MOVING,
            at_target=all(a.at_target for a in axes) if axes else True,
            settled=all(a.settled for a in axes) if axes else True,
            move_id=move.id if move else 0,
            element_id=self._element_id(move),
            feedrate=self.clock.feedrate(self._ctl.time),
            last_action=self.last_action,
            action_source=self.action_source.value,
            moves_pending=len(self.queue),
            motion_type=move.type.name if move else "",
            progress=self.progress(),
            latched_events=tuple(self.latched.names()),
        )

    def _reported_state(self) -> MPIState:
        """The state status reports: IDLE at the sample of a start given NO_HANDSHAKE or
        NO_WAIT (MPI 001 remarks: "the state is reported as MPIStateIDLE until the controller
        begins the profile execution"), the state otherwise."""
        state = self.state
        if self._unacknowledged == self._ctl.sample and state is MPIState.MOVING:
            return MPIState.IDLE
        return state

    def progress(self) -> float:
        """0..1 along the current move (profile time over its duration)."""
        move = self.current
        if move is None:
            return 1.0 if self.last_move is not None else 0.0
        fractions = []
        for plan in move.plans:
            axis = self._axis(plan.axis)
            if axis.plan is not plan:
                fractions.append(0.0)
            elif plan.is_velocity:
                fractions.append(1.0 if plan.ramp_end <= 0.0 else min(1.0, max(0.0, axis.rel / plan.ramp_end)))
            else:
                fractions.append(1.0 if plan.duration <= 0.0 else min(1.0, max(0.0, axis.rel / plan.duration)))
        return min(fractions) if fractions else 0.0

    @property
    def element_id(self) -> int:
        """The element id status shows: the current (else last) move's; a path's, of the
        point it runs toward."""
        return self._element_id(self.current or self.last_move)

    def _element_id(self, move: Move | None) -> int:
        """The move's element id; a path's, of the point its first axis runs toward."""
        if move is None:
            return 0
        if move.stream is not None and move.plans:
            axis = self._axis(move.plans[0].axis)
            if axis.plan is move.plans[0]:
                return axis.current_element_id
        return move.element_id

    # ================================================================= events ====
    def _emit(self, kind: MPIEventType, axis: int = -1, move: Move | None = None, detail: str = "",
              sample: int | None = None) -> None:
        move = move or self.current
        self._ctl.emit(kind, supervisor=self.number, axis=axis,
                       move_id=move.id if move else 0, element_id=self._element_id(move),
                       detail=detail, extra_mask=move.event_mask if move else MPIEventType.NONE,
                       sample=sample)
