"""The simulated MPI/XMP motion controller: pure Python + numpy, no ROS here.

Where each concept of the MPI reference lives (MPI 000: motion objects, 001: path attributes,
002: axes; who owns what and how they collaborate: docs/architecture.md). The subpackages are
layers, each importing only the ones above it in this list (test/mpi/test_architecture.py):

| concept                                                   | module |
| --------------------------------------------------------- | ------ |
| **base/**: the reference's vocabulary                     |   |
| message codes (MPIMessage*, MPIMotionMessage*, MEI...)    | base/messages.py |
| MPIState, MPIAction, MPIMotionType, attribute masks,      | base/types.py |
|   MEIMotionAttrHoldType, MEIMotionAttrOutputType          |   |
| MPIEventType / event masks, events with move/element id   | base/events.py |
| MPIMotionParams, MPITrajectory, MEIMotionAttrHold/Output, | base/params.py |
|   MPIMotionConfig, MPIMotionDecelTime, MPIAxisInPosition  |   |
| the one outcome type (message + detail), a move's end     | base/outcome.py |
| feedrate (STOP ramps it to pauseFeedrate, RESUME back)    | base/clock.py |
| I/O image, control gates (meiControlGateSet)              | base/io.py |
| MPIAxisMaster sources, masterCorrection, 2nd encoders     | base/masters.py |
| mpiMotionStatus / mpiAxisStatus / frame buffer status     | base/snapshot.py |
| 32-bit position wrap                                      | base/wrap.py |
| **planning/**: from a request to a plan                   |   |
| one record per motion type: family, fields, attributes,   | planning/families.py |
|   modifiable, option 21, line and stop ramps              |   |
| the start/modify return table, ATTRIBUTE_INVALID lists    | planning/validate.py |
| trapezoid (TRAPEZOIDAL), S-curve reshaping (S_CURVE)      | planning/profiles/ramps.py, scurve.py |
| VELOCITY, point-to-point from (p, v) incl. reversal       | planning/profiles/point_to_point.py |
| S_CURVE_JERK / VELOCITY_JERK (firmware option 21)         | planning/profiles/jerk.py |
| constant-jerk segments ("frames"), the one representation | planning/profiles/segment.py |
| path kinds (PT, PVT, SPLINE, BSPLINE, BESSEL, ...)        | planning/profiles/path.py, planning/paths.py |
| MPIMotionCam tables (CAM_LINEAR, CAM_CUBIC, REPEAT)       | planning/profiles/cam.py |
| cams: plans; progress, MASTER_START, NO_BACKTRACK(_HOLD)  | planning/cams.py, cam_follow.py (docs/cams.md) |
| vector moves, SYNC_START/END, DELAY, RELATIVE, quirks     | planning/planner.py (from planning/start.py) |
| frames per axis, the 128-frame buffer accounting          | planning/frames.py |
| **axes/**: the axes and their arrays                      |   |
| Axis: positions, origin, command-position-set rules       | axes/axis.py |
| every axis' state as arrays across axes, and the rows a   | axes/bank.py |
|   stretch is computed from                                |   |
| simulated servo / encoder (actual lags command)           | axes/plant.py |
| every axis over a stretch of samples at once              | axes/trace.py (into axes/stretch.py, scratch.py) |
| status bits IN_FINE/IN_COARSE/AT_TARGET/DONE/SETTLED/...  | axes/status.py (002 tables, NOTE 1-3) |
| **host.py**: what a supervisor or the fault monitor may   | host.py |
|   ask of the controller                                   |   |
| **faults/**: limits, trips and their actions              | faults/monitor.py (docs/faults.md) |
| **supervisor/**: the Motion object of MPI 000             |   |
| create/delete/validate, config, params, position,         | supervisor/motion.py (a facade) |
|   trajectory, status, events, start/modify                |   |
| its own state, feedrate clock, stop under way             | supervisor/state.py |
| its axis list (append/insert/remove/...) and the mapping  | supervisor/axis_list.py |
| its moves: current, queued, held; load, replace, drop     | supervisor/moves.py |
| HOLD triggers and timeouts                                | supervisor/holds.py |
| its actions STOP/E_STOP/ABORT/RESET/RESUME/MAP            | supervisor/actions.py |
| its state machine as the controller steps (DONE, stop     | supervisor/stepping.py |
|   complete, ERROR, hold release at the exact sample)      |   |
| motion log (meiMotionLogOpen/Print/Close)                 | supervisor/log.py |
| its mpiMotionStatus from a template (what holds until the | supervisor/status.py |
|   next change) and a sample's axis snapshots              |   |
| **the controller**                                        |   |
| Controller: sample clock, step/run_until, objects, events | control.py |
| how moves ended, when a goal is over                      | move_log.py |
| status snapshots of every axis and supervisor, from       | snapshots.py |
|   templates (the live status and inside stretches)        |   |

Start with ``Controller``: create it, ``create_motion``, ``axis_list_set``, ``start``,
then ``step(n)`` or ``run_until(...)``. Every call answers a ``Message``.
"""

from mpi_ros.mpi.base.events import Event, MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import (
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
from mpi_ros.mpi.base.types import (
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
from mpi_ros.mpi.control import Controller
from mpi_ros.mpi.supervisor.motion import MotionSupervisor

__all__ = [
    "ActionSource",
    "AxisInPosition",
    "AxisMaster",
    "AxisMasterType",
    "Controller",
    "ControllerConfig",
    "DecelTime",
    "Event",
    "Hold",
    "HoldType",
    "IoSpace",
    "MPIAction",
    "MPIEventType",
    "MPIMotionType",
    "MPIState",
    "Message",
    "MotionAttr",
    "MotionConfig",
    "MotionParams",
    "MotionSupervisor",
    "Output",
    "OutputType",
    "PlantConfig",
    "SecondaryFeedback",
    "Trajectory",
]
