"""The moves of one motion supervisor: the one in progress, the ones queued behind it
(APPEND), the holds its axes wait on, and how each move ends.

Loading a move puts its plans on the axes; dropping it releases them where their command is.
Every end of a move (done, at velocity, stopped, dropped) is recorded with the controller
(SupervisorHost.record_end) as a MoveEnd at the sample it happened: what the goals that
follow a move wait for (Controller.move_end).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from mpi_ros.mpi.axes.axis import Axis, CommandMode
from mpi_ros.mpi.axes.status import StatusMode
from mpi_ros.mpi.base.clock import ProfileClock
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, MoveEnd, Outcome
from mpi_ros.mpi.base.params import Hold, Output
from mpi_ros.mpi.base.types import STATE_SEVERITY, ActionSource, HoldType, IoSpace, MotionAttr, MPIState, OutputType
from mpi_ros.mpi.host import SupervisorHost
from mpi_ros.mpi.planning import blend
from mpi_ros.mpi.planning.frames import AxisPlan, Move
from mpi_ros.mpi.supervisor.axis_list import AxisList
from mpi_ros.mpi.supervisor.holds import HoldWait
from mpi_ros.mpi.supervisor.state import SupervisorState
from mpi_ros.mpi.supervisor.status import Progress

OK = Message.MPIMessageOK
_ID = int(MotionAttr.ID)  # (an IntFlag's ``in`` is a Python call, an int's & is not)


class Moves:
    """The move in progress (``current``), the queue behind it, the last one that ran and the
    holds its axes wait on, for the supervisor whose ``state`` and ``axis_list`` are given."""

    def __init__(self, host: SupervisorHost, state: SupervisorState, axis_list: AxisList):
        self._host = host
        self._state = state
        self._axis_list = axis_list
        self.current: Move | None = None
        self.queue: deque[Move] = deque()
        self.last_move: Move | None = None
        self.holds: dict[int, HoldWait] = {}
        self.at_velocity_sent = False

    # -- queries -----------------------------------------------------------------------
    def axis(self, number: int) -> Axis:
        return self._host.axes[number]

    @property
    def axes(self) -> list[Axis]:
        """The mapped axes."""
        return [self._host.axes[n] for n in self._axis_list.mapped]

    def pending_serials(self) -> set[int]:
        """The serials of the current and queued moves (and of the appends to them)."""
        pending = {serial for move in self.queue for serial in move.serials()}
        if self.current is not None:
            pending |= self.current.serials()
        return pending

    def find(self, serial: int) -> Move | None:
        """The current or queued move with ``serial`` (a modify keeps the serial it replaces)."""
        for move in reversed(self.queue):
            if move.serial == serial:
                return move
        current = self.current
        return current if current is not None and current.serial == serial else None

    def frames_queued(self, number: int) -> int:
        """Frames axis ``number`` holds beyond the plan it runs: a held plan, queued moves."""
        held = self.current.plan_for(number) if self.axis(number).holding and self.current is not None else None
        count = held.frame_count if held is not None else 0
        return count + sum(m.frame_counts.get(number, 0) for m in self.queue)

    def open_path(self) -> Move | None:
        """The path in progress, if it is open (more points are expected)."""
        move = self.current
        if move is None or move.stream is None or not move.stream.open or self.queue:
            return None
        return move

    def cruising(self) -> bool:
        """A FINAL_VEL move has reached its target and the axes go on at its final velocity."""
        move = self.current  # ends_moving: it ends at its target with a velocity (FINAL_VEL)
        return move is not None and move.ends_moving and all(
            self.axis(p.axis).plan is p and self.axis(p.axis).rel >= p.duration for p in move.plans)

    def progress(self) -> float:
        """0..1 along the current move (profile time over its duration)."""
        return self.progress_of().at(lambda n: self.axis(n).rel)

    def progress_of(self) -> Progress:
        """How :meth:`progress` follows the axes' profile times until the next change of
        move or plan."""
        move = self.current
        if move is None:
            return Progress((1.0,) if self.last_move is not None else (), ())
        fixed: list[float] = []
        spans: list[tuple[int, float]] = []
        for plan in move.plans:
            if self.axis(plan.axis).plan is not plan:
                fixed.append(0.0)
            else:
                spans.append((plan.axis, plan.ramp_end if plan.is_velocity else plan.duration))
        return Progress(tuple(fixed), tuple(spans))

    def element_id(self, move: Move | None) -> int:
        """The move's element id; a path's, of the point its first axis runs toward."""
        axis, fixed = self.element_of(move)
        return fixed if axis is None else axis.current_element_id

    def element_of(self, move: Move | None) -> tuple[Axis | None, int]:
        """Where :meth:`element_id` comes from until the next change of move or plan: the
        axis whose path point gives it (None: none does) and the id otherwise."""
        if move is None:
            return None, 0
        if move.stream is not None and move.plans:
            axis = self.axis(move.plans[0].axis)
            if axis.plan is move.plans[0]:
                return axis, 0
        return None, move.element_id

    def shown_state(self) -> MPIState:
        """The most severe of the supervisor's own state and the states of the supervisors
        commanding its mapped axes (MPI 000: status is derived from each axis' status)."""
        return self.state_for(self._axis_list.mapped)

    def state_for(self, numbers: list[int]) -> MPIState:
        """The state as a command on axes ``numbers`` sees it: the own state, and the states
        of the other supervisors whose motion holds one of them."""
        return self.state_with(self.held_by_others(numbers))

    def state_with(self, held: list[tuple[int, int, MPIState]]) -> MPIState:
        """The own state, or the most severe of it and the states ``held`` gives
        (:meth:`held_by_others`' answer, for a caller that needs both)."""
        own = self._state.own_state
        if not held:
            return own
        return max([own, *(state for _, _, state in held)], key=STATE_SEVERITY.__getitem__)

    def held_by_others(self, numbers: list[int]) -> list[tuple[int, int, MPIState]]:
        """(axis, supervisor, its own state) for each axis of ``numbers`` in the motion of
        another supervisor (one not IDLE)."""
        held: list[tuple[int, int, MPIState]] = []
        for n in numbers:
            owner = self.axis(n).owner
            if owner not in (-1, self._state.number):
                state = self._host.own_state_of(owner)
                if state is not None and state is not MPIState.IDLE:
                    held.append((n, owner, state))
        return held

    def clock_of(self, axis: Axis) -> ProfileClock | None:
        """The clock of the supervisor commanding ``axis`` (None without one)."""
        return self._host.clock_of(axis.owner) if axis.owner >= 0 else None

    def position_of(self, hold: Hold) -> float:
        """The position (user units, continuous: not wrapped at 32 bits) a position hold watches:
        actual or command."""
        axis = self.axis(hold.number)
        return axis.unwrapped_actual if hold.type is HoldType.AXIS_POSITION_ACTUAL else axis.unwrapped_command

    # -- events and ends ---------------------------------------------------------------------
    def emit(self, kind: MPIEventType, axis: int = -1, move: Move | None = None, detail: str = "",
             sample: int | None = None) -> None:
        move = move or self.current
        self._host.emit(kind, supervisor=self._state.number, axis=axis,
                        move_id=move.id if move else 0, element_id=self.element_id(move),
                        detail=detail, extra_mask=move.event_mask if move else MPIEventType.NONE,
                        sample=sample)

    def end_move(self, move: Move, message: Message, detail: str) -> None:
        """Record how ``move`` ended (with the appends to it still pending)."""
        if move.stream is not None:
            detail = f"{detail}; {move.stream.describe_peaks(move.plan_axes)}"
            for serial, _ in move.stream.chunks:
                self.end_serial(serial, message, detail)
            move.stream.chunks.clear()
        self.end_serial(move.serial, message, detail)

    def end_serial(self, serial: int, message: Message, detail: str) -> None:
        axes = self.axes
        self._host.record_end(MoveEnd(serial, Outcome(message, detail), self._host.sample,
                                      tuple(a.command_position for a in axes),
                                      tuple(a.actual_position for a in axes), self._state.number))

    def at_velocity_reached(self) -> None:
        """The velocity move is at velocity (the controller is at that sample): the event,
        and the outcome a goal on this move waits for."""
        assert self.current is not None  # scan found the current move at its velocity
        self.at_velocity_sent = True
        self.emit(MPIEventType.MOTION_AT_VELOCITY)
        self.end_move(self.current, OK, "at velocity")

    def end_now(self, serial: int) -> MoveEnd | None:
        """What the supervisor says now of move ``serial`` when the move recorded no end since
        a goal's sample: ended (the move is gone, or STOPPED, or a FINAL_VEL move at its
        target going on at its final velocity, which never becomes DONE), or None while the
        move runs or waits its turn."""
        sample = self._host.sample
        if serial not in self.pending_serials():
            return MoveEnd(serial, Outcome(Message.MPIMotionMessageIDLE, "the move is no longer on the supervisor"),
                           sample)
        state = self._state
        if state.own_state is MPIState.STOPPED:
            return MoveEnd(serial, Outcome(Message.MPIMotionMessageSTOPPED,
                                           f"stopped by {state.last_action} ({state.action_source.value})"), sample)
        if not self.queue and self.current is not None and self.current.serial == serial and self.cruising():
            return MoveEnd(serial, Outcome(OK, "at target, going on at the final velocity"), sample)
        return None

    # -- changes -------------------------------------------------------------------------------
    def rebase(self, t: float) -> None:
        """The supervisor's axes take their state at ``t`` as the start of their pieces (before
        its clock or their plans change)."""
        axes, number, clock = self._host.axes, self._state.number, self._state.clock
        for n in self._axis_list.mapped:
            axis = axes[n]
            if axis.owner == number:
                axis.rebase(t, clock)

    def drop_pending(self, message: Message, detail: str) -> None:
        """End the move in progress and the queued ones. Every axis that runs (or waits to
        run) a plan of the dropped move is released where its command is now, whether or
        not it is still mapped: no axis keeps motion that no supervisor owns."""
        for move in list(self.queue):
            self.end_move(move, message, detail)
        self.queue.clear()
        if self.current is not None:
            self._release_axes(self.current)
            self.end_move(self.current, message, detail)
            self.last_move = self.current
            self.current = None
        self.holds.clear()

    def _release_axes(self, move: Move) -> None:
        t = self._host.time
        for plan in move.plans:
            axis = self.axis(plan.axis)
            if axis.owner == self._state.number and (axis.plan is plan or axis.holding):
                axis.unload(t, self._state.clock)

    def begin(self, move: Move) -> None:
        """A start: whatever is pending is dropped and ``move`` runs from now."""
        t = self._host.time
        state = self._state
        self.rebase(t)
        self.drop_pending(Message.MPIMotionMessageSTOPPED, "replaced by a new start")
        state.clock = state.clock.ramp_to(t, state.config.normal_feedrate, 0.0)
        state.stop_end = math.inf
        state.enter(MPIState.MOVING, "START", ActionSource.USER)
        self.load(move)

    def replace(self, move: Move) -> None:
        """A modify: the move in progress (and anything appended) becomes ``move``."""
        self.rebase(self._host.time)
        previous = self.current
        for queued in list(self.queue):
            self.end_move(queued, Message.MPIMotionMessageSTOPPED, "replaced by a modify")
        self.queue.clear()
        self.holds.clear()
        if previous is not None:
            move.serial = previous.serial
            if not int(move.attributes) & _ID:
                move.id = previous.id
            if previous.stream is not None:  # points appended to the path are replaced too
                for serial, _ in previous.stream.chunks:
                    self.end_serial(serial, Message.MPIMotionMessageSTOPPED, "replaced by a modify")
        self.load(move, announce=False)

    def load(self, move: Move, announce: bool = True) -> None:
        """Put ``move`` on its axes now (held axes wait for their trigger)."""
        host, state = self._host, self._state
        t, sample = host.time, host.sample
        self.current = move
        self.last_move = move
        self.at_velocity_sent = False
        tau = state.clock.tau_at(t)
        for plan in move.plans:
            axis = self.axis(plan.axis)
            axis.rebase(t, self.clock_of(axis))
            axis.owner = state.number
            axis.move_id = move.id
            axis.element_id = move.element_id
            if axis.amp_enabled:
                axis.mode = CommandMode.SERVO
            axis.status_mode = StatusMode.VELOCITY if plan.is_velocity else StatusMode.POINT_TO_POINT
            if plan.hold is not None:
                axis.unload(t, self.clock_of(axis))
                axis.holding = True
                # The move is loaded and waits (MPI 000, MEIMotionAttrHOLD): its target is the
                # target, as while a DELAY waits (MPI 002 status table: IN_COARSE_POSITION is
                # the distance to it).
                axis.target = plan.target
                self.holds[plan.axis] = HoldWait.begin(
                    plan, move.attributes, sample, host.rate,
                    self.position_of(plan.hold) if HoldWait.watches(plan.hold) else 0.0)
            else:
                axis.load(plan, tau, t, state.clock)
                self.fire_outputs(plan)
        if announce:
            self.emit(MPIEventType.MOTION_START, move=move)
        if self.holds:
            self.release_holds()

    def next_move(self) -> bool:
        """The current move is done: the next queued one runs from now; False if none."""
        self.current = None
        if not self.queue:
            return False
        move = self.queue.popleft()
        if move.blend > 0.0:
            self._blend(move)
        self.load(move)
        return True

    def _blend(self, move: Move) -> None:
        """``move`` starts while the one before still decelerates (blendLimit): what is left of
        that one's profile is added to its plans (planning/blend.py)."""
        t = self._host.time
        for k, plan in enumerate(move.plans):
            axis = self.axis(plan.axis)
            previous = axis.plan
            if previous is None:
                continue
            axis.rebase(t, self.clock_of(axis))
            move.plans[k] = blend.blended(plan, blend.tail(previous.segments, axis.rel), previous.target,
                                           previous.limits)

    def fire_outputs(self, plan: AxisPlan) -> None:
        for output in plan.outputs:
            self.fire_output(output)

    def fire_output(self, output: Output) -> None:
        io = self._host.io
        if output.type is OutputType.MOTOR:
            io.apply_masks(IoSpace.MOTOR_GENERAL_IO, output.motor, output.on_mask, output.off_mask)
        elif output.type is OutputType.OUTPUT:
            io.apply_masks(IoSpace.IO, output.address, output.on_mask, output.off_mask)

    def release_holds(self) -> None:
        """Release holds whose trigger is true now (after a gate or I/O change, a load)."""
        io = self._host.io
        for axis_number, wait in list(self.holds.items()):
            if wait.watches_position:
                fired = bool(wait.position_trigger(np.array([self.position_of(wait.hold)]))[0])
            else:
                fired = wait.static_trigger(io)
            if fired:
                self.release(axis_number, wait, timed_out=False)

    def release(self, axis_number: int, wait: HoldWait, timed_out: bool) -> None:
        """The hold of ``axis_number`` is over: its plan starts now."""
        del self.holds[axis_number]
        t = self._host.time
        clock = self._state.clock
        axis = self.axis(axis_number)
        axis.load(wait.plan, clock.tau_at(t), t, clock)
        self.fire_outputs(wait.plan)
        kind = MPIEventType.HOLD_TIMEOUT if timed_out else MPIEventType.HOLD_RELEASED
        self.emit(kind, axis=axis_number, move=self.current, detail=wait.hold.type.name)

    def still_creeping(self, numbers: list[int]) -> Outcome:
        """The one rule for ending a STOPPED motion (RESET; a remap that drops it): refused
        while one of axes ``numbers`` still moves, as it does at a non-zero pauseFeedrate
        (MPI 000, MPIMotionConfig): dropping its plan would stop it dead in one sample."""
        moving = [n for n in numbers if self.axis(n).cmd_v != 0.0]
        if self._state.own_state is not MPIState.STOPPED or not moving:
            return VALID
        return Outcome(Message.MPIMotionMessageSTOPPED,
                       f"axis {moving[0]} still moves at pauseFeedrate {self._state.config.pause_feedrate:g}: "
                       "ending the stopped motion would stop it dead; RESUME, or E_STOP (it decelerates) and RESET")

    def remap(self) -> Outcome:
        """Write the axis list to the controller (MEIActionMAP).

        A stopped motion's pending profile belongs to the axes it was started on. Mapping a
        list that leaves out one of them drops that profile (the supervisor goes IDLE, as a
        RESET would take it): RESUME could not continue it, and the axes it leaves must not
        keep a plan no supervisor runs. Refused while such an axis still moves (a non-zero
        pauseFeedrate), by the rule RESET follows too (:meth:`still_creeping`)."""
        move, state = self.current, self._state
        # (only a stopped motion is dropped: the axes a running one leaves are not asked for)
        stopped = move is not None and state.own_state is MPIState.STOPPED
        leaving = self._axis_list.leaving(move.plan_axes) if stopped and move is not None else []
        if leaving:
            creeping = self.still_creeping(leaving)
            if not creeping.ok:
                return creeping
            self.rebase(self._host.time)
            self.drop_pending(Message.MPIMotionMessageSTOPPED, "dropped: its axes were remapped")
            state.enter(MPIState.IDLE, "MAP", state.action_source)
        state.config.axis_numbers = list(self._axis_list.commit_mapping())
        return VALID
