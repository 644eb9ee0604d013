"""The controller gives the same result however its samples are batched.

docs/decisions.md, "Samples, commands and replay": every command takes effect at a sample boundary
and is recorded with that sample's index, which is what makes replay exact. A live run steps in
wall-clock batches, a replay in others; every value at every sample must agree to the bit. Random scripts of starts,
modifies, appends, holds and every action, with the settle-on-stop variants.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mpi_ros.mpi import (
    AxisInPosition,
    Controller,
    Hold,
    HoldType,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    Trajectory,
)

SAMPLES = 3000
TRAJ = Trajectory(3000.0, 30000.0, 20000.0, 40.0)


def _commands(draw_script):
    """(sample, callable(controller, ms)) pairs."""
    out = []
    for sample, kind, x, y in draw_script:
        out.append((sample, kind, float(x), float(y)))
    return sorted(out, key=lambda c: c[0])


def _apply(ctl, ms, kind: str, x: float, y: float) -> None:
    params = MotionParams(trajectory=[TRAJ], position=[x, y])
    if kind == "start":
        ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE, params)
    elif kind == "append":
        ms.start(MPIMotionType.TRAPEZOIDAL, MotionAttr.APPEND, params)
    elif kind == "modify":
        ms.modify(MPIMotionType.S_CURVE, MotionAttr.NONE, params)
    elif kind == "velocity":
        ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                 MotionParams(trajectory=[Trajectory(x / 3.0, 20000.0, 0.0, 30.0)]))
    elif kind == "hold":
        hold = Hold(HoldType.GATE, gate=2)
        ms.start(MPIMotionType.S_CURVE, MotionAttr.HOLD, MotionParams(trajectory=[TRAJ], position=[x, y],
                                                                       hold=[hold, hold]))
    elif kind == "gate":
        ctl.gate_set(2, x > 0)
    else:
        ms.action(MPIAction[kind])


def _run(script, batches, settle: bool):
    ctl = Controller()
    for axis in ctl.axes:
        axis.in_position = AxisInPosition(settle_on_stop=settle, settle_on_estop=settle)
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    seen = {}
    pending = list(script)
    while ctl.sample < SAMPLES:
        while pending and pending[0][0] <= ctl.sample:
            _apply(ctl, ms, *pending.pop(0)[1:])
        upcoming = pending[0][0] if pending else SAMPLES
        ctl.step(max(1, min(next(batches), upcoming - ctl.sample)))
        seen[ctl.sample] = (ms.state, [(a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v, a.status) for a in ctl.axes])
    events = [(e.sample, e.type, e.axis, e.move_id) for e in ctl.drain_events()]
    return seen, events


KINDS = ["start", "append", "modify", "velocity", "hold", "gate", "STOP", "RESUME", "E_STOP", "ABORT",
         "E_STOP_ABORT", "RESET"]


@settings(max_examples=25, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(script=st.lists(st.tuples(st.integers(0, SAMPLES - 1), st.sampled_from(KINDS),
                                 st.integers(-3000, 3000), st.integers(-3000, 3000)), min_size=1, max_size=10),
       seed=st.integers(0, 2**31), settle=st.booleans())
def test_any_batching_gives_bit_identical_samples_and_events(script, seed, settle):
    script = _commands(script)
    fine, fine_events = _run(script, iter(lambda: 1, None), settle)
    rng = np.random.default_rng(seed)
    coarse, coarse_events = _run(script, iter(lambda: int(rng.integers(1, 700)), None), settle)
    assert coarse_events == fine_events
    different = [s for s, values in coarse.items() if fine[s] != values]
    assert not different, f"{len(different)} samples differ, first at {different[:3]}"
