"""Fixtures of the simulated-controller tests (test/mpi).

- ``ctl``: a default controller (2000 Hz, 4 axes, 2 supervisors, 128-frame buffers);
- ``ms``: its supervisor 0 on axes [0, 1], mapped (MEIActionMAP); ``ms1``: supervisor 1 on [2, 3];
- ``params``: builds MotionParams for a point-to-point or velocity move;
- ``run_to``: steps until a supervisor reaches a state (fails the test if it never does);
- ``bring``: puts ``ms`` into any MPIState the way a user would (start, STOP, E_STOP, ...).

Everything steps the controller by samples; nothing sleeps.
"""

from __future__ import annotations

import pytest

from mpi_ros.mpi import Controller, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory

LONG_MOVE = (100_000.0, 0.0)  # 100 s at the default 1000 counts/s: still moving in every test


def make_params(position=(1000.0, 0.0), velocity=1000.0, acceleration=10_000.0, deceleration=None,
                jerk_percent=0.0, trajectory=None, **fields) -> MotionParams:
    """MotionParams of one (vector) trajectory, or of the given trajectory list."""
    if trajectory is None:
        decel = acceleration if deceleration is None else deceleration
        trajectory = [Trajectory(velocity, acceleration, decel, jerk_percent)]
    return MotionParams(trajectory=list(trajectory), position=list(position), **fields)


def run_to_state(ctl: Controller, ms, state: MPIState, max_samples: int = 400_000, chunk: int = 1) -> int:
    """Step until ``ms`` is in ``state``; returns the sample at which it got there."""
    reached = ctl.run_until(lambda c: ms.state is state, max_samples, chunk=chunk)
    assert reached, f"supervisor {ms.number} still {ms.state.name} after {max_samples} samples"
    return ctl.sample


@pytest.fixture
def params():
    return make_params


@pytest.fixture
def run_to():
    return run_to_state


@pytest.fixture
def ctl() -> Controller:
    return Controller()


def _supervisor(ctl: Controller, number: int, axes: list[int]):
    message, ms = ctl.create_motion(number)
    assert message.ok
    assert ms.axis_list_set(axes).ok
    assert ms.action(MPIAction.MAP).ok
    return ms


def sharing_axis_1(ctl: Controller):
    """Supervisor 0 on axes [0, 1] and supervisor 1 on [1, 2], both mapped."""
    return _supervisor(ctl, 0, [0, 1]), _supervisor(ctl, 1, [1, 2])


@pytest.fixture
def ms(ctl):
    return _supervisor(ctl, 0, [0, 1])


@pytest.fixture
def ms1(ctl, ms):
    return _supervisor(ctl, 1, [2, 3])


def drive_to(ctl: Controller, ms, state: MPIState) -> None:
    """Drive ``ms`` into ``state`` through the public API, mid-way through a long move
    (IDLE: untouched; STOPPING/STOPPING_ERROR: a few samples into the ramp)."""
    if state is MPIState.IDLE:
        return
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=make_params(LONG_MOVE)).ok
    ctl.step(400)  # at speed (the ramp takes 200 samples)
    if state in (MPIState.STOPPING, MPIState.STOPPED):
        assert ms.action(MPIAction.STOP).ok
    elif state in (MPIState.STOPPING_ERROR, MPIState.ERROR):
        assert ms.action(MPIAction.E_STOP).ok
    if state in (MPIState.STOPPING, MPIState.STOPPING_ERROR):
        ctl.step(10)
    elif state in (MPIState.STOPPED, MPIState.ERROR):
        run_to_state(ctl, ms, state, chunk=50)
    assert ms.state is state


@pytest.fixture
def bring(ctl, ms):
    """bring(state): drive the fixture's ``ms`` into ``state`` (see drive_to)."""
    return lambda state: drive_to(ctl, ms, state)


@pytest.fixture
def prepared():
    """prepared(state) -> (ctl, ms): a new controller whose supervisor 0 (axes 0, 1) is in
    ``state`` (see drive_to); call it twice for two identical controllers."""

    def prepare(state: MPIState):
        ctl = Controller()
        ms = _supervisor(ctl, 0, [0, 1])
        drive_to(ctl, ms, state)
        ctl.drain_events()
        return ctl, ms

    return prepare
