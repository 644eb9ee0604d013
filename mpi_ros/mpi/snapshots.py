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
from dataclasses import dataclass, fields
from operator import attrgetter
from typing import Any

import numpy as np

from mpi_ros.mpi.axes.axis import Axis
from mpi_ros.mpi.axes.bank import VALUES
from mpi_ros.mpi.axes.plant import servo_effort
from mpi_ros.mpi.axes.status import AT_TARGET, AT_VELOCITY, DONE, IN_COARSE, IN_FINE, SETTLED, TC
from mpi_ros.mpi.base.params import PlantConfig
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.mpi.base.wrap import wrap_positions
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

    def frame_counts(self, rel: list[float]) -> int | list[int]:
        """:meth:`frame_count` at each profile time of ``rel``, or one count for them all. A
        plan's frames left never grow with its profile time, so a count equal at the least
        and the greatest of them holds at every one between."""
        if self.plan is None or len(rel) == 1:
            return self.frame_count(rel[0])
        reached = [r if math.isfinite(r) else 0.0 for r in rel]  # (what frame_count reads)
        low, high = min(reached), max(reached)
        first = self.frame_count(low)
        if low == high or first == self.frame_count(high):
            return first
        return [self.frame_count(r) for r in rel]

    def feedforwards(self, rel: list[float]) -> float | list[float]:
        """The feedforward at each profile time of ``rel``, or one for them all."""
        if self.feedforward is not None:
            return self.feedforward
        return [self.axis.feedforward_at(r) for r in rel]

    def element_ids(self, rel: list[float]) -> int | list[int]:
        """The element id at each profile time of ``rel``, or one for them all."""
        if self.element_id is not None:
            return self.element_id
        return [self.axis.element_id_at(r) for r in rel]

    def at(self, sample: int, values: Sequence[float], bits: Sequence[bool]) -> AxisSnapshot:
        """The snapshot at ``sample`` from the axis' values there (bank.VALUES order) and its
        status bits (status.BITS order)."""
        return axis_snapshots((self,), [sample], np.array(values, dtype=float)[:, None, None],
                              np.array(bits, dtype=bool)[:, None, None])[0]


_FIELDS = tuple(f.name for f in fields(AxisSnapshot))  # AxisSnapshot's positional order
_BIT_FIELDS = {"done": DONE, "at_target": AT_TARGET, "in_fine_position": IN_FINE, "in_coarse_position": IN_COARSE,
               "settled": SETTLED, "at_velocity": AT_VELOCITY, "trajectory_complete": TC}
_BIT_ROWS = list(_BIT_FIELDS.values())
_PLANT_VALUES = attrgetter(*(f.name for f in fields(PlantConfig)))  # plants alike: the same effort
_HELD = ("state", "target_position", "origin", "amp_enabled", "move_id", "supervisor", "faults")
_HELD_OF = attrgetter(*_HELD)
_FLOATS = ("command_position", "actual_position", "position_error", "command_velocity", "actual_velocity",
           "command_acceleration", "servo_effort")
# the values each of _FLOATS is computed from (the effort's row is a placeholder)
_FLOAT_ROWS = [VALUES.index(name) for name in ("cmd_p", "act_p", "cmd_p", "cmd_v", "act_v", "cmd_a", "cmd_a")]


def axis_snapshots(templates: Sequence[AxisTemplate], samples: Sequence[int], values: np.ndarray,
                   bits: np.ndarray) -> list[AxisSnapshot]:
    """The snapshot of every template at each of ``samples``, from the axes' values there
    (bank.VALUES x samples x templates) and status bits (status.BITS x samples x templates):
    those of the first sample first, in the order of ``templates``.

    What follows the values is computed for every sample and axis at once, in arrays; each
    field is then one list in the snapshots' order (what holds along the stretch repeated),
    and the snapshots are built from those lists in one pass."""
    if not templates:
        return []
    stops, rel = len(samples), values[REL]
    by_axis = rel.T.tolist()  # each axis' profile times
    held = list(zip(*map(_HELD_OF, templates), strict=True))  # each of _HELD, by axis
    columns = {name: list(column) * stops for name, column in zip(_HELD, held, strict=True)}
    feedforward = [t.feedforwards(r) for t, r in zip(templates, by_axis, strict=True)]
    columns["feedforward"] = _column(feedforward, stops)
    origin = held[_HELD.index("origin")]
    columns.update(zip(_FLOATS, _flat(_floats(templates, values, origin, feedforward)), strict=True))
    columns.update(zip(_BIT_FIELDS, _flat(bits[_BIT_ROWS]), strict=True))
    columns["number"] = [t.axis.number for t in templates] * stops
    columns["sample"] = [s for s in samples for _ in templates]
    columns["element_id"] = _column([t.element_ids(r) for t, r in zip(templates, by_axis, strict=True)], stops)
    columns["frame_count"] = _column([t.frame_counts(r) for t, r in zip(templates, by_axis, strict=True)], stops)
    return list(map(AxisSnapshot, *(columns[name] for name in _FIELDS)))


def _floats(templates: Sequence[AxisTemplate], values: np.ndarray, origin: Sequence[float],
            feedforward: Sequence[float | list[float]]) -> np.ndarray:
    """The fields of _FLOATS (x samples x axes) from the axes' values."""
    _, cmd_v, cmd_a, act_p, act_v, _ = values
    floats = values[_FLOAT_ROWS]  # (a copy) the values each field is computed from
    floats[:2] = wrap_positions(floats[:2] - np.array(origin))
    floats[2] -= act_p
    floats[6] = _efforts(templates, feedforward, floats[2], cmd_v, act_v, cmd_a)
    return floats


def _flat(arrays: np.ndarray) -> list[list[Any]]:
    """Arrays (fields x samples x axes) as one list per field, sample by sample."""
    return arrays.reshape(len(arrays), -1).tolist()


def _column(per_axis: Sequence[Any], samples: int) -> list[Any]:
    """One list, sample by sample, of what each axis gives: one value for every sample or a
    list of one per sample."""
    count = len(per_axis)
    column = [None if isinstance(v, list) else v for v in per_axis] * samples
    for j, v in enumerate(per_axis):
        if isinstance(v, list):
            column[j::count] = v
    return column


def _efforts(templates: Sequence[AxisTemplate], feedforward: Sequence[float | list[float]], error: np.ndarray,
             cmd_v: np.ndarray, act_v: np.ndarray, cmd_a: np.ndarray) -> np.ndarray:
    """Each axis' servo effort (samples x axes; 0 with the amplifier off), computed at once for
    the axes whose plants are configured alike and whose feedforward is the same."""
    effort = np.zeros(error.shape)
    shared: dict[tuple[tuple[float, ...], float], list[int]] = {}
    for j, (t, ff) in enumerate(zip(templates, feedforward, strict=True)):
        if not t.amp_enabled:
            continue
        if isinstance(ff, list):
            effort[:, j] = [servo_effort(t.axis.plant.config, *x) for x in
                            zip(error[:, j].tolist(), cmd_v[:, j].tolist(), act_v[:, j].tolist(),
                                cmd_a[:, j].tolist(), ff, strict=True)]
        else:
            shared.setdefault((_PLANT_VALUES(t.axis.plant.config), ff), []).append(j)
    for (_, ff), cols in shared.items():
        config = templates[cols[0]].axis.plant.config
        if len(cols) == len(templates):  # (nearly always: every axis alike)
            return servo_effort(config, error, cmd_v, act_v, cmd_a, ff)
        effort[:, cols] = servo_effort(config, error[:, cols], cmd_v[:, cols], act_v[:, cols], cmd_a[:, cols], ff)
    return effort


@dataclass(slots=True)
class StatusTemplate:
    """Every axis' and supervisor's template: what the controller's status holds until its
    next discrete change."""

    axes: tuple[AxisTemplate, ...]  # every axis, by number
    supervisors: tuple[tuple[MotionSupervisor, MotionTemplate], ...]
    # every axis' snapshot at a sample ahead, taken with those before it (:meth:`keep`)
    ahead: tuple[int, list[AxisSnapshot]] | None = None

    def __post_init__(self) -> None:
        if any(t.axis.number != n for n, t in enumerate(self.axes)):
            raise ValueError("a status template holds every axis, in the order of their numbers")

    def axes_at(self, samples: Sequence[int], values: np.ndarray, bits: np.ndarray) -> list[list[AxisSnapshot]]:
        """Every axis' snapshot at each of ``samples`` (one list a sample, by axis number), from
        the axes' values there (bank.VALUES x samples x axes) and status bits (status.BITS x
        samples x axes)."""
        snaps = axis_snapshots(self.axes, samples, values, bits)
        count = len(self.axes)
        return [snaps[i * count:(i + 1) * count] for i in range(len(samples))]

    def motions_at(self, sample: int, axes: list[AxisSnapshot], rel: list[float]) -> dict[int, MotionSnapshot]:
        """Every supervisor's snapshot at ``sample``, by number, from every axis' snapshot and
        profile time there. The supervisors' events latched are read now: the caller has
        delivered those of samples up to ``sample``."""
        return {ms.number: motion.at(sample, axes, rel.__getitem__, ms.latched_events())
                for ms, motion in self.supervisors}

    def at(self, sample: int, values: np.ndarray, bits: np.ndarray) -> Snapshots:
        """Every supervisor's snapshot, by number, and every axis', at ``sample``, from the axes'
        values (bank.VALUES x axes) and status bits (status.BITS x axes) there: as
        :meth:`motions_at` reads the events latched."""
        if self.ahead is not None and self.ahead[0] == sample:
            axes = self.ahead[1]
        else:
            (axes,) = self.axes_at([sample], values[:, None], bits[:, None])
        return self.motions_at(sample, axes, values[REL].tolist()), axes

    def keep(self, sample: int, axes: list[AxisSnapshot]) -> None:
        """Keep every axis' snapshot at ``sample``, the stop of a stretch, for :meth:`at`
        there: taken with the snapshots inside the stretch (one pass over the arrays), it
        holds if the template does (nothing discrete happened at the stop) and the axes'
        values and bits are the stretch's there."""
        self.ahead = (sample, axes)
