"""What mpiAxisStatus / mpiMotionStatus / meiMotionFrameBufferStatus return (user units)."""

from __future__ import annotations

from dataclasses import dataclass, field

from mpi_ros.mpi.base.types import MPIState


@dataclass(slots=True)
class AxisSnapshot:
    """mpiAxisStatus of one axis at one sample.

    A value nobody assigns to: the same snapshot is shared between the status topics, the
    supervisors' snapshots that hold it, the Packer's cache (wire.Packer) and replay. Not
    frozen only because a frozen dataclass sets every field through object.__setattr__, which
    cost more than the rest of building it (docs/architecture.md, "Status snapshots"); not
    hashable either (eq without frozen: a snapshot is never a set member or a key)."""

    sample: int
    number: int
    state: MPIState
    command_position: float
    actual_position: float
    position_error: float
    target_position: float
    origin: float
    command_velocity: float
    actual_velocity: float
    command_acceleration: float
    done: bool
    at_target: bool
    in_fine_position: bool
    in_coarse_position: bool
    settled: bool
    at_velocity: bool
    trajectory_complete: bool
    amp_enabled: bool
    move_id: int
    element_id: int
    frame_count: int
    supervisor: int
    feedforward: float = 0.0  # PTF/PVTF feedforward (raw DAC counts)
    faults: tuple[str, ...] = ()  # the faults latched on the axis (mpi/faults.py)
    servo_effort: float = 0.0  # the position loop's effort, counts/s^2 (plant.servo_effort; 0 with the amp off)


@dataclass(slots=True)
class MotionSnapshot:
    """mpiMotionStatus of one supervisor at one sample: a value nobody assigns to, as
    :class:`AxisSnapshot` (not frozen for the same reason)."""

    sample: int
    number: int
    state: MPIState
    axis_numbers: tuple[int, ...]
    axes: tuple[AxisSnapshot, ...]
    done: bool
    at_target: bool
    settled: bool
    move_id: int
    element_id: int
    feedrate: float
    last_action: str
    action_source: str
    moves_pending: int
    motion_type: str
    progress: float = 0.0
    latched_events: tuple[str, ...] = field(default_factory=tuple)


@dataclass(frozen=True, slots=True)
class FrameBufferStatus:
    """MEIMotionFrameBufferStatus of one axis."""

    axis: int
    size: int
    frame_count: int


@dataclass(frozen=True, slots=True)
class MotionFeedback:
    """What a goal's feedback and result show of a supervisor at a sample
    (Controller.motion_feedback): lighter than mpiMotionStatus, taken for every feedback."""

    sample: int
    state: MPIState
    command_position: tuple[float, ...]
    actual_position: tuple[float, ...]
    command_velocity: tuple[float, ...]
    progress: float  # 0..1 along the move in progress (0 without one)
    move_id: int  # the move in progress, else the last one
    element_id: int
    serial: int | None  # the move in progress (None without one)
