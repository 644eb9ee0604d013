"""Controller: the sample clock, the axes and motion supervisors, I/O, gates, events.

The controller advances in whole samples. Every command takes effect at a sample
boundary: a command given while the controller is at sample k changes the trajectory
from time k/rate on, so sample k+1 is the first that shows it (``effective_sample``).
:meth:`step` advances any number of samples; it computes the axes over a stretch at
once (vectorised over time) and stops inside it exactly at the samples where something
discrete happens (a move done, a stop complete, a hold released), so the result does
not depend on how the samples are batched.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections import deque
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from mpi_ros.mpi.axes.axis import Axis
from mpi_ros.mpi.axes.bank import AxisBank, CommandRows, Kind
from mpi_ros.mpi.axes.scratch import Scratch
from mpi_ros.mpi.axes.status import (
    BITS,
    EVENT_BITS,
    StretchStatus,
    compute,
)
from mpi_ros.mpi.axes.stretch import Stretch
from mpi_ros.mpi.axes.trace import trace
from mpi_ros.mpi.base.clock import ProfileClock
from mpi_ros.mpi.base.events import MASK_AXIS, Event, MPIEventType
from mpi_ros.mpi.base.io import IoImage
from mpi_ros.mpi.base.masters import SecondaryInputs, Sources
from mpi_ros.mpi.base.messages import STATE_MESSAGES, Message
from mpi_ros.mpi.base.outcome import VALID, MoveEnd, Outcome
from mpi_ros.mpi.base.params import (
    AxisFaultConfig,
    AxisInPosition,
    AxisMaster,
    ControllerConfig,
    MotionConfig,
    PlantConfig,
    SecondaryFeedback,
    check_position,
    check_settling_reachable,
)
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionFeedback
from mpi_ros.mpi.base.types import ActionSource, IoSpace, MPIAction, MPIState
from mpi_ros.mpi.base.wrap import wrap_positions
from mpi_ros.mpi.faults.monitor import FaultMonitor
from mpi_ros.mpi.move_log import MoveLog
from mpi_ros.mpi.snapshots import REL, AxisTemplate, Snapshots, StatusTemplate
from mpi_ros.mpi.supervisor.motion import HANDLE_INVALID, MotionSupervisor

MAX_STRETCH = 4096  # samples computed at once
EVENTS_KEPT = 10_000  # events Controller.events keeps for a caller that drains them
# Elements (axes x samples) of a stretch at most: its arrays stay a few megabytes (they live in
# a scratch reused from stretch to stretch), and with many axes a shorter stretch loses nothing.
_STRETCH_ELEMENTS = 32 * MAX_STRETCH
# The event of each status bit turning on, in status.BITS order (the order they are emitted
# in when several turn on in one sample).
_EDGE_EVENTS = tuple(MPIEventType[name.upper()] for name in BITS[:EVENT_BITS])

EventListener = Callable[[Event], None]
_Found = tuple[int, int, int, MPIEventType, str]  # an event found in a stretch: index, axis, rank, type, detail


class Controller:
    def __init__(
        self,
        config: ControllerConfig | None = None,
        in_position: AxisInPosition | None = None,
        plant: PlantConfig | None = None,
        motion_config: MotionConfig | None = None,
    ):
        self.config = config or ControllerConfig()
        # The one validator of each struct (params.py), as the YAML loader and the services.
        for what, struct in (("config", self.config), ("in_position", in_position), ("plant", plant),
                             ("motion_config", motion_config)):
            verdict = struct.validate() if struct is not None else None
            if verdict is not None and not verdict.ok:
                raise ValueError(f"{what}.{verdict.detail}")
        self.rate = float(self.config.sample_rate)
        self.sample = 0
        self.bank = AxisBank(self.config.axis_count, self.config.supervisor_count)
        self._scratch = Scratch()  # the arrays of a stretch, reused by the next one
        self.axes = [
            Axis(n, self.bank, self.rate, in_position or AxisInPosition(), plant or PlantConfig())
            for n in range(self.config.axis_count)
        ]
        self.io = IoImage(self.config.io_words, self.config.motors)
        self.secondary = SecondaryInputs(self.config.motors)  # the motors' second encoder inputs (cams)
        self._sources: tuple[Stretch, Sources] | None = None  # where the cam slaves of a stretch read masters
        self.motion_defaults = motion_config or MotionConfig()
        self._supervisors: dict[int, MotionSupervisor] = {}
        # The latest events, for a caller that drains them (drain_events); the oldest go first,
        # so a suite that never drains them (its listeners get every event) holds no more than
        # EVENTS_KEPT.
        self.events: deque[Event] = deque(maxlen=EVENTS_KEPT)
        self.listeners: list[EventListener] = []
        self.faults = FaultMonitor(self)
        self.move_log = MoveLog()  # how moves ended: what their goals wait for (move_end)
        self._serials = itertools.count(1)

    # -- time -------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Controller time of the current sample (seconds)."""
        return self.sample / self.rate

    @property
    def effective_sample(self) -> int:
        """The sample at which a command given now takes effect."""
        return self.sample + 1

    # -- objects ------------------------------------------------------------------------
    def create_motion(self, number: int = -1, axis: int | None = None) -> tuple[Message, MotionSupervisor | None]:
        """mpiMotionCreate: -1 selects the next unused supervisor."""
        if number == -1:
            free = [n for n in range(self.config.supervisor_count) if n not in self._supervisors]
            if not free:
                return Message.MPIMotionMessageMOTION_INVALID, None
            number = free[0]
        if not 0 <= number < self.config.supervisor_count:
            return Message.MPIMotionMessageMOTION_INVALID, None
        if number in self._supervisors:
            return Message.MPIMotionMessageMOTION_INVALID, None
        ms = MotionSupervisor(self, number, self.motion_defaults)
        if axis is not None:
            appended = ms.axis_append(axis)
            if not appended.ok:
                return appended.message, None
        self._supervisors[number] = ms
        return Message.MPIMessageOK, ms

    def delete_motion(self, ms: MotionSupervisor) -> Outcome:
        """mpiMotionDelete (the axes are not deleted)."""
        if not ms.valid or self._supervisors.get(ms.number) is not ms:
            return HANDLE_INVALID
        unmapped = [n for n in ms.axis_list if n not in ms.mapped]
        if unmapped:
            return Outcome(Message.MPIAxisMessageNOT_MAPPED_TO_MS,
                           f"axis_list: axes {unmapped} are listed but not mapped (MAP them or remove them first)")
        if ms.own_state not in (MPIState.IDLE, MPIState.ERROR):
            return Outcome(STATE_MESSAGES[ms.own_state.name],
                           f"state: supervisor {ms.number} is {ms.own_state.name} (IDLE or ERROR only)")
        for axis in self.axes:
            if axis.owner == ms.number:
                axis.unload(self.time, ms.clock)
                axis.owner = -1
        ms.valid = False
        del self._supervisors[ms.number]
        return VALID

    def supervisor(self, number: int) -> MotionSupervisor | None:
        return self._supervisors.get(number)

    # -- axis objects (docs/decisions.md, "Axis objects") -----------------------------------
    # The firmware's axes are fixed (config.axis_count, the twin's MEIXmpMAX_Axes); an Axis
    # object is the application's handle on one of them. Every axis has one at the start.
    def axis_create(self, number: int) -> tuple[Outcome, Axis | None]:
        """mpiAxisCreate (MPI 002): MPIAxisMessageAXIS_INVALID "if the axis number is less than
        zero or greater than or equal to MEIXmpMAX_Axes". Creating a valid one again answers
        the same object (one handle per axis here)."""
        if not 0 <= number < len(self.axes):
            count = len(self.axes)
            return Outcome(Message.MPIAxisMessageAXIS_INVALID,
                           f"axis {number}: expected 0 to {count - 1} (MEIXmpMAX_Axes = {count})"), None
        axis = self.axes[number]
        axis.valid = True
        return Outcome(Message.MPIMessageOK), axis

    def axis_delete(self, number: int) -> Outcome:
        """mpiAxisDelete (MPI 002). Objects are deleted "in reverse order" of their creation
        (its remarks): an axis a supervisor lists or has mapped is refused with
        MPIMessageOBJECT_ON_LIST, so no supervisor ever holds a deleted axis."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        for ms in self.supervisors:
            if number in ms.axis_list or number in ms.mapped:
                return Outcome(Message.MPIMessageOBJECT_ON_LIST,
                               f"axis {number} is on supervisor {ms.number}'s axis list: remove it and MAP first")
        self.axes[number].valid = False
        return Outcome(Message.MPIMessageOK)

    def axis_validate(self, number: int) -> Outcome:
        """mpiAxisValidate (MPI 002): OK for a valid Axis object, HANDLE_INVALID for a deleted one."""
        if not 0 <= number < len(self.axes):
            return Outcome(Message.MPIAxisMessageAXIS_INVALID, f"axis: no axis {number} ({len(self.axes)} axes)")
        if not self.axes[number].valid:
            return Outcome(Message.MPIMessageHANDLE_INVALID, f"axis: axis {number} was deleted (create it again)")
        return Outcome(Message.MPIMessageOK)

    def valid_axes(self) -> list[int]:
        """The numbers of the valid Axis objects, in order."""
        return [axis.number for axis in self.axes if axis.valid]

    def axis_control(self, number: int) -> Controller | None:
        """mpiAxisControl (MPI 002): the Control of a valid axis, None (MPIHandleVOID) otherwise."""
        return self if self.axis_validate(number).ok else None

    def motion_control(self, ms: MotionSupervisor) -> Controller | None:
        """mpiMotionControl (MPI 000): the Control of a valid motion, None (MPIHandleVOID) otherwise."""
        return self if ms.valid and self._supervisors.get(ms.number) is ms else None

    # -- what supervisors ask of the controller (host.SupervisorHost) ------------------------
    def next_serial(self) -> int:
        """The serial of a move a supervisor takes (each controller counts its own)."""
        return next(self._serials)

    def record_end(self, end: MoveEnd) -> None:
        self.move_log.record(end)

    def clock_changed(self, supervisor: int, clock: ProfileClock) -> None:
        self.bank.clock_changed(supervisor, clock)

    def own_state_of(self, supervisor: int) -> MPIState | None:
        """Supervisor ``supervisor``'s own state (None if there is none)."""
        ms = self._supervisors.get(supervisor)
        return ms.own_state if ms is not None else None

    def clock_of(self, supervisor: int) -> ProfileClock | None:
        ms = self._supervisors.get(supervisor)
        return ms.clock if ms is not None else None

    def act_on(self, supervisor: int, action: MPIAction, source: ActionSource) -> Outcome:
        """An action a supervisor passes to another one (the motion that holds its axes)."""
        ms = self._supervisors.get(supervisor)
        if ms is None:
            return Outcome(Message.MPIMotionMessageMOTION_INVALID, f"no supervisor {supervisor}")
        return ms.action(action, source)

    def responsible_for(self, axis: int) -> list[int]:
        """The supervisors that act on a fault of ``axis``: the one commanding it (if the
        axis is mapped to it), else every one it is mapped to."""
        owner = self._supervisors.get(self.axes[axis].owner)
        if owner is not None and axis in owner.mapped:
            return [owner.number]
        return [ms.number for ms in self.supervisors if axis in ms.mapped]

    # -- queries ------------------------------------------------------------------------
    def move_end(self, supervisor: int, serial: int, since: int) -> MoveEnd | None:
        """How the goals that follow move ``serial`` of ``supervisor`` from sample ``since``
        ended, or None while the move runs or waits its turn (move_log.py says when)."""
        return self.move_ends(supervisor, [(serial, since)])[0]

    def move_ends(self, supervisor: int, goals: Iterable[tuple[int, int]]) -> list[MoveEnd | None]:
        """:meth:`move_end` of each (serial, since) in ``goals``: hundreds of goals may follow
        one move, and the supervisor is asked once per move."""
        ms = self._supervisors.get(supervisor)
        now: dict[int, MoveEnd | None] = {}
        ends = []
        for serial, since in goals:
            end = self.move_log.since(serial, since)
            if end is None:
                if serial not in now:
                    now[serial] = (ms.end_now(serial) if ms is not None else MoveEnd(
                        serial, Outcome(Message.MPIMotionMessageMOTION_INVALID, "supervisor deleted"), self.sample))
                end = now[serial]
            ends.append(end)
        return ends

    def ends_read(self) -> None:
        """Every goal that follows a move has read the ends recorded so far (the runner, after
        the reviews of a step batch or command): the log may let them go (move_log.py)."""
        self.move_log.mark_read()

    def current_serial(self, supervisor: int) -> int | None:
        """The serial of the move supervisor ``supervisor`` runs now (None: none, or no such one)."""
        ms = self._supervisors.get(supervisor)
        move = ms.current if ms is not None else None
        return move.serial if move is not None else None

    def motion_feedback(self, supervisor: int) -> MotionFeedback | None:
        """What a goal's feedback and result show of a supervisor now (None: no such one)."""
        ms = self._supervisors.get(supervisor)
        if ms is None:
            return None
        axes = [self.axes[n] for n in ms.mapped]
        move = ms.current or ms.last_move
        state = ms.state
        return MotionFeedback(
            sample=self.sample, state=state, command_position=tuple(a.command_position for a in axes),
            actual_position=tuple(a.actual_position for a in axes), command_velocity=tuple(a.cmd_v for a in axes),
            progress=float(ms.progress()) if ms.current is not None else 0.0, move_id=move.id if move else 0,
            element_id=ms.element_id, serial=ms.current.serial if ms.current is not None else None)

    @property
    def supervisors(self) -> list[MotionSupervisor]:
        return [self._supervisors[n] for n in sorted(self._supervisors)]

    def axis(self, number: int) -> Axis:
        return self.axes[number]

    # -- axis calls ---------------------------------------------------------------------
    def axis_command_position_set(self, number: int, position: float) -> Outcome:
        """mpiAxisCommandPositionSet under the rule of MPI 002 (Axis.can_set_command, which
        mpiMotionPositionSet applies too): MPIAxisMessageCOMMAND_NOT_SET while it moves."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        axis = self.axes[number]
        verdict = check_position("position", position)
        if not verdict.ok:
            return verdict
        owner = self.supervisor(axis.owner)  # an axis is in its owner's state (IDLE without one)
        state = owner.own_state if owner is not None else MPIState.IDLE
        if not axis.can_set_command(state):
            return Outcome(Message.MPIAxisMessageCOMMAND_NOT_SET,
                           f"axis: axis {number} cannot take a command position while {state.name}")
        axis.set_command_position(float(position), self.time, owner.clock if owner is not None else None)
        return VALID

    def axis_actual_position_set(self, number: int, position: float) -> Outcome:
        """mpiAxisActualPositionSet (the axis checks the range), at any time: the plant is
        re-anchored along the move the axis follows (its owner's clock)."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        axis = self.axes[number]
        owner = self.supervisor(axis.owner)
        return axis.set_actual_position(position, self.time, owner.clock if owner is not None else None)

    def axis_origin_set(self, number: int, origin: float) -> Outcome:
        """mpiAxisOriginSet (the axis checks the range)."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        return self.axes[number].set_origin(origin)

    def axis_amp_enable_set(self, number: int, enabled: bool) -> Outcome:
        """The amplifier enable of an axis' motor (MPI 000, MPIMessageOBJECT_NOT_ENABLED).
        Disabling an axis that a motion moves, or keeps STOPPED, ABORTs that motion first
        (docs/decisions.md, "Amplifier enable")."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        axis = self.axes[number]
        state = self.own_state_of(axis.owner) if axis.owner >= 0 else None
        detail = "amplifier enabled" if enabled else "amplifier disabled: the motor coasts"
        if not enabled and state not in (None, MPIState.IDLE, MPIState.ERROR):
            self.act_on(axis.owner, MPIAction.ABORT, ActionSource.USER)
            detail += f"; the motion of supervisor {axis.owner} was ABORTed"
            state = self.own_state_of(axis.owner)
        elif enabled and state in (MPIState.STOPPING_ERROR, MPIState.ERROR) and not axis.amp_enabled:
            detail = f"enabled: RESET of supervisor {axis.owner} turns the amplifier on"
        axis.amp_enable_set(enabled, self.time, self.clock_of(axis.owner) if axis.owner >= 0 else None,
                            servo=state not in (MPIState.STOPPING_ERROR, MPIState.ERROR))
        return Outcome(Message.MPIMessageOK, detail)

    def axis_event_notify_get(self, number: int) -> tuple[Message, MPIEventType]:
        """mpiAxisEventNotifyGet (MPI 002)."""
        verdict = self.axis_validate(number)
        return verdict.message, self.axes[number].events.mask if verdict.ok else MPIEventType.NONE

    def axis_event_notify_set(self, number: int, mask: MPIEventType) -> Outcome:
        """mpiAxisEventNotifySet (MPI 002): the events an axis generates (MPIEventMaskAXIS) are
        notified when its mask or a mapped supervisor's asks for them (once, not twice)."""
        verdict = self.axis_validate(number)
        if verdict.ok:
            self.axes[number].events.notify_set(mask)
        return verdict

    def axis_event_reset(self, number: int, mask: MPIEventType) -> Outcome:
        """mpiAxisEventReset (MPI 002): clear the axis' latched events in ``mask``."""
        verdict = self.axis_validate(number)
        if verdict.ok:
            self.axes[number].events.reset(mask)
        return verdict

    def axis_in_position_set(self, number: int, in_position: AxisInPosition) -> Outcome:
        """mpiAxisConfigSet (inPosition), checked by the one AxisInPosition validator (the
        YAML loader and the service use it too) and against the axis' encoder."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        axis = self.axes[number]
        verdict = in_position.validate()
        if verdict.ok:
            verdict = check_settling_reachable(in_position, axis.plant.config)
        if not verdict.ok:
            return verdict
        axis.in_position = in_position.copy()
        return VALID

    def axis_master_check(self, number: int, master: AxisMaster) -> Outcome:
        """The one AxisMaster validator, against this controller's axes, motors and I/O words."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        return master.validate(len(self.axes), self.config.motors, self.config.io_words)

    def axis_master_set(self, number: int, master: AxisMaster) -> Outcome:
        """mpiAxisConfigSet (master, masterCorrection): used by the next cam the axis runs (a
        running cam keeps the master it started with: docs/cams.md)."""
        verdict = self.axis_master_check(number, master)
        if not verdict.ok:
            return verdict
        motor = master.encoder_fault_motor_number
        if motor is not None:  # its home is the fault configuration (AxisMaster's docstring)
            faults = self.faults.axes[number].config.copy()
            faults.encoder_fault_motor_number = motor
            verdict = self.faults.config_set(number, faults)  # (trips if that encoder faults now)
            if not verdict.ok:
                return verdict
        self.axes[number].master = dataclasses.replace(master, encoder_fault_motor_number=None)
        return VALID

    def axis_master_get(self, number: int) -> AxisMaster:
        """mpiAxisConfigGet's master (MPIAxisMaster, with masterCorrection), encoderFaultMotorNumber
        included."""
        motor = self.faults.axes[number].config.encoder_fault_motor_number
        return dataclasses.replace(self.axes[number].master, encoder_fault_motor_number=motor)

    def secondary_feedback_set(self, motor: int, feedback: SecondaryFeedback) -> Outcome:
        """Drive a motor's secondary feedback input (MOTOR_FEEDBACK_SECONDARY masters): from the
        next sample it reads ``feedback.position`` and moves at ``feedback.velocity``."""
        if not 0 <= motor < len(self.secondary):
            return Outcome(Message.MPIMessagePARAM_INVALID, f"motor: no motor {motor} ({len(self.secondary)} motors)")
        verdict = feedback.validate()  # the one SecondaryFeedback validator (the YAML's too)
        if not verdict.ok:
            return verdict
        self.secondary.set(motor, feedback, self.sample)
        return VALID

    def master_sources(self, stretch: Stretch | None = None) -> Sources:
        """Where master positions are read: over ``stretch`` (as far as it is traced), or now."""
        if stretch is None:
            samples = np.array([self.sample], dtype=np.int64)
            cmd_p, act_p = self.bank.cmd_p[:, None], self.bank.act_p[:, None]
        else:
            samples, cmd_p, act_p = stretch.samples, stretch.cmd_p, stretch.act_p
        return Sources(cmd_p, act_p, samples, lambda n: self.axes[n].origin, self.io, self.secondary, self.rate)

    def _cam_inputs(self, axis: Axis, stretch: Stretch) -> tuple[np.ndarray, np.ndarray]:
        """A cam slave's master position and feedrate ratio at each sample of ``stretch``: a
        stop ramps its supervisor's feedrate, which scales the slave's progress (cams.py)."""
        plan, owner = axis.plan, self.supervisor(axis.owner)
        assert plan is not None and plan.cam is not None and owner is not None  # a camming axis
        feedrate, _ = owner.clock.feedrates(stretch.t)
        if self._sources is None or self._sources[0] is not stretch:  # one per stretch, for all its slaves
            self._sources = (stretch, self.master_sources(stretch))
        return self._sources[1].position(plan.cam.master, plan.cam.frame), feedrate / owner.config.normal_feedrate
    def axis_fault_config_set(self, number: int, config: AxisFaultConfig) -> Outcome:
        """The fault limits and actions of an axis (docs/faults.md), checked by the one
        AxisFaultConfig validator (the YAML loader and the service use it too)."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        return self.faults.config_set(number, config)

    def axis_fault_config_get(self, number: int) -> tuple[Message, AxisFaultConfig]:
        verdict = self.axis_validate(number)
        return verdict.message, self.faults.axes[number].config.copy() if verdict.ok else AxisFaultConfig()

    def axis_fault_inject(self, number: int, fault: object, active: bool = True) -> Outcome:
        """Inject a fault on an axis (faults.FaultMonitor.inject): it acts at once."""
        verdict = self.axis_validate(number)
        if not verdict.ok:
            return verdict
        return self.faults.inject(number, fault, active)

    def frame_count(self, number: int) -> int:
        """Frames in an axis' buffer (AxisTemplate.frame_count)."""
        axis = self.axes[number]
        return self._axis_template(axis, axis.owner).frame_count(axis.rel)

    def joint_values(self) -> tuple[list[float], list[float], list[float]]:
        """Every axis' actual position (user units), actual velocity and servo effort
        (counts/s^2, plant.servo_effort): the axes as joints, read at once."""
        axes = self.axes
        return ([a.actual_position for a in axes], [a.act_v for a in axes], [a.servo_effort() for a in axes])

    def axis_snapshot(self, number: int) -> AxisSnapshot:
        """mpiAxisStatus."""
        return self.axis_snapshots((number,))[0]

    def axis_snapshots(self, numbers: Sequence[int] | None = None) -> list[AxisSnapshot]:
        """mpiAxisStatus of several axes (every axis by default). Their values are read from
        the bank's arrays in one go: reading them axis by axis, value by value, cost more than
        the rest of a snapshot."""
        bank = self.bank
        if numbers is None:
            numbers = range(len(self.axes))
            values, bits, owners = bank.values.T.tolist(), bank.bits.T.tolist(), bank.owner.tolist()
        else:
            index = list(numbers)
            values, bits = bank.values[:, index].T.tolist(), bank.bits[:, index].T.tolist()
            owners = bank.owner[index].tolist()
        axes = self.axes
        return [self._axis_template(axes[n], o).at(self.sample, v, b)
                for n, v, b, o in zip(numbers, values, bits, owners, strict=True)]

    def motion_snapshots(self) -> Snapshots:
        """Every supervisor's mpiMotionStatus, by number, and every axis' mpiAxisStatus, all
        from one read of the axes (the supervisors' snapshots hold the same axis snapshots)."""
        return self._snapshots_now(self.status_template())

    def _snapshots_now(self, template: StatusTemplate) -> Snapshots:
        """The snapshots of ``template`` at the current sample, from the bank's values and bits."""
        return template.at(self.sample, self.bank.values, self.bank.bits)

    def status_template(self) -> StatusTemplate:
        """What the status of every axis and supervisor holds until the next discrete change
        (snapshots.py)."""
        return StatusTemplate(tuple(map(self._axis_template, self.axes, self.bank.owner.tolist())),
                              tuple((ms, ms.status_template()) for ms in self.supervisors))

    def _axis_template(self, axis: Axis, owner: int) -> AxisTemplate:
        """Axis ``axis``' status template; ``owner``: the supervisor commanding it (-1: none)."""
        return AxisTemplate.of(axis, owner, self._supervisors.get(owner),
                               self.config.frame_buffer_size_of(axis.number), self.faults.names(axis.number))

    # -- gates and I/O -------------------------------------------------------------------
    def gate_set(self, gate: int, closed: bool) -> Outcome:
        """meiControlGateSet: opening a gate releases the moves held on it."""
        outcome = self.io.gate_set(gate, closed)
        if outcome.ok:
            self._io_changed()
        return outcome

    def gate_get(self, gate: int) -> tuple[Message, bool]:
        return self.io.gate_get(gate)

    def io_set(self, space: IoSpace, index: int, value: int, mask: int = -1) -> Outcome:
        outcome = self.io.set(space, index, value, mask)
        if outcome.ok:
            self._io_changed()
        return outcome

    def io_get(self, space: IoSpace, index: int) -> tuple[Message, int]:
        return self.io.get(space, index)

    def _io_changed(self) -> None:
        for ms in self.supervisors:
            ms.release_holds()

    # -- events -------------------------------------------------------------------------
    def emit(self, kind: MPIEventType, supervisor: int = -1, axis: int = -1, move_id: int = 0,
             element_id: int = 0, detail: str = "", extra_mask: MPIEventType = MPIEventType.NONE,
             sample: int | None = None) -> None:
        """Latch the event on every supervisor it concerns and notify those that asked."""
        sample = self.sample if sample is None else sample
        targets = self._event_targets(supervisor, axis)
        delivered = False
        for ms in targets:
            ms.latched |= kind
            if kind & (ms.notify_mask | (extra_mask if ms.number == supervisor else MPIEventType.NONE)):
                self._deliver(Event(sample, kind, ms.number, axis, move_id, element_id, detail))
                delivered = True
        # the axis' own mask (mpiAxisEventNotifySet) asks for what its supervisors' did not
        wanted = bool(kind & MASK_AXIS) and 0 <= axis < len(self.axes) and self.axes[axis].events.latch(kind)
        if not targets or (wanted and not delivered):
            self._deliver(Event(sample, kind, supervisor, axis, move_id, element_id, detail))

    def _event_targets(self, supervisor: int, axis: int) -> list[MotionSupervisor]:
        """MPI 000 mpiMotionAxisAppend: supervisors sharing axes both get the events."""
        targets = []
        own = self.supervisor(supervisor)
        if own is not None:
            targets.append(own)
        axes = {axis} if axis >= 0 else (set(own.mapped) if own is not None else set())
        for ms in self.supervisors:
            if ms is not own and axes & set(ms.mapped):
                targets.append(ms)
        return targets

    def _deliver(self, event: Event) -> None:
        self.events.append(event)
        for listener in self.listeners:
            listener(event)

    def drain_events(self) -> list[Event]:
        out = list(self.events)
        self.events.clear()
        return out

    # -- stepping -----------------------------------------------------------------------
    def step(self, samples: int = 1) -> None:
        """Advance ``samples`` samples."""
        if samples < 0:
            raise ValueError("samples must be >= 0")
        self._step_to(self.sample + int(samples), {})

    def step_snapshots(self, samples: int, at: Iterable[int]) -> dict[int, Snapshots]:
        """Advance ``samples`` samples, as :meth:`step`, and answer :meth:`motion_snapshots`
        at each sample of ``at`` (sample numbers, from the current one to the end), equal to
        what stepping to each of them and taking motion_snapshots() there gives.

        A stretch costs about the same whatever its length (its numpy calls), so a caller
        that wants status at many samples (replay, issue 35) steps in long stretches and
        takes the snapshots of the samples inside them from the stretch's arrays, instead
        of cutting the stepping at each one."""
        if samples < 0:
            raise ValueError("samples must be >= 0")
        end = self.sample + int(samples)
        wanted = sorted({int(s) for s in at})
        if wanted and (wanted[0] < self.sample or wanted[-1] > end):
            raise ValueError(f"snapshots asked at samples {wanted[0]} to {wanted[-1]}, "
                             f"outside {self.sample} to {end}")
        taken: dict[int, Snapshots | None] = dict.fromkeys(wanted)
        if self.sample in taken:
            taken[self.sample] = self.motion_snapshots()
        self._step_to(end, taken)
        return {s: snaps for s, snaps in taken.items() if snaps is not None}

    def _step_to(self, end: int, taken: dict[int, Snapshots | None]) -> None:
        """Step to sample ``end``, filling ``taken``'s samples (None: still wanted) with
        their snapshots on the way."""
        longest = max(64, min(MAX_STRETCH, _STRETCH_ELEMENTS // len(self.axes)))
        while self.sample < end:
            template = self._advance(min(end, self.sample + longest), taken)
            # where the stretch stopped, after its transitions: as stepping there leaves it
            if self.sample in taken:
                taken[self.sample] = self._snapshots_now(template if template is not None else self.status_template())

    def run_until(self, condition: Callable[[Controller], bool], max_samples: int, chunk: int = 1) -> bool:
        """Step ``chunk`` samples at a time until ``condition`` holds (True) or
        ``max_samples`` have passed (False)."""
        limit = self.sample + max_samples
        while not condition(self):
            if self.sample >= limit:
                return False
            self.step(min(chunk, limit - self.sample))
        return True

    def _clock(self, axis: Axis) -> ProfileClock | None:
        owner = self.supervisor(axis.owner)
        return owner.clock if owner is not None else None

    def _advance(self, k1: int, taken: dict[int, Snapshots | None]) -> StatusTemplate | None:
        """Step one stretch, to sample ``k1`` at most: up to its first transition or fault.
        Answers the status template the snapshots inside it were taken from, if they were
        and it still holds (the stretch stopped without a discrete change)."""
        k0 = self.sample
        self.bank.refresh(lambda row: self.axes[row].refresh(self._clock(self.axes[row])),
                          lambda row: self.axes[row].reanchor(self._clock(self.axes[row])))
        stretch = trace(self.bank, self.axes, self._clock, k0, k1, self.rate, self._scratch,
                                  self._cam_inputs)
        status = compute(stretch, self.bank.status, self.bank.runs, self._scratch)
        stop = len(stretch) - 1
        event_at = None
        supervisors = self.supervisors
        for ms in supervisors:
            first = ms.scan(stretch, status)
            if first is not None and first <= stop:
                stop = event_at = first
        fault_at = self.faults.scan(stretch)
        if fault_at is not None and fault_at <= stop:
            stop = event_at = fault_at
        template = self._status_events(stop, stretch, status, taken)
        self._log(stop, stretch, supervisors)
        self._commit(stop, stretch, status)
        self.faults.commit(stop)
        self.sample = int(stretch.samples[stop])
        if event_at is not None:
            for ms in supervisors:
                ms.transition(stop, stretch.samples)
            # after the supervisors' transitions of the same sample (a move done there is done)
            self.faults.transition(stop)
            return None
        return template

    def _log(self, stop: int, stretch: Stretch, supervisors: list[MotionSupervisor]) -> None:
        for ms in supervisors:
            if ms.log is not None and not ms.log.full:
                ms.log.record(stretch.samples[: stop + 1], ms.state.name,
                              [(wrap_positions(stretch.cmd_p[n, : stop + 1] - self.axes[n].origin),
                                wrap_positions(stretch.act_p[n, : stop + 1] - self.axes[n].origin),
                                stretch.cmd_v[n, : stop + 1]) for n in ms.mapped])

    def _commit(self, stop: int, stretch: Stretch, status: StretchStatus) -> None:
        """Keep every axis' state at stretch sample ``stop``."""
        bank = self.bank
        bank.values[:] = stretch.values[:, :, stop]
        bank.bits[:] = status.bits[:, :, stop]
        status.counters_at(stop, out=bank.runs)
        t = float(stretch.t[stop])
        for row, anchors in stretch.anchors.items():
            self.axes[row].keep_anchor(anchors, t)
        plant = bank.plant
        # only an axis at rest snaps (a finite snap_after): with none, nothing to test
        if bank.memo("snapping", lambda: bool(np.isfinite(plant.snap_after[bank.of_kind(Kind.PIECE)]).any())):
            rows = stretch.pieces
            for row in rows[t - plant.anchor_t[rows] >= plant.snap_after[rows]].tolist():
                self.axes[row].snap(t)

    def _status_events(self, stop: int, stretch: Stretch, status: StretchStatus,
                       taken: dict[int, Snapshots | None]) -> StatusTemplate | None:
        """Events for status bits that turn on in samples up to ``stop``, in sample order;
        between them, the snapshots ``taken`` wants at samples before ``stop`` (each after
        the events of its own sample and before those of later ones, as stepping there).

        One status template serves every snapshot of the stretch: nothing discrete happens
        before the stretch's stop (a transition or a fault stops the stretch where it
        happens), so the supervisors, plans, faults and queues of every sample before it are
        those of its first. The values, status bits and profile times come from the
        stretch's arrays, and the events latched by each sample are read as its snapshot is
        taken. Answers that template (None: no snapshot was wanted), with the axes' snapshots
        at the stop kept on it when that sample is wanted (StatusTemplate.keep): built in the
        same pass, they serve the snapshot after the stretch if nothing discrete happens there."""
        found = sorted(self._edge_events(stop, stretch, status), key=lambda e: e[:3])
        emitted = 0
        inside = self._wanted_before(stop, stretch, taken)
        at_stop = taken.get(int(stretch.samples[stop]), ()) is None
        template = None
        if inside or at_stop:
            template = self.status_template()
            rows = [*inside, stop] if at_stop else inside
            samples = stretch.samples[rows].tolist()
            values = stretch.values[:, :, rows].transpose(0, 2, 1)
            axes = template.axes_at(samples, values, status.bits[:, :, rows].transpose(0, 2, 1))
            rel = values[REL].tolist()
            if at_stop:  # for the snapshot after the stretch, if nothing discrete happens at its stop
                template.keep(samples.pop(), axes.pop())
                rel.pop()
            for i, sample, axes_then, rel_then in zip(inside, samples, axes, rel, strict=True):
                while emitted < len(found) and found[emitted][0] <= i:
                    self._emit_found(found[emitted], stretch)
                    emitted += 1
                taken[sample] = template.motions_at(sample, axes_then, rel_then), axes_then
        for item in found[emitted:]:
            self._emit_found(item, stretch)
        return template

    @staticmethod
    def _wanted_before(stop: int, stretch: Stretch, taken: dict[int, Snapshots | None]) -> list[int]:
        """The stretch indices before ``stop`` whose snapshots ``taken`` still wants, in order."""
        if not taken:
            return []
        first = int(stretch.samples[0])  # the stretch's samples are consecutive
        return sorted(s - first for s, snaps in taken.items() if snaps is None and 0 <= s - first < stop)

    def _emit_found(self, item: _Found, stretch: Stretch) -> None:
        i, number, _, kind, detail = item
        axis = self.axes[number]
        # The element id at the event's own sample (a path's changes along the stretch).
        self.emit(kind, supervisor=axis.owner, axis=number, move_id=axis.move_id,
                  element_id=axis.element_id_at(float(stretch.rel[number, i])), detail=detail,
                  sample=int(stretch.samples[i]))

    def _edge_events(self, stop: int, stretch: Stretch, status: StretchStatus) -> list[_Found]:
        """The status bits that turn on in samples up to ``stop`` and the frame time limits
        reached, unsorted: (stretch index, axis, rank, type, detail). Read against the bank
        as the stretch found it."""
        bits = status.bits[:EVENT_BITS, :, : stop + 1]
        # Each sample's bits beside the sample's before (the first: the bank's): one pass
        # finds every rising edge of every bit and axis.
        before = self._scratch.take("edges.before", bits.shape, bool)
        before[:, :, 0] = self.bank.bits[:EVENT_BITS]
        before[:, :, 1:] = bits[:, :, :-1]
        rising = np.greater(bits, before, out=before)
        found: list[_Found] = [(i, number, rank, _EDGE_EVENTS[rank], "")
                               for rank, number, i in zip(*(x.tolist() for x in np.nonzero(rising)), strict=True)]
        return found + self._frame_time_limits(stop, stretch)

    def _frame_time_limits(self, stop: int, stretch: Stretch) -> list[_Found]:
        """MPI 000 mpiMotionStart: a frame lasts at most 16,384,000 samples; a plan cut there
        ends abruptly, reported when the axis gets there."""
        rows, duration = self.bank.command_memo("truncated", lambda: _truncated(self.bank.command))
        reached = stretch.rel[rows, : stop + 1] >= duration  # (nan: no plan running)
        if not reached.any():  # (nearly always: one test of them all)
            return []
        waiting = self.bank.rel[rows] < duration[:, 0]  # not there yet
        found = []
        for i in np.flatnonzero(waiting & reached.any(axis=1)).tolist():
            found.append((int(np.argmax(reached[i])), int(rows[i]), -1, MPIEventType.FRAME_TIME_LIMIT,
                          "a frame reached 16,384,000 samples: the axis stopped abruptly"))
        return found


def _truncated(command: CommandRows) -> tuple[np.ndarray, np.ndarray]:
    """The rows whose plan a frame's limit cut, and the (rows, 1) durations of those plans."""
    rows = np.flatnonzero(command.truncated)
    return rows, command.duration[rows, None]
