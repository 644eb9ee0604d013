"""Controller.step_snapshots: the snapshots it takes inside long stretches are the ones stepping
to each sample and calling motion_snapshots() there gives, every field of every supervisor and
axis to the bit, and the events are the same (issue 35: replay steps in long stretches)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mpi_ros.mpi import AxisInPosition, Controller

from .test_batching import KINDS, SAMPLES, _apply, _commands


def exact(snapshots) -> str:
    """Every field, bit for bit: a float's repr is exact (and tells -0.0 from 0.0), and NaN
    equals NaN here, as a replay's bytes do."""
    return repr(snapshots)


def _controller(settle: bool):
    ctl = Controller()
    for axis in ctl.axes:
        axis.in_position = AxisInPosition(settle_on_stop=settle, settle_on_estop=settle)
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    return ctl, ms


def _stepped(script, wanted: list[int], settle: bool):
    """The old route: step to each wanted sample, then motion_snapshots() (before the
    commands given at that sample, as replay compares them)."""
    ctl, ms = _controller(settle)
    pending, taken = list(script), {}
    for sample in [*wanted, SAMPLES]:
        while pending and pending[0][0] < sample:
            ctl.step(max(0, pending[0][0] - ctl.sample))
            _apply(ctl, ms, *pending.pop(0)[1:])
        ctl.step(max(0, sample - ctl.sample))
        taken[sample] = exact(ctl.motion_snapshots())
    return {s: taken[s] for s in wanted}, _events(ctl)


def _in_stretches(script, wanted: list[int], settle: bool):
    """The new route: from command to command, one step_snapshots for the samples between."""
    ctl, ms = _controller(settle)
    pending, taken = list(script), {}
    while True:
        end = pending[0][0] if pending else SAMPLES
        at = [s for s in wanted if ctl.sample <= s <= end and s not in taken]
        taken.update({s: exact(snaps) for s, snaps in ctl.step_snapshots(end - ctl.sample, at).items()})
        if not pending:
            break
        _apply(ctl, ms, *pending.pop(0)[1:])
    return {s: taken[s] for s in wanted}, _events(ctl)


def _events(ctl):
    return [(e.sample, e.type, e.supervisor, e.axis, e.move_id, e.element_id, e.detail) for e in ctl.drain_events()]


def _compare(script, wanted, settle):
    old, old_events = _stepped(script, wanted, settle)
    new, new_events = _in_stretches(script, wanted, settle)
    assert new_events == old_events
    different = [s for s in wanted if new[s] != old[s]]
    assert not different, f"{len(different)} samples differ, first at {different[:3]}"


@settings(max_examples=25, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(script=st.lists(st.tuples(st.integers(0, SAMPLES - 1), st.sampled_from(KINDS),
                                 st.integers(-3000, 3000), st.integers(-3000, 3000)), min_size=1, max_size=10),
       seed=st.integers(0, 2**31), settle=st.booleans())
def test_snapshots_in_stretches_are_those_of_stepping_to_each_sample(script, seed, settle):
    rng = np.random.default_rng(seed)
    # status every few samples (as at 100 Hz of 2 kHz), with the commands' samples among them
    wanted = sorted(set(np.cumsum(rng.integers(1, 40, size=SAMPLES // 10)).tolist()) & set(range(SAMPLES)))
    _compare(_commands(script), wanted, settle)


def test_every_sample_of_two_moves_with_their_events():
    """A status at every sample of two moves: the status bits' events (in coarse position,
    at target) fall inside stretches, and each is latched from exactly its own sample."""
    script = [(0, "start", 1500.0, -1000.0), (1700, "start", -500.0, 800.0)]
    _compare(script, list(range(SAMPLES)), settle=True)


def test_samples_outside_the_step_are_refused():
    ctl, _ = _controller(False)
    ctl.step(10)
    with pytest.raises(ValueError):
        ctl.step_snapshots(5, [9])
    with pytest.raises(ValueError):
        ctl.step_snapshots(5, [16])
    assert set(ctl.step_snapshots(5, [10, 12, 15])) == {10, 12, 15}
    assert ctl.sample == 15
