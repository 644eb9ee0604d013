"""Parameter and configuration structs of the MPI as dataclasses (units: counts, seconds).

C pointers become data (DESIGN.md): a NULL array is an empty list here, a hold or
output is a value, an I/O address is the index of a word in the simulated I/O image.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

from .events import MASK_ALL, MPIEventType
from .types import HoldType, OutputType

MAX_COORD_AXES = 8  # MEIXmpMAX_COORD_AXES
MAX_GATES = 32  # gate numbers 0..31 (spec 000 MEIMotionAttrHoldSource)
VELOCITY_FRAME_LIMIT_SAMPLES = 16_384_000  # spec 000 mpiMotionStart
ID_BITS = 16  # spec 000 MPIMotionAttributes: "limited to 16-bit resolution"


@dataclass(slots=True)
class Trajectory:
    """MPITrajectory."""

    velocity: float = 0.0
    acceleration: float = 0.0
    deceleration: float = 0.0
    jerk_percent: float = 0.0
    acceleration_jerk: float = 0.0
    deceleration_jerk: float = 0.0


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


@dataclass(slots=True)
class Output:
    """MEIMotionAttrOutput."""

    type: OutputType = OutputType.NONE
    motor: int = 0
    address: int = 0
    on_mask: int = 0
    off_mask: int = 0
    point_index: int = 0


@dataclass(slots=True)
class UserFrame:
    """MEIXmpFrame as given to a FRAME move: one constant-jerk segment."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0
    jerk: float = 0.0
    time: float = 0.0


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

    def copy(self) -> "MotionParams":
        return copy.deepcopy(self)


@dataclass(slots=True)
class DecelTime:
    """MPIMotionDecelTime (seconds)."""

    stop: float = 0.5
    e_stop: float = 0.05


@dataclass(slots=True)
class MotionConfig:
    """MPIMotionConfig + MEIMotionConfig (axisCount/axisNumber are read from the mapping)."""

    decel_time: DecelTime = field(default_factory=DecelTime)
    normal_feedrate: float = 1.0
    pause_feedrate: float = 0.0
    user_label: str = ""
    axis_numbers: list[int] = field(default_factory=list)
    blend_limit: float = 0.0

    @property
    def axis_count(self) -> int:
        return len(self.axis_numbers)

    def copy(self) -> "MotionConfig":
        return copy.deepcopy(self)


USER_LABEL_MAX = 16  # MEIObjectLabelCharMAX


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

    def copy(self) -> "AxisInPosition":
        return copy.deepcopy(self)


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


@dataclass(slots=True)
class ControllerConfig:
    """The controller: sample clock, objects and options."""

    sample_rate: float = 2000.0
    axis_count: int = 4
    supervisor_count: int = 2
    frame_buffer_size: int = 128
    firmware_option_21: bool = False
    io_words: int = 64
    motor_count: int = -1  # -1: one motor per axis
    event_notify: MPIEventType = MASK_ALL

    @property
    def motors(self) -> int:
        return self.axis_count if self.motor_count < 0 else self.motor_count
