"""The client's typed surface, without a suite: its names agree with the controller's
(messages and codes, event types, states), goals are filled from YAML-like data with the
types checked at the edge, messages become plain data, and goal outcomes are classified.
The client and mpi_ros.errors must import nothing of the simulated controller."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from concurrent.futures import Future
from types import SimpleNamespace

import pytest
from action_msgs.msg import GoalStatus

from mpi_ros import client as client_module
from mpi_ros import errors
from mpi_ros.action import MotionStart
from mpi_ros.client import (
    Action,
    EventType,
    Goal,
    GoalOutcome,
    MotionClient,
    MotionResult,
    MotionType,
    State,
    fill,
    message_class,
    message_to_dict,
)
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.types import MPIState


def test_one_exception_class_per_message_with_the_same_name_and_code():
    expected = {m.name: m.code for m in Message if m is not Message.MPIMessageOK}
    assert {name: cls.code for name, cls in errors.ERRORS.items()} == expected
    assert {m.name: m.code for m in Message} == errors.CODES
    for name in expected:
        cls = getattr(errors, name)
        assert cls.message_name == name
        assert issubclass(cls, errors.MpiError)
        assert errors.error_for(name) is cls


def test_state_refusals_are_state_errors():
    states = {name for name in errors.ERRORS if issubclass(errors.ERRORS[name], errors.StateError)}
    assert states == {f"MPIMotionMessage{s}" for s in ("IDLE", "MOVING", "STOPPING", "STOPPED", "STOPPING_ERROR",
                                                       "ERROR")}


def test_raise_for_raises_the_messages_class_with_detail_and_result():
    errors.raise_for("MPIMessageOK", "fine")  # nothing
    with pytest.raises(errors.MPIMotionMessageMOVING) as caught:
        errors.raise_for("MPIMotionMessageMOVING", "supervisor is MOVING", result="the reply")
    assert (caught.value.message, caught.value.code, caught.value.detail, caught.value.result) == (
        "MPIMotionMessageMOVING", Message.MPIMotionMessageMOVING.code, "supervisor is MOVING", "the reply")
    assert str(caught.value) == "MPIMotionMessageMOVING: supervisor is MOVING"


def test_a_message_this_client_does_not_know_still_raises_by_name():
    first = errors.error_for("MPIMotionMessageFROM_THE_FUTURE")
    assert first is errors.error_for("MPIMotionMessageFROM_THE_FUTURE")  # made once: `except` on it works
    with pytest.raises(first) as caught:
        errors.raise_for("MPIMotionMessageFROM_THE_FUTURE")
    assert isinstance(caught.value, errors.MpiError)
    assert caught.value.message == "MPIMotionMessageFROM_THE_FUTURE"


def test_connection_errors_are_not_controller_errors():
    assert issubclass(errors.SuiteNotFound, errors.NoResponse)
    assert issubclass(errors.NoResponse, TimeoutError)
    assert not issubclass(errors.NoSuchSupervisor, errors.MpiError)


def test_enums_name_what_the_controller_names():
    assert set(EventType) == {e.name for e in MPIEventType if e.name and e is not MPIEventType.NONE}
    assert set(State) == {s.name for s in MPIState}
    assert {"STOP", "E_STOP", "ABORT", "E_STOP_ABORT", "RESET", "RESUME", "MAP"} == set(Action)
    assert MotionType.S_CURVE == "S_CURVE"
    assert f"{MotionType.VELOCITY}" == "VELOCITY"


def test_fill_sets_nested_fields_and_makes_numbers_float64():
    from mpi_ros.action import MotionStart

    goal = fill(MotionStart.Goal(), {"type": MotionType.S_CURVE, "position": [1000, 0],
                                     "trajectory": [{"velocity": 500, "acceleration": 5000}],
                                     "attributes": ["RELATIVE"], "id": 7.0})
    assert goal.type == "S_CURVE"
    assert type(goal.type) is str
    assert list(goal.position) == [1000.0, 0.0]
    assert goal.trajectory[0].velocity == 500.0
    assert goal.id == 7


@pytest.mark.parametrize(("data", "text"), [
    ({"positions": [1.0]}, "positions: no such field in MotionStart_Goal (fields: "),
    ({"position": 5.0}, "position: expected a list, got 5.0"),
    ({"position": ["a"]}, "position[0]: expected a number, got 'a'"),
    ({"id": 1.5}, "id: expected an integer, got 1.5"),
    ({"id": True}, "id: expected an integer, got True"),
    ({"type": 3}, "type: expected a string, got 3"),
    ({"trajectory": [{"velocity": "fast"}]}, "trajectory[0].velocity: expected a number, got 'fast'"),
    ({"trajectory": [5]}, "trajectory[0]: expected a mapping of fields, got 5"),
    ({"final": "yes"}, "final: expected true or false, got 'yes'"),
])
def test_fill_names_the_field_that_is_wrong(data, text):
    from mpi_ros.action import MotionStart

    with pytest.raises(ValueError) as caught:
        fill(MotionStart.Goal(), data)
    assert str(caught.value).startswith(text)


def test_message_to_dict_and_message_class():
    from mpi_ros.msg import AxisStatus, MotionStatus

    status = MotionStatus(number=1, state_name="IDLE", axis_numbers=[2, 3], axes=[AxisStatus(number=2)])
    plain = message_to_dict(status)
    assert plain["number"] == 1
    assert plain["axis_numbers"] == [2, 3]
    assert plain["axes"][0]["number"] == 2
    assert plain["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}  # nested messages as dicts
    assert list(plain)[:3] == ["header", "sample", "number"]  # in field order
    assert message_class("mpi_ros/msg/MotionStatus") is MotionStatus
    assert message_class("mpi_ros/MotionStatus") is MotionStatus
    with pytest.raises(ValueError):
        message_class("MotionStatus")


@pytest.mark.parametrize(("message", "sample", "end", "status", "outcome"), [
    ("MPIMessageOK", 10, 500, 4, GoalOutcome.DONE),
    ("MPIMessagePARAM_INVALID", 10, 10, 6, GoalOutcome.REFUSED),
    ("MPIMotionMessageERROR", 10, 900, 6, GoalOutcome.ENDED),
    ("MPIMotionMessageSTOPPED", 10, 900, 5, GoalOutcome.CANCELED),
])
def test_motion_result_outcome(message, sample, end, status, outcome):
    raw = SimpleNamespace(message=message, code=0, state_name="IDLE", actual_position=[1.0], command_position=[1.0],
                          move_id=0, sample=sample, end_sample=end, detail="")
    result = MotionResult.from_ros(raw, status)
    assert result.outcome is outcome
    assert result.ok == (message == "MPIMessageOK")
    assert result.state is State.IDLE
    assert result.actual_position == (1.0,)


def test_client_motion_types_are_the_family_records():
    # The client imports nothing of the controller (below), so its MotionType is checked
    # against the one table of motion types here (mpi_ros/mpi/planning/families.py)
    from mpi_ros.client import MotionType
    from mpi_ros.mpi.planning.families import FAMILIES

    assert [t.value for t in MotionType] == [t.name for t in FAMILIES]


def test_client_and_errors_import_nothing_of_the_simulated_controller():
    code = ("import sys, mpi_ros.client, mpi_ros.errors;"
            "print(sorted(m for m in sys.modules if m.startswith(('mpi_ros.mpi', 'mpi_ros.ros', 'mpi_ros.runner'))))")
    proc = subprocess.run([sys.executable, "-P", "-c", code], check=False, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    # Of the suite's ROS layer only its executor thread (the Spinner, and the rclpy binding it
    # catches): none of the suite's nodes, its runner or the controller.
    assert proc.stdout.strip() == "['mpi_ros.ros', 'mpi_ros.ros.rcl', 'mpi_ros.ros.spinner']"


# -- paths: path() and stream() against a recorder of their goals (no suite) ----------------------------
# The controller's side is in test/ros/test_paths_ros.py; here the goals the client sends and
# the cues it follows: this supervisor's FRAMES_LOW on /mpi/events, and a MotionStatus of the
# running path with few frames left. Goals are recorded and ended by the test.


def test_interleave_and_path_goal_build_the_goals_flat_lists():
    from mpi_ros.client import interleave, path_goal

    assert interleave([(100.0, 0.0), (200, 50.0)]) == [100.0, 0.0, 200.0, 50.0]
    assert interleave([1.0, 2]) == [1.0, 2.0]  # a bare number: a point of one axis
    goal = path_goal(MotionType.PVT, [(1.0, 2.0), (3.0, 4.0)], [0.5, 0.25], velocities=[(5.0, 6.0), (0.0, 0.0)],
                     element_ids=[7, 8], final=False)
    assert goal == {"type": "PVT", "attributes": ["ELEMENT_ID"], "position": [1.0, 2.0, 3.0, 4.0],
                    "time": [0.5, 0.25], "point_velocity": [5.0, 6.0, 0.0, 0.0], "element_id": [7, 8],
                    "final": False}
    from mpi_ros.action import MotionStart

    assert list(fill(MotionStart.Goal(), goal).point_velocity) == [5.0, 6.0, 0.0, 0.0]
    with pytest.raises(ValueError, match=r"velocities\[1\]: 1 value\(s\), but velocities\[0\] has 2"):
        interleave([(1.0, 2.0), (3.0,)], "velocities")


def test_path_chunks_cut_every_per_point_list_alike():
    from mpi_ros.client import path_chunks

    chunks = path_chunks([(1.0,), (2.0,), (3.0,)], [0.1, 0.2, 0.3], 2, velocities=[(4.0,), (5.0,), (6.0,)],
                         element_ids=None)
    assert chunks == [{"points": [(1.0,), (2.0,)], "times": [0.1, 0.2], "velocities": [(4.0,), (5.0,)]},
                      {"points": [(3.0,)], "times": [0.3], "velocities": [(6.0,)]}]
    for args, text in [(([(1.0,)], [0.1, 0.2], 5), "times: 2 value"), (([], [], 5), "at least one point"),
                       (([(1.0,)], [0.1], 0), "chunk must be at least 1")]:
        with pytest.raises(ValueError, match=text):
            path_chunks(*args)


class _Sent:
    """What a recorded client sent: ``(kind, goal fields, result future)``, in order."""

    def __init__(self):
        self.goals = []
        self.cond = threading.Condition()

    def add(self, kind, goal, future):
        with self.cond:
            self.goals.append((kind, goal, future))
            self.cond.notify_all()

    def wait(self, count, timeout=5.0):
        with self.cond:
            assert self.cond.wait_for(lambda: len(self.goals) >= count, timeout), f"{len(self.goals)} goal(s) sent"
            return self.goals[count - 1]


def _ros_result(message="MPIMessageOK", detail="motion done", sample=10, end_sample=900, status=4):
    result = SimpleNamespace(message=message, code=0, state_name="IDLE", actual_position=[0.0, 0.0],
                             command_position=[0.0, 0.0], move_id=0, sample=sample, end_sample=end_sample,
                             detail=detail)
    return SimpleNamespace(result=result, status=status)


@pytest.fixture
def recorder(ros_context):
    """A MotionClient of ms0 whose goals are recorded (``recorder.sent``), not sent."""
    from rclpy.task import Future

    from mpi_ros.client import Goal, MotionClient

    class Recorder(MotionClient):
        sent: _Sent

        def start(self, goal, feedback=None):
            return self._record("start", goal)

        def modify(self, goal, feedback=None):
            return self._record("modify", goal)

        def _record(self, kind, goal):
            future = Future()
            running = Goal(self, SimpleNamespace(status=2), future, threading.Event())
            self.sent.add(kind, goal, future)
            return running

    client = Recorder(0, context=ros_context, timeout=5.0, node_name="test_path_recorder")
    client.sent = _Sent()
    yield client
    client.close()


@pytest.fixture
def cue(probe):
    """``cue.low(sample, supervisor=0)``: a FRAMES_LOW on /mpi/events; ``cue.status(sample,
    frames, state)``: a MotionStatus of ms0 whose axes hold ``frames`` frames."""
    from mpi_ros.client import EVENTS_QOS, STATUS_QOS
    from mpi_ros.msg import AxisStatus, MotionEvent, MotionStatus

    class Cue:
        events = probe.create_publisher(MotionEvent, "/mpi/events", EVENTS_QOS)
        statuses = probe.create_publisher(MotionStatus, "/mpi/ms0/status", STATUS_QOS)

        def matched(self, publisher):
            pause = threading.Event()
            for _ in range(500):
                if publisher.get_subscription_count() > 0:
                    return
                pause.wait(0.01)
            raise AssertionError(f"nobody subscribed to {publisher.topic_name}")

        def low(self, sample, supervisor=0):
            self.matched(self.events)
            self.events.publish(MotionEvent(sample=sample, type="FRAMES_LOW", supervisor=supervisor))

        def status(self, sample, frames, state="MOVING"):
            self.matched(self.statuses)
            self.statuses.publish(MotionStatus(sample=sample, state_name=state,
                                               axes=[AxisStatus(frame_count=frames), AxisStatus(frame_count=frames)]))

    return Cue()


def _stream_in_thread(client, *args, **kwargs):
    outcome = {}

    def run():
        try:
            outcome["result"] = client.stream(*args, **kwargs)
        except Exception as exc:  # noqa: BLE001 - the test looks at it
            outcome["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread, outcome


POINTS = [(float(k), -float(k)) for k in range(1, 8)]  # 7 points of two axes


def test_stream_opens_the_path_then_appends_a_chunk_per_cue_the_last_final(recorder, cue):
    thread, outcome = _stream_in_thread(recorder, MotionType.BESSEL, POINTS, [0.01] * 7, chunk=3, empty_count=7,
                                        timeout=5.0)
    kind, first, start = recorder.sent.wait(1)
    assert (kind, first["type"], first["final"], first["empty_count"]) == ("start", "BESSEL", False, 7)
    assert first["position"] == [1.0, -1.0, 2.0, -2.0, 3.0, -3.0]
    assert first["time"] == [0.01] * 3
    cue.low(100)
    kind, second, _ = recorder.sent.wait(2)
    assert (kind, second["attributes"], second["final"], second["position"]) == (
        "modify", ["APPEND"], False, [4.0, -4.0, 5.0, -5.0, 6.0, -6.0])
    cue.status(140, frames=128)   # a full buffer asks for nothing
    cue.low(150, supervisor=1)    # nor does another supervisor's FRAMES_LOW
    cue.status(160, frames=31)    # a MotionStatus with fewer than low_count frames does
    kind, third, _ = recorder.sent.wait(3)
    assert (kind, third["final"], third["position"], third["time"]) == ("modify", True, [7.0, -7.0], [0.01])
    for _, _, future in recorder.sent.goals[1:]:
        future.set_result(_ros_result(detail="points executed"))
    start.set_result(_ros_result(detail="motion done; path peaks ..."))
    thread.join(5.0)
    assert outcome["result"].detail == "motion done; path peaks ..."
    assert len(recorder.sent.goals) == 3


def test_stream_ignores_cues_of_other_supervisors_and_of_stale_statuses(recorder, cue):
    thread, outcome = _stream_in_thread(recorder, MotionType.PT, POINTS, [0.01] * 7, chunk=3, timeout=5.0)

    def no_append_after(sample, sent):
        recorder.wait_for(lambda s: s.sample == sample, 5.0)
        with recorder.sent.cond:  # the stream had every message up to ``sample`` to act on
            assert not recorder.sent.cond.wait_for(lambda: len(recorder.sent.goals) > sent, 0.2)

    recorder.sent.wait(1)
    cue.low(100, supervisor=1)
    cue.status(110, frames=0, state="IDLE")  # from before the path began
    cue.status(120, frames=100)
    no_append_after(120, 1)
    cue.status(130, frames=25)
    assert recorder.sent.wait(2)[0] == "modify"
    cue.status(140, frames=20)  # published before the append took effect: the buffer has not refilled
    no_append_after(140, 2)
    recorder.sent.goals[0][2].set_result(_ros_result("MPIMotionMessageERROR", "E_STOP by CONTROLLER"))
    thread.join(5.0)
    assert isinstance(outcome["error"], errors.MPIMotionMessageERROR)
    assert len(recorder.sent.goals) == 2


def test_stream_raises_a_refused_start_and_a_refused_append(recorder, cue):
    thread, outcome = _stream_in_thread(recorder, MotionType.SPLINE, POINTS, [0.01] * 7, chunk=4, timeout=5.0)
    recorder.sent.wait(1)[2].set_result(_ros_result("MPIMotionMessagePATH_ERROR", "final is false", 10, 10, 6))
    thread.join(5.0)
    assert isinstance(outcome["error"], errors.MPIMotionMessagePATH_ERROR)
    assert len(recorder.sent.goals) == 1
    recorder.sent = _Sent()
    thread, outcome = _stream_in_thread(recorder, MotionType.PT, POINTS, [0.01] * 7, chunk=2, timeout=5.0)
    recorder.sent.wait(1)
    cue.low(200)
    recorder.sent.wait(2)[2].set_result(_ros_result("MPIMessagePARAM_INVALID", "position needs ...", 210, 210, 6))
    thread.join(5.0)
    assert isinstance(outcome["error"], errors.MPIMessagePARAM_INVALID)
    assert len(recorder.sent.goals) == 2


def test_a_path_that_fits_one_chunk_is_one_final_goal(recorder):
    thread, outcome = _stream_in_thread(recorder, MotionType.PVT, POINTS[:2], [0.5, 0.5],
                                        velocities=[(1.0, 1.0), (0.0, 0.0)], timeout=5.0)
    kind, goal, future = recorder.sent.wait(1)
    assert kind == "start"
    assert "final" not in goal
    assert goal["point_velocity"] == [1.0, 1.0, 0.0, 0.0]
    future.set_result(_ros_result())
    thread.join(5.0)
    assert outcome["result"].ok


def test_path_sends_one_goal_and_raises_as_move_does(recorder):
    running = recorder.path(MotionType.PT, POINTS[:2], [0.1, 0.1], attributes=["RELATIVE"], wait=False, id=3)
    kind, goal, future = recorder.sent.wait(1)
    assert (kind, goal["attributes"], goal["id"]) == ("start", ["RELATIVE"], 3)
    assert goal["position"] == [1.0, -1.0, 2.0, -2.0]
    assert goal["time"] == [0.1, 0.1]
    future.set_result(_ros_result("MEIMotionMessageBAD_PATH_DATA", "a path value is infinite or NaN", 5, 5, 6))
    with pytest.raises(errors.MEIMotionMessageBAD_PATH_DATA):
        running.wait()


def test_a_goal_whose_status_ended_without_a_result_asks_for_it_again():
    # The answer to the first result request was lost (a link cut too briefly for the graph
    # to lose the server): the status says SUCCEEDED, so the goal asks again.
    response = MotionStart.Impl.GetResultService.Response(
        status=GoalStatus.STATUS_SUCCEEDED, result=MotionStart.Result(message="MPIMessageOK"))
    asked: list[Future] = []

    def get_result_async() -> Future:
        answer: Future = Future()
        answer.set_result(response)
        asked.append(answer)
        return answer

    handle = SimpleNamespace(status=GoalStatus.STATUS_SUCCEEDED, get_result_async=get_result_async)
    client = SimpleNamespace(timeout=10.0, _on_executor=lambda call: call())
    server = SimpleNamespace(server_is_ready=lambda: True)
    goal = Goal(client, handle, Future(), threading.Event(), server)  # type: ignore[arg-type]
    result = goal.wait(10.0)
    assert result.message == "MPIMessageOK"
    assert goal.asked_again == 1
    assert len(asked) == 1


class _Dropping:
    """An action client whose server loses its first ``lost`` result requests' answers (the
    discovery race MotionClient.wait_for_server guards against); the rest are answered at once."""

    def __init__(self, lost: int):
        self.lost = lost
        self.requests: list[Future] = []

    def _get_result_async(self, _handle) -> Future:
        request: Future = Future()
        if len(self.requests) >= self.lost:
            request.set_result(MotionStart.Impl.GetResultService.Response(status=GoalStatus.STATUS_UNKNOWN))
        self.requests.append(request)
        return request


def _probe(actions: dict, seconds: float) -> tuple[bool, float]:
    prober = SimpleNamespace(_on_executor=lambda call: call())
    began = time.monotonic()
    answered = MotionClient._answered(prober, actions, began + seconds)  # type: ignore[arg-type]
    return answered, time.monotonic() - began


def test_a_lost_readiness_answer_costs_a_resend_not_a_second():
    start, modify = _Dropping(lost=1), _Dropping(lost=0)
    answered, took = _probe({start: MotionStart, modify: MotionStart}, 10.0)
    assert answered
    assert len(start.requests) == 2
    assert len(modify.requests) == 1
    assert took < client_module._PROBE_ANSWER  # the second request went out after _PROBE_FIRST


def test_a_late_answer_to_an_earlier_readiness_request_counts():
    start = _Dropping(lost=100)
    threading.Timer(0.25, lambda: start.requests[0].set_result("late")).start()
    answered, _ = _probe({start: MotionStart}, 10.0)
    assert answered
    assert 2 <= len(start.requests) < 100


def test_readiness_without_any_answer_is_false_at_the_deadline():
    start = _Dropping(lost=100)
    answered, took = _probe({start: MotionStart}, 0.5)
    assert not answered
    assert took >= 0.5
    assert len(start.requests) >= 3
