"""Parameter and configuration structs of the MPI as dataclasses (units: counts, seconds).

C pointers become data (docs/decisions.md, "The ROS contract: names, numbers, arrays"): a
NULL array is an empty list here, a hold or output is a value, an I/O address is the index of
a word in the simulated I/O image.

Each struct has one validator, ``validate() -> Outcome``: the ranges a controller can
hold (docs/decisions.md, "Validation and ranges"). The YAML loader, the services and
the controller all call it, so a value is accepted or refused the same way whatever
way it comes in, and a value the controller accepted can never break its clock.
"""

from __future__ import annotations

import copy
import math
import numbers
import reprlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Protocol, TypeGuard

from mpi_ros.mpi.base.events import MASK_ALL, MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, Outcome
from mpi_ros.mpi.base.types import (
    HOLD_ATTRS,
    AxisMasterType,
    HoldType,
    MotionAttr,
    OutputType,
)

MAX_COORD_AXES = 8  # MEIXmpMAX_COORD_AXES
MAX_GATES = 32  # gate numbers 0..31 (MPI 000 MEIMotionAttrHoldSource)
VELOCITY_FRAME_LIMIT_SAMPLES = 16_384_000  # MPI 000 mpiMotionStart
ID_BITS = 16  # MPI 000 MPIMotionAttributes: "limited to 16-bit resolution"
USER_LABEL_MAX = 16  # MEIObjectLabelCharMAX

# -- ranges (docs/decisions.md "Validation and ranges") -------------------------------------
LONG_MIN, LONG_MAX = -(2**31), 2**31 - 1  # the MPI's C long (32 bits)
FLOAT_MAX = 3.4028234663852886e38  # the MPI's C float (MPIAxisInPosition, MPIMotionConfig)
SAMPLE_RATE_MIN, SAMPLE_RATE_MAX = 1.0, 100_000.0  # Hz
# The sample counter is a C long: a duration must fit in 2^31 - 1 samples. Bounding it at the
# highest allowed rate makes it fit at every rate (5.96 h).
MAX_DURATION = LONG_MAX / SAMPLE_RATE_MAX  # seconds
# Positions are doubles. A raw position is a user position plus the origin, and a relative
# move adds a distance: below 2^47 each, their sums stay below 2^49, where a double still
# resolves 1/16 count (far finer than any settling tolerance).
MAX_POSITION = 2.0**47  # counts
MAX_VELOCITY = 1e12  # counts/s
MAX_ACCELERATION = 1e15  # counts/s^2
MAX_JERK = 1e18  # counts/s^3
MAX_RATIO = 1e6  # a cam's gear ratio (slave counts per master count)
FEEDRATE_MIN, FEEDRATE_MAX = 1e-3, 1e3  # 0.1 % .. 100,000 % of the programmed speed
# The simulated servo: the closed-form response of an over-damped loop overflows after a
# few seconds of one command piece, so the loop is at most critically damped.
BANDWIDTH_MIN_HZ, BANDWIDTH_MAX_HZ = 0.01, SAMPLE_RATE_MAX / 2.0
DAMPING_MAX = 1.0
FEEDFORWARD_MAX = 10.0
MAX_OBJECTS = 1024  # axes, supervisors and motors of one controller
FRAME_BUFFER_MIN, FRAME_BUFFER_MAX = 16, 65_536  # frames per axis
IO_WORDS_MAX = 65_536
# The size of one request (a goal or a service request; docs/hostile-input.md). A request is
# read only if it carries at most MAX_REQUEST_VALUES array elements over all its arrays (a
# path's positions, times, velocities ... together) and MAX_REQUEST_TEXT characters over all
# its strings; a larger one is refused with MPIMessagePARAM_INVALID before any of its values
# is read or kept (mpi_ros/requests.py, check_size). It bounds what one request may cost: the
# time the controller is held planning it, the memory it claims, and what the commands topic
# and recordings keep of it. A longer path is streamed in parts (APPEND), as a frame buffer
# (at most FRAME_BUFFER_MAX frames per axis) is fed anyway.
MAX_REQUEST_VALUES = 1 << 16
MAX_REQUEST_TEXT = 1 << 14
# The attributes whose arrays MotionParams.validate reads, as ints (an IntFlag's & makes a member)
_DELAY, _FINAL_VEL, _HOLDS, _OUTPUT = (int(MotionAttr.DELAY), int(MotionAttr.FINAL_VEL), int(HOLD_ATTRS),
                                       int(MotionAttr.OUTPUT))
_EVERY_ATTRIBUTE = -1  # every bit set: validate(None) reads every attribute's array




_SHOWN = reprlib.Repr()
_SHOWN.maxstring = _SHOWN.maxother = 80
_SHOWN.maxlist = _SHOWN.maxtuple = _SHOWN.maxdict = _SHOWN.maxset = 8


def shown(value: object) -> str:
    """``repr(value)`` cut short (a long string, list or number shows its ends): what a
    refusal quotes of the value it refuses, so an answer never carries a 100 kB string back."""
    try:
        return _SHOWN.repr(value)
    except Exception:  # noqa: BLE001 - a repr that fails (an int beyond str's digit limit) shows its type
        return f"<{type(value).__name__}>"


def refuse(detail: str, message: Message = Message.MPIMessagePARAM_INVALID) -> Outcome:
    return Outcome(message, detail)


def first_refusal(verdicts: Iterable[Outcome]) -> Outcome:
    """The first verdict that refuses, else VALID."""
    for verdict in verdicts:
        if not verdict.ok:
            return verdict
    return VALID


def _finite_number(value: object) -> TypeGuard[float]:
    """A finite real number (bool excluded): int, float, numpy's, ..."""
    if type(value) is float:  # nearly every value checked (no ABC check for it)
        return math.isfinite(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an int beyond every double: not a finite number here
        return False


def check_range(name: str, value: object, low: float, high: float, above_low: bool = False) -> Outcome:
    """``value`` is a finite number within [low, high] ((low, high] with ``above_low``)."""
    if _finite_number(value) and low <= value <= high and not (above_low and value == low):
        return VALID
    lower = f"> {low:g}" if above_low else f">= {low:g}"
    return refuse(f"{name}: must be a finite number {lower} and <= {high:g}, got {shown(value)}")


def check_frame_buffer_size(name: str, value: object) -> Outcome:
    """Frames per axis (MPI 000 mpiMotionStart: 128 by default)."""
    return check_integer(name, value, FRAME_BUFFER_MIN, FRAME_BUFFER_MAX)


def check_integer(name: str, value: object, low: int, high: int) -> Outcome:
    if type(value) is int and low <= value <= high:  # nearly every value checked (no ABC check for it)
        return VALID
    if isinstance(value, numbers.Integral) and not isinstance(value, bool) and low <= int(value) <= high:
        return VALID
    return refuse(f"{name}: must be an integer >= {low} and <= {high}, got {shown(value)}")


def check_long(name: str, value: object) -> Outcome:
    """An integer a C long (the MPI's 32 bits) holds."""
    return check_integer(name, value, LONG_MIN, LONG_MAX)


def check_bool(name: str, value: object) -> Outcome:
    return VALID if isinstance(value, bool) else refuse(f"{name}: must be true or false, got {shown(value)}")


def check_magnitude(name: str, value: object, limit: float) -> Outcome:
    if _finite_number(value) and abs(value) <= limit:
        return VALID
    return refuse(f"{name}: must be a finite number of magnitude <= {limit:g}, got {shown(value)}")


def check_position(name: str, value: object) -> Outcome:
    """A position, origin or distance (counts)."""
    return check_magnitude(name, value, MAX_POSITION)


def check_duration(name: str, value: object, positive: bool = False) -> Outcome:
    """A time in seconds that fits the sample counter (> 0 with ``positive``)."""
    return check_range(name, value, 0.0, MAX_DURATION, above_low=positive)


def _magnitudes(struct: object, limits: tuple[tuple[str, float], ...]) -> Outcome:
    """check_magnitude of each (field, limit) of ``struct`` in turn: the first refusal, else
    VALID. A finite float within its limit, nearly every value, passes on one test here (abs
    of a NaN or an infinity is not <= a limit); any other is check_magnitude's to answer."""
    for name, limit in limits:
        value = getattr(struct, name)
        if type(value) is not float or not abs(value) <= limit:
            verdict = check_magnitude(name, value, limit)
            if not verdict.ok:
                return verdict
    return VALID


def _longs(struct: object, names: tuple[str, ...]) -> Outcome:
    """check_long of each field ``names`` of ``struct`` in turn: the first refusal, else VALID
    (a plain int in range passes on one test, as in check_integer)."""
    for name in names:
        value = getattr(struct, name)
        if type(value) is not int or not LONG_MIN <= value <= LONG_MAX:
            verdict = check_long(name, value)
            if not verdict.ok:
                return verdict
    return VALID


def _each_magnitude(name: str, values: Iterable[object], limit: float) -> Outcome:
    """:func:`_each` with check_magnitude at ``limit``, a finite float within it passing on one
    test (as in :func:`_magnitudes`)."""
    for i, value in enumerate(values):
        if type(value) is not float or not abs(value) <= limit:
            verdict = check_magnitude(f"{name}[{i}]", value, limit)
            if not verdict.ok:
                return verdict
    return VALID


def _each(name: str, values: Iterable[object], check: Callable[[str, object], Outcome]) -> Outcome:
    """The first of ``values`` that ``check`` refuses, named by its index ("position[3]: ..."),
    else VALID. The indexed name is made for a refusal only: every value of every start and
    modify passes through here."""
    for i, value in enumerate(values):
        if not check(name, value).ok:
            return check(f"{name}[{i}]", value)
    return VALID


class _Validated(Protocol):
    """A parameter struct that checks itself (Trajectory, MotionHold, MotionOutput, ...)."""

    def validate(self) -> Outcome: ...


def _each_struct(name: str, structs: Iterable[_Validated]) -> Outcome:
    """The first refusal of ``structs``' validators, prefixed by the struct's index, else VALID."""
    for i, struct in enumerate(structs):
        verdict = struct.validate()
        if not verdict.ok:
            return verdict.prefixed(f"{name}[{i}].")
    return VALID


# Trajectory's fields and the magnitude each may have
_TRAJECTORY_LIMITS = (("velocity", MAX_VELOCITY), ("acceleration", MAX_ACCELERATION),
                      ("deceleration", MAX_ACCELERATION), ("jerk_percent", 100.0),
                      ("acceleration_jerk", MAX_JERK), ("deceleration_jerk", MAX_JERK))


@dataclass(slots=True)
class Trajectory:
    """MPITrajectory."""

    velocity: float = 0.0
    acceleration: float = 0.0
    deceleration: float = 0.0
    jerk_percent: float = 0.0
    acceleration_jerk: float = 0.0
    deceleration_jerk: float = 0.0

    def share(self, share: float) -> Trajectory:
        """An axis' share of a vector's limits (jerk percent is a ratio and stays)."""
        return Trajectory(self.velocity * share, self.acceleration * share, self.deceleration * share,
                          self.jerk_percent, self.acceleration_jerk * share, self.deceleration_jerk * share)

    def validate(self) -> Outcome:
        """Magnitudes a controller can hold. Which must be positive depends on the motion
        type and is checked with the move (validate.check_params): VELOCITY ignores the
        deceleration, the jerk types the jerk percentage (MPI 000, MPIMotionSCurve and
        MPIMotionVelocity: the trajectory parameters each type reads)."""
        return _magnitudes(self, _TRAJECTORY_LIMITS)



_HOLD_LONGS = ("gate", "number", "address", "mask", "pattern")


@dataclass(slots=True)
class Hold:
    """MEIMotionAttrHold; ``timeout`` in seconds, 0 waits forever."""

    type: HoldType = HoldType.NONE
    gate: int = 0
    number: int = 0
    address: int = 0
    mask: int = 0
    pattern: int = 0
    position: float = 0.0
    timeout: float = 0.0

    def validate(self) -> Outcome:
        """The trigger position, the timeout, and C longs (the MPI's 32 bits) elsewhere; the
        source (gate, word, motor, axis) is checked against the controller's objects with
        the move (validate.check_params)."""
        return first_refusal((
            _longs(self, _HOLD_LONGS),
            check_position("position", self.position),
            check_duration("timeout", self.timeout),
        ))


_OUTPUT_LONGS = ("motor", "address", "on_mask", "off_mask", "point_index")


@dataclass(slots=True)
class Output:
    """MEIMotionAttrOutput."""

    type: OutputType = OutputType.NONE
    motor: int = 0
    address: int = 0
    on_mask: int = 0
    off_mask: int = 0
    point_index: int = 0

    def validate(self) -> Outcome:
        """C longs (32 bits, as the ROS interface's int32); the motor or I/O word is checked
        against the controller's objects with the move (validate.check_params)."""
        return _longs(self, _OUTPUT_LONGS)


@dataclass(slots=True)
class UserFrame:
    """MEIXmpFrame as given to a FRAME move: one constant-jerk segment."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0
    jerk: float = 0.0
    time: float = 0.0

    def validate(self) -> Outcome:
        return first_refusal((
            check_position("position", self.position),
            check_magnitude("velocity", self.velocity, MAX_VELOCITY),
            check_magnitude("acceleration", self.acceleration, MAX_ACCELERATION),
            check_magnitude("jerk", self.jerk, MAX_JERK),
            check_duration("time", self.time),
        ))


# (empty_count: any value, <= 0 disables, MotionParams.empty_count_disabled)
_PARAMS_LONGS = ("empty_count", "id", "master_start", "repeat_from", "behavior", "low_count", "expected_axes")


@dataclass(slots=True)
class MotionParams:
    """MPIMotionParams with MPIMotionAttributes and MEIMotionAttributes, flattened."""

    trajectory: list[Trajectory] = field(default_factory=list)
    position: list[float] = field(default_factory=list)
    point_velocity: list[float] = field(default_factory=list)
    time: list[float] = field(default_factory=list)
    feedforward: list[float] = field(default_factory=list)
    final: bool = True
    retain: bool = False
    empty_count: int = 5
    delay: list[float] = field(default_factory=list)
    id: int = 0
    element_id: list[int] = field(default_factory=list)
    final_velocity: list[float] = field(default_factory=list)
    hold: list[Hold] = field(default_factory=list)
    output: list[Output] = field(default_factory=list)
    event_mask: MPIEventType = MPIEventType.NONE
    master_start: int = 0
    repeat_from: int = 0
    master_distance: list[float] = field(default_factory=list)
    slave_position: list[float] = field(default_factory=list)
    gear_ratio: list[float] = field(default_factory=list)
    frames: list[UserFrame] = field(default_factory=list)
    # MPIMotionPathAttributes (MPI 001), each read only with its attribute.
    behavior: int = 0  # BEHAVIOR
    low_count: int = 0  # LOW_COUNT: FRAMES_LOW below this many points
    expected_axes: int = 0  # EXPECTED_AXES: must equal the mapped axes

    def copy(self) -> MotionParams:
        return copy.deepcopy(self)

    @property
    def empty_count_disabled(self) -> bool:
        """MPI 000 MPIMotionPoint: emptyCount (-1) disables the E_STOP on a starving buffer;
        MPI 001 MPIMotionPathAttrMask EMPTY_COUNT: "To disable path-based deceleration, set
        the value to zero". Both do, and so does any value below: emptyCount <= 0 (no buffer
        holds fewer than 0 points, so the trigger could never fire anyway)."""
        return self.empty_count <= 0

    def validate(self, attributes: MotionAttr | None = None, position: bool = True, path_data: bool = True) -> Outcome:
        """The values a move with ``attributes`` uses (None: every value, as mpiMotionParamsSet
        stores them for any later start). Values a move ignores are not read: ``position``
        and ``path_data`` (times, point velocities, feedforward, cam tables, frames) only if
        its family reads them (planning/families.py; MPI 000 MPIMotionSCurve, position:
        VELOCITY "will ignore these values"), an attribute's array only with the attribute.
        Lengths are checked with the move."""

        bits = _EVERY_ATTRIBUTE if attributes is None else int(attributes)
        return first_refusal((
            _each_magnitude("position", self.position, MAX_POSITION) if position else VALID,
            _each_struct("trajectory", self.trajectory),
            check_bool("final", self.final),
            check_bool("retain", self.retain),
            _longs(self, _PARAMS_LONGS),
            _each("element_id", self.element_id, check_long),
            _each("delay", self.delay, check_duration) if bits & _DELAY else VALID,
            _each_magnitude("final_velocity", self.final_velocity, MAX_VELOCITY) if bits & _FINAL_VEL else VALID,
            _each_struct("hold", self.hold) if bits & _HOLDS else VALID,
            _each_struct("output", self.output) if bits & _OUTPUT else VALID,
            self._path_data() if path_data else VALID,
        ))

    def _path_data(self) -> Outcome:
        """Path, cam and frame data (read only by those types)."""
        return first_refusal((
            _each_magnitude("point_velocity", self.point_velocity, MAX_VELOCITY),
            _each("time", self.time, check_duration),
            _each_magnitude("feedforward", self.feedforward, MAX_VELOCITY),
            _each_magnitude("master_distance", self.master_distance, MAX_POSITION),
            _each_magnitude("slave_position", self.slave_position, MAX_POSITION),
            _each_magnitude("gear_ratio", self.gear_ratio, MAX_RATIO),
            _each_struct("frames", self.frames),
        ))


@dataclass(slots=True)
class DecelTime:
    """MPIMotionDecelTime (seconds)."""

    stop: float = 0.5
    e_stop: float = 0.05

    def validate(self) -> Outcome:
        """Durations (MPI 000 MPIMotionDecelTime, seconds); a stop takes some time."""
        return first_refusal((check_duration("stop", self.stop, positive=True),
                              check_duration("e_stop", self.e_stop, positive=True)))


@dataclass(slots=True)
class MotionConfig:
    """MPIMotionConfig + MEIMotionConfig (axisCount/axisNumber are read from the mapping)."""

    decel_time: DecelTime = field(default_factory=DecelTime)
    normal_feedrate: float = 1.0
    pause_feedrate: float = 0.0
    user_label: str = ""
    axis_numbers: list[int] = field(default_factory=list)
    blend_limit: float = -1.0

    @property
    def axis_count(self) -> int:
        return len(self.axis_numbers)

    def copy(self) -> MotionConfig:
        return copy.deepcopy(self)

    def validate(self) -> Outcome:
        """MPI 000 MPIMotionConfig/MEIMotionConfig. The decel times are named as the ROS
        interface and the YAML name them (decel_time_stop); axis_numbers is read only."""
        return first_refusal((
            self.decel_time.validate().prefixed("decel_time_"),
            check_range("normal_feedrate", self.normal_feedrate, FEEDRATE_MIN, FEEDRATE_MAX),
            self._pause_feedrate(),
            check_range("blend_limit", self.blend_limit, -1.0, 1.0),  # a cosine (MEIMotionConfig)
            self._user_label(),
        ))

    def _pause_feedrate(self) -> Outcome:
        # 0 (the default) stops; a pause feedrate above 0 keeps the axes crawling and is held
        # to the range of the normal one.
        if self.pause_feedrate == 0.0 and _finite_number(self.pause_feedrate):
            return VALID
        return check_range("pause_feedrate", self.pause_feedrate, FEEDRATE_MIN, FEEDRATE_MAX)

    def _user_label(self) -> Outcome:
        if isinstance(self.user_label, str) and len(self.user_label) <= USER_LABEL_MAX:
            return VALID
        return refuse(f"user_label: at most {USER_LABEL_MAX} characters (MEIObjectLabelCharMAX), "
                      f"got {shown(self.user_label)}")


@dataclass(slots=True)
class AxisInPosition:
    """MPIAxisInPosition. The spec gives no numeric defaults but for the velocity
    tolerance ("so large that this criteria is ignored"); these are this project's."""

    position_fine: float = 10.0
    position_coarse: int = 100
    velocity: float = 1.0e9
    settling_time: float = 0.01
    settle_on_stop: bool = False
    settle_on_estop: bool = False
    settle_on_estop_cmd_eq_act: bool = False

    def copy(self) -> AxisInPosition:
        return copy.deepcopy(self)

    def validate(self) -> Outcome:
        """MPI 002 MPIAxisInPosition. The tolerances are compared with a strict "<" (the
        NOTEs under the status tables), so a zero tolerance could never be met."""
        return first_refusal((
            check_range("position_fine", self.position_fine, 0.0, MAX_POSITION, above_low=True),
            check_integer("position_coarse", self.position_coarse, 0, LONG_MAX),
            check_range("velocity", self.velocity, 0.0, FLOAT_MAX, above_low=True),
            check_duration("settling_time", self.settling_time),
            check_bool("settle_on_stop", self.settle_on_stop),
            check_bool("settle_on_estop", self.settle_on_estop),
            check_bool("settle_on_estop_cmd_eq_act", self.settle_on_estop_cmd_eq_act),
        ))


@dataclass(slots=True)
class AxisMaster:
    """MPIAxisMaster with MPIAxisConfig.masterCorrection (MPI 002): where the master position a
    cam on this axis follows comes from. ``number`` is the motor (MOTOR_FEEDBACK_*) or the axis
    (AXIS_*), ``address`` the I/O word (ADDRESS); the other one is "Not used" (MPI 002,
    MPIAxisMaster) and not checked. ``correction``: the axis whose command position is added
    to the master position (masterCorrection; -1: none, docs/cams.md).
    ``encoder_fault_motor_number``: MPIAxisMaster.encoderFaultMotorNumber, the motor whose
    encoder fault aborts this axis (-1: none). Its one home is the axis' fault configuration
    (AxisFaultConfig, which the fault monitor acts on): the controller fills it in on a get,
    and on a set None keeps the current value (docs/decisions.md, "encoderFaultMotorNumber")."""

    type: AxisMasterType = AxisMasterType.AXIS_COMMANDED_POSITION
    number: int = 0
    address: int = 0
    correction: int = -1
    encoder_fault_motor_number: int | None = None

    def copy(self) -> AxisMaster:
        return copy.deepcopy(self)

    def validate(self, axes: int = MAX_OBJECTS, motors: int = MAX_OBJECTS, io_words: int = IO_WORDS_MAX) -> Outcome:
        """Against a controller of ``axes`` axes, ``motors`` motors and ``io_words`` I/O words.
        The primary feedback of motor n is the encoder of axis n's motor (the simulated plant),
        so it needs an axis n; a secondary input exists for every motor."""
        if not isinstance(self.type, AxisMasterType):
            return refuse(f"type: must be one of {[t.name for t in AxisMasterType]}, got {shown(self.type)}")
        bounds = {AxisMasterType.MOTOR_FEEDBACK_PRIMARY: ("number", self.number, min(axes, motors)),
                  AxisMasterType.MOTOR_FEEDBACK_SECONDARY: ("number", self.number, motors),
                  AxisMasterType.AXIS_COMMANDED_POSITION: ("number", self.number, axes),
                  AxisMasterType.AXIS_ACTUAL_POSITION: ("number", self.number, axes),
                  AxisMasterType.ADDRESS: ("address", self.address, io_words)}
        name, value, count = bounds[self.type]
        return first_refusal((
            check_integer(name, value, 0, count - 1),
            check_integer("correction", self.correction, -1, axes - 1),
            (VALID if self.encoder_fault_motor_number is None
             else check_integer("encoder_fault_motor_number", self.encoder_fault_motor_number, -1, motors - 1)),
        ))


@dataclass(slots=True)
class SecondaryFeedback:
    """The secondary feedback input of a motor (MPI 002, MPIAxisMasterTypeMOTOR_FEEDBACK_SECONDARY):
    a second encoder, such as a line shaft's, that reads ``position`` when it is set and moves
    on at ``velocity`` (docs/cams.md)."""

    position: float = 0.0
    velocity: float = 0.0

    def validate(self) -> Outcome:
        return first_refusal((check_position("position", self.position),
                              check_magnitude("velocity", self.velocity, MAX_VELOCITY)))


@dataclass(slots=True)
class PlantConfig:
    """The simulated servo: a closed position loop of the given bandwidth and damping,
    with velocity/acceleration feed-forward, read through an encoder of the given
    resolution. After ABORT the amplifier is off and the motor coasts to rest."""

    bandwidth_hz: float = 30.0
    damping: float = 0.7
    velocity_feedforward: float = 0.9
    acceleration_feedforward: float = 0.0
    encoder_resolution: float = 1.0
    coast_time_constant: float = 0.2
    # The motor's acceleration per DAC count of PTF/PVTF feedforward (counts/s^2 per count):
    # a full-scale 32,767 gives about 1e6 counts/s^2 by default.
    dac_acceleration: float = 30.0

    def validate(self) -> Outcome:
        return first_refusal((
            check_range("bandwidth_hz", self.bandwidth_hz, BANDWIDTH_MIN_HZ, BANDWIDTH_MAX_HZ),
            check_range("damping", self.damping, 0.0, DAMPING_MAX, above_low=True),
            check_magnitude("velocity_feedforward", self.velocity_feedforward, FEEDFORWARD_MAX),
            check_magnitude("acceleration_feedforward", self.acceleration_feedforward, FEEDFORWARD_MAX),
            self._encoder_resolution(),
            check_duration("coast_time_constant", self.coast_time_constant, positive=True),
            check_magnitude("dac_acceleration", self.dac_acceleration, MAX_ACCELERATION),
        ))

    def _encoder_resolution(self) -> Outcome:
        # 0 reads the exact position; a step finer than 1e-6 count would overflow the reading
        # of a large position (y / resolution).
        if self.encoder_resolution == 0.0 and _finite_number(self.encoder_resolution):
            return VALID
        return check_range("encoder_resolution", self.encoder_resolution, 1e-6, MAX_POSITION)


# The actions a fault may take (MPIAction; STOP, RESUME, RESET and MAP are not a fault's).
FAULT_ACTIONS = ("NONE", "E_STOP", "ABORT", "E_STOP_ABORT")


def check_action(name: str, value: object) -> Outcome:
    if isinstance(value, str) and value in FAULT_ACTIONS:
        return VALID
    return refuse(f"{name}: must be one of {', '.join(FAULT_ACTIONS)}, got {shown(value)}")


@dataclass(slots=True)
class AxisFaultConfig:
    """The fault limits of one axis and the action each takes (docs/faults.md). The
    reference names the encoder fault (MPI 002, MPIAxisMaster, encoderFaultMotorNumber:
    "If this motor detects an encoder fault this axis will abort. A value of -1 disables")
    and the actions (MPIAction); the limits and their defaults are this project's, like a
    real XMP's: off until configured, so existing programs behave as before."""

    following_error_limit: float = 0.0  # counts; 0 disables
    following_error_time: float = 0.0  # seconds the error must stay above the limit (0: one sample)
    following_error_action: str = "ABORT"
    software_limit_positive_enabled: bool = False
    software_limit_positive: float = 0.0  # counts, user coordinates
    software_limit_positive_action: str = "E_STOP"
    software_limit_negative_enabled: bool = False
    software_limit_negative: float = 0.0
    software_limit_negative_action: str = "E_STOP"
    amp_fault_action: str = "ABORT"
    # -1 disables; the suite configures each axis' own motor (config.py, Controller)
    encoder_fault_motor_number: int = -1
    frame_underflow_action: str = "NONE"

    def copy(self) -> AxisFaultConfig:
        return copy.deepcopy(self)

    def validate(self) -> Outcome:
        return first_refusal((
            check_range("following_error_limit", self.following_error_limit, 0.0, MAX_POSITION),
            check_duration("following_error_time", self.following_error_time),
            check_action("following_error_action", self.following_error_action),
            check_bool("software_limit_positive_enabled", self.software_limit_positive_enabled),
            check_position("software_limit_positive", self.software_limit_positive),
            check_action("software_limit_positive_action", self.software_limit_positive_action),
            check_bool("software_limit_negative_enabled", self.software_limit_negative_enabled),
            check_position("software_limit_negative", self.software_limit_negative),
            check_action("software_limit_negative_action", self.software_limit_negative_action),
            self._limits_ordered(),
            check_action("amp_fault_action", self.amp_fault_action),
            check_integer("encoder_fault_motor_number", self.encoder_fault_motor_number, -1, MAX_OBJECTS - 1),
            check_action("frame_underflow_action", self.frame_underflow_action),
        ))

    def _limits_ordered(self) -> Outcome:
        """Both limits on: the negative one below the positive one, and (MPI 002, MEIAxisConfig)
        "The distance between the positive and negative software position limits must be less
        than 32 bits (4,294,967,296 counts)"."""
        if not (self.software_limit_positive_enabled is True and self.software_limit_negative_enabled is True
                and _finite_number(self.software_limit_positive) and _finite_number(self.software_limit_negative)):
            return VALID  # (a value that is not a number is refused by its own check)
        span = self.software_limit_positive - self.software_limit_negative
        if 0.0 < span < 2.0**32:
            return VALID
        return refuse(f"software_limit_negative: must be below software_limit_positive and less than "
                      f"4,294,967,296 counts from it, got {shown(self.software_limit_negative)} and "
                      f"{shown(self.software_limit_positive)}")


def check_settling_reachable(in_position: AxisInPosition, plant: PlantConfig) -> Outcome:
    """The encoder rounds to its resolution, so a reading can be resolution/2 from any
    target: a fine tolerance below that would never be met and no move would end."""
    if plant.encoder_resolution / 2.0 < in_position.position_fine:
        return VALID
    return refuse(f"position_fine: must be above half the encoder resolution "
                  f"({plant.encoder_resolution:g} counts), got {shown(in_position.position_fine)}")


@dataclass(slots=True)
class ControllerConfig:
    """The controller: sample clock, objects and options."""

    sample_rate: float = 2000.0
    axis_count: int = 4
    supervisor_count: int = 2
    frame_buffer_size: int = 128  # frames per axis, for every axis not in axis_frame_buffer_sizes
    firmware_option_21: bool = False
    io_words: int = 64
    motor_count: int = -1  # -1: one motor per axis
    event_notify: MPIEventType = MASK_ALL
    # axis number -> its frame buffer size (MPI 000 MPIMotionMessageAXIS_FRAME_COUNT: "The axis
    # frame buffer sizes are configured with ... mpiControlConfigSet")
    axis_frame_buffer_sizes: dict[int, int] = field(default_factory=dict)

    @property
    def motors(self) -> int:
        return self.axis_count if self.motor_count < 0 else self.motor_count

    def frame_buffer_size_of(self, axis: int) -> int:
        return self.axis_frame_buffer_sizes.get(axis, self.frame_buffer_size)

    def _check_axis_frame_buffer_sizes(self) -> Outcome:
        sizes = self.axis_frame_buffer_sizes
        if not isinstance(sizes, dict):
            return refuse(f"axis_frame_buffer_sizes: must be a mapping of axis number -> size, got {shown(sizes)}")
        axes = self.axis_count if isinstance(self.axis_count, int) else MAX_OBJECTS
        return first_refusal(
            first_refusal((check_integer("axis_frame_buffer_sizes: axis", axis, 0, axes - 1),
                           check_frame_buffer_size(f"axis_frame_buffer_sizes[{axis}]", size)))
            for axis, size in sizes.items()
        )

    def validate(self) -> Outcome:
        return first_refusal((
            check_range("sample_rate", self.sample_rate, SAMPLE_RATE_MIN, SAMPLE_RATE_MAX),
            check_integer("axis_count", self.axis_count, 1, MAX_OBJECTS),
            check_integer("supervisor_count", self.supervisor_count, 1, MAX_OBJECTS),
            check_frame_buffer_size("frame_buffer_size", self.frame_buffer_size),
            check_bool("firmware_option_21", self.firmware_option_21),
            check_integer("io_words", self.io_words, 1, IO_WORDS_MAX),
            check_integer("motor_count", self.motor_count, -1, MAX_OBJECTS),  # -1: one per axis
            self._check_axis_frame_buffer_sizes(),
        ))
