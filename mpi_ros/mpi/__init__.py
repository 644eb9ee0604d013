"""The simulated MPI/XMP motion controller: pure Python + numpy, no ROS here.

Where each concept of the MPI reference lives (MPI 000: motion objects, 001: path attributes,
002: axes; who owns what and how they collaborate: docs/architecture.md):

| concept                                                  | module |
| -------------------------------------------------------- | ------ |
| message codes (MPIMessage*, MPIMotionMessage*, MEI...)    | messages.py |
| MPIState, MPIAction, MPIMotionType, attribute masks,      | types.py |
|   MEIMotionAttrHoldType, MEIMotionAttrOutputType          |   |
| MPIEventType / event masks, events with move/element id   | events.py |
| MPIMotionParams, MPITrajectory, MEIMotionAttrHold/Output, | params.py |
|   MPIMotionConfig, MPIMotionDecelTime, MPIAxisInPosition  |   |
| the start/modify return table, ATTRIBUTE_INVALID lists    | validate.py |
| trapezoid (TRAPEZOIDAL), S-curve reshaping (S_CURVE)      | profiles/ramps.py, profiles/scurve.py |
| VELOCITY, point-to-point from (p, v) incl. reversal       | profiles/point_to_point.py |
| S_CURVE_JERK / VELOCITY_JERK (firmware option 21)         | profiles/jerk.py |
| constant-jerk segments ("frames"), the one representation | profiles/segment.py |
| vector moves, SYNC_START/END, DELAY, RELATIVE, quirks     | planner.py |
| frames per axis, the 128-frame buffer accounting          | frames.py |
| feedrate (STOP ramps it to pauseFeedrate, RESUME back)    | clock.py |
| simulated servo / encoder (actual lags command)           | plant.py |
| Axis: positions, origin, command-position-set rules       | axis.py |
| status bits IN_FINE/IN_COARSE/AT_TARGET/DONE/SETTLED/...  | status.py (002 tables, NOTE 1-3) |
| HOLD triggers and timeouts                                | holds.py |
| I/O image, control gates (meiControlGateSet)              | io.py |
| Motion object: create/delete/validate, config, params,    | motion.py (a facade) |
|   position, trajectory, status, events, start/modify      |   |
| its own state, feedrate clock, stop under way             | supervisor_state.py |
| its axis list (append/insert/remove/...) and the mapping  | axis_list.py |
| its moves: current, queued, held; load, replace, drop     | moves.py |
| its actions STOP/E_STOP/ABORT/RESET/RESUME/MAP            | supervisor_actions.py |
| its state machine as the controller steps (DONE, stop     | supervisor_stepping.py |
|   complete, ERROR, hold release at the exact sample)      |   |
| what a supervisor may ask of the controller               | host.py |
| the one outcome type (message + detail), a move's end     | outcome.py |
| how moves ended, when a goal is over                      | move_log.py |
| motion log (meiMotionLogOpen/Print/Close)                 | log.py |
| mpiMotionStatus / mpiAxisStatus / frame buffer status     | snapshot.py |
| Controller: sample clock, step/run_until, objects, events | control.py |
| every axis' state as arrays across axes, and the rows a   | bank.py |
|   stretch is computed from (command piece, plant anchor,  |   |
|   status inputs, supervisors' clocks)                     |   |
| every axis over a stretch of samples at once              | stretch.py |
| MPIMotionCam tables (CAM_LINEAR, CAM_CUBIC, REPEAT)       | profiles/cam.py |
| cams: progress, MASTER_START, NO_BACKTRACK(_HOLD)          | cams.py (docs/cams.md) |
| MPIAxisMaster sources, masterCorrection, 2nd encoders     | masters.py |

Start with ``Controller``: create it, ``create_motion``, ``axis_list_set``, ``start``,
then ``step(n)`` or ``run_until(...)``. Every call answers a ``Message``.
"""

from .control import Controller
from .events import Event, MPIEventType
from .messages import Message
from .motion import MotionSupervisor
from .params import (
    AxisInPosition,
    AxisMaster,
    ControllerConfig,
    DecelTime,
    Hold,
    MotionConfig,
    MotionParams,
    Output,
    PlantConfig,
    SecondaryFeedback,
    Trajectory,
)
from .types import (
    ActionSource,
    AxisMasterType,
    HoldType,
    IoSpace,
    MotionAttr,
    MPIAction,
    MPIMotionType,
    MPIState,
    OutputType,
)

__all__ = [
    "ActionSource", "AxisInPosition", "AxisMaster", "AxisMasterType", "Controller", "ControllerConfig", "DecelTime",
    "Event", "Hold",
    "HoldType", "IoSpace", "Message", "MotionAttr", "MotionConfig", "MotionParams", "MotionSupervisor",
    "MPIAction", "MPIEventType", "MPIMotionType", "MPIState", "Output", "OutputType", "PlantConfig",
    "SecondaryFeedback", "Trajectory",
]
