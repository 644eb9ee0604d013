"""Path moves through ROS (in-process suite, real actions, services and topics): PVT and FRAME
goals, an open path streamed with APPEND goals, the emptyCount E_STOP of a starving path,
bad path data, and the Python client's path() and stream().

The controller is stepped by the tests. Where a test answers the controller's cue to append
(FRAMES_LOW), stepping pauses at the cue, so the test never depends on how fast this machine
runs the ROS round trip; MPI 000 is "the MPI reference pages" (docs/paths.md)."""

from __future__ import annotations

import math
import threading

import pytest
import yaml
from action_msgs.msg import GoalStatus

from mpi_ros import errors
from mpi_ros.client import EVENTS_QOS, STATUS_QOS, MotionType

from .conftest import WAIT

RATE = 2000.0  # config/default.yaml: controller.sample_rate

# As `ros2 action send_goal /mpi/ms0/motion_start mpi_ros/action/MotionStart "<this>"` reads it:
# integers where the YAML has integers (the goal's fields are float64).
PVT_YAML = """
{type: PVT, attributes: [ELEMENT_ID], element_id: [11, 12, 13],
 position: [100, 0, 200.0, 50.0, 300.0, 0],
 point_velocity: [100.0, 0, 100, 0, 0, 0],
 time: [0.5, 0.5, 0.5]}
"""


class Topic:
    """A probe subscription that keeps every message and lets a test wait for one."""

    def __init__(self, probe, msg_type, name: str, qos):
        self.messages = []
        self._cond = threading.Condition()
        self.subscription = probe.create_subscription(msg_type, name, self._keep, qos)

    def _keep(self, msg) -> None:
        with self._cond:
            self.messages.append(msg)
            self._cond.notify_all()

    def wait_for(self, predicate, what: str, timeout: float = WAIT):
        with self._cond:
            assert self._cond.wait_for(lambda: any(predicate(m) for m in self.messages), timeout), f"no {what}"
            return next(m for m in self.messages if predicate(m))

    def matched(self, timeout: float = WAIT) -> None:
        """Wait until a publisher is connected (what it publishes from then on arrives)."""
        pause = threading.Event()
        for _ in range(int(timeout / 0.01)):
            if self.subscription.get_publisher_count() > 0:
                return
            pause.wait(0.01)
        raise AssertionError(f"{self.subscription.topic_name}: no publisher connected")


@pytest.fixture
def events(probe):
    from mpi_ros.msg import MotionEvent

    topic = Topic(probe, MotionEvent, "/mpi/events", EVENTS_QOS)
    topic.matched()
    return topic


@pytest.fixture
def cues(suite):
    """The controller's FRAMES_LOW events, as it emits them (to pause stepping at a cue)."""
    seen = []
    suite.runner.on_event(lambda event: event.type_name == "FRAMES_LOW" and seen.append(event.sample))
    return seen


def line(first: int, count: int, step=(10.0, -5.0)):
    """Points first..first+count-1 of a straight line, interleaved by axis."""
    return [v for k in range(first, first + count) for v in (step[0] * k, step[1] * k)]


def element_at(sample: int, ids, times) -> int | None:
    """The id of the point a path started at sample 0 runs toward at ``sample`` (None within
    a sample of a point, where either id is right)."""
    reached = 0.0
    for element, dt in zip(ids, times, strict=True):
        reached += dt * RATE
        if abs(sample - reached) <= 1:
            return None
        if sample < reached:
            return element
    return ids[-1]


def started(applied) -> int:
    """The sample at which the test's first goal (a MotionStart) took effect."""
    sample, command, reply = applied.wait(1)
    assert command.operation == "motion_start", reply
    assert reply.message.name == "MPIMessageOK", reply
    return sample


# -- one path ------------------------------------------------------------------------------------
def test_pvt_goal_from_send_goal_yaml_ends_ok_at_its_last_point(suite, client, applied, drive, probe):
    from mpi_ros.msg import AxisStatus, MotionStatus

    goal = yaml.safe_load(PVT_YAML)
    status = Topic(probe, MotionStatus, "/mpi/ms0/status", STATUS_QOS)
    axis = Topic(probe, AxisStatus, "/mpi/axis0/status", STATUS_QOS)
    status.matched()
    axis.matched()
    running = client.start(goal)
    begin = started(applied)
    drive(lambda: running.done, chunk=40)
    result = running.wait()
    # docs/decisions.md, "The ROS goals": the goal ends when the path is done, with MPIMessageOK and its
    # peaks (docs/paths.md, "Limits")
    assert running.handle.status == GoalStatus.STATUS_SUCCEEDED
    assert (result.message, result.state_name) == ("MPIMessageOK", "IDLE")
    assert result.detail.startswith("motion done; path peaks axis 0: |v| ")
    assert list(result.command_position) == [300.0, 0.0]  # the last point, exactly
    assert all(abs(a - t) < 10.0 for a, t in zip(result.actual_position, [300.0, 0.0], strict=True))
    assert result.end_sample >= begin + 1.5 * RATE  # not before the last point's time
    # MotionStatus and AxisStatus element_id: the point being run toward (ELEMENT_ID)
    for topic in (status, axis):
        topic.wait_for(lambda m: m.sample >= begin + 1.5 * RATE - 100, "status near the last point")
        seen = [(m.sample - begin, m.element_id) for m in topic.messages if begin < m.sample < begin + 1.5 * RATE]
        expected = [(s, element_at(s, [11, 12, 13], [0.5] * 3)) for s, _ in seen]
        assert ([e for (_, e), (_, x) in zip(seen, expected, strict=True) if x is not None]
                == [x for _, x in expected if x])
        assert {e for _, e in seen} == {11, 12, 13}


def test_pvt_feedback_element_id_follows_the_points(suite, client, applied, drive):
    feedback = []
    running = client.start(yaml.safe_load(PVT_YAML), feedback=feedback.append)
    begin = started(applied)
    drive(lambda: running.done, chunk=40)
    assert running.wait().message == "MPIMessageOK"
    seen = [(fb.sample - begin, fb.element_id) for fb in feedback if fb.sample - begin < 1.5 * RATE]
    assert seen, "no feedback while the path ran"
    expected = [element_at(s, [11, 12, 13], [0.5] * 3) for s, _ in seen]
    assert ([e for (_, e), x in zip(seen, expected, strict=True) if x is not None]
            == [x for x in expected if x is not None])


def test_frame_goal_runs_its_frames(suite, client, applied, drive):
    # MEIMotionFrame (MPI 000): constant-jerk frames as given, interleaved by axis.
    frames = [{"position": 0.0, "velocity": 0.0, "acceleration": 2000.0, "jerk": 0.0, "time": 0.5},
              {"position": 0.0, "velocity": 0.0, "acceleration": 0.0, "jerk": 0.0, "time": 0.5},
              {"position": 250.0, "velocity": 1000.0, "acceleration": -2000.0, "jerk": 0.0, "time": 0.5},
              {"position": 0.0, "velocity": 0.0, "acceleration": 0.0, "jerk": 0.0, "time": 0.5}]
    running = client.path(MotionType.FRAME, [], [], frames=frames, wait=False)
    begin = started(applied)
    drive(lambda: running.done, chunk=40)
    result = running.wait()
    assert result.message == "MPIMessageOK"
    assert result.end_sample >= begin + RATE
    assert [round(p, 9) for p in result.command_position] == [500.0, 0.0]


# -- streaming ----------------------------------------------------------------------------------------
def test_streamed_path_appends_end_with_their_points_and_the_start_with_the_path(
        suite, client, applied, drive, probe, events, cues):
    from mpi_ros.msg import AxisStatus

    axis = Topic(probe, AxisStatus, "/mpi/axis0/status", STATUS_QOS)
    axis.matched()
    bessel = {"type": "BESSEL", "time": [0.005] * 40}
    # 150 points: more than the 128 frames of the buffer (the rest waits in the library)
    start = client.start({"type": "BESSEL", "position": line(1, 150), "time": [0.005] * 150, "final": False})
    started(applied)
    appends = []
    for n, final in enumerate((False, False, True)):
        drive(lambda n=n: len(cues) > n, chunk=10)
        events.wait_for(lambda e, at=cues[n]: e.type == "FRAMES_LOW" and e.supervisor == 0 and e.sample == at,
                        "FRAMES_LOW on /mpi/events")
        assert not start.done
        send = client.start if n == 1 else client.modify  # APPEND works with either (MPI 000, MPIMotionAttrAPPEND)
        appends.append(send({**bessel, "attributes": ["APPEND"], "position": line(151 + 40 * n, 40), "final": final}))
        assert applied.wait(2 + n)[2].message.name == "MPIMessageOK"
    drive(lambda: appends[1].done)
    assert not start.done  # the path is open while points may follow
    drive(lambda: start.done)
    ends = [goal.wait() for goal in appends]
    result = start.wait()
    assert [(r.message, r.detail) for r in ends] == [("MPIMessageOK", "points executed")] * 3
    assert [r.end_sample for r in ends] == sorted(r.end_sample for r in ends)
    assert result.message == "MPIMessageOK"
    assert result.detail.startswith("motion done; path peaks")
    assert result.end_sample >= ends[-1].end_sample
    assert list(result.command_position) == line(270, 1)
    axis.wait_for(lambda m: m.sample >= ends[-1].end_sample, "an axis status at the path's last point")
    counts = [m.frame_count for m in axis.messages]
    assert max(counts) == 128
    assert min(counts) >= 0
    assert not [e for e in events.messages if e.type in ("E_STOP", "FRAMES_EMPTY")]


def test_starving_open_path_is_e_stopped(suite, client, applied, drive, events):
    # MPI 000, MPIMotionPoint emptyCount: "If the number of points in the buffer is below
    # emptyCount, an E_STOP action will occur" (final false, no points appended).
    running = client.start({"type": "PVT", "position": line(1, 40), "point_velocity": [2000.0, -1000.0] * 40,
                            "time": [0.005] * 40, "final": False})
    begin = started(applied)
    drive(lambda: running.done)
    result = running.wait(raise_on_error=False)
    assert running.handle.status == GoalStatus.STATUS_ABORTED
    assert (result.message, result.state_name) == ("MPIMotionMessageERROR", "ERROR")
    e_stop = events.wait_for(lambda e: e.type == "E_STOP" and e.supervisor == 0, "E_STOP event")
    assert "emptyCount = 5" in e_stop.detail
    # fewer than 5 of the 40 points (10 samples apart) left: when point 36 is reached
    assert abs(e_stop.sample - (begin + 36 * 0.005 * RATE)) <= 2
    events.wait_for(lambda e: e.type == "FRAMES_LOW" and e.supervisor == 0, "FRAMES_LOW event")
    assert client.reset().state_name == "IDLE"


def test_empty_count_zero_rests_on_the_last_point_until_an_empty_final_append(suite, client, applied, drive, events):
    # emptyCount <= 0 disables the E_STOP (docs/decisions.md, "emptyCount <= 0 disables"); an append
    # without points closes the path.
    running = client.start({"type": "PT", "position": line(1, 10), "time": [0.005] * 10, "final": False,
                            "empty_count": 0})
    started(applied)
    drive(lambda: running.done or any(e.type == "FRAMES_EMPTY" and e.supervisor == 0 for e in events.messages))
    assert not running.done
    assert client.status().state_name == "MOVING"
    close = client.modify({"type": "PT", "attributes": ["APPEND"], "final": True})
    drive(lambda: running.done and close.done)
    assert close.wait().message == running.wait().message == "MPIMessageOK"
    assert list(running.wait().command_position) == line(10, 1)


def test_spline_may_not_stay_open(suite, client):
    # MPI 000: SPLINE may not carry APPEND, so it cannot be left open for more points.
    running = client.start({"type": "SPLINE", "position": line(1, 3), "time": [0.1] * 3, "final": False})
    result = running.wait(raise_on_error=False)
    assert result.message == "MPIMotionMessagePATH_ERROR"
    assert result.state_name == "IDLE"


# -- bad data ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("goal", [
    {"type": "PVT", "position": [math.nan, 0.0], "point_velocity": [0.0, 0.0], "time": [0.5]},
    {"type": "PVT", "position": [1.0, 0.0], "point_velocity": [math.inf, 0.0], "time": [0.5]},
    {"type": "BESSEL", "position": [1.0, 0.0], "time": [math.nan]},
    {"type": "FRAME", "frames": [{"position": 0.0, "velocity": math.nan, "time": 0.5}, {"time": 0.5}]},
])
def test_bad_path_data_is_refused_and_the_node_stays_up(suite, client, applied, drive, goal):
    # MPI 000, MEIMotionMessageBAD_PATH_DATA: "If any of the motion parameters passed to the
    # MPI for path motion are infinite or NAN ... will not load the move"
    running = client.start(goal)
    result = running.wait(raise_on_error=False)
    assert running.handle.status == GoalStatus.STATUS_ABORTED
    assert (result.message, result.state_name) == ("MEIMotionMessageBAD_PATH_DATA", "IDLE")
    after = client.path(MotionType.PT, [(5.0, 5.0)], [0.01], wait=False)
    drive(lambda: after.done)
    assert list(after.wait().command_position) == [5.0, 5.0]


# -- the Python client ---------------------------------------------------------------------------------
def test_client_path_pvt_pick_and_place_stops_at_rest(suite, client, drive):
    points = [(0.0, 500.0), (1000.0, 500.0), (1000.0, 0.0)]
    running = client.path(MotionType.PVT, points, [0.25, 0.5, 0.25], velocities=[(2000.0, 0.0), (0.0, -2000.0),
                                                                              (0.0, 0.0)],
                          element_ids=[1, 2, 3], wait=False)
    drive(lambda: running.done, chunk=40)
    result = running.wait()
    assert result.command_position == (1000.0, 0.0)
    assert result.detail.startswith("motion done; path peaks")


def test_client_stream_keeps_a_10000_point_path_going(suite, client, events, cues, applied):
    # One point per sample (0.5 ms, the shortest time slice). Stepping pauses before fewer
    # than 8 points could be left, until the client has appended: it must answer every cue.
    count = 10_000
    turn = 2.0 * math.pi / count
    points = [(1000.0 * math.cos(turn * k) - 1000.0, 1000.0 * math.sin(turn * k)) for k in range(1, count + 1)]
    velocities = [(-1000.0 * math.sin(turn * k) * turn * RATE, 1000.0 * math.cos(turn * k) * turn * RATE)
                  for k in range(1, count + 1)]
    outcome = {}

    def run():
        try:
            outcome["result"] = client.stream(MotionType.PVT, points, [1.0 / RATE] * count, velocities=velocities,
                                              chunk=100, timeout=WAIT)
        except Exception as exc:  # noqa: BLE001 - reported by the test
            outcome["error"] = exc

    streaming = threading.Thread(target=run)
    streaming.start()
    step_gated(suite, applied, streaming, closing=count // 100)
    streaming.join(WAIT)
    assert "error" not in outcome, outcome
    result = outcome["result"]
    assert result.message == "MPIMessageOK"
    assert result.state_name == "IDLE"
    assert max(abs(p - e) for p, e in zip(result.command_position, points[-1], strict=True)) < 1e-6
    sends = [(c.operation, c.request["final"]) for _, c, _ in applied.commands]
    assert sends == [("motion_start", False)] + [("motion_modify", False)] * 98 + [("motion_modify", True)]
    assert cues  # the controller asked for points (a MotionStatus with few frames may ask first)
    assert not [e for e in events.messages if e.type in ("E_STOP", "FRAMES_EMPTY")]


def test_client_stream_ahead_keeps_chunks_queued_beyond_the_buffer_cue(suite, client, events, applied):
    # MPI 001, MPIMotionPathAttrMask, LOW_COUNT: points that do not fit the buffer wait in the library,
    # so a client may append before the controller asks. ahead=3: the start and 3 appends at once;
    # then one append each time an append's last point is reached (its goal ends "points executed").
    count, chunk = 1000, 100
    points = [(float(k), 0.0) for k in range(1, count + 1)]
    outcome = {}

    def run():
        try:
            outcome["result"] = client.stream(MotionType.PT, points, [1.0 / RATE] * count, chunk=chunk,
                                              timeout=WAIT, ahead=3)
        except Exception as exc:  # noqa: BLE001 - reported by the test
            outcome["error"] = exc

    streaming = threading.Thread(target=run)
    streaming.start()
    applied.wait(4)  # nothing stepped: no FRAMES_LOW cue, the client sent ahead
    runner = suite.runner
    runner.step(150)  # one point a sample: the start's chunk done, the first append's half
    assert len(applied.commands) == 4
    assert not outcome
    runner.step(60)  # the first append's last point (sample 200) reached: its goal ends, one more goes
    applied.wait(5)
    step_gated(suite, applied, streaming, closing=count // chunk)
    streaming.join(WAIT)
    assert "error" not in outcome, outcome
    assert outcome["result"].message == "MPIMessageOK"
    assert outcome["result"].command_position[0] == count
    sends = [(c.operation, c.request["final"]) for _, c, _ in applied.commands]
    assert sends == [("motion_start", False)] + [("motion_modify", False)] * 8 + [("motion_modify", True)]
    assert not [e for e in events.messages if e.type in ("E_STOP", "FRAMES_EMPTY")]


def step_gated(suite, applied, streaming: threading.Thread, closing: int, keep: int = 8, most: int = 100) -> None:
    """Step while ``streaming`` runs; until the ``closing``-th command (the final append) has
    been applied, never so far that fewer than ``keep`` frames would be left in axis 0's
    buffer (one point per sample): there, wait for the next command."""
    runner = suite.runner
    pause = threading.Event()
    while streaming.is_alive():
        known = len(applied.commands)  # before the buffer is read: an append in between counts
        left = runner.read(lambda ctl: ctl.frame_count(0))
        room = left - keep if known < closing and left > 0 else most
        if room < 1:
            applied.wait(known + 1)  # fails if the client does not append
            continue
        runner.step(min(room, most))
        pause.wait(0.0005)


def test_client_stream_of_a_spline_is_refused(suite, client):
    points = [(float(k), 0.0) for k in range(1, 8)]
    with pytest.raises(errors.MPIMotionMessagePATH_ERROR):
        client.stream(MotionType.SPLINE, points, [0.01] * 7, chunk=4)
