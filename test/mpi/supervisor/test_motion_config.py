"""Motion configuration and parameters (mpi_ros/mpi/supervisor/motion.py, params.py): MPIMotionConfig
defaults, config get/set, the feedrate, params get/set, frame buffer status, the action
callback."""

from __future__ import annotations

import pytest

from mpi_ros.mpi import DecelTime, MotionAttr, MotionConfig, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.messages import Message

M = Message
T = MPIMotionType


def test_decel_time_defaults(ms):
    # MPI 000, MPIMotionDecelTime, stop stop "The default value is .5 seconds"; MPI 000, MPIMotionDecelTime, eStop eStop
    # "The default value is .05 seconds"
    config = ms.config_get()[1]
    assert config.decel_time.stop == 0.5
    assert config.decel_time.e_stop == 0.05


def test_feedrate_defaults(ms):
    # MPI 000, MPIMotionConfig, normalFeedrate normalFeedrate "The default value is 1.0 (100%)"; MPI 000,
    # MPIMotionConfig, pauseFeedrate pauseFeedrate "The default value is 0.0"
    config = ms.config_get()[1]
    assert config.normal_feedrate == 1.0
    assert config.pause_feedrate == 0.0


def test_mei_config_fields(ms):
    # MPI 000, MEIMotionConfig, userLabel userLabel (16 characters, not used by the controller); MPI 000,
    # MEIMotionConfig, axisCount axisCount/axisNumber = the current mapping; MPI 000, MEIMotionConfig, blendLimit
    # blendLimit
    config = ms.config_get()[1]
    assert config.user_label == ""
    assert config.axis_numbers == [0, 1]
    assert config.axis_count == 2
    config.user_label = "x" * 16
    config.blend_limit = -1.0
    assert ms.config_set(config).ok
    again = ms.config_get()[1]
    assert again.user_label == "x" * 16
    assert again.blend_limit == -1.0


def test_config_get_is_a_copy(ms):
    # MPI 000, mpiMotionConfigGet ConfigGet "puts (writes) it in the structure pointed to by config"
    config = ms.config_get()[1]
    config.decel_time.stop = 3.0
    assert ms.config_get()[1].decel_time.stop == 0.5


def test_config_set_cannot_change_the_mapping(ms):
    # MPI 000, MEIMotionConfig, axisCount axisCount/axisNumber report the mapping on the controller (MAP writes it)
    config = ms.config_get()[1]
    config.axis_numbers = [3]
    assert ms.config_set(config).ok
    assert ms.config_get()[1].axis_numbers == [0, 1]


@pytest.mark.parametrize("change", [
    lambda c: setattr(c.decel_time, "stop", 0.0),
    lambda c: setattr(c.decel_time, "e_stop", -1.0),
    lambda c: setattr(c.decel_time, "stop", float("nan")),
    lambda c: setattr(c, "normal_feedrate", 0.0),
    lambda c: setattr(c, "pause_feedrate", -0.1),
    lambda c: setattr(c, "blend_limit", 1.5),
    lambda c: setattr(c, "user_label", "x" * 17),
])
def test_config_set_refuses_bad_values(ms, change):
    # MPI 000, MEIMotionConfig, userLabel userLabel 16 characters; MPI 000, MEIMotionConfig, blendLimit blendLimit from
    # -1.0 to 1.0; the times are durations and the feedrates fractions (docs/quality.md, "Robust")
    config = ms.config_get()[1]
    change(config)
    assert ms.config_set(config).message is M.MPIMessagePARAM_INVALID
    assert ms.config_get()[1] == MotionConfig(axis_numbers=[0, 1])


def test_decel_time_stop_is_used_by_stop(ctl, ms, params, run_to):
    # MPI 000, mpiMotionAction "The deceleration stop and Estop times can be set with mpiMotionConfigSet"
    config = ms.config_get()[1]
    config.decel_time = DecelTime(stop=0.25, e_stop=0.01)
    ms.config_set(config)
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(400)
    k = ctl.sample
    ms.action(MPIAction.STOP)
    run_to(ctl, ms, MPIState.STOPPED, 2000)
    assert ctl.sample - k == 500
    ms.action(MPIAction.E_STOP)
    k = ctl.sample
    run_to(ctl, ms, MPIState.ERROR, 2000)
    assert ctl.sample - k == 20


def test_normal_feedrate_scales_the_speed(ctl, ms, params):
    # MPI 000, MPIMotionConfig, normalFeedrate normalFeedrate "defines the normal feed speed rate"
    config = ms.config_get()[1]
    config.normal_feedrate = 0.5
    ms.config_set(config)
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    assert ctl.axes[0].cmd_v == pytest.approx(500.0)
    assert ms.snapshot().feedrate == 0.5


def test_normal_feedrate_change_while_moving_ramps(ctl, ms, params):
    # MPI 000, mpiMotionConfigGet, sample code sample modifyFeedrate: the feedrate is changed with ConfigSet while
    # moving; motion.py: "a new normal feedrate applies on the fly (ramped over the stop time while moving)"
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    config = ms.config_get()[1]
    config.normal_feedrate = 2.0
    ms.config_set(config)
    ctl.step(500)
    assert 1000.0 < ctl.axes[0].cmd_v < 2000.0
    ctl.step(500)
    assert ctl.axes[0].cmd_v == pytest.approx(2000.0)


def test_pause_feedrate_is_the_speed_after_stop(ctl, ms, params, run_to):
    # MPI 000, MPIMotionConfig, pauseFeedrate pauseFeedrate "defines the feed speed rate for the Stop action"
    config = ms.config_get()[1]
    config.pause_feedrate = 0.25
    ms.config_set(config)
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.STOP)
    run_to(ctl, ms, MPIState.STOPPED, 2000)
    assert ctl.axes[0].cmd_v == pytest.approx(250.0)
    assert ms.snapshot().feedrate == 0.25


# ------------------------------------------------------------------ params ----
def test_params_get_initially_empty(ms):
    # MPI 000, mpiMotionParamsGet ParamsGet: "These motion parameters will be used if mpiMotionStart(...) is
    # called with Null motion params"
    message, params = ms.params_get()
    assert message.ok
    assert params.trajectory == []
    assert params.position == []


def test_start_with_null_params_uses_the_stored_ones(ctl, ms, params, run_to):
    # MPI 000, mpiMotionStart "If params is Null, then the motion parameters that were set by the most recent
    # call to mpiMotionParamsSet(...) will be used"; MPI 000, mpiMotionParamsSet
    assert ms.params_set(params((300.0, -100.0))).ok
    assert ms.params_set(params((400.0, -200.0))).ok  # the most recent one wins
    assert ms.start(T.TRAPEZOIDAL, params=None).ok
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=100)
    assert [a.command_position for a in ms.axes] == [400.0, -200.0]
    assert ms.params_get()[1].position == [400.0, -200.0]


def test_start_with_null_params_and_nothing_stored(ms):
    # MPI 000, MPIMotionMessageATTRIBUTE_INVALID / MPI 000, MPIMessagePARAM_INVALID: no usable parameters -> refused,
    # nothing moves
    assert ms.start(T.TRAPEZOIDAL, params=None).message is M.MPIMessagePARAM_INVALID
    assert ms.state is MPIState.IDLE


def test_modify_with_null_params_uses_the_stored_ones(ctl, ms, params, run_to):
    # MPI 000, mpiMotionParamsSet ParamsSet "These motion parameters will be used if mpiMotionStart(...) is called
    # with a Null motion parameter" (and a modify alike)
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(300)
    ms.params_set(params((-50.0, 50.0)))
    assert ms.modify(T.TRAPEZOIDAL, params=None).ok
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=100)
    assert [a.command_position for a in ms.axes] == [-50.0, 50.0]


def test_params_set_keeps_a_copy(ms, params):
    # MPI 000, mpiMotionParamsSet ParamsSet sets the parameters of the Motion object (later changes of the caller's
    # structure do not leak in)
    mine = params((1.0, 2.0))
    ms.params_set(mine)
    mine.position[0] = 99.0
    assert ms.params_get()[1].position == [1.0, 2.0]


def test_params_get_after_a_start_returns_the_start_s_parameters(ms, params):
    # MPI 000, mpiMotionParamsGet: the parameters are the ones set "by mpiMotionParamsSet(...) or
    # mpiMotionStart(...)": after a start with parameters of its own, a get returns those.
    assert ms.params_set(params((1.0, 2.0))).ok
    assert ms.start(T.TRAPEZOIDAL, params=params((300.0, -100.0))).ok
    assert ms.params_get()[1].position == [300.0, -100.0]


def test_params_set_refuses_a_value_no_start_could_use(ms, params):
    # MPI 000 mpiMotionParamsSet stores the parameters for a later start (params Null): a value no
    # controller holds is refused now, with the field that holds it, and nothing is stored
    assert ms.params_set(params((1.0, 2.0))).ok
    refused = ms.params_set(params((1e300, 0.0)))
    assert (refused.message, refused.detail.split(":")[0]) == (M.MPIMessagePARAM_INVALID, "position[0]")
    assert ms.params_get()[1].position == params((1.0, 2.0)).position


def test_params_set_while_moving_changes_the_move_on_the_fly(ctl, ms, params, run_to):
    # MPI 000, mpiMotionParamsSet: while a motion runs the new parameters take effect "on-the-fly"
    # (docs/decisions.md: as a modify of the running move's type)
    assert ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0))).ok
    ctl.step(300)
    assert ms.params_set(params((-50.0, 50.0))).ok
    assert ms.state is MPIState.MOVING
    run_to(ctl, ms, MPIState.IDLE, 40_000, chunk=100)
    assert [a.command_position for a in ms.axes] == [-50.0, 50.0]


def test_params_set_while_moving_that_the_move_refuses_changes_nothing(ctl, ms, params):
    # MPI 000, mpiMotionParamsSet on the fly: refused as the modify would be, and then not stored
    assert ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0))).ok
    ctl.step(300)
    before = ms.params_get()[1]
    assert ms.params_set(params((1.0,))).message is M.MPIMessagePARAM_INVALID  # one position for two axes
    assert ms.params_get()[1].position == before.position
    assert ms.current.plans[0].target == 100_000.0


# ------------------------------------------------------------------ frame buffer status ----
def test_frame_buffer_status(ctl, ms, params, run_to):
    # MPI 000, meiMotionFrameBufferStatus "gets a Motion object (motion) frame buffer status"; MPI 000,
    # MEIMotionFrameBufferStatus, size size "the size of the controller's frame buffer"; MPI 000,
    # MEIMotionFrameBufferStatus, frameCount frameCount "the number of frames in the buffer"
    message, status = ms.frame_buffer_status()
    assert message.ok
    assert [(s.axis, s.size) for s in status] == [(0, 128), (1, 128)]
    ms.start(T.S_CURVE, params=params((5000.0, 0.0), jerk_percent=50.0))
    first = ms.frame_buffer_status()[1][0].frame_count
    ms.start(T.S_CURVE, MotionAttr.APPEND, params((0.0, 0.0), jerk_percent=50.0))
    second = ms.frame_buffer_status()[1][0].frame_count
    assert first > 1
    assert second > first
    run_to(ctl, ms, MPIState.IDLE, 50_000, chunk=100)
    assert ms.frame_buffer_status()[1][0].frame_count == 1  # the final frame holding the end


# ------------------------------------------------------------------ action callback ----
def test_action_callback_sees_every_action(ctl, ms, params):
    # MPI 000, meiMotionActionFunction "the callback function is called whenever the MPI writes to the action variable"
    # (start, modify, stop, abort, reset ...); MPI 000, MEIMotionActionFunction, motion it receives the motion, the
    # motion type and the action
    calls = []
    assert ms.action_function(lambda motion, kind, action: calls.append((motion.number, kind, action))) is None
    ms.start(T.S_CURVE, params=params((100_000.0, 0.0)))
    ctl.step(100)
    ms.modify(T.S_CURVE, params=params((50_000.0, 0.0)))
    ms.action(MPIAction.STOP)
    assert calls == [(0, T.S_CURVE, "START"), (0, T.S_CURVE, "MODIFY"), (0, T.S_CURVE, "STOP")]


def test_action_function_returns_the_previous_callback(ms):
    # MPI 000, meiMotionActionFunction meiMotionActionFunction(motion, function) returns an MEIMotionActionFunction
    def first(*_):
        return None

    assert ms.action_function(first) is None
    assert ms.action_function(None) is first
    assert ms.action_function(None) is None


def test_action_callback_runs_on_every_call_even_refused(ms):
    # MPI 000, MEIMotionActionFunction "every time the application calls mpiMotionAction(...), the callback function
    # will be executed"
    calls = []
    ms.action_function(lambda motion, kind, action: calls.append(action))
    assert ms.action(MPIAction.STOP).message is M.MPIMotionMessageIDLE
    assert calls == ["STOP"]
