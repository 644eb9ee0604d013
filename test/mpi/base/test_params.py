"""The one validator per struct (mpi_ros/mpi/base/params.py): the ranges a controller can hold.

The YAML loader, the services and the controller all ask ``validate()``, so a value is
accepted or refused alike whichever way it comes in (docs/decisions.md, "Validation and
ranges"). Refusals answer the reference's message, MPIMessagePARAM_INVALID (MPI 000,
"Returns for mpiMotionStart and mpiMotionModify": "if the specified motion parameters are
not valid"), with the field named first in the detail.
"""

from __future__ import annotations

import math
import re

import pytest

from mpi_ros.mpi import Controller, MPIAction, MPIState
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import (
    FEEDRATE_MAX,
    FEEDRATE_MIN,
    LONG_MAX,
    LONG_MIN,
    MAX_DURATION,
    MAX_POSITION,
    SAMPLE_RATE_MAX,
    AxisInPosition,
    ControllerConfig,
    DecelTime,
    Hold,
    MotionConfig,
    MotionParams,
    Output,
    PlantConfig,
    Trajectory,
    UserFrame,
    check_duration,
    check_position,
    check_settling_reachable,
)
from mpi_ros.mpi.base.types import HoldType, MotionAttr, MPIMotionType, OutputType

M = Message
NOT_NUMBERS = [math.nan, math.inf, -math.inf, True, "1.0", None, 10**400]


def refused(verdict: Outcome, field: str) -> bool:
    """Refused with PARAM_INVALID, the detail naming ``field`` first."""
    return verdict.message is M.MPIMessagePARAM_INVALID and verdict.detail.startswith(field + ":")


# ------------------------------------------------------------------ the helpers ----
@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_only_finite_numbers_pass_a_range(value):
    # docs/decisions.md, "Validation and ranges": every value must be a finite number; a bool, a string or an int past
    # every double is not a number a C double could hold
    assert refused(check_position("p", value), "p")
    assert refused(check_duration("d", value), "d")


def test_a_duration_fits_the_sample_counter_at_every_rate():
    # The sample counter is a C long (MPI 000: MPIMotionPoint and MPIMotionAttributes use
    # long for counts); a duration that fits it at the highest rate fits it at every rate.
    assert MAX_DURATION * SAMPLE_RATE_MAX <= LONG_MAX
    assert check_duration("d", MAX_DURATION).ok
    assert refused(check_duration("d", MAX_DURATION * 1.001), "d")
    assert check_duration("d", 0.0).ok
    assert refused(check_duration("d", 0.0, positive=True), "d")
    assert refused(check_duration("d", -1e-9), "d")


def test_positions_keep_sub_count_resolution():
    # A position plus an origin plus a relative distance stays below 2**49, where a double
    # still resolves 1/16 count: finer than any settling tolerance (002 MPIAxisInPosition).
    assert (3 * MAX_POSITION + 1 / 16) - 3 * MAX_POSITION == 1 / 16
    assert check_position("p", -MAX_POSITION).ok
    assert refused(check_position("p", 1e308), "p")


# ------------------------------------------------------------------ MPIMotionConfig ----
def test_motion_config_defaults_are_valid():
    # MPI 000 MPIMotionConfig: normalFeedrate 1.0 (100 %), pauseFeedrate 0.0
    assert MotionConfig().validate().ok


@pytest.mark.parametrize("value", [1e308, 1e-300, 0.0, -1.0, *NOT_NUMBERS[:3]])
def test_normal_feedrate_out_of_range_is_refused(value):
    # issue 9: normal_feedrate 1e308 gave NaN command positions, 1e-300 a division by zero.
    # MPI 000 MPIMotionConfig: normalFeedrate is a C float, 1.0 = 100 %.
    assert refused(MotionConfig(normal_feedrate=value).validate(), "normal_feedrate")


@pytest.mark.parametrize("value", [FEEDRATE_MIN, 1.0, FEEDRATE_MAX])
def test_normal_feedrate_range_ends_are_accepted(value):
    assert MotionConfig(normal_feedrate=value).validate().ok


def test_pause_feedrate_zero_or_within_the_normal_range():
    # MPI 000 MPIMotionConfig: pauseFeedrate "for the Stop action. The default value is 0.0"
    assert MotionConfig(pause_feedrate=0.0).validate().ok
    assert MotionConfig(pause_feedrate=0.5).validate().ok
    for value in (1e-300, -0.1, 1e308, math.nan):
        assert refused(MotionConfig(pause_feedrate=value).validate(), "pause_feedrate")


@pytest.mark.parametrize(("value", "ok"), [(-1.0, True), (0.0, True), (1.0, True), (5.0, False), (-1.01, False),
                                      (math.nan, False)])
def test_blend_limit_is_a_cosine(value, ok):
    # MPI 000 MEIMotionConfig blendLimit: "If cosine (turn angle) is greater than the
    # blendLimit ... 1.0 causes all moves to be blended. -1.0 allows no blending"
    verdict = MotionConfig(blend_limit=value).validate()
    assert verdict.ok if ok else refused(verdict, "blend_limit")


def test_user_label_holds_16_characters():
    # MPI 000 MEIMotionConfig: userLabel[MEIObjectLabelCharMAX+1], "16 characters"
    assert MotionConfig(user_label="x" * 16).validate().ok
    assert refused(MotionConfig(user_label="x" * 17).validate(), "user_label")


@pytest.mark.parametrize("field", ["stop", "e_stop"])
@pytest.mark.parametrize("value", [0.0, -0.5, MAX_DURATION * 2, 1e308, math.nan])
def test_decel_times_are_positive_durations(field, value):
    # MPI 000 mpiMotionAction: MPIMotionConfig.decelTime.stop / .eStop, "seconds"; a stop that
    # takes no time, or more samples than the counter holds, is not one a controller can run
    decel = DecelTime()
    setattr(decel, field, value)
    # named as the ROS interface and the YAML name them: decel_time_stop, decel_time_e_stop
    assert refused(MotionConfig(decel_time=decel).validate(), f"decel_time_{field}")


# ------------------------------------------------------------------ MPIAxisInPosition ----
def test_in_position_defaults_are_valid():
    assert AxisInPosition().validate().ok


@pytest.mark.parametrize(("field", "value"), [
    ("settling_time", 1e308),  # issue 9: crashed the controller clock on every step
    ("settling_time", MAX_DURATION * 2),
    ("settling_time", -0.01),
    ("position_fine", 0.0),  # 002 NOTE 1/NOTE 3: |error| < fine tolerance, strictly: 0 never holds
    ("position_fine", 1e308),
    ("velocity", 0.0),  # likewise strict "<" (NOTE 1)
    ("velocity", math.inf),
    ("position_coarse", -1),
    ("position_coarse", 2**31),  # a C long (002 MPIAxisInPosition)
    ("position_coarse", 10.5),
    ("settle_on_stop", 1),  # MPI_BOOL fields: true or false
])
def test_in_position_out_of_range_is_refused(field, value):
    # MPI 002 MPIAxisInPosition: positionFine and velocity are C floats, positionCoarse a long,
    # settlingTime seconds (which must fit the sample counter)
    in_position = AxisInPosition()
    setattr(in_position, field, value)
    assert refused(in_position.validate(), field)


def test_in_position_range_ends_are_accepted():
    assert AxisInPosition(position_fine=1e-9, position_coarse=0, velocity=3.4e38,
                          settling_time=MAX_DURATION).validate().ok


def test_fine_tolerance_must_be_reachable_through_the_encoder():
    # 002 NOTE 3: |target - actual| < positionFine, with actual read in encoder steps: a reading
    # can be half a step from any target, so a tolerance at or below that never settles
    plant = PlantConfig(encoder_resolution=1.0)
    assert check_settling_reachable(AxisInPosition(position_fine=0.6), plant).ok
    assert refused(check_settling_reachable(AxisInPosition(position_fine=0.5), plant), "position_fine")
    assert check_settling_reachable(AxisInPosition(position_fine=0.1), PlantConfig(encoder_resolution=0.0)).ok


# ------------------------------------------------------------------ the simulated servo ----
@pytest.mark.parametrize(("field", "value"), [
    ("damping", 0.0),
    ("damping", 1.5),  # over-damped: the closed-form response overflows on a long command piece
    ("bandwidth_hz", 0.0),
    ("bandwidth_hz", 1e9),
    ("velocity_feedforward", 1e308),
    ("encoder_resolution", 1e-9),
    ("encoder_resolution", -1.0),
    ("coast_time_constant", 0.0),
    ("coast_time_constant", 1e308),
])
def test_plant_out_of_range_is_refused(field, value):
    plant = PlantConfig()
    setattr(plant, field, value)
    assert refused(plant.validate(), field)


def test_plant_defaults_and_ends_are_valid():
    assert PlantConfig().validate().ok
    assert PlantConfig(damping=1.0, encoder_resolution=0.0, bandwidth_hz=0.01).validate().ok


# ------------------------------------------------------------------ the controller ----
@pytest.mark.parametrize(("field", "value"), [
    ("sample_rate", 0.0),
    ("sample_rate", 1e9),
    ("axis_count", 0),
    ("supervisor_count", 0),
    ("frame_buffer_size", 15),  # MPI 000 mpiMotionStart: a frame buffer per axis (128 by default)
    ("io_words", 0),
    ("motor_count", -2),
    ("firmware_option_21", 1),
])
def test_controller_config_out_of_range_is_refused(field, value):
    cfg = ControllerConfig()
    setattr(cfg, field, value)
    assert refused(cfg.validate(), field)


def test_controller_config_defaults_are_valid():
    # MPI 000 MPIMotionConfig sample code: "sample rate configured for 2000 (default)"
    assert ControllerConfig().validate().ok


# ------------------------------------------------------------------ MPIMotionParams ----
def test_trajectory_magnitudes():
    # MPI 000 MPIMotionSCurve / MPIMotionVelocity: which trajectory values a type reads, and so
    # which must be positive, depends on the type (checked with the move); here only what a
    # controller could hold
    assert Trajectory(1000.0, 1e4, 1e4, 50.0).validate().ok
    assert Trajectory(-500.0, 1e4, 0.0).validate().ok  # a VELOCITY move's signed velocity
    assert refused(Trajectory(1e300, 1e4, 1e4).validate(), "velocity")
    assert refused(Trajectory(1e3, 1e4, 1e4, 100.5).validate(), "jerk_percent")
    assert refused(Trajectory(1e3, 1e4, math.nan).validate(), "deceleration")


def test_params_name_the_nested_field():
    params = MotionParams(trajectory=[Trajectory(1e3, 1e4, 1e4), Trajectory(1e3, math.inf, 1e4)])
    assert refused(params.validate(), "trajectory[1].acceleration")
    frames = MotionParams(frames=[UserFrame(time=-1.0)])
    assert refused(frames.validate(), "frames[0].time")


def test_params_check_only_what_the_move_reads():
    # MPI 000 MPIMotionSCurve, position: "VELOCITY and VELOCITY_JERK do not require target
    # positions and will ignore these values"; an attribute's array is read only with the
    # attribute (MPIMotionAttributes)
    params = MotionParams(trajectory=[Trajectory(100.0, 1e4, 0.0)], position=[1e300], delay=[-1.0])
    # (what a family reads is its record's: planning/families.py, Kind.reads_position)
    assert params.validate(MotionAttr.NONE, position=False).ok
    assert refused(params.validate(MotionAttr.DELAY, position=False), "delay[0]")
    assert refused(params.validate(MotionAttr.NONE), "position[0]")
    # mpiMotionParamsSet stores the parameters for any later start: every value is checked
    assert refused(params.validate(), "position[0]")


def test_params_answer_the_first_refusal_in_field_order_with_its_index():
    # Every value passes one check a start or modify needs: the first refused field wins (the
    # array before the attribute arrays after it), and within it the first refused value, named
    # by its index; a refused value after it changes nothing of the answer.
    params = MotionParams(trajectory=[Trajectory(1e3, 1e4, 1e4)], position=[1.0, 2.0, math.inf, math.nan],
                          final_velocity=[1e300])
    assert refused(params.validate(MotionAttr.FINAL_VEL), "position[2]")
    params.position = [1.0, 2.0]
    assert refused(params.validate(MotionAttr.FINAL_VEL), "final_velocity[0]")
    assert params.validate(MotionAttr.NONE).ok
    params.trajectory.append(Trajectory(1e3, 1e4, -math.inf))
    assert refused(params.validate(MotionAttr.FINAL_VEL), "trajectory[1].deceleration")


@pytest.mark.parametrize(("struct", "field"), [
    (Hold(type=HoldType.GATE, mask=2**32), "mask"),
    (Hold(type=HoldType.INPUT, pattern=-(2**31) - 1), "pattern"),
    (Hold(type=HoldType.GATE, timeout=MAX_DURATION * 2), "timeout"),
    (Hold(type=HoldType.AXIS_POSITION_ACTUAL, position=1e308), "position"),
    (Output(type=OutputType.OUTPUT, on_mask=2**31), "on_mask"),
    (Output(type=OutputType.MOTOR, motor=2**40), "motor"),
])
def test_hold_and_output_fields_are_c_longs(struct, field):
    # MPI 000 MEIMotionAttrHold / MEIMotionAttrOutput: long fields (32 bits, as the ROS
    # interface's int32); the timeout must fit the sample counter
    assert refused(struct.validate(), field)


def test_ids_are_c_longs():
    # MPI 000 MPIMotionAttributes: id and elementId are longs (the firmware keeps 16 bits)
    assert MotionParams(id=LONG_MIN, element_id=[LONG_MAX]).validate().ok
    assert refused(MotionParams(id=2**31).validate(), "id")
    assert refused(MotionParams(element_id=[1, 2**40]).validate(), "element_id[1]")


# ------------------------------------------------------------------ emptyCount ----
@pytest.mark.parametrize(("empty_count", "disabled"), [(-1, True), (0, True), (-7, True), (1, False), (5, False)])
def test_empty_count_at_or_below_zero_disables(empty_count, disabled):
    # MPI 000, MPIMotionPoint: "When emptyCount is (-1), the buffer low trigger is disabled";
    # MPI 001, MPIMotionPathAttrMask EMPTY_COUNT: "To disable path-based deceleration, set the
    # value to zero". Both disable, and so does anything below (docs/decisions.md, "emptyCount <= 0 disables").
    params = MotionParams(empty_count=empty_count)
    assert params.empty_count_disabled is disabled
    assert params.validate().ok  # every value disables or counts: none is refused


def test_empty_count_is_a_c_long():
    # MPI 000 MPIMotionPoint: long emptyCount
    assert refused(MotionParams(empty_count=2**31).validate(), "empty_count")


# ------------------------------------------------------------------ the controller uses them ----
@pytest.mark.parametrize(("kwargs", "field"), [
    ({"config": ControllerConfig(frame_buffer_size=8)}, "config.frame_buffer_size"),
    ({"config": ControllerConfig(sample_rate=math.inf)}, "config.sample_rate"),
    ({"in_position": AxisInPosition(settling_time=1e308)}, "in_position.settling_time"),
    ({"plant": PlantConfig(damping=2.0)}, "plant.damping"),
    ({"motion_config": MotionConfig(normal_feedrate=1e308)}, "motion_config.normal_feedrate"),
])
def test_a_controller_is_not_built_from_values_it_cannot_hold(kwargs, field):
    # the same validators as the YAML loader and the services (one per struct)
    with pytest.raises(ValueError, match=f"^{re.escape(field)}:"):
        Controller(**kwargs)


def _mapped(ctl: Controller):
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    return ms


def _move_runs_to_idle(ctl: Controller, ms) -> None:
    params = MotionParams(trajectory=[Trajectory(1000.0, 1e4, 1e4)], position=[500.0, -500.0])
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=params).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000, chunk=97)
    assert [a.command_position for a in ctl.axes[:2]] == [500.0, -500.0]
    assert all(math.isfinite(x) for a in ctl.axes for x in (a.cmd_p, a.cmd_v, a.act_p, a.act_v))


@pytest.mark.parametrize("feedrate", [1e308, 1e-300, math.nan])
def test_config_set_refuses_a_feedrate_it_cannot_run(feedrate):
    # issue 9: normal_feedrate 1e308 gave NaN command positions and a move that never ends;
    # 1e-300 made the start divide by zero. MPI 000 mpiMotionConfigSet answers a Message:
    # PARAM_INVALID, and nothing changes.
    ctl = Controller()
    ms = _mapped(ctl)
    before = ms.config.copy()
    assert ms.config_set(MotionConfig(normal_feedrate=feedrate)).message is M.MPIMessagePARAM_INVALID
    assert ms.config == before
    _move_runs_to_idle(ctl, ms)


def test_axis_config_set_refuses_a_settling_time_past_the_sample_counter():
    # issue 9: settling_time 1e308 via mpiAxisConfigSet killed the clock on every step after.
    # MPI 002 MPIAxisInPosition settlingTime "Duration in seconds"; it is counted in samples.
    ctl = Controller()
    ms = _mapped(ctl)
    before = ctl.axes[0].in_position.copy()
    assert ctl.axis_in_position_set(0, AxisInPosition(settling_time=1e308)).message is M.MPIMessagePARAM_INVALID
    assert ctl.axes[0].in_position == before
    assert ctl.axis_in_position_set(0, AxisInPosition(settling_time=MAX_DURATION)).ok  # the longest it holds
    ctl.step(5000)
    params = MotionParams(trajectory=[Trajectory(1000.0, 1e4, 1e4)], position=[500.0, -500.0])
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=params).ok
    ctl.step(20_000)  # still settling (21,474 s), but the clock runs
    assert ctl.axes[0].command_position == 500.0
    assert ms.state is MPIState.MOVING


@pytest.mark.parametrize("setter", ["axis_command_position_set", "axis_actual_position_set", "axis_origin_set"])
def test_axis_positions_past_what_a_controller_holds_are_refused(setter):
    # issue 9: an actual position of 1e308 was accepted and read back as -inf. MPI 002
    # mpiAxisActualPositionSet / CommandPositionSet / OriginSet take a position (a double);
    # PARAM_INVALID and nothing changes.
    ctl = Controller()
    before = [(a.cmd_p, a.act_p, a.origin) for a in ctl.axes]
    assert getattr(ctl, setter)(0, 1e308).message is M.MPIMessagePARAM_INVALID
    assert getattr(ctl, setter)(0, -MAX_POSITION * 2).message is M.MPIMessagePARAM_INVALID
    ctl.step(10)
    assert [(a.cmd_p, a.act_p, a.origin) for a in ctl.axes] == before
    assert getattr(ctl, setter)(0, MAX_POSITION).ok


_LOW = dict(
    config=ControllerConfig(sample_rate=1.0, axis_count=2, supervisor_count=1),
    in_position=AxisInPosition(position_fine=1e-9, position_coarse=0, velocity=1e-30, settling_time=0.0),
    plant=PlantConfig(bandwidth_hz=0.01, damping=1e-6, velocity_feedforward=-10.0, acceleration_feedforward=-10.0,
                      encoder_resolution=0.0, coast_time_constant=1e-9),
    motion_config=MotionConfig(DecelTime(1e-12, 1e-12), normal_feedrate=FEEDRATE_MIN, pause_feedrate=FEEDRATE_MIN,
                               blend_limit=-1.0),
)
_HIGH = dict(
    config=ControllerConfig(sample_rate=SAMPLE_RATE_MAX, axis_count=2, supervisor_count=1),
    in_position=AxisInPosition(position_fine=MAX_POSITION, position_coarse=LONG_MAX, velocity=3.4e38,
                               settling_time=MAX_DURATION, settle_on_stop=True, settle_on_estop=True),
    plant=PlantConfig(bandwidth_hz=SAMPLE_RATE_MAX / 2, damping=1.0, velocity_feedforward=10.0,
                      acceleration_feedforward=10.0, encoder_resolution=MAX_POSITION / 4,
                      coast_time_constant=MAX_DURATION),
    motion_config=MotionConfig(DecelTime(MAX_DURATION, MAX_DURATION), normal_feedrate=FEEDRATE_MAX,
                               pause_feedrate=FEEDRATE_MAX, blend_limit=1.0),
)


@pytest.mark.parametrize("ends", [_LOW, _HIGH, {**_LOW, "plant": _HIGH["plant"]}, {**_HIGH, "config": _LOW["config"]}],
                         ids=["low", "high", "low-stiff", "high-slow"])
@pytest.mark.parametrize("trajectory", [Trajectory(1e12, 1e15, 1e15, 100.0), Trajectory(1e-300, 1e-300, 1e-300, 0.0),
                                        Trajectory(1.0, 1e15, 1.0, 50.0)], ids=["fast", "tiny", "mixed"])
def test_the_clock_runs_at_the_ends_of_every_range(ends, trajectory):
    # issue 9: "the clock thread can never die on a value it accepted". Every struct at the ends
    # of its range; moves at the ends of the trajectory ranges; every action. Each command is
    # answered with a Message or an Outcome (a profile no controller can compute is PROFILE_ERROR, MPI 000),
    # and every sample after it is finite.
    ctl = Controller(**ends)
    ms = _mapped(ctl)
    p2p = MotionParams(trajectory=[trajectory], position=[MAX_POSITION, -MAX_POSITION])
    velocity = MotionParams(trajectory=[Trajectory(-1e12, 1e15, 0.0, 100.0)])
    steps = [lambda: ms.start(MPIMotionType.S_CURVE, params=p2p), lambda: ms.action(MPIAction.STOP),
             lambda: ms.action(MPIAction.RESUME), lambda: ms.action(MPIAction.E_STOP),
             lambda: ms.action(MPIAction.RESET), lambda: ms.start(MPIMotionType.VELOCITY, params=velocity),
             lambda: ms.modify(MPIMotionType.TRAPEZOIDAL, params=p2p), lambda: ms.action(MPIAction.ABORT),
             lambda: ms.action(MPIAction.RESET)]
    for step in steps:
        assert isinstance(step(), M | Outcome)
        for samples in (1, 17, 400):
            ctl.step(samples)
            assert all(math.isfinite(x) for a in ctl.axes for x in (a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v))
