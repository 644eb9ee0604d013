"""The simulated MPI/XMP motion controller (pure Python + numpy; no ROS here)."""

from .control import Controller
from .events import Event, MPIEventType
from .messages import Message
from .motion import MotionSupervisor
from .params import (
    AxisInPosition,
    ControllerConfig,
    DecelTime,
    Hold,
    MotionConfig,
    MotionParams,
    Output,
    PlantConfig,
    Trajectory,
)
from .types import ActionSource, HoldType, IoSpace, MotionAttr, MPIAction, MPIMotionType, MPIState, OutputType

__all__ = [
    "ActionSource", "AxisInPosition", "Controller", "ControllerConfig", "DecelTime", "Event", "Hold",
    "HoldType", "IoSpace", "Message", "MotionAttr", "MotionConfig", "MotionParams", "MotionSupervisor",
    "MPIAction", "MPIEventType", "MPIMotionType", "MPIState", "Output", "OutputType", "PlantConfig",
    "Trajectory",
]
