"""The controller's status snapshots (MPI 000, mpiAxisStatus and mpiMotionStatus), built from
templates.

Most of a snapshot holds from one discrete change to the next (a command, a transition, a
fault): an axis' state, plan, origin, target, move id, amplifier, faults and queued frames,
a supervisor's state, move, queue and last action. The controller steps in stretches that
stop at every such change (Controller._status_events), so a template taken once holds
for every sample of a stretch; a snapshot is then the template and the values, status
bits and profile time of its sample. The live status (Controller.motion_snapshots) is a
template taken now and used once; the snapshots inside a stretch (Controller.step_snapshots)
share one template: both are built by the same code.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from mpi_ros.mpi.axes.axis import Axis
from mpi_ros.mpi.axes.bank import VALUES
from mpi_ros.mpi.axes.status import AT_TARGET, AT_VELOCITY, DONE, IN_COARSE, IN_FINE, SETTLED, TC
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.mpi.base.wrap import wrap_position
from mpi_ros.mpi.planning.frames import AxisPlan
from mpi_ros.mpi.supervisor.motion import MotionSupervisor
from mpi_ros.mpi.supervisor.status import MotionTemplate

Snapshots = tuple[dict[int, MotionSnapshot], list[AxisSnapshot]]  # what Controller.motion_snapshots answers
REL = VALUES.index("rel")


@dataclass(slots=True)
class AxisTemplate:
    """What an axis' mpiAxisStatus holds until its next discrete change. (A template lives
    for one status read or one stretch, so it is not frozen: frozen costs a call a field.)"""

    axis: Axis
    plan: AxisPlan | None
    state: MPIState  # of the supervisor commanding it (IDLE without one)
    supervisor: int  # that supervisor (-1: none)
    target_position: float  # NaN for a velocity move: it has no target
    origin: float
    amp_enabled: bool
    move_id: int
    frames_queued: int  # frames its supervisor holds for it beyond the plan it runs
    frame_buffer_size: int
    faults: tuple[str, ...]
    # what does not follow the profile time without a plan (or a plan's table) to follow
    feedforward: float | None  # None: it follows the plan's PTF/PVTF feedforward
    element_id: int | None  # None: it follows the path's points

    def __post_init__(self) -> None:
        if self.frame_buffer_size <= 0:
            raise ValueError(f"a frame buffer holds at least one frame, not {self.frame_buffer_size}")

    @classmethod
    def of(cls, axis: Axis, number: int, owner: MotionSupervisor | None, frame_buffer_size: int,
           faults: tuple[str, ...]) -> AxisTemplate:
        """The template of ``axis`` now, commanded by supervisor ``number`` (-1: none),
        ``owner`` (None: none, or not a supervisor of this controller)."""
        plan = axis.plan
        return cls(
            axis=axis,
            plan=plan,
            state=owner.own_state if owner is not None else MPIState.IDLE,
            supervisor=number,
            # A velocity move has no target: NaN, rather than the end of its long frame.
            target_position=math.nan if plan is not None and plan.is_velocity else axis.target_position,
            origin=axis.origin,
            amp_enabled=axis.amp_enabled,
            move_id=axis.move_id,
            frames_queued=owner.frames_queued(axis.number) if owner is not None else 0,
            frame_buffer_size=frame_buffer_size,
            faults=faults,
            feedforward=axis.feedforward_at(math.nan) if plan is None or plan.feedforward is None else None,
            element_id=axis.element_id_at(math.nan) if plan is None or not plan.element_ids else None,
        )

    def frame_count(self, rel: float) -> int:
        """Frames in the axis' buffer at profile time ``rel``: the rest of the move it runs and
        the ones queued. A path's points beyond the buffer wait in the library (MPI 001,
        LOW_COUNT): the buffer never shows more than it holds."""
        count = self.frames_queued
        if self.plan is not None:
            count += self.plan.frames_left(rel if math.isfinite(rel) else 0.0)
        return min(count, self.frame_buffer_size)

    def at(self, sample: int, values: Sequence[float], bits: Sequence[bool]) -> AxisSnapshot:
        """The snapshot at ``sample`` from the axis' values there (bank.VALUES order) and its
        status bits (status.BITS order)."""
        cmd_p, cmd_v, cmd_a, act_p, act_v, rel = values
        axis, origin, feedforward, element_id = self.axis, self.origin, self.feedforward, self.element_id
        if feedforward is None:
            feedforward = axis.feedforward_at(rel)
        error = cmd_p - act_p
        return AxisSnapshot(
            sample=sample,
            number=axis.number,
            state=self.state,
            command_position=wrap_position(cmd_p - origin),
            actual_position=wrap_position(act_p - origin),
            position_error=error,
            target_position=self.target_position,
            origin=origin,
            command_velocity=cmd_v,
            actual_velocity=act_v,
            command_acceleration=cmd_a,
            done=bits[DONE],
            at_target=bits[AT_TARGET],
            in_fine_position=bits[IN_FINE],
            in_coarse_position=bits[IN_COARSE],
            settled=bits[SETTLED],
            at_velocity=bits[AT_VELOCITY],
            trajectory_complete=bits[TC],
            amp_enabled=self.amp_enabled,
            move_id=self.move_id,
            element_id=axis.element_id_at(rel) if element_id is None else element_id,
            frame_count=self.frame_count(rel),
            supervisor=self.supervisor,
            feedforward=feedforward,
            faults=self.faults,
            servo_effort=axis.effort_of(error, cmd_v, act_v, cmd_a, feedforward) if self.amp_enabled else 0.0,
        )


@dataclass(slots=True)
class StatusTemplate:
    """Every axis' and supervisor's template: what the controller's status holds until its
    next discrete change."""

    axes: tuple[AxisTemplate, ...]  # every axis, by number
    supervisors: tuple[tuple[MotionSupervisor, MotionTemplate], ...]

    def __post_init__(self) -> None:
        if any(t.axis.number != n for n, t in enumerate(self.axes)):
            raise ValueError("a status template holds every axis, in the order of their numbers")

    def at(self, sample: int, values: Sequence[Sequence[float]], bits: Sequence[Sequence[bool]]) -> Snapshots:
        """Every supervisor's snapshot, by number, and every axis', at ``sample``, from each
        axis' values and status bits there (by axis number). The supervisors' events
        latched are read now: the caller has delivered those of samples up to ``sample``."""
        axes = [t.at(sample, v, b) for t, v, b in zip(self.axes, values, bits, strict=True)]
        rel = [v[REL] for v in values]
        return {ms.number: motion.at(sample, axes, rel.__getitem__, ms.latched_events())
                for ms, motion in self.supervisors}, axes
