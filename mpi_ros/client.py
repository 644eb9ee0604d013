"""The Python client of the suite: commands, status and events over ROS, nothing else.

    from mpi_ros.client import MotionClient, MotionType, GoalOutcome
    with MotionClient(supervisor=0) as ms0:
        result = ms0.move([1000.0, 0.0], velocity=500.0, acceleration=5000.0, deceleration=5000.0, jerk_percent=50.0)
        print(result.outcome, result.message, result.actual_position)   # waits until DONE
        goal = ms0.start({"type": "VELOCITY", "trajectory": [{"velocity": 200.0, "acceleration": 1000.0}]})
        ms0.stop()
        goal.wait(raise_on_error=False).outcome                        # GoalOutcome.ENDED
        ms0.reset()
        print(ms0.status().state_name)

Path moves: ``ms0.path(MotionType.PVT, points, times, velocities=...)`` runs one (points as
one tuple per point, interleaved here); ``ms0.stream(...)`` streams a long one chunk by chunk
as the controller asks for points (FRAMES_LOW, frame_count). Cams: ``ms1.cam("CAM_CUBIC",
master_distances, slave_positions, gear_ratios, repeat_from=0)`` (:func:`cam_goal`); each slave
axis' master is set with :class:`AxisClient` (``config_set(axis, master={...})``), which also
drives the motors' secondary feedback inputs (docs/cams.md).

It imports rclpy and the generated interfaces (``mpi_ros.msg/.srv/.action``) and nothing of
the simulated controller, so it runs wherever the suite is reachable over DDS.

Refusals raise the exception of the spec's message (``mpi_ros.errors.MPIMotionMessageMOVING``
...); a missing answer raises ``mpi_ros.errors.NoResponse``. Every client spins its own node
in a background thread (ros/spinner.py's Spinner, which stops it before the node goes); action
goals are sent from that thread (rclpy's ActionClient is not safe to send from another thread
while spinning). :class:`Watcher` follows the whole suite
(every supervisor's and axis' status, the events, any topic), as ``mpi-ros status`` does.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from functools import partial
from typing import Any, Self

import rclpy
from action_msgs.msg import GoalStatus
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from unique_identifier_msgs.msg import UUID

from mpi_ros.action import MotionModify, MotionStart
from mpi_ros.msg import AxisStatus, MotionEvent, MotionStatus
from mpi_ros.srv import AxisConfigGet, AxisConfigSet, AxisFaultInject, MotionAction, MotorFeedbackSecondarySet

from . import discovery, errors
from . import graph_names as gn
from .action_call import ActionReply, State, action_reply
from .errors import NoResponse, NoSuchSupervisor, SuiteNotFound, raise_for
from .graph_names import DEFAULT_NAMESPACE
from .message_dicts import fill, message_class, to_dict
from .qos import action_qos, matching, profile
from .ros.spinner import Spinner

ACTION_QOS = action_qos(gn.ACTION_SERVICE_QOS)
STATUS_QOS = profile(gn.STATUS_READER_QOS)
EVENTS_QOS = profile(gn.EVENTS_QOS)
DIAGNOSTICS_QOS = profile(gn.DIAGNOSTICS.qos)

_POLL = 0.05  # s between graph queries (rclpy has no graph-change wait for node names)
RESULT_RECHECK = 0.5  # s between looks for a goal's action server while waiting for its result
RESULT_REASK = 2.0  # s without an answer after asking again (the server came back) before asking once more
# The goal states after which the server has a result to give.
_ENDED = frozenset({GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_ABORTED})
# Every node of a process is announced together (one DDS participant per context), but give
# a late announcement a moment before saying a supervisor is not there.
_GRACE = 0.5
# An unanswered readiness round trip (MotionClient.wait_for_server) is sent again after
# _PROBE_FIRST s, then after twice as long each time, up to _PROBE_ANSWER s: a lost first
# answer (see wait_for_server) costs a tenth of a second, not a second.
_PROBE_FIRST = 0.1
_PROBE_ANSWER = 1.0


# -- typed arguments and answers --------------------------------------------------------------
class MotionType(StrEnum):
    """MPIMotionType names without the prefix (a goal's ``type``)."""

    TRAPEZOIDAL = "TRAPEZOIDAL"
    S_CURVE = "S_CURVE"
    S_CURVE_JERK = "S_CURVE_JERK"
    VELOCITY = "VELOCITY"
    VELOCITY_JERK = "VELOCITY_JERK"
    PT = "PT"
    PTF = "PTF"
    PVT = "PVT"
    PVTF = "PVTF"
    SPLINE = "SPLINE"
    BESSEL = "BESSEL"
    BSPLINE = "BSPLINE"
    BSPLINE2 = "BSPLINE2"
    CAM_LINEAR = "CAM_LINEAR"
    CAM_CUBIC = "CAM_CUBIC"
    FRAME = "FRAME"


class Attribute(StrEnum):
    """MPIMotionAttrMask and MPIMotionPathAttrMask names without the prefix (a goal's ``attributes``)."""

    APPEND = "APPEND"
    AUTO_START = "AUTO_START"
    DELAY = "DELAY"
    ID = "ID"
    ELEMENT_ID = "ELEMENT_ID"
    RELATIVE = "RELATIVE"
    SYNC_START = "SYNC_START"
    SYNC_END = "SYNC_END"
    REPEAT = "REPEAT"
    MASTER_START = "MASTER_START"
    NO_BACKTRACK = "NO_BACKTRACK"
    NO_BACKTRACK_HOLD = "NO_BACKTRACK_HOLD"
    EVENT = "EVENT"
    FINAL_VEL = "FINAL_VEL"
    NO_REVERSAL = "NO_REVERSAL"
    HOLD = "HOLD"
    HOLD_LESS = "HOLD_LESS"
    HOLD_GREATER = "HOLD_GREATER"
    OUTPUT = "OUTPUT"
    BEHAVIOR = "BEHAVIOR"
    RELATIVE_MOVE = "RELATIVE_MOVE"
    RETAIN = "RETAIN"
    EMPTY_COUNT = "EMPTY_COUNT"
    LOW_COUNT = "LOW_COUNT"
    NO_HANDSHAKE = "NO_HANDSHAKE"
    EXPECTED_AXES = "EXPECTED_AXES"
    NO_WAIT = "NO_WAIT"


class Action(StrEnum):
    """mpiMotionAction's actions (MotionAction ``action``)."""

    STOP = "STOP"
    E_STOP = "E_STOP"
    ABORT = "ABORT"
    E_STOP_ABORT = "E_STOP_ABORT"
    RESET = "RESET"
    RESUME = "RESUME"
    MAP = "MAP"


class EventType(StrEnum):
    """MPIEventType names without the prefix (MotionEvent ``type``)."""

    MOTION_DONE = "MOTION_DONE"
    MOTION_AT_VELOCITY = "MOTION_AT_VELOCITY"
    MOTION_START = "MOTION_START"
    STOP = "STOP"
    E_STOP = "E_STOP"
    ABORT = "ABORT"
    RESET = "RESET"
    RESUME = "RESUME"
    FRAMES_LOW = "FRAMES_LOW"
    FRAMES_EMPTY = "FRAMES_EMPTY"
    HOLD_RELEASED = "HOLD_RELEASED"
    HOLD_TIMEOUT = "HOLD_TIMEOUT"
    FRAME_TIME_LIMIT = "FRAME_TIME_LIMIT"
    RELATIVE_TRUNCATED = "RELATIVE_TRUNCATED"
    ID_TRUNCATED = "ID_TRUNCATED"
    CROSSCHECK = "CROSSCHECK"
    CLIENT_LOST = "CLIENT_LOST"
    SETTLED = "SETTLED"
    IN_FINE_POSITION = "IN_FINE_POSITION"
    IN_COARSE_POSITION = "IN_COARSE_POSITION"
    AT_TARGET = "AT_TARGET"
    AT_VELOCITY = "AT_VELOCITY"
    DONE = "DONE"
    # faults of an axis (docs/faults.md)
    LIMIT_ERROR = "LIMIT_ERROR"
    LIMIT_SW_POSITIVE = "LIMIT_SW_POSITIVE"
    LIMIT_SW_NEGATIVE = "LIMIT_SW_NEGATIVE"
    AMP_FAULT = "AMP_FAULT"
    ENCODER_FAULT = "ENCODER_FAULT"
    FRAME_UNDERFLOW = "FRAME_UNDERFLOW"


class GoalOutcome(StrEnum):
    """How a MotionStart/MotionModify goal ended."""

    DONE = "DONE"          # MPIMessageOK: the move is done (a VELOCITY move: at velocity)
    REFUSED = "REFUSED"    # the controller refused the command; nothing moved
    ENDED = "ENDED"        # it moved, then ended early: STOP, E_STOP, ABORT, a new start, RESET
    CANCELED = "CANCELED"  # the goal was cancelled (a cancel is a STOP)


@dataclass(frozen=True)
class FaultReply:
    """The answer of a fault injection (/<ns>/axis<k>/fault_inject, docs/faults.md)."""

    message: str
    code: int
    detail: str  # why it was refused
    faults: tuple[str, ...]  # the faults latched on the axis afterwards

    @property
    def ok(self) -> bool:
        return self.message == errors.OK


@dataclass(frozen=True)
class MotionResult:
    """How a goal ended: the controller's message, the state and where the axes are."""

    message: str
    code: int
    state_name: str
    actual_position: tuple[float, ...]
    command_position: tuple[float, ...]
    move_id: int
    sample: int      # the sample at which the command took effect
    end_sample: int  # the sample at which the goal ended
    detail: str
    outcome: GoalOutcome
    raw: Any = field(default=None, repr=False, compare=False)  # the action's Result message

    @property
    def ok(self) -> bool:
        return self.message == errors.OK

    @property
    def state(self) -> State:
        return State(self.state_name)

    @classmethod
    def from_ros(cls, result: Any, status: int) -> MotionResult:
        return cls(result.message, result.code, result.state_name, tuple(result.actual_position),
                   tuple(result.command_position), result.move_id, result.sample, result.end_sample,
                   result.detail, _outcome(result, status), result)


def _outcome(result: Any, status: int) -> GoalOutcome:
    if status == GoalStatus.STATUS_CANCELED:
        return GoalOutcome.CANCELED
    if result.message == errors.OK:
        return GoalOutcome.DONE
    # A refused command is answered at the sample it arrived; a move that ran ends later.
    if result.end_sample == result.sample:
        return GoalOutcome.REFUSED
    return GoalOutcome.ENDED


# -- messages <-> plain data (mpi_ros/message_dicts.py) -----------------------------------------------
message_to_dict = to_dict  # the client's name for it


def _name(value: Any) -> str:
    return str(value)  # StrEnum members print as their value


# -- paths: per-point data -> goal fields ----------------------------------------------------------
def interleave(rows: Iterable[Sequence[float] | float], name: str = "points") -> list[float]:
    """Per-point tuples (one value per axis) as a goal's flat list, interleaved by axis.

        interleave([(100.0, 0.0), (200.0, 50.0)]) == [100.0, 0.0, 200.0, 50.0]

    A bare number is a point of one axis. Points of different lengths raise ValueError.
    """
    flat: list[float] = []
    width = None
    for i, row in enumerate(rows):
        values = (row,) if isinstance(row, (int, float)) else tuple(row)
        width = len(values) if width is None else width
        if len(values) != width:
            raise ValueError(f"{name}[{i}]: {len(values)} value(s), but {name}[0] has {width} (one per axis)")
        flat.extend(float(v) for v in values)
    return flat


def path_goal(motion_type: MotionType | str, points: Iterable[Sequence[float] | float], times: Iterable[float],
              velocities: Iterable[Sequence[float] | float] | None = None,
              feedforward: Iterable[Sequence[float] | float] | None = None,
              attributes: Iterable[Attribute | str] = (), element_ids: Iterable[int] | None = None,
              **fields: Any) -> dict[str, Any]:
    """The fields of a path goal (MotionStart or MotionModify) from per-point data.

        path_goal("PVT", [(100.0, 0.0), (200.0, 0.0)], [0.5, 0.5], velocities=[(200.0, 0.0), (0.0, 0.0)])

    ``times``: seconds from the previous point (the first from the start); ``velocities``
    (PVT/PVTF) and ``feedforward`` (PTF/PVTF) per point like ``points``; ``element_ids`` one
    per point (adds the ELEMENT_ID attribute); ``fields``: any other goal field (final, ...).
    """
    attrs = [_name(a) for a in attributes]
    goal: dict[str, Any] = {"type": _name(motion_type), "attributes": attrs, "position": interleave(points),
                            "time": [float(t) for t in times]}
    if velocities is not None:
        goal["point_velocity"] = interleave(velocities, "velocities")
    if feedforward is not None:
        goal["feedforward"] = interleave(feedforward, "feedforward")
    if element_ids is not None:
        goal["element_id"] = [int(i) for i in element_ids]
        if Attribute.ELEMENT_ID not in attrs:
            attrs.append(Attribute.ELEMENT_ID.value)
    return {**goal, **fields}


def path_chunks(points: Sequence[Any], times: Sequence[float], size: int,
                **per_point: Sequence[Any] | None) -> list[dict[str, list[Any]]]:
    """A path cut into chunks of ``size`` points: the arguments of path_goal for each.

        path_chunks([(1.0,), (2.0,), (3.0,)], [0.1] * 3, 2) ==
            [{"points": [(1.0,), (2.0,)], "times": [0.1, 0.1]}, {"points": [(3.0,)], "times": [0.1]}]

    ``per_point``: velocities, feedforward, element_ids (None: not given), cut alike.
    """
    if size < 1:
        raise ValueError(f"chunk must be at least 1 point, got {size}")
    columns = {"points": list(points), "times": list(times)}
    columns.update({key: list(values) for key, values in per_point.items() if values is not None})
    if not columns["points"]:
        raise ValueError("a path needs at least one point")
    for key, values in columns.items():
        if len(values) != len(columns["points"]):
            raise ValueError(f"{key}: {len(values)} value(s) for {len(columns['points'])} point(s) (one per point)")
    return [{key: values[i:i + size] for key, values in columns.items()}
            for i in range(0, len(columns["points"]), size)]


def cam_goal(motion_type: MotionType | str, master_distances: Iterable[float],
             slave_positions: Iterable[Sequence[float] | float],
             gear_ratios: Iterable[Sequence[float] | float] | None = None, attributes: Iterable[Attribute | str] = (),
             repeat_from: int | None = None, master_start: int | None = None, **fields: Any) -> dict[str, Any]:
    """The fields of a cam goal (CAM_LINEAR or CAM_CUBIC; MPI 000, MPIMotionCam) per segment.

        cam_goal("CAM_CUBIC", [1000.0, 1000.0], [(500.0,), (500.0,)], gear_ratios=[(0.5,), (0.0,)])

    ``master_distances``: the master's travel in each segment; ``slave_positions``: the
    distance each slave axis moves in it (a tuple per segment, one value per axis);
    ``gear_ratios`` (CAM_CUBIC): the slave's gear ratio at the end of each segment, like
    ``slave_positions``; ``repeat_from`` (adds REPEAT) and ``master_start`` (adds MASTER_START).
    """
    attrs = [_name(a) for a in attributes]
    goal: dict[str, Any] = {"type": _name(motion_type), "attributes": attrs,
                            "master_distance": [float(d) for d in master_distances],
                            "slave_position": interleave(slave_positions, "slave_positions")}
    if gear_ratios is not None:
        goal["gear_ratio"] = interleave(gear_ratios, "gear_ratios")
    for attribute, key, value in ((Attribute.REPEAT, "repeat_from", repeat_from),
                                  (Attribute.MASTER_START, "master_start", master_start)):
        if value is not None:
            goal[key] = int(value)
            if attribute not in attrs:
                attrs.append(attribute.value)
    return {**goal, **fields}


# -- a node that spins itself ------------------------------------------------------------------------------
class _Endpoint:
    """A node of its own, spun by an executor in a background thread; finds the suite."""

    def __init__(self, namespace: str, context: Context | None, timeout: float, node_name: str):
        self.namespace = "/" + namespace.strip("/")
        self.timeout = timeout
        self._own_context = context is None and not rclpy.ok()
        if self._own_context:
            rclpy.init()
        self._context = context
        self.node = Node(node_name, context=context)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._spinner = Spinner(self.node, self._executor)

    def _start_spinning(self) -> None:
        self._spinner.start()

    def close(self) -> None:
        # The spinning thread ends first: Executor.shutdown while a thread still spins the
        # executor destroys the guard condition that thread is about to trigger (spinner.py).
        self._spinner.stop(timeout=2.0)
        self._executor.shutdown(timeout_sec=2.0)
        # destroy_node leaves a node's action clients (and their feedback and status
        # subscriptions) on the graph until they are garbage collected: a closed client would
        # still look present, to the suite's lost-client watchdog among others
        for action_client in self._action_clients():
            action_client.destroy()
        self.node.destroy_node()
        if self._own_context:
            rclpy.try_shutdown()

    def _action_clients(self) -> list[ActionClient]:
        return []

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- plumbing ------------------------------------------------------------------------
    def _on_executor(self, call: Callable[[], Any]) -> Any:
        """Run ``call`` on the spinning thread; returns what it returns (a future)."""
        box: dict[str, Any] = {}
        ready = threading.Event()

        def run() -> None:
            try:
                box["future"] = call()
            finally:
                ready.set()

        self._executor.create_task(run)
        if not ready.wait(self.timeout):
            raise NoResponse("the client's executor did not run the request")
        if "future" not in box:
            raise NoResponse("the request failed on the client's executor (see its log)")
        return box["future"]

    def _wait_future(self, future: Any, timeout: float | None, what: str) -> Any:
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        if not done.wait(self.timeout if timeout is None else timeout):
            raise NoResponse(f"no answer for {what} within the timeout")
        return future.result()

    # -- the graph -------------------------------------------------------------------------
    @property
    def domain_id(self) -> int:
        return self.node.context.get_domain_id()

    def supervisors_on_graph(self, namespace: str | None = None) -> list[int]:
        """Numbers of the supervisor nodes (``<namespace>/ms<n>``) on the graph now."""
        return discovery.supervisors_on_graph(self.node, self.namespace if namespace is None else namespace)

    def twins_on_graph(self, namespace: str | None = None) -> list[str]:
        """The nodes under ``namespace`` that are on the graph more than once: two suites
        under one namespace (``mpi-ros run`` refuses a second one it can see; one that
        discovery did not show in time, or started at the same moment, shows here)."""
        namespace = self.namespace if namespace is None else namespace
        seen = Counter(name for name, ns in self.node.get_node_names_and_namespaces() if ns == namespace)
        return [f"{namespace.rstrip('/')}/{name}" for name, count in sorted(seen.items()) if count > 1]

    def wait_for_suite(self, timeout: float | None = None, supervisor: int | None = None) -> list[int]:
        """Wait until the suite (and ``supervisor``, if given) is on the graph.

        Returns the supervisor numbers; raises SuiteNotFound or NoSuchSupervisor with a
        message an operator can act on.
        """
        timeout = self.timeout if timeout is None else timeout
        deadline = time.monotonic() + timeout
        first_seen: float | None = None
        pause = threading.Event()  # never set: a wait that a debugger can interrupt, unlike sleep
        while True:
            found = self.supervisors_on_graph()
            now = time.monotonic()
            if found and (supervisor is None or supervisor in found):
                return found
            if found and first_seen is None:
                first_seen = now
            if now >= deadline or (first_seen is not None and now - first_seen >= _GRACE):
                break
            pause.wait(_POLL)
        if found and supervisor is not None:  # (with no supervisor asked for, any found was enough)
            runs = ", ".join(f"ms{n}" for n in found)
            raise NoSuchSupervisor(f"no supervisor {gn.supervisor_node(self.namespace, supervisor)}: "
                                   f"the suite runs {runs}")
        raise SuiteNotFound(self._not_found(timeout))

    def _not_found(self, timeout: float) -> str:
        return discovery.not_found(self.node, self.namespace, timeout)


# -- goals and the motion client ---------------------------------------------------------------------------
class Goal:
    """A running MotionStart/MotionModify goal.

    Its result survives a lost link: while waiting, the goal watches its action server on
    the graph; when the server has left it (a link down past the DDS lease) and comes back,
    the goal asks for its result again (the suite keeps results of ended goals), because an
    answer sent while the link was down is lost (docs/cell.md, "A cut link"). It asks again
    too when the goal's status says it ended and no result has come within RESULT_REASK."""

    def __init__(self, client: MotionClient, handle: Any, result_future: Any, progress: threading.Event,
                 action_client: ActionClient | None = None):
        self._client = client
        self.handle = handle
        self._action_client = action_client
        self.asked_again = 0  # results asked again after the server came back
        self._result_future = result_future
        self._progress = progress  # set by the first feedback or the result
        self._finished = threading.Event()

        def finished(_future: Any) -> None:
            self._finished.set()
            progress.set()

        result_future.add_done_callback(finished)
        self.feedback = None  # the latest feedback message (MotionStart.Feedback)

    @property
    def done(self) -> bool:
        return self._result_future.done()

    def result_ready(self, timeout: float | None = None) -> bool:
        """Wait up to ``timeout`` s (None: forever) for the result; whether it has arrived."""
        return self._finished.wait(timeout)

    def wait_started(self, timeout: float | None = None) -> bool:
        """Wait for the first feedback (the move runs: True) or the result (False)."""
        if not self._progress.wait(self._client.timeout if timeout is None else timeout):
            raise NoResponse("neither feedback nor a result for the goal within the timeout")
        return not self.done

    def wait(self, timeout: float | None = None, raise_on_error: bool = True) -> MotionResult:
        """Wait for the result; raises the message's exception unless it is MPIMessageOK.

        ``timeout``: seconds (None: the client's timeout); NoResponse when it passes.
        """
        self._follow_server(self._client.timeout if timeout is None else timeout)
        if not self._result_future.done():
            raise NoResponse("no answer for the goal's result within the timeout")
        response = self._result_future.result()
        result = MotionResult.from_ros(response.result, response.status)
        if raise_on_error:
            raise_for(result.message, result.detail, result)
        return result

    def _follow_server(self, timeout: float) -> None:
        """Wait up to ``timeout`` s for the result, asking again whenever the action server
        reappears on the graph after having left it."""
        deadline = time.monotonic() + timeout
        lost = False
        asked_at: float | None = None
        ended_at: float | None = None  # when the goal's status was first seen terminal
        while not self._finished.wait(max(0.0, min(RESULT_RECHECK, deadline - time.monotonic()))):
            now = time.monotonic()
            if now >= deadline or self._action_client is None:
                return
            if ended_at is None and self.handle.status in _ENDED:
                ended_at = now
            quiet_since = asked_at if asked_at is not None else ended_at
            if not self._action_client.server_is_ready():
                lost = True
            elif lost or (quiet_since is not None and now - quiet_since >= RESULT_REASK):
                # Right after a link comes back the suite may answer before its middleware
                # has matched this client's reader again, and that answer is dropped: ask
                # again until one arrives. The same when the goal's status says it ended
                # and no result follows: a link cut too briefly for the graph to lose the
                # server can drop the answer without the server ever seeming gone.
                lost = False
                asked_at = now
                self._ask_again()

    def _ask_again(self) -> None:
        def forward(future: Any) -> None:
            if not self._result_future.done() and future.result() is not None:
                self._result_future.set_result(future.result())

        self._client._on_executor(self.handle.get_result_async).add_done_callback(forward)
        self.asked_again += 1

    def cancel(self, timeout: float | None = 5.0) -> None:
        """Cancel = STOP: the axes decelerate over decelTime.stop and the goal ends."""
        future = self._client._on_executor(self.handle.cancel_goal_async)
        self._client._wait_future(future, timeout, "the cancel answer")


@dataclass
class _BufferCue:
    """When stream() appends: on a FRAMES_LOW event of its supervisor, or on a MotionStatus
    of the running path with an axis holding fewer than ``low_count`` frames (frame_count)
    once a status has shown the last chunk arrive; either newer than the last chunk sent.
    (A status published before the chunk was applied still shows the buffer low.)"""

    low_count: int
    since: int = -1  # the latest sample known when the last chunk was sent
    frames_at_send: int = 0  # the fewest frames of an axis then
    arrived: bool = False  # a status after the send shows more frames: the chunk is in

    def sent(self, status: MotionStatus | None, frames_low_at: int) -> None:
        self.since = max(status.sample if status is not None else -1, frames_low_at)
        self.frames_at_send = _fewest_frames(status)
        self.arrived = False

    def low(self, status: MotionStatus | None, frames_low_at: int) -> bool:
        if frames_low_at > self.since:
            return True
        if status is None or status.sample <= self.since or status.state_name != State.MOVING:
            return False
        frames = _fewest_frames(status)
        self.arrived = self.arrived or frames > self.frames_at_send
        return self.arrived and 0 < frames < self.low_count


def _fewest_frames(status: MotionStatus | None) -> int:
    return min((axis.frame_count for axis in status.axes), default=0) if status is not None else 0


class MotionClient(_Endpoint):
    """One motion supervisor (``<namespace>/ms<supervisor>``): goals, actions and status."""

    def __init__(self, supervisor: int = 0, namespace: str = DEFAULT_NAMESPACE, context: Context | None = None,
                 timeout: float = 10.0, node_name: str | None = None):
        super().__init__(namespace, context, timeout, node_name or f"mpi_ros_client_ms{supervisor}")
        self.supervisor = supervisor
        self.prefix = gn.supervisor_node(self.namespace, supervisor)
        ns = self.namespace
        self._start = ActionClient(self.node, MotionStart, gn.MOTION_START.name(ns, supervisor), **ACTION_QOS)
        self._modify = ActionClient(self.node, MotionModify, gn.MOTION_MODIFY.name(ns, supervisor), **ACTION_QOS)
        self._action = self.node.create_client(MotionAction, gn.MOTION_ACTION.name(ns, supervisor),
                                               qos_profile=profile(gn.MOTION_ACTION.qos))
        self._status: MotionStatus | None = None
        self._status_event = threading.Condition()
        self.node.create_subscription(MotionStatus, gn.MOTION_STATUS.name(ns, supervisor), self._on_status,
                                      STATUS_QOS)
        self._events: Any = None  # <namespace>/events, subscribed by the first stream()
        self._frames_low_at = -1  # sample of this supervisor's latest FRAMES_LOW event
        self._start_spinning()

    def wait_for_server(self, timeout: float | None = None) -> bool:
        """Wait for the supervisor's actions and services (False if they did not appear),
        then until each action has answered a round trip.

        Why the round trip: the middleware sees the server from this client before the
        server sees this client, and Fast DDS drops a response to a client it has not matched
        yet ("client will not receive response"): a goal sent in that window is applied, but
        its answer never comes. A result request for a goal that does not exist changes
        nothing (the server answers STATUS_UNKNOWN), so it is sent again until one is answered.
        """
        timeout = self.timeout if timeout is None else timeout
        deadline = time.monotonic() + timeout
        pause = threading.Event()  # never set: looked at every few ms (rclpy's own waits look every 0.25 s)
        while not self.servers_ready():
            if time.monotonic() >= deadline:
                return False
            pause.wait(discovery.READY_POLL)
        return self._answered({self._start: MotionStart, self._modify: MotionModify}, deadline)

    def servers_ready(self) -> bool:
        """Whether both actions' servers and the action service are matched (no round trip)."""
        return self._start.server_is_ready() and self._modify.server_is_ready() and self._action.service_is_ready()

    def _answered(self, actions: dict[ActionClient, Any], deadline: float) -> bool:
        """Both actions at once: a result request for an unknown goal to each, sent again
        (after _PROBE_FIRST s, then twice as long each time, up to _PROBE_ANSWER) until any
        request to it is answered. An earlier request may still be answered after a later
        one is sent; any answer will do, so none is given up."""
        answered = threading.Event()
        requests: dict[ActionClient, list[Any]] = {client: [] for client in actions}
        waiting = dict(actions)
        resend = _PROBE_FIRST
        while waiting and (remaining := deadline - time.monotonic()) > 0:
            for client, action_type in waiting.items():
                handle = ClientGoalHandle(client, UUID(uuid=list(uuid.uuid4().bytes)),
                                          action_type.Impl.SendGoalService.Response(accepted=True))
                request = self._on_executor(handle.get_result_async)
                request.add_done_callback(lambda _request: answered.set())
                requests[client].append(request)
            answered.wait(min(resend, remaining))
            answered.clear()
            waiting = {client: action_type for client, action_type in waiting.items()
                       if not any(request.done() for request in requests[client])}
            resend = min(2.0 * resend, _PROBE_ANSWER)
        return not waiting

    def _action_clients(self) -> list[ActionClient]:
        return [self._start, self._modify]

    # -- goals ---------------------------------------------------------------------------
    def start(self, goal: Mapping[str, Any] | Any, feedback: Callable[[Any], None] | None = None) -> Goal:
        """Send a MotionStart goal (a mapping of its fields, or a MotionStart.Goal); returns the running Goal.

        ``feedback`` is called on the client's thread with each MotionStart.Feedback.
        """
        return self._send(self._start, goal if isinstance(goal, MotionStart.Goal) else fill(MotionStart.Goal(), goal),
                          feedback)

    def modify(self, goal: Mapping[str, Any] | Any, feedback: Callable[[Any], None] | None = None) -> Goal:
        """Send a MotionModify goal (a mapping of its fields, or a MotionModify.Goal)."""
        return self._send(self._modify,
                          goal if isinstance(goal, MotionModify.Goal) else fill(MotionModify.Goal(), goal), feedback)

    def _send(self, action_client: ActionClient, msg: Any, feedback: Callable[[Any], None] | None) -> Goal:
        progress = threading.Event()
        holder: dict[str, Goal] = {}
        early: list[Any] = []  # feedback that came before the goal's answer (the suite sends it from its next tick)

        def on_feedback(message: Any) -> None:
            if "goal" in holder:
                holder["goal"].feedback = message.feedback
            else:
                early.append(message.feedback)
            progress.set()
            if feedback is not None:
                feedback(message.feedback)

        if not action_client.wait_for_server(timeout_sec=self.timeout):
            raise NoResponse(f"action server {action_client._action_name} not available")
        send = self._on_executor(lambda: action_client.send_goal_async(msg, feedback_callback=on_feedback))
        handle = self._wait_future(send, None, "the goal request")
        if not handle.accepted:
            raise NoResponse(f"{action_client._action_name} rejected the goal (the suite is shutting down)")
        result = self._on_executor(handle.get_result_async)
        goal = holder["goal"] = Goal(self, handle, result, progress, action_client)
        if goal.feedback is None and early:
            goal.feedback = early[-1]
        return goal

    def move(self, position: Iterable[float], velocity: float, acceleration: float, deceleration: float,
             jerk_percent: float = 0.0, motion_type: MotionType | str = MotionType.S_CURVE,
             attributes: Iterable[Attribute | str] = (), wait: bool = True, timeout: float | None = None,
             **fields: Any) -> MotionResult | Goal:
        """A point-to-point move (one position per axis); waits for the result (or returns the Goal).

        ``deceleration`` is required, as MPITrajectory requires it of TRAPEZOIDAL, S_CURVE and
        S_CURVE_JERK (MPI 000, MPIMotionTrapezoidal, MPIMotionSCurve): none is made up here.

        ``timeout``: seconds to wait for the result (None: the client's timeout; give a long
        move a longer one). Refused or ended early: raises the message's exception.
        """
        goal = {
            "type": _name(motion_type),
            "attributes": [_name(a) for a in attributes],
            "position": [float(p) for p in position],
            "trajectory": [{"velocity": velocity, "acceleration": acceleration,
                            "deceleration": deceleration,
                            "jerk_percent": jerk_percent}],
            **fields,
        }
        running = self.start(goal)
        return running.wait(timeout) if wait else running

    def wait_done(self, goal: Goal, timeout: float | None = None, raise_on_error: bool = True) -> MotionResult:
        """``goal.wait(timeout, raise_on_error)``: the result of a goal this client sent."""
        return goal.wait(timeout, raise_on_error)

    # -- paths --------------------------------------------------------------------------------
    def path(self, motion_type: MotionType | str, points: Iterable[Sequence[float] | float], times: Iterable[float],
             velocities: Iterable[Sequence[float] | float] | None = None,
             feedforward: Iterable[Sequence[float] | float] | None = None,
             attributes: Iterable[Attribute | str] = (), element_ids: Iterable[int] | None = None,
             wait: bool = True, timeout: float | None = None, **fields: Any) -> MotionResult | Goal:
        """One path move (PT, PTF, PVT, PVTF, SPLINE, BESSEL, BSPLINE, BSPLINE2 or FRAME) from the command position.

            result = ms0.path(MotionType.PVT, [(500.0, 0.0), (1000.0, 0.0)], [0.5, 0.5],
                              velocities=[(1500.0, 0.0), (0.0, 0.0)])
            print(result.detail)   # "motion done; path peaks axis 0: |v| ... counts/s, |a| ..."

        ``points``: one tuple per point (a position per axis), interleaved here; ``times``:
        seconds from the previous point (the first from the start); ``velocities`` (PVT/PVTF)
        and ``feedforward`` (PTF/PVTF) per point like ``points``; ``element_ids``: one per point
        (sets ELEMENT_ID). FRAME: no points or times, ``frames=[{...}, ...]`` interleaved by
        axis. ``fields``: any other goal field (``final=False`` leaves the path open for
        appends, ``empty_count``, ``id``, ...). Waits for the result (``timeout`` None: the
        client's timeout plus the path's duration), or returns the Goal with wait=False.
        Refused or ended early: raises the message's exception, as move() does.
        """
        goal = path_goal(motion_type, points, times, velocities, feedforward, attributes, element_ids, **fields)
        running = self.start(goal)
        return running.wait(self._path_timeout(timeout, goal["time"])) if wait else running

    def stream(self, motion_type: MotionType | str, points: Sequence[Sequence[float] | float], times: Sequence[float],
               velocities: Sequence[Sequence[float] | float] | None = None, chunk: int = 50, low_count: int = 32,
               feedforward: Sequence[Sequence[float] | float] | None = None, element_ids: Sequence[int] | None = None,
               attributes: Iterable[Attribute | str] = (), empty_count: int = 5,
               timeout: float | None = None, ahead: int = 0) -> MotionResult:
        """Stream a long path, ``chunk`` points at a time, as the controller asks for them.

            step = 2.0 * math.pi / 10_000  # a circle through the start (0, 0), 10,000 points 2 ms apart
            points = [(1000.0 * math.cos(k * step) - 1000.0, 1000.0 * math.sin(k * step)) for k in range(1, 10_001)]
            result = ms0.stream(MotionType.BESSEL, points, [0.002] * len(points), chunk=100, low_count=64)

        The first chunk opens the path (MotionStart, final false); each further chunk is
        appended (MotionModify with APPEND, the last one final true) when this supervisor's
        FRAMES_LOW event arrives (the path is opened with the LOW_COUNT attribute, so the
        controller sends it when fewer than ``low_count`` points are left; at most the frame
        buffer's size, 128) or a MotionStatus shows an axis with fewer than ``low_count``
        frames in its buffer (frame_count, which never shows more than the buffer holds). The
        controller E_STOPs an open path with fewer than ``empty_count`` points left, so
        (low_count - empty_count) points must last longer than a round trip to the suite. Not
        SPLINE: it may not be appended to.

        ``ahead`` > 0 also keeps up to that many appended chunks not yet executed: a chunk is
        sent as soon as fewer are outstanding (an append's goal ends when its last point is
        reached). Points beyond the frame buffer wait in the library (MPI 001, LOW_COUNT), so
        this gives a round trip about (ahead - 1) * chunk points of time, where the buffer
        alone gives (low_count - empty_count): with 1 ms points and the default 128-frame
        buffer that is 123 ms, which a loaded host can exceed (bench/RESULTS.md). A client
        holding a long path in memory should also keep Python's garbage collector off it
        (``gc.freeze()`` once the points are built): full collections over 100,000 points took
        up to 97 ms there.

        Returns the MotionStart goal's result once the whole path is done. ``timeout``: the
        longest wait for a cue or an answer (None: the client's timeout plus the path's
        duration). Refused, E-stopped or ended early: raises the message's exception (a path
        left open then is E-stopped by the controller when its points run out).
        """
        parts = path_chunks(points, times, chunk, velocities=velocities, feedforward=feedforward,
                            element_ids=element_ids)
        timeout = self._path_timeout(timeout, times)
        attrs = [_name(a) for a in attributes]
        if len(parts) == 1:  # what path() does, with the timeout computed
            goal = path_goal(motion_type, **parts[0], attributes=attrs, empty_count=empty_count)
            return self.start(goal).wait(timeout)
        self._follow_buffer()
        cue = _BufferCue(low_count)
        self._sent(cue)
        # LOW_COUNT: the controller's FRAMES_LOW comes at the client's threshold.
        open_attrs = attrs if Attribute.LOW_COUNT in attrs else [*attrs, Attribute.LOW_COUNT.value]
        start = self._watched(self.start(path_goal(motion_type, **parts[0], attributes=open_attrs, final=False,
                                                   empty_count=empty_count, low_count=low_count)))
        appends: list[Goal] = []
        append_attrs = attrs if Attribute.APPEND in attrs else [*attrs, Attribute.APPEND.value]
        for number, part in enumerate(parts[1:], 2):
            if not self._await_low(start, appends, cue, timeout, ahead):
                break  # the path ended early: its goal says why
            goal = path_goal(motion_type, **part, attributes=append_attrs, final=number == len(parts),
                             empty_count=empty_count)
            self._sent(cue)
            appends.append(self._watched(self.modify(goal)))
        result = start.wait(timeout)
        for append in appends:
            append.wait(timeout)
        return result

    def _path_timeout(self, timeout: float | None, times: Iterable[float]) -> float:
        return self.timeout + sum(times) if timeout is None else timeout

    def _await_low(self, start: Goal, appends: list[Goal], cue: _BufferCue, timeout: float, ahead: int = 0) -> bool:
        """Wait for the cue to append (or, with ``ahead``, fewer appends outstanding): True;
        False if the path's goal ended. Appends that are done leave ``appends``; one the
        controller refused raises its message's exception."""
        def woken() -> bool:
            return (start.done or len(appends) < ahead or any(goal.done for goal in appends)
                    or cue.low(self._status, self._frames_low_at))

        while True:
            with self._status_event:
                if not self._status_event.wait_for(woken, timeout):
                    raise NoResponse(f"{self.prefix}: no FRAMES_LOW and no MotionStatus showing fewer than "
                                     f"{cue.low_count} frames within {timeout:g} s")
                low = cue.low(self._status, self._frames_low_at)
            if start.done:
                return False
            for goal in [goal for goal in appends if goal.done]:
                goal.wait(timeout)  # "points executed", or raises the message of a refused append
                appends.remove(goal)
            if low or len(appends) < ahead:
                return True

    def _sent(self, cue: _BufferCue) -> None:
        """A chunk is about to be sent: what the client knows now is older than its points."""
        with self._status_event:
            cue.sent(self._status, self._frames_low_at)

    def _follow_buffer(self) -> None:
        """Subscribe (once) to <namespace>/events for this supervisor's FRAMES_LOW."""
        if self._events is None:
            self._events = self.node.create_subscription(MotionEvent, gn.EVENTS.name(self.namespace),
                                                         self._on_event, EVENTS_QOS)

    def _on_event(self, event: MotionEvent) -> None:
        if event.supervisor == self.supervisor and event.type == EventType.FRAMES_LOW:
            with self._status_event:
                self._frames_low_at = max(self._frames_low_at, event.sample)
                self._status_event.notify_all()

    def _watched(self, goal: Goal) -> Goal:
        """``goal``, its end waking whoever waits on this client's status."""
        def wake(_future: Any) -> None:
            with self._status_event:
                self._status_event.notify_all()

        goal._result_future.add_done_callback(wake)
        return goal

    def cam(self, motion_type: MotionType | str, master_distances: Iterable[float],
            slave_positions: Iterable[Sequence[float] | float],
            gear_ratios: Iterable[Sequence[float] | float] | None = None, attributes: Iterable[Attribute | str] = (),
            repeat_from: int | None = None, master_start: int | None = None, wait: bool = False,
            timeout: float | None = None, **fields: Any) -> MotionResult | Goal:
        """A cam (CAM_LINEAR or CAM_CUBIC) on the supervisor's axes, which follow each axis'
        master (AxisClient.config_set); the arguments as :func:`cam_goal`. Returns the running
        Goal (a cam ends when its master reaches the table's end, a REPEAT cam only when
        stopped), or with wait=True its result."""
        goal = cam_goal(motion_type, master_distances, slave_positions, gear_ratios, attributes, repeat_from,
                        master_start, **fields)
        running = self.start(goal)
        return running.wait(timeout) if wait else running

    # -- actions ----------------------------------------------------------------------------
    def action(self, name: Action | str, raise_on_error: bool = True) -> ActionReply:
        """mpiMotionAction: STOP, E_STOP, ABORT, E_STOP_ABORT, RESET, RESUME or MAP."""
        name = _name(name)
        if not self._action.wait_for_service(timeout_sec=self.timeout):
            raise NoResponse(f"the supervisor's action service {self.prefix}/action is not available")
        response = self._wait_future(self._action.call_async(MotionAction.Request(action=name)), None,
                                     f"action {name}")
        return action_reply(name, response, raise_on_error)

    def fault_inject(self, axis: int, fault: str, active: bool = True) -> FaultReply:
        """Inject a fault on an axis (AMP_FAULT, ENCODER_FAULT: a condition, cleared with
        ``active`` False; the others trip once), docs/faults.md. RESET clears it afterwards."""
        name = gn.FAULT_INJECT.name(self.namespace, axis)
        service = self.node.create_client(AxisFaultInject, name, qos_profile=profile(gn.FAULT_INJECT.qos))
        try:
            if not service.wait_for_service(timeout_sec=self.timeout):
                raise NoResponse(f"the axis service {name} is not available")
            request = AxisFaultInject.Request(fault=fault, active=active)
            response = self._wait_future(service.call_async(request), None, f"the injection of {fault}")
        finally:
            self.node.destroy_client(service)
        return FaultReply(response.message, response.code, response.detail, tuple(response.faults))

    def stop(self) -> ActionReply:
        return self.action(Action.STOP)

    def e_stop(self) -> ActionReply:
        return self.action(Action.E_STOP)

    def abort(self) -> ActionReply:
        return self.action(Action.ABORT)

    def e_stop_abort(self) -> ActionReply:
        return self.action(Action.E_STOP_ABORT)

    def reset(self) -> ActionReply:
        return self.action(Action.RESET)

    def resume(self) -> ActionReply:
        return self.action(Action.RESUME)

    # -- status ---------------------------------------------------------------------------------
    def _on_status(self, msg: MotionStatus) -> None:
        with self._status_event:
            self._status = msg
            self._status_event.notify_all()

    def wait_for(self, predicate: Callable[[MotionStatus], bool], timeout: float | None = None,
                 what: str = "the awaited status") -> MotionStatus:
        """Wait for a MotionStatus for which ``predicate`` holds; returns it."""
        with self._status_event:
            ok = self._status_event.wait_for(lambda: self._status is not None and predicate(self._status),
                                             self.timeout if timeout is None else timeout)
            if not ok:
                raise NoResponse(f"{self.prefix}: no MotionStatus showed {what}")
            return self._status

    def status(self, timeout: float | None = None, newer_than: int = -1) -> MotionStatus:
        """The latest MotionStatus (waits for one newer than sample ``newer_than``)."""
        return self.wait_for(lambda s: s.sample > newer_than, timeout, f"a sample after {newer_than}")

    def wait_for_state(self, state_name: State | str, timeout: float | None = None,
                       newer_than: int = -1) -> MotionStatus:
        """Wait until the supervisor's status (after sample ``newer_than``) shows ``state_name``."""
        wanted = _name(state_name)
        return self.wait_for(lambda s: s.state_name == wanted and s.sample > newer_than, timeout,
                             f"state {wanted}")


@dataclass(frozen=True, slots=True)
class ServiceReply:
    """The answer of a controller service: the spec's message name and its code."""

    message: str
    code: int

    @property
    def ok(self) -> bool:
        return self.message == "MPIMessageOK"


class AxisClient(_Endpoint):
    """The controller's axis services: mpiAxisConfigGet/Set (inPosition, master,
    masterCorrection) and the motors' secondary feedback inputs that cams can follow.

        with AxisClient() as axes:
            axes.config_set(1, master={"type": "AXIS_COMMANDED_POSITION", "number": 0})
    """

    def __init__(self, namespace: str = DEFAULT_NAMESPACE, context: Context | None = None, timeout: float = 10.0,
                 node_name: str | None = None):
        super().__init__(namespace, context, timeout, node_name or "mpi_ros_axis_client")
        self._clients: dict[tuple[type, str], Any] = {}
        self._start_spinning()

    def _call(self, srv_type: type, endpoint: gn.Endpoint, number: int | None, request: Any,
              raise_on_error: bool) -> Any:
        full = endpoint.name(self.namespace, number)
        name = full[len(self.namespace) + 1:]  # as the answers name it: axis0/config_set
        key = (srv_type, name)
        if key not in self._clients:
            self._clients[key] = self.node.create_client(srv_type, full, qos_profile=profile(endpoint.qos))
        client = self._clients[key]
        if not client.wait_for_service(timeout_sec=self.timeout):
            raise NoResponse(f"the controller's service {full} is not available")
        response = self._wait_future(self._on_executor(lambda: client.call_async(request)), None, name)
        if raise_on_error:
            raise_for(response.message, name, ServiceReply(response.message, response.code))
        return response

    def config_get(self, axis: int) -> Any:
        """mpiAxisConfigGet: the AxisConfigGet response (in_position, master, master_correction)."""
        return self._call(AxisConfigGet, gn.AXIS_CONFIG_GET, axis, AxisConfigGet.Request(), True)

    def config_set(self, axis: int, in_position: Mapping[str, Any] | None = None,
                   master: Mapping[str, Any] | None = None, master_correction: int | None = None,
                   raise_on_error: bool = True) -> ServiceReply:
        """mpiAxisConfigSet; what is not given stays as the axis has it (read first)."""
        current = self.config_get(axis)
        request = AxisConfigSet.Request(in_position=current.in_position, master=current.master,
                                        master_correction=current.master_correction)
        if in_position is not None:
            fill(request.in_position, in_position, "in_position")
        if master is not None:
            fill(request.master, master, "master")
        if master_correction is not None:
            request.master_correction = int(master_correction)
        response = self._call(AxisConfigSet, gn.AXIS_CONFIG_SET, axis, request, raise_on_error)
        return ServiceReply(response.message, response.code)

    def secondary_feedback_set(self, motor: int, position: float, velocity: float,
                               raise_on_error: bool = True) -> ServiceReply:
        """Drive motor ``motor``'s secondary feedback input: from the next sample it reads
        ``position`` and moves at ``velocity`` counts/s (a line shaft's encoder, say)."""
        request = MotorFeedbackSecondarySet.Request(motor=motor, position=float(position), velocity=float(velocity))
        response = self._call(MotorFeedbackSecondarySet, gn.MOTOR_FEEDBACK_SECONDARY_SET, None, request,
                              raise_on_error)
        return ServiceReply(response.message, response.code)


# -- the whole suite ----------------------------------------------------------------------------------------
class Watcher(_Endpoint):
    """Follows the suite: every supervisor's and axis' latest status, the events, any topic.

        with Watcher() as watch:
            supervisors = watch.wait_for_suite(5.0)
            watch.follow_status(supervisors, watch.axes_on_graph())
            statuses, axes = watch.latest()
    """

    def __init__(self, namespace: str = DEFAULT_NAMESPACE, context: Context | None = None, timeout: float = 10.0,
                 node_name: str | None = None):
        super().__init__(namespace, context, timeout, node_name or "mpi_ros_watcher")
        self._changed = threading.Condition()
        self._supervisors: dict[int, MotionStatus] = {}
        self._axes: dict[int, AxisStatus] = {}
        self._suite: DiagnosticStatus | None = None
        self._start_spinning()

    def axes_on_graph(self) -> list[int]:
        """Numbers of the axes whose status topic (``<namespace>/axis<k>/status``) is on the graph."""
        return sorted(k for name, _ in self.node.get_topic_names_and_types()
                      if (k := gn.axis_status_number(self.namespace, name)) is not None)

    def topics_on_graph(self) -> dict[str, str]:
        """Topic name -> type (``pkg/msg/Type``) of every topic on the graph."""
        return {name: types[0] for name, types in self.node.get_topic_names_and_types() if types}

    # -- status ---------------------------------------------------------------------------------
    def follow_status(self, supervisors: Iterable[int], axes: Iterable[int]) -> None:
        """Keep the latest MotionStatus of ``supervisors`` and AxisStatus of ``axes``."""
        for n in supervisors:
            self.node.create_subscription(MotionStatus, gn.MOTION_STATUS.name(self.namespace, n),
                                          partial(self._keep, self._supervisors, n), STATUS_QOS)
        for k in axes:
            self.node.create_subscription(AxisStatus, gn.AXIS_STATUS.name(self.namespace, k),
                                          partial(self._keep, self._axes, k), STATUS_QOS)

    def _keep(self, table: dict[int, Any], key: int, msg: Any) -> None:
        with self._changed:
            table[key] = msg
            self._changed.notify_all()

    def latest(self) -> tuple[dict[int, MotionStatus], dict[int, AxisStatus]]:
        """Copies of the latest statuses: supervisor number -> MotionStatus, axis -> AxisStatus."""
        with self._changed:
            return dict(self._supervisors), dict(self._axes)

    def wait_for_status(self, supervisors: Iterable[int], axes: Iterable[int], timeout: float | None = None,
                        newer_than: int = -1) -> tuple[dict[int, MotionStatus], dict[int, AxisStatus]]:
        """Wait until every one of ``supervisors`` and ``axes`` has a status after ``newer_than``."""
        wanted_ms, wanted_axes = list(supervisors), list(axes)

        def complete() -> bool:
            return (all(n in self._supervisors and self._supervisors[n].sample > newer_than for n in wanted_ms)
                    and all(k in self._axes and self._axes[k].sample > newer_than for k in wanted_axes))

        with self._changed:
            if not self._changed.wait_for(complete, self.timeout if timeout is None else timeout):
                missing = [gn.MOTION_STATUS.name(self.namespace, n) for n in wanted_ms if n not in self._supervisors]
                missing += [gn.AXIS_STATUS.name(self.namespace, k) for k in wanted_axes if k not in self._axes]
                raise NoResponse(f"no status from {', '.join(missing) or 'the suite'} within the timeout")
            return dict(self._supervisors), dict(self._axes)

    # -- the suite's own health -----------------------------------------------------------------------
    def follow_suite(self) -> None:
        """Keep the latest ``<namespace>/suite`` entry of /diagnostics: whether the controller
        keeps to the wall clock (WARN: behind real time) and what the suite holds (docs/reliability.md)."""
        self.node.create_subscription(DiagnosticArray, gn.DIAGNOSTICS.name(self.namespace), self._keep_suite,
                                      DIAGNOSTICS_QOS)

    def _keep_suite(self, msg: DiagnosticArray) -> None:
        name = f"{self.namespace.strip('/')}/suite"  # (/diagnostics is shared by the suites of a cell)
        for status in msg.status:
            if status.name == name:
                with self._changed:
                    self._suite = status
                    self._changed.notify_all()

    def suite_status(self) -> DiagnosticStatus | None:
        """The latest ``<namespace>/suite`` entry (:meth:`follow_suite`), None before the first."""
        with self._changed:
            return self._suite

    # -- events and other topics ----------------------------------------------------------------------
    def follow_events(self, callback: Callable[[MotionEvent], None]) -> Any:
        """Call ``callback`` (on the watcher's thread) with every MotionEvent; returns the subscription."""
        return self.node.create_subscription(MotionEvent, gn.EVENTS.name(self.namespace), callback, EVENTS_QOS)

    def follow_topic(self, topic: str, callback: Callable[[Any], None], depth: int = 100) -> tuple[Any, str]:
        """Subscribe to any topic on the graph, with a QoS its publishers accept.

        Returns (subscription, type name). Reliable unless a publisher is best effort (/clock
        is); transient local when every publisher is (latched topics).
        """
        types = self.topics_on_graph()
        if topic not in types:
            raise LookupError(topic)
        qos = matching(self.node.get_publishers_info_by_topic(topic), depth)
        return self.node.create_subscription(message_class(types[topic]), topic, callback, qos), types[topic]

    def wait_matched(self, subscription: Any, timeout: float | None = None) -> None:
        """Wait until ``subscription`` is connected to a publisher (what it gets from then on arrives)."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        pause = threading.Event()
        while subscription.get_publisher_count() == 0:
            if time.monotonic() >= deadline:
                raise NoResponse(f"no publisher of {subscription.topic_name} connected within the timeout")
            pause.wait(_POLL)
