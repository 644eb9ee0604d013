"""No input can crash the suite or leave it inconsistent: fuzzed goals, random
STOP/E_STOP/RESET interleavings, a client killed in the middle of a goal."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mpi_ros import config
from mpi_ros.commands import Command, apply
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.types import MPIState

TYPES = ["S_CURVE", "TRAPEZOIDAL", "VELOCITY", "S_CURVE_JERK", "VELOCITY_JERK", "PT", "PVT", "SPLINE", "FRAME",
         "CAM_LINEAR", "BOGUS", "", "s_curve"]
ATTRIBUTES = ["APPEND", "AUTO_START", "DELAY", "ID", "ELEMENT_ID", "RELATIVE", "SYNC_START", "SYNC_END", "REPEAT",
              "EVENT", "FINAL_VEL", "NO_REVERSAL", "HOLD", "HOLD_LESS", "HOLD_GREATER", "OUTPUT", "WHATEVER"]
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64), st.integers(-10**6, 10**6))
small_lists = st.lists(numbers, max_size=4)
trajectory = st.fixed_dictionaries({}, optional={
    "velocity": numbers, "acceleration": numbers, "deceleration": numbers, "jerk_percent": numbers,
    "acceleration_jerk": numbers, "deceleration_jerk": numbers})
hold = st.fixed_dictionaries({}, optional={
    "type": st.sampled_from(["GATE", "INPUT", "AXIS_POSITION_ACTUAL", "USER_ADDRESS", "NONE", "BAD", ""]),
    "gate": st.integers(-5, 40), "number": st.integers(-5, 10), "address": st.integers(-5, 100),
    "mask": st.integers(-(2**31), 2**31 - 1), "pattern": st.integers(-(2**31), 2**31 - 1),
    "position": numbers, "timeout": numbers})
goals = st.fixed_dictionaries(
    {"type": st.sampled_from(TYPES)},
    optional={
        "attributes": st.lists(st.sampled_from(ATTRIBUTES), max_size=4),
        "trajectory": st.lists(trajectory, max_size=3),
        "position": small_lists, "delay": small_lists, "final_velocity": small_lists,
        "id": st.integers(-(2**31), 2**31 - 1), "element_id": st.lists(st.integers(-5, 5), max_size=2),
        "hold": st.lists(hold, max_size=3), "event_mask": st.lists(st.sampled_from(["MOTION_DONE", "ALL", "X"]),
                                                                    max_size=2),
        "use_stored_params": st.booleans(),
    })
actions = st.sampled_from(["STOP", "E_STOP", "ABORT", "E_STOP_ABORT", "RESET", "RESUME", "MAP"])

DOOMED = Path(__file__).with_name("doomed_client.py")  # a client process killed mid-goal


def _finite_state(ctl) -> bool:
    values = [v for a in ctl.axes for v in (a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v)]
    return all(math.isfinite(v) for v in values)


@settings(max_examples=400, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(script=st.lists(st.tuples(st.sampled_from(["motion_start", "motion_modify"]), goals,
                                 st.integers(0, 3000)), min_size=1, max_size=4))
def test_fuzzed_goals_never_crash_and_answer_a_known_message(script):
    ctl = config.load().build_controller()
    for operation, goal, samples in script:
        before_state = ctl.supervisor(0).state
        reply = apply(ctl, Command(operation, 0, request=goal))
        assert isinstance(reply.message, Message)
        if not reply.accepted:
            # a refused command changes nothing
            assert ctl.supervisor(0).state is before_state
        ctl.step(samples)
        assert _finite_state(ctl)


@settings(max_examples=200, derandomize=True, deadline=None)
@given(script=st.lists(st.tuples(st.one_of(actions, st.just("MOVE")), st.integers(0, 1500)), min_size=1,
                       max_size=12))
def test_random_action_interleavings_keep_the_state_machine_consistent(script):
    ctl = config.load().build_controller()
    ms = ctl.supervisor(0)
    goal = {"type": "S_CURVE", "position": [4000.0, -2000.0],
            "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0, "deceleration": 10000.0,
                            "jerk_percent": 30.0}]}
    for what, samples in script:
        state = ms.state
        if what == "MOVE":
            goal["position"] = [-goal["position"][0], goal["position"][1]]
            reply = apply(ctl, Command("motion_start", 0, request=goal))
            assert reply.accepted == (state in (MPIState.IDLE, MPIState.STOPPED))
        else:
            reply = apply(ctl, Command("action", 0, request={"action": what}))
            # docs/state-machine.md: the safety actions are never refused
            if what in ("E_STOP", "ABORT", "E_STOP_ABORT"):
                assert reply.message is Message.MPIMessageOK
        ctl.step(samples)
        assert _finite_state(ctl)
        if ms.state is MPIState.ERROR:
            assert ms.current is None
            assert not ms.queue
        if ms.state is MPIState.IDLE:
            assert all(not ctl.axes[n].holding for n in ms.mapped)


def test_fuzzed_goals_through_the_action_server(suite, client, drive):
    """The node answers malformed goals through ROS with a result, never a crash."""
    weird = [
        {"type": "S_CURVE", "position": [1e308, -1e308], "trajectory": [{"velocity": 1e-300, "acceleration": 1e300,
                                                                          "deceleration": 1.0}]},
        {"type": "VELOCITY", "attributes": ["SYNC_END"], "trajectory": [{"velocity": 1.0, "acceleration": 1.0}]},
        {"type": "S_CURVE", "attributes": ["HOLD"], "position": [1.0, 1.0],
         "hold": [{"type": "AXIS_POSITION_ACTUAL", "number": 42}] * 2},
        {"type": "TRAPEZOIDAL", "position": [1.0, 2.0], "trajectory": [{}, {}, {}]},
        {"type": "s_curve", "position": [0.0, 0.0], "attributes": ["append", "ID"], "id": 2**31 - 1,
         "trajectory": [{"velocity": 10.0, "acceleration": 10.0, "deceleration": 10.0}]},
    ]
    for goal in weird:
        running = client.start(goal)
        drive(lambda running=running: running.done)  # a valid one (names are case-insensitive) runs to its end
        assert running.wait(raise_on_error=False).message in Message.__members__
    assert suite.runner.read(lambda ctl: _finite_state(ctl))


def test_a_client_killed_mid_goal_leaves_the_suite_working(suite, client, applied, drive, tmp_path):
    doomed = subprocess.Popen([sys.executable, "-P", str(DOOMED), "0", "50000.0"], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert doomed.stdout.readline().strip() == "sent"
        applied.wait(1)
        drive(lambda: suite.runner.ctl.axes[0].cmd_v > 500.0)
    finally:
        doomed.kill()
        doomed.wait(timeout=10)
    # the orphaned goal keeps its move (until the lost-client watchdog: the client's 20 s DDS
    # lease + lost_client_timeout, test_watchdog.py); the suite still serves others
    assert client.stop().message == "MPIMessageOK"
    drive(lambda: suite.runner.read(lambda ctl: ctl.supervisor(0).state is MPIState.STOPPED))
    client.reset()
    result = client.move([0.0, 0.0], velocity=5000.0, acceleration=50000.0, deceleration=50000.0, wait=False)
    applied.wait(4)
    drive(lambda: result.done)
    assert result.wait().message == "MPIMessageOK"
