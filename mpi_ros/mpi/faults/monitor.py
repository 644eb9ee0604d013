"""Faults of an axis: following error, software position limits, amplifier and encoder
faults, and the underflow of a streamed path's frame buffer (docs/faults.md).

Each fault has a condition and an action (MPIAction: NONE, E_STOP, ABORT, E_STOP_ABORT,
per axis in AxisFaultConfig). When its condition becomes true the fault *trips*: it is
latched on the axis, an event of its own type names it and the axis (the XMP family's
MPIEventType names: LIMIT_ERROR, LIMIT_SW_POSITIVE, ...), and the supervisor commanding
the axis takes the action, as the controller (ActionSource.CONTROLLER). A latched fault
shows in the axis' status and /diagnostics until a RESET of that supervisor clears it;
while its condition still holds, the RESET is refused and says which fault persists.

Conditions found while stepping (following error, limits) are scanned over a stretch at
once, like the supervisors' transitions, and trip at the exact sample they become true:
the controller stops there (Controller._advance), so faults do not depend on how the
samples are batched. The following error's run of samples above its limit is carried
from stretch to stretch at the committed sample. Amplifier and encoder faults are
conditions injected by a command (Controller.axis_fault_inject, recorded like every
command), and so is a one-off trip of any other fault.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING

import numpy as np

from mpi_ros.mpi.axes.status import run_lengths
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import AxisFaultConfig, refuse, shown
from mpi_ros.mpi.base.types import ActionSource, MPIAction

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.axis import Axis
    from mpi_ros.mpi.axes.stretch import Stretch
    from mpi_ros.mpi.host import FaultHost

OK = Message.MPIMessageOK


class Fault(Enum):
    """The faults of an axis, named as their events (events.MPIEventType)."""

    LIMIT_ERROR = "LIMIT_ERROR"  # following error above its limit for longer than its time
    LIMIT_SW_POSITIVE = "LIMIT_SW_POSITIVE"
    LIMIT_SW_NEGATIVE = "LIMIT_SW_NEGATIVE"
    AMP_FAULT = "AMP_FAULT"
    ENCODER_FAULT = "ENCODER_FAULT"
    FRAME_UNDERFLOW = "FRAME_UNDERFLOW"

    @property
    def event(self) -> MPIEventType:
        return MPIEventType[self.value]


# Conditions that come from the hardware: injected on, and they hold until injected off.
INJECTED = (Fault.AMP_FAULT, Fault.ENCODER_FAULT)
_WORDS = {
    Fault.LIMIT_ERROR: "following error",
    Fault.LIMIT_SW_POSITIVE: "positive software limit",
    Fault.LIMIT_SW_NEGATIVE: "negative software limit",
    Fault.AMP_FAULT: "amplifier fault",
    Fault.ENCODER_FAULT: "encoder fault",
    Fault.FRAME_UNDERFLOW: "frame buffer underflow",
}


def action_of(config: AxisFaultConfig, fault: Fault) -> MPIAction:
    """The action ``fault`` takes on an axis of this configuration. The encoder fault's is
    the reference's: "If this motor detects an encoder fault this axis will abort" (MPI 002,
    MPIAxisMaster, encoderFaultMotorNumber)."""
    name = {
        Fault.LIMIT_ERROR: config.following_error_action,
        Fault.LIMIT_SW_POSITIVE: config.software_limit_positive_action,
        Fault.LIMIT_SW_NEGATIVE: config.software_limit_negative_action,
        Fault.AMP_FAULT: config.amp_fault_action,
        Fault.ENCODER_FAULT: "ABORT",
        Fault.FRAME_UNDERFLOW: config.frame_underflow_action,
    }[fault]
    return MPIAction[name]


def error_samples(config: AxisFaultConfig, rate: float) -> int:
    """Consecutive samples the following error must exceed its limit to trip: above it "for
    longer than" the time, so the first sample plus the time (as settling counts samples)."""
    return max(0, math.ceil(config.following_error_time * rate - 1e-9)) + 1


_NO_ROWS = np.zeros(0, dtype=np.int64)
_STEPPED = (Fault.LIMIT_ERROR, Fault.LIMIT_SW_POSITIVE, Fault.LIMIT_SW_NEGATIVE)  # checked while stepping


@dataclass(frozen=True, slots=True)
class _Checks:
    """The axes (rows) that check one condition while stepping, with its limit on each and
    (the following error) the samples it must hold."""

    rows: np.ndarray
    limits: np.ndarray
    need: np.ndarray


def _configured(config: AxisFaultConfig, fault: Fault) -> bool:
    """The condition of ``fault`` is checked while stepping on an axis of this configuration."""
    if fault is Fault.LIMIT_ERROR:
        return config.following_error_limit > 0.0
    if fault is Fault.LIMIT_SW_POSITIVE:
        return config.software_limit_positive_enabled
    return fault is Fault.LIMIT_SW_NEGATIVE and config.software_limit_negative_enabled


def _limit(config: AxisFaultConfig, fault: Fault) -> float:
    return config.software_limit_positive if fault is Fault.LIMIT_SW_POSITIVE else config.software_limit_negative


def _stepping_checks(config: AxisFaultConfig) -> bool:
    """The configuration has a condition checked at every sample (the others are injected)."""
    return any(_configured(config, fault) for fault in _STEPPED)


@dataclass(slots=True)
class AxisFaults:
    """The faults of one axis: its configuration, what is latched, what is injected."""

    config: AxisFaultConfig
    latched: dict[Fault, str] = field(default_factory=dict)  # fault -> why it tripped, in order
    amp_fault: bool = False  # the injected amplifier fault holds


@dataclass(frozen=True, slots=True)
class _Found:
    """A fault a scan found: at stretch index ``index`` on ``axis``, and why."""

    index: int
    axis: int
    fault: Fault
    detail: str


class FaultMonitor:
    """The faults of every axis of a controller."""

    def __init__(self, host: FaultHost):
        self._host = host
        self.axes = [AxisFaults(AxisFaultConfig(encoder_fault_motor_number=n if n < host.config.motors else -1))
                     for n in range(len(host.axes))]
        self.encoder_faults: set[int] = set()  # motors whose encoder has an injected fault
        self._watched: list[int] = []  # axes with a condition checked while stepping (limits)
        self._watched_rows = _NO_ROWS
        # the rows of each condition checked while stepping, with their limits; rebuilt after a
        # change (configuration, a trip, RESET) or when an amplifier goes off or on (the key)
        self._checks: tuple[tuple[bool, ...], dict[Fault, _Checks]] | None = None
        # samples the following error has been above its limit, per axis, at the current sample
        self.error_runs = np.zeros(len(host.axes), dtype=np.int64)
        self._found: list[_Found] = []
        # the axes whose following error the last scan followed, and its runs over the stretch
        self._error_rows = _NO_ROWS
        self._error_runs = np.zeros((0, 0), dtype=np.int64)

    # -- configuration -----------------------------------------------------------------
    def check(self, config: AxisFaultConfig) -> Outcome:
        """The struct's validator, then what only the controller knows (its motors)."""
        verdict = config.validate()
        if verdict.ok and config.encoder_fault_motor_number >= self._host.config.motors:
            return refuse(f"encoder_fault_motor_number: motor {shown(config.encoder_fault_motor_number)} does not "
                          f"exist ({self._host.config.motors} motors)")
        return verdict

    def config_set(self, number: int, config: AxisFaultConfig) -> Outcome:
        verdict = self.check(config)
        if not verdict.ok:
            return verdict
        faults = self.axes[number]
        faults.config = config.copy()
        self.error_runs[number] = 0  # a new limit counts from here
        self._watched = [n for n, f in enumerate(self.axes) if _stepping_checks(f.config)]
        self._watched_rows = np.array(self._watched, dtype=np.int64)
        self._checks = None
        if config.encoder_fault_motor_number in self.encoder_faults:
            self._trip_encoder(number, config.encoder_fault_motor_number)
        return verdict

    def names(self, number: int) -> tuple[str, ...]:
        """The faults latched on an axis (what its status shows)."""
        return tuple(fault.value for fault in self.axes[number].latched)

    # -- stepping ----------------------------------------------------------------------
    def scan(self, stretch: Stretch) -> int | None:
        """The first stretch index at which a fault trips (following error, limits), or None.
        What was found is kept for :meth:`transition`. The axes that check a condition are
        computed together (rows of the stretch), so a scan costs a few array operations
        however many axes are watched."""
        self._found = []
        self._error_rows = _NO_ROWS
        if not self._watched:
            return None
        self._scan_error(stretch)
        for fault in (Fault.LIMIT_SW_POSITIVE, Fault.LIMIT_SW_NEGATIVE):
            self._scan_limit(fault, stretch)
        return min((found.index for found in self._found), default=None)

    def _stepped(self) -> dict[Fault, _Checks]:
        """The rows that check each condition now (:class:`_Checks`), kept until they change."""
        axes = self._host.axes
        amps = tuple(axes[n].amp_enabled for n in self._watched)
        if self._checks is None or self._checks[0] != amps:
            self._checks = (amps, {fault: self._rows(fault) for fault in _STEPPED})
        return self._checks[1]

    def _rows(self, fault: Fault) -> _Checks:
        """The watched axes that check ``fault``: configured, not latched, and for the
        following error with the amplifier on (off, the command is frozen and the motor
        coasts: there is no loop to follow)."""
        axes, faults = self._host.axes, self.axes
        rows = [n for n in self._watched if fault not in faults[n].latched and _configured(faults[n].config, fault)
                and (fault is not Fault.LIMIT_ERROR or axes[n].amp_enabled)]
        configs = [faults[n].config for n in rows]
        if fault is Fault.LIMIT_ERROR:
            limits = [c.following_error_limit for c in configs]
        else:
            limits = [_limit(c, fault) for c in configs]
        return _Checks(np.array(rows, dtype=np.int64), np.array(limits, dtype=float),
                       np.array([error_samples(c, self._host.rate) for c in configs], dtype=np.int64))

    def _scan_error(self, stretch: Stretch) -> None:
        """|command - actual| above the limit for longer than the configured time."""
        checks = self._stepped()[Fault.LIMIT_ERROR]
        rows, limits, need = checks.rows, checks.limits, checks.need
        if not len(rows):
            return
        error = np.abs(stretch.cmd_p[rows] - stretch.act_p[rows])
        above = error > limits[:, None]
        if not above.any():
            return  # no run anywhere: every carry is 0 (commit)
        runs = run_lengths(above, self.error_runs[rows])
        self._error_rows, self._error_runs = rows, runs
        tripped = runs >= need[:, None]
        for r in np.flatnonzero(tripped.any(axis=1)).tolist():
            i = int(np.argmax(tripped[r]))
            self._found.append(_Found(i, int(rows[r]), Fault.LIMIT_ERROR,
                                      f"following error {error[r, i]:.1f} counts above the limit "
                                      f"{limits[r]:g} for {need[r]} samples"))

    def _scan_limit(self, fault: Fault, stretch: Stretch) -> None:
        """The actual position (user coordinates, as the encoder reads it) beyond a limit."""
        checks = self._stepped()[fault]
        rows, limits = checks.rows, checks.limits
        if not len(rows):
            return
        axes = self._host.axes
        origins = np.array([axes[n].origin for n in rows.tolist()])
        position = stretch.act_p[rows] - origins[:, None]
        beyond = position > limits[:, None] if fault is Fault.LIMIT_SW_POSITIVE else position < limits[:, None]
        for r in np.flatnonzero(beyond.any(axis=1)).tolist():
            i = int(np.argmax(beyond[r]))
            self._found.append(_Found(i, int(rows[r]), fault, f"actual position {position[r, i]:.1f} beyond the "
                                                              f"{_WORDS[fault]} {limits[r]:g}"))

    def commit(self, stop: int) -> None:
        """The controller keeps stretch index ``stop``: carry the following-error runs (0 on
        an axis whose error was not followed)."""
        if not self._watched:
            return
        self.error_runs[self._watched_rows] = 0
        if len(self._error_rows):
            self.error_runs[self._error_rows] = self._error_runs[:, stop]

    def transition(self, index: int) -> None:
        """Trip what :meth:`scan` found at stretch index ``index`` (the controller is there)."""
        found, self._found = self._found, []
        for item in sorted(found, key=lambda f: (f.axis, list(Fault).index(f.fault))):
            if item.index == index:
                self.trip(item.axis, item.fault, item.detail)

    # -- tripping ----------------------------------------------------------------------
    def trip(self, number: int, fault: Fault, detail: str) -> None:
        """Latch ``fault`` on axis ``number``, tell it (the fault's event), take its action."""
        faults = self.axes[number]
        if fault in faults.latched:
            return
        faults.latched[fault] = detail
        self._checks = None
        axis = self._host.axes[number]
        action = action_of(faults.config, fault)
        supervisors = self._supervisors_of(axis)
        self._host.emit(fault.event, supervisor=supervisors[0] if supervisors else -1, axis=number,
                       move_id=axis.move_id, element_id=axis.current_element_id,
                       detail=f"{fault.value} ({_WORDS[fault]}) on axis {number}: {detail}; action {action.name}")
        if fault is Fault.AMP_FAULT and axis.amp_enabled:
            axis.amp_fault(self._host.time, self._host.clock_of(axis.owner) if axis.owner >= 0 else None)
        if action is not MPIAction.NONE:
            for number in supervisors:
                self._host.act_on(number, action, ActionSource.CONTROLLER)

    def _supervisors_of(self, axis: Axis) -> list[int]:
        """Who acts on a fault of ``axis``: the supervisor commanding it, else every one it
        is mapped to (an action on shared axes reaches the motion that runs them)."""
        return self._host.responsible_for(axis.number)

    def underflow(self, numbers: Sequence[int]) -> None:
        """An open path's frame buffer ran empty on these axes while it moves."""
        for number in numbers:
            self.trip(number, Fault.FRAME_UNDERFLOW,
                      "the streamed path ran out of points while more are expected (final false)")

    def watches_underflow(self, numbers: Sequence[int]) -> bool:
        """An underflow of these axes would trip something (not every one has it latched)."""
        return any(Fault.FRAME_UNDERFLOW not in self.axes[n].latched for n in numbers)

    # -- injection ---------------------------------------------------------------------
    def inject(self, number: int, name: object, active: bool) -> Outcome:
        """Inject a fault on an axis: AMP_FAULT and ENCODER_FAULT set (``active``) or clear
        a condition that holds until cleared; the others trip once, as if detected."""
        fault = Fault.__members__.get(str(name).strip().upper()) if isinstance(name, str) else None
        if fault is None:
            return Outcome(Message.MPIMessagePARAM_INVALID,
                           f"fault: unknown fault {shown(name)} ({', '.join(f.value for f in Fault)})")
        if fault is Fault.AMP_FAULT:
            self.axes[number].amp_fault = active
            if active:
                self.trip(number, fault, "amplifier fault injected: amplifier disabled, the motor coasts")
            return Outcome(OK)
        if fault is Fault.ENCODER_FAULT:
            return self._inject_encoder(number, active)
        if not active:
            return Outcome(Message.MPIMessagePARAM_INVALID, f"fault: {fault.value} is not a condition that holds: "
                           "it trips once (active true) and is cleared by RESET")
        self.trip(number, fault, "injected")
        return Outcome(OK)

    def _inject_encoder(self, number: int, active: bool) -> Outcome:
        """The encoder of the axis' own motor (axis k drives motor k)."""
        if number >= self._host.config.motors:
            motors = self._host.config.motors
            return Outcome(Message.MPIMessagePARAM_INVALID, f"axis {number} has no motor ({motors} motors)")
        if not active:
            self.encoder_faults.discard(number)
            return Outcome(OK)
        self.encoder_faults.add(number)
        for watcher, faults in enumerate(self.axes):
            if faults.config.encoder_fault_motor_number == number:
                self._trip_encoder(watcher, number)
        return Outcome(OK)

    def _trip_encoder(self, number: int, motor: int) -> None:
        self.trip(number, Fault.ENCODER_FAULT, f"the encoder of motor {motor} faulted")

    # -- RESET -------------------------------------------------------------------------
    def persisting(self, numbers: list[int]) -> list[str]:
        """The latched faults of these axes whose condition still holds, in words."""
        out = []
        for number in numbers:
            for fault in self.axes[number].latched:
                why = self._holds(number, fault)
                if why:
                    out.append(f"axis {number} {fault.value} persists ({why})")
        return out

    def _holds(self, number: int, fault: Fault) -> str:
        """Why the condition of ``fault`` still holds on axis ``number`` ("" if it does not)."""
        faults, axis = self.axes[number], self._host.axes[number]
        config = faults.config
        if fault is Fault.LIMIT_ERROR:
            # with the amplifier off RESET sets the command to the actual: no error is left
            limit = config.following_error_limit
            error = abs(axis.position_error)
            held = limit > 0.0 and axis.amp_enabled and error > limit
            return f"following error {error:.1f} > {limit:g} counts" if held else ""
        if fault is Fault.LIMIT_SW_POSITIVE:
            held = config.software_limit_positive_enabled and axis.unwrapped_actual > config.software_limit_positive
            return f"actual position {axis.unwrapped_actual:.1f} > {config.software_limit_positive:g}" if held else ""
        if fault is Fault.LIMIT_SW_NEGATIVE:
            held = config.software_limit_negative_enabled and axis.unwrapped_actual < config.software_limit_negative
            return f"actual position {axis.unwrapped_actual:.1f} < {config.software_limit_negative:g}" if held else ""
        if fault is Fault.AMP_FAULT:
            return "the amplifier fault is still active" if faults.amp_fault else ""
        if fault is Fault.ENCODER_FAULT:
            motor = config.encoder_fault_motor_number
            return f"the encoder of motor {motor} still faults" if motor in self.encoder_faults else ""
        return ""  # FRAME_UNDERFLOW: over once the path is dropped

    def latched_on(self, numbers: list[int]) -> bool:
        return any(self.axes[n].latched for n in numbers)

    def clear(self, numbers: list[int]) -> set[int]:
        """RESET: clear the latched faults of these axes; the axes whose amplifier faulted
        (their command must be set to the actual as the amplifier comes back on)."""
        amp = set()
        for number in numbers:
            faults = self.axes[number]
            if Fault.AMP_FAULT in faults.latched:
                amp.add(number)
            faults.latched.clear()
            self.error_runs[number] = 0
        self._checks = None
        return amp
