"""meiMotionParamsValidate (MPI 000): the checks of a start, against the coordinate system of
the motion, without starting; and the number of points the parameters specify."""

from __future__ import annotations

from mpi_ros.mpi import MotionAttr, MotionParams, MPIMotionType, MPIState
from mpi_ros.mpi.base.messages import Message

from ..conftest import LONG_MOVE

T = MPIMotionType


def test_valid_parameters_answer_ok_and_nothing_moves(ctl, ms, params):
    outcome, points = ms.params_validate(T.S_CURVE, MotionAttr.NONE, params((1000.0, 50.0), jerk_percent=50.0))
    assert outcome.ok
    assert points == 0
    ctl.step(50)
    assert ms.state is MPIState.IDLE
    assert ms.current is None
    assert ctl.axis_snapshot(0).command_position == 0.0


def test_it_answers_what_the_start_answers(ms, params):
    # MPI 000, MPIMessagePARAM_INVALID (array lengths: one position per axis) and MPIMotionMessageTYPE_INVALID
    cases = [(T.TRAPEZOIDAL, MotionAttr.NONE, params((1000.0,))),
             (T.TRAPEZOIDAL, MotionAttr.NONE, params((1000.0, 0.0), velocity=-5.0)),
             (T.INVALID, MotionAttr.NONE, params()),
             (T.PT, MotionAttr.FINAL_VEL, MotionParams(position=[1.0, 2.0], time=[0.1]))]
    for motion_type, attrs, request in cases:
        validated, _ = ms.params_validate(motion_type, attrs, request)
        assert not validated.ok
        assert ms.start(motion_type, attrs, request).message is validated.message, (motion_type, attrs)


def test_a_path_counts_its_points(ms):
    request = MotionParams(position=[10.0, 0.0, 20.0, 5.0, 30.0, 5.0], time=[0.1, 0.1, 0.1])
    outcome, points = ms.params_validate(T.PT, MotionAttr.NONE, request)
    assert outcome.ok
    assert points == 3


def test_the_state_is_the_starts_business(ctl, ms, params):
    # meiMotionParamsValidate checks the parameters; the state (MPIMotionMessageMOVING) is mpiMotionStart's
    assert ms.start(T.VELOCITY, params=params(LONG_MOVE)).ok
    assert ms.params_validate(T.TRAPEZOIDAL, MotionAttr.NONE, params((10.0, 0.0)))[0].ok
    assert ms.start(T.TRAPEZOIDAL, params=params((10.0, 0.0))).message is Message.MPIMotionMessageMOVING


def test_no_axes(ctl, params):
    _, empty = ctl.create_motion(0)
    assert empty.params_validate(T.TRAPEZOIDAL, MotionAttr.NONE, params())[0].message is (
        Message.MPIMotionMessageAXIS_COUNT)
