"""The supervisor node through real ROS actions, services and topics (in-process)."""

from __future__ import annotations

import threading

import pytest
from action_msgs.msg import GoalStatus

from mpi_ros import errors

from .conftest import WAIT

S_CURVE = {"type": "S_CURVE", "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0,
                                               "deceleration": 20000.0, "jerk_percent": 50.0}]}


def move(position, **extra):
    return {**S_CURVE, "position": list(position), **extra}


def state_of(suite, number=0):
    return suite.runner.read(lambda ctl: ctl.supervisor(number).state.name)


def test_move_reaches_target_and_succeeds_with_ok(suite, client, applied, drive):
    goal = client.start(move([1000.0, -250.0]))
    sample, command, reply = applied.wait(1)
    assert command.operation == "motion_start"
    assert reply.message.name == "MPIMessageOK"
    drive(lambda: goal.done)
    result = goal.wait()
    # docs/decisions.md, "The ROS goals": the goal succeeds when the motion is DONE, with MPIMessageOK.
    assert goal.handle.status == GoalStatus.STATUS_SUCCEEDED
    assert (result.message, result.code, result.state_name) == ("MPIMessageOK", 0, "IDLE")
    assert list(result.command_position) == [1000.0, -250.0]  # exactly on target
    assert all(abs(a - t) < 10.0 for a, t in zip(result.actual_position, [1000.0, -250.0], strict=True))  # positionFine
    assert result.sample == sample
    assert result.end_sample > sample
    # Never reported done while the axes still move: DONE needs the settled actual position.
    done_axes = suite.runner.read(lambda ctl: [ctl.axes[n].status.done for n in (0, 1)])
    assert done_axes == [True, True]


def test_feedback_reports_progress_and_positions(suite, client, applied, drive):
    seen = []
    goal = client.start(move([3000.0, 0.0]), feedback=seen.append)
    applied.wait(1)
    drive(lambda: goal.done, chunk=200)
    goal.wait()
    assert seen, "no feedback"
    last = seen[-1]
    assert last.state_name in ("MOVING", "IDLE")
    assert len(last.command_position) == 2
    assert all(0.0 <= fb.progress <= 1.0 for fb in seen)
    assert [fb.progress for fb in seen] == sorted(fb.progress for fb in seen)


def test_e_stop_mid_move_ends_goal_with_error_then_reset_returns_idle(suite, client, applied, drive, probe):
    from mpi_ros.msg import MotionStatus

    states = []
    probe.create_subscription(MotionStatus, "/mpi/ms0/status", lambda m: states.append(m.state_name), 100)
    goal = client.start(move([20000.0, 0.0]))
    applied.wait(1)
    drive(lambda: state_of(suite) == "MOVING" and suite.runner.ctl.axes[0].cmd_v > 1000.0)
    reply = client.e_stop()
    assert (reply.message, reply.state_name) == ("MPIMessageOK", "STOPPING_ERROR")
    drive(lambda: goal.done)
    result = goal.wait(raise_on_error=False)
    # MPI 000, MPIMotionMessageERROR MPIMotionMessageERROR: "in an error state due to an E_STOP or ABORT action"
    assert goal.handle.status == GoalStatus.STATUS_ABORTED
    assert result.message == "MPIMotionMessageERROR"
    assert "E_STOP" in result.detail
    assert result.state_name == "ERROR"
    with pytest.raises(errors.MPIMotionMessageERROR):
        goal.wait()
    ended = threading.Event()
    drive(lambda: ended.wait(0) or ("ERROR" in states and states.index("STOPPING_ERROR") < states.index("ERROR")))
    assert client.reset().state_name == "IDLE"


def test_stop_ends_goal_stopped_and_resume_completes_the_move(suite, client, applied, drive, probe):
    from mpi_ros.msg import MotionEvent

    motion_done = threading.Event()
    probe.create_subscription(MotionEvent, "/mpi/events",
                              lambda e: e.type == "MOTION_DONE" and e.supervisor == 0 and motion_done.set(), 1000)
    goal = client.start(move([8000.0, 0.0]))
    applied.wait(1)
    drive(lambda: suite.runner.ctl.axes[0].command_position > 1000.0)
    assert client.stop().state_name == "STOPPING"
    drive(lambda: goal.done)
    result = goal.wait(raise_on_error=False)
    # docs/state-machine.md: STOP -> STOPPING -> STOPPED; docs/decisions.md, "The ROS goals": the goal
    # ends with MPIMotionMessageSTOPPED.
    assert result.message == "MPIMotionMessageSTOPPED"
    assert result.state_name == "STOPPED"
    stopped_at = suite.runner.ctl.axes[0].command_position
    assert stopped_at < 8000.0
    assert client.resume().state_name == "MOVING"
    drive(lambda: state_of(suite) == "IDLE")
    assert suite.runner.ctl.axes[0].command_position == 8000.0
    # the move that reached IDLE emitted MOTION_DONE (nothing more to step: wait for its delivery)
    assert motion_done.wait(WAIT)


def test_modify_retargets_a_running_move(suite, client, applied, drive):
    goal = client.start(move([10000.0, 0.0]))
    applied.wait(1)
    drive(lambda: suite.runner.ctl.axes[0].command_position > 500.0)
    modify = client.modify(move([-1500.0, 300.0]))
    applied.wait(2)
    drive(lambda: goal.done and modify.done)
    assert modify.wait().message == "MPIMessageOK"
    result = goal.wait()  # the start goal follows the modified move to its end
    assert list(result.command_position) == [-1500.0, 300.0]


def test_a_goal_is_applied_before_it_is_answered(suite, client, applied, drive):
    # A client that modifies the move as soon as its start is answered finds the move: the
    # command is applied before rclpy sends the goal's answer (no applied.wait in between).
    start = client.start(move([10000.0, 0.0]))
    assert [command.operation for _, command, _ in applied.commands] == ["motion_start"]
    modify = client.modify(move([-1500.0, 300.0]))
    assert [reply.message.name for _, _, reply in applied.commands] == ["MPIMessageOK", "MPIMessageOK"]
    drive(lambda: start.done and modify.done)
    assert modify.wait().message == "MPIMessageOK"
    assert list(start.wait().command_position) == [-1500.0, 300.0]


def test_a_velocity_modify_goal_succeeds_only_once_its_own_velocity_is_reached(suite, client, applied, drive):
    # MPI 000, mpiMotionModify: a VELOCITY move can be modified while MOVING (here from +200 to
    # -300 counts/s). The modify keeps the move, so the move's +200 "at velocity"
    # (MPIEventTypeMOTION_AT_VELOCITY) belongs to the start's goal; the modify's goal succeeds
    # only when the commanded velocity has ramped to -300 through zero.
    def velocity(v):
        return {"type": "VELOCITY", "trajectory": [{"velocity": v, "acceleration": 5000.0, "deceleration": 5000.0}]}

    def command_velocity():
        return suite.runner.read(lambda ctl: [ctl.axes[n].cmd_v for n in (0, 1)])

    start = client.start(velocity(200.0))
    applied.wait(1)
    drive(lambda: start.done)
    first = start.wait()
    assert (first.message, first.detail) == ("MPIMessageOK", "at velocity")
    assert command_velocity() == [200.0, 200.0]
    modify = client.modify(velocity(-300.0))
    sample, command, reply = applied.wait(2)
    assert command.operation == "motion_modify"
    assert reply.message.name == "MPIMessageOK"
    ramped = []  # the first sample at which the commanded velocity is -300 on both axes
    drive(lambda: ramped or (command_velocity() == [-300.0, -300.0] and ramped.append(suite.runner.ctl.sample)),
          chunk=1)
    assert ramped[0] > sample  # it did ramp: +200 -> -300 at 5000 counts/s^2 takes 0.1 s
    drive(lambda: modify.done)
    result = modify.wait()
    assert (result.message, result.detail) == ("MPIMessageOK", "at velocity")
    assert result.sample == sample <= ramped[0] <= result.end_sample
    assert command_velocity() == [-300.0, -300.0]


def test_cancel_is_a_stop(suite, client, applied, drive):
    goal = client.start(move([20000.0, 0.0]))
    applied.wait(1)
    drive(lambda: suite.runner.ctl.axes[0].cmd_v > 1000.0)
    cancel = threading.Thread(target=goal.cancel)
    cancel.start()
    drive(lambda: goal.done)
    cancel.join(timeout=10.0)
    result = goal.wait(raise_on_error=False)
    assert goal.handle.status == GoalStatus.STATUS_CANCELED
    assert result.message == "MPIMotionMessageSTOPPED"
    assert result.state_name == "STOPPED"
    # decelerated over decelTime.stop, not an abrupt halt: the axis went on after cancel
    assert applied.commands[1][1].request == {"action": "STOP"}


@pytest.mark.parametrize(
    ("goal", "message"),
    [
        ({"type": "WARP_DRIVE", "position": [1.0, 0.0]}, "MPIMotionMessageTYPE_INVALID"),
        ({**S_CURVE, "attributes": ["TELEPORT"], "position": [1.0, 0.0]}, "MPIMotionMessageTYPE_INVALID"),
        ({**S_CURVE, "position": [1.0]}, "MPIMessagePARAM_INVALID"),
        ({**S_CURVE, "position": [float("nan"), 0.0]}, "MPIMessagePARAM_INVALID"),
        ({"type": "S_CURVE", "position": [1.0, 0.0], "trajectory": [{"velocity": 0.0, "acceleration": 1.0,
                                                                    "deceleration": 1.0}]}, "MPIMessagePARAM_INVALID"),
        ({**S_CURVE, "attributes": ["DELAY"], "position": [1.0, 0.0]}, "MPIMotionMessageATTRIBUTE_INVALID"),
        ({"type": "S_CURVE_JERK", "position": [1.0, 0.0], "trajectory": [{"velocity": 1.0, "acceleration": 1.0,
                                                                         "deceleration": 1.0}]},
         "MPIMotionMessagePROFILE_NOT_SUPPORTED"),
        ({"type": "CAM_LINEAR", "position": [1.0, 0.0]}, "MPIMessagePARAM_INVALID"),  # no segments
    ],
)
def test_bad_goals_get_the_spec_message_and_change_nothing(suite, client, applied, goal, message):
    before = suite.runner.read(lambda ctl: (ctl.supervisor(0).state, [a.cmd_p for a in ctl.axes]))
    running = client.start(goal)
    result = running.wait(raise_on_error=False)
    assert running.handle.status == GoalStatus.STATUS_ABORTED
    assert result.message == message
    with pytest.raises(errors.error_for(message)):
        running.wait()
    after = suite.runner.read(lambda ctl: (ctl.supervisor(0).state, [a.cmd_p for a in ctl.axes]))
    assert after == before


def test_start_while_moving_answers_moving_and_leaves_the_move_alone(suite, client, applied, drive):
    first = client.start(move([6000.0, 0.0]))
    applied.wait(1)
    drive(lambda: suite.runner.ctl.axes[0].command_position > 100.0)
    # MPI 000, MPIMotionMessageMOVING MPIMotionMessageMOVING: "A motion cannot be started if a motion is in progress"
    second = client.start(move([0.0, 0.0]))
    assert second.wait(raise_on_error=False).message == "MPIMotionMessageMOVING"
    drive(lambda: first.done)
    assert list(first.wait().command_position) == [6000.0, 0.0]


def test_append_queues_moves_and_each_goal_ends_with_its_own_move(suite, client, applied, drive):
    goals = [client.start(move([x, 0.0], attributes=["APPEND", "ID"], id=i + 1))
             for i, x in enumerate((500.0, 1000.0, 1500.0))]
    applied.wait(3)
    drive(lambda: all(g.done for g in goals))
    results = [g.wait() for g in goals]
    assert [r.end_sample for r in results] == sorted(r.end_sample for r in results)
    assert [r.command_position[0] for r in results] == [500.0, 1000.0, 1500.0]


def test_two_supervisors_move_independently(suite, client, client1, applied, drive):
    a = client.start(move([4000.0, 0.0]))
    b = client1.start(move([-700.0, 700.0]))
    applied.wait(2)
    drive(lambda: b.done)
    assert not a.done  # ms0's longer move is still running
    assert b.wait().message == "MPIMessageOK"
    drive(lambda: a.done)
    assert list(a.wait().command_position) == [4000.0, 0.0]
    positions = suite.runner.read(lambda ctl: [ctl.axes[n].command_position for n in range(4)])
    assert positions == [4000.0, 0.0, -700.0, 700.0]


def test_e_stop_is_served_while_many_goals_execute(suite, client, applied, drive, probe, service):
    from mpi_ros.srv import MotionAction

    goals = [client.start(move([float(1000 * (i + 1)), 0.0], attributes=["APPEND"])) for i in range(12)]
    applied.wait(12)
    drive(lambda: suite.runner.ctl.axes[0].cmd_v > 100.0)
    response = service(probe, MotionAction, "/mpi/ms0/action", MotionAction.Request(action="E_STOP"))
    assert response.message == "MPIMessageOK"
    drive(lambda: all(g.done for g in goals))
    assert {g.wait(raise_on_error=False).message for g in goals} == {"MPIMotionMessageERROR"}


def test_trigger_services_answer_the_spec_message(suite, probe, service):
    from std_srvs.srv import Trigger

    # docs/state-machine.md: STOP in IDLE answers MPIMotionMessageIDLE; RESET in IDLE is OK.
    stop = service(probe, Trigger, "/mpi/ms0/stop", Trigger.Request())
    assert (stop.success, stop.message.split(":")[0]) == (False, "MPIMotionMessageIDLE")
    reset = service(probe, Trigger, "/mpi/ms0/reset", Trigger.Request())
    assert reset.success
    assert reset.message.startswith("MPIMessageOK")


def test_a_refused_axis_list_set_service_carries_the_controllers_words(suite, probe, service, applied):
    # MPI 000 mpiMotionAxisListSet: an axis that does not exist is an invalid handle. The node passes the
    # controller's outcome on as it is: the response's message and detail, and the reply (commands topic,
    # recordings, the Python client) names the axis and why; nothing changes.
    from mpi_ros.srv import AxisListGet, AxisListSet

    answer = service(probe, AxisListSet, "/mpi/ms0/axis_list_set", AxisListSet.Request(axis_numbers=[0, 9]))
    assert (answer.message, answer.detail) == ("MPIMessageHANDLE_INVALID", "axis: no axis 9 (4 axes)")
    _, command, reply = applied.wait(1)
    assert (command.operation, reply.message.name, reply.detail) == (
        "axis_list_set", "MPIMessageHANDLE_INVALID", "axis: no axis 9 (4 axes)")
    assert list(service(probe, AxisListGet, "/mpi/ms0/axis_list_get", AxisListGet.Request()).axis_numbers) == [0, 1]


def test_action_service_rejects_unknown_actions(suite, probe, service):
    from mpi_ros.srv import MotionAction

    response = service(probe, MotionAction, "/mpi/ms0/action", MotionAction.Request(action="SELF_DESTRUCT"))
    assert response.message == "MPIMessagePARAM_INVALID"
    assert response.state_name == "IDLE"


def test_config_and_params_services_round_trip(suite, probe, service):
    from mpi_ros.srv import MotionConfigGet, MotionConfigSet, MotionParamsGet, MotionParamsSet

    config = service(probe, MotionConfigGet, "/mpi/ms0/config_get", MotionConfigGet.Request())
    # MPI 000, MPIMotionDecelTime, stop decelTime defaults .5 s / .05 s; MPI 000, MPIMotionConfig, normalFeedrate
    # normalFeedrate 1.0, pauseFeedrate 0.0
    assert (config.config.decel_time_stop, config.config.decel_time_e_stop) == pytest.approx((0.5, 0.05))
    assert (config.config.normal_feedrate, config.config.pause_feedrate) == (1.0, 0.0)
    assert list(config.config.axis_numbers) == [0, 1]
    request = MotionConfigSet.Request()
    request.config = config.config
    request.config.decel_time_stop = 0.25
    request.config.user_label = "spindle"
    assert service(probe, MotionConfigSet, "/mpi/ms0/config_set", request).message == "MPIMessageOK"
    again = service(probe, MotionConfigGet, "/mpi/ms0/config_get", MotionConfigGet.Request())
    assert (again.config.decel_time_stop, again.config.user_label) == (0.25, "spindle")
    request.config.decel_time_stop = -1.0
    assert service(probe, MotionConfigSet, "/mpi/ms0/config_set", request).message == "MPIMessagePARAM_INVALID"

    params = MotionParamsSet.Request()
    params.params.position = [12.0, 34.0]
    assert service(probe, MotionParamsSet, "/mpi/ms0/params_set", params).message == "MPIMessageOK"
    stored = service(probe, MotionParamsGet, "/mpi/ms0/params_get", MotionParamsGet.Request())
    assert list(stored.params.position) == [12.0, 34.0]


def test_start_with_stored_params(suite, client, probe, service, applied, drive):
    from mpi_ros.msg import Trajectory
    from mpi_ros.srv import MotionParamsSet

    request = MotionParamsSet.Request()
    request.params.position = [250.0, 125.0]
    request.params.trajectory = [Trajectory(velocity=1000.0, acceleration=10000.0, deceleration=10000.0)]
    service(probe, MotionParamsSet, "/mpi/ms0/params_set", request)
    # MPI 000, mpiMotionStart mpiMotionStart: "If params is Null, the parameters set by the most recent
    # call to mpiMotionParamsSet(...) will be used"
    goal = client.start({"type": "TRAPEZOIDAL", "use_stored_params": True})
    applied.wait(2)
    drive(lambda: goal.done)
    assert list(goal.wait().command_position) == [250.0, 125.0]


def test_axis_list_position_frame_buffer_and_event_services(suite, probe, service):
    from mpi_ros.srv import (
        AxisListEdit,
        AxisListGet,
        EventNotifyGet,
        EventNotifySet,
        EventReset,
        FrameBufferStatusGet,
        PositionGet,
        PositionSet,
    )

    listing = service(probe, AxisListGet, "/mpi/ms0/axis_list_get", AxisListGet.Request())
    assert list(listing.axis_numbers) == [0, 1]
    assert list(listing.mapped_axis_numbers) == [0, 1]
    # MPI 000, mpiMotionAxisAppend, return values MPIMessageOBJECT_ON_LIST: "axis is already on the list"
    edit = service(probe, AxisListEdit, "/mpi/ms0/axis_list_edit", AxisListEdit.Request(operation="APPEND", axis=1))
    assert edit.message == "MPIMessageOBJECT_ON_LIST"
    assert list(edit.axis_numbers) == [0, 1]
    edit = service(probe, AxisListEdit, "/mpi/ms0/axis_list_edit", AxisListEdit.Request(operation="APPEND", axis=9))
    assert edit.message == "MPIMessageHANDLE_INVALID"

    assert service(probe, PositionSet, "/mpi/ms0/position_set",
                   PositionSet.Request(actual=[5.0, 6.0], command=[5.0, 6.0])).message == "MPIMessageOK"
    position = service(probe, PositionGet, "/mpi/ms0/position_get", PositionGet.Request())
    assert list(position.command) == [5.0, 6.0]
    bad = service(probe, PositionSet, "/mpi/ms0/position_set", PositionSet.Request(actual=[1.0], command=[1.0]))
    assert bad.message == "MPIMessagePARAM_INVALID"

    frames = service(probe, FrameBufferStatusGet, "/mpi/ms0/frame_buffer_status", FrameBufferStatusGet.Request())
    assert [(f.axis, f.size) for f in frames.axes] == [(0, 128), (1, 128)]

    assert service(probe, EventNotifySet, "/mpi/ms0/event_notify_set",
                   EventNotifySet.Request(event_types=["MOTION_DONE", "E_STOP"])).message == "MPIMessageOK"
    notify = service(probe, EventNotifyGet, "/mpi/ms0/event_notify_get", EventNotifyGet.Request())
    assert sorted(notify.event_types) == ["E_STOP", "MOTION_DONE"]
    bad = service(probe, EventNotifySet, "/mpi/ms0/event_notify_set", EventNotifySet.Request(event_types=["NOPE"]))
    assert bad.message == "MPIMessagePARAM_INVALID"
    reset = service(probe, EventReset, "/mpi/ms0/event_reset", EventReset.Request(event_types=["ALL"]))
    assert reset.message == "MPIMessageOK"
    assert list(reset.latched_event_types) == []
