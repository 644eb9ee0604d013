"""Axis status bits, generated exactly as the two tables at the end of spec 002 say.

settleOnStop (settleOnEstop) = FALSE (the default):

| status             | after S-curve/trapezoidal | during velocity | after STOP (E-STOP)   | after ABORT |
| IN_FINE_POSITION   | target distance (note 3)  | FALSE           | FALSE                 | FALSE |
| IN_COARSE_POSITION | target distance           | FALSE           | FALSE                 | FALSE |
| AT_TARGET          | command = target          | FALSE           | FALSE                 | FALSE |
| DONE               | TC and IN_FINE_POSITION   | FALSE           | command velocity = 0  | TRUE  |

settleOnStop (settleOnEstop) = TRUE: after STOP (E-STOP) IN_FINE_POSITION is based on
position error (note 1) and DONE is the same as IN_FINE_POSITION.

NOTE 1: IN_FINE_POSITION after a stop = trajectory complete, |command - actual| < fine,
|target velocity - actual velocity| < velocity tolerance, all for the settling time.
NOTE 3: after a point-to-point move = trajectory complete, |target - actual| < fine,
|command velocity - actual velocity| < velocity tolerance, all for the settling time.
TC (trajectory complete, note 2) is set when all the move's frames have executed.

SETTLED (MEIEventTypeSETTLED) is the note-1 criterion after any stop of the command
(point-to-point done, or stopped): the axis has come to rest on its command.
AT_VELOCITY (velocity moves): the ramp is done and |command velocity - actual
velocity| < velocity tolerance for the settling time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from enum import Enum

import numpy as np

from .params import AxisInPosition

_STOPPED_VELOCITY = 1e-9
_NONE = np.zeros(0, dtype=np.int64)  # counts/s: "command velocity = 0"


class StatusMode(Enum):
    POINT_TO_POINT = "POINT_TO_POINT"
    VELOCITY = "VELOCITY"
    STOP = "STOP"
    E_STOP = "E_STOP"
    ABORT = "ABORT"


@dataclass(slots=True)
class AxisStatusBits:
    in_fine_position: bool = False
    in_coarse_position: bool = False
    at_target: bool = False
    done: bool = False
    settled: bool = False
    at_velocity: bool = False
    trajectory_complete: bool = False


BIT_NAMES = tuple(f.name for f in fields(AxisStatusBits))


@dataclass(slots=True)
class SettleCounters:
    """Consecutive samples each settling criterion has held (carried between stretches)."""

    fine: int = 0
    settled: int = 0
    velocity: int = 0


@dataclass(slots=True)
class StatusContext:
    """What the status of an axis depends on besides its trace."""

    mode: StatusMode
    target: float
    in_position: AxisInPosition
    sample_rate: float
    holding: bool = False
    plan_duration: float = 0.0  # profile time at which the trajectory completes
    velocity_target: float | None = None  # VELOCITY moves
    ramp_end: float = 0.0  # VELOCITY moves: profile time the ramp is done
    has_plan: bool = False
    ends_moving: bool = False  # a FINAL_VEL plan: its last frame goes on at the final velocity


@dataclass(slots=True)
class StatusTrace:
    bits: dict[str, np.ndarray]
    runs: dict[str, np.ndarray]

    def at(self, index: int) -> AxisStatusBits:
        return AxisStatusBits(**{name: bool(arr[index]) for name, arr in self.bits.items()})

    def counters_at(self, index: int) -> SettleCounters:
        return SettleCounters(
            int(self.runs["fine"][index]), int(self.runs["settled"][index]), int(self.runs["velocity"][index])
        )


def settle_samples(in_position: AxisInPosition, sample_rate: float) -> int:
    """Consecutive samples a criterion must hold: the settling time, plus the first."""
    return max(0, math.ceil(in_position.settling_time * sample_rate - 1e-9)) + 1


def run_lengths(criterion: np.ndarray, carry: int) -> np.ndarray:
    """Length of the run of True ending at each index (continuing ``carry``)."""
    n = len(criterion)
    index = np.arange(1, n + 1)
    last_false = np.maximum.accumulate(np.where(criterion, 0, index))
    runs = index - last_false
    return np.where(last_false == 0, runs + carry, runs)


def _trajectory_complete(trace, ctx: StatusContext, stopped: np.ndarray) -> np.ndarray:
    """TC: every frame executed (after a stop: the command has stopped)."""
    if ctx.mode in (StatusMode.STOP, StatusMode.E_STOP):
        return stopped
    if ctx.holding:
        return np.zeros(len(trace), dtype=bool)
    if ctx.ends_moving:
        # The last frame of a FINAL_VEL move runs on at the final velocity: it never completes.
        return np.zeros(len(trace), dtype=bool)
    if ctx.has_plan:
        return trace.rel >= ctx.plan_duration
    return np.ones(len(trace), dtype=bool)


def compute(trace, ctx: StatusContext, counters: SettleCounters) -> StatusTrace:
    """Status bits of every sample of an axis trace."""
    n = len(trace)
    tol = ctx.in_position
    need = settle_samples(tol, ctx.sample_rate)
    false = np.zeros(n, dtype=bool)
    no_runs = np.zeros(n, dtype=np.int64)
    velocity_ok = np.abs(trace.cmd_v - trace.act_v) < tol.velocity
    stopped = np.abs(trace.cmd_v) < _STOPPED_VELOCITY
    tc = _trajectory_complete(trace, ctx, stopped)

    # Note 1: at rest on the command (used by SETTLED, and by IN_FINE after a stop).
    if ctx.mode is StatusMode.ABORT:
        settled_runs = no_runs
    else:
        at_rest = tc & stopped & (np.abs(trace.cmd_p - trace.act_p) < tol.position_fine) & velocity_ok
        settled_runs = run_lengths(at_rest, counters.settled)
    settled = settled_runs >= need
    fine_runs = vel_runs = no_runs
    at_velocity = false

    if ctx.mode is StatusMode.ABORT:
        bits = dict(in_fine_position=false, in_coarse_position=false, at_target=false, done=~false)
    elif ctx.mode in (StatusMode.STOP, StatusMode.E_STOP):
        settle_on = tol.settle_on_stop if ctx.mode is StatusMode.STOP else tol.settle_on_estop
        in_fine, fine_runs = (settled, settled_runs) if settle_on else (false, no_runs)
        bits = dict(in_fine_position=in_fine, in_coarse_position=false, at_target=false,
                    done=in_fine if settle_on else stopped)
    else:
        # Note 3: after a point-to-point move, distance to the target.
        distance = np.abs(ctx.target - trace.act_p)
        fine_runs = run_lengths(tc & (distance < tol.position_fine) & velocity_ok, counters.fine)
        in_fine = fine_runs >= need
        in_coarse = distance < tol.position_coarse
        if ctx.velocity_target is not None:
            # During a velocity move (until its frame ends) these bits are FALSE;
            # IN_FINE and DONE already require TC.
            in_coarse = in_coarse & tc
            ramp_done = ~tc & (trace.rel >= ctx.ramp_end)
            vel_runs = run_lengths(ramp_done & velocity_ok, counters.velocity)
            at_velocity = vel_runs >= need
        # AT_TARGET: "TRUE when command = target" (002's table), at rest there; an axis of a
        # SYNC_START move that arrives early is at its target while the others still move.
        at_target = (trace.cmd_p == ctx.target) & stopped & (not ctx.holding)
        if ctx.velocity_target is not None:
            at_target = false
        bits = dict(in_fine_position=in_fine, in_coarse_position=in_coarse, at_target=at_target,
                    done=tc & in_fine)

    bits.update(settled=settled, at_velocity=at_velocity, trajectory_complete=tc)
    runs = {"fine": fine_runs, "settled": settled_runs, "velocity": vel_runs}
    return StatusTrace({k: np.asarray(v, dtype=bool) for k, v in bits.items()}, runs)


def rising_edges(previous: bool, bits: np.ndarray) -> np.ndarray:
    """Indices at which a bit turns on."""
    if not bits.any() or (previous and bits.all()):
        return _NONE
    before = np.concatenate(([previous], bits[:-1]))
    return np.flatnonzero(bits & ~before)
