"""`ros.crosscheck: true` in the node suite: a disagreement reaches /mpi/events as a
CROSSCHECK MotionEvent, the controller node's log and /diagnostics (mpi/crosscheck).
The controller runs in manual mode; waits are on conditions with timeouts, never sleeps."""

from __future__ import annotations

import threading

import pytest

WAIT = 10.0


@pytest.fixture
def crosscheck_suite(ros_context):
    from mpi_ros import config
    from mpi_ros.ros.suite import Suite

    cfg = config.load()
    cfg.ros.crosscheck = True
    cfg.ros.diagnostics_rate = 100.0  # every 20 samples
    suite = Suite(cfg, time_scale=None, context=ros_context)
    suite.start(spin_in_thread=True)
    try:
        yield suite
    finally:
        suite.shutdown()


class Collector:
    def __init__(self, probe, msg_type, topic, qos, match):
        self.items, self._cond, self._match = [], threading.Condition(), match
        probe.create_subscription(msg_type, topic, self._on, qos)

    def _on(self, msg):
        if self._match(msg):
            with self._cond:
                self.items.append(msg)
                self._cond.notify_all()

    def wait(self, step=None, timeout=WAIT):
        """Wait for a message (stepping the controller with ``step`` between checks)."""
        with self._cond:
            deadline = threading.Event()
            timer = threading.Timer(timeout, deadline.set)
            timer.start()
            try:
                while not self.items and not deadline.is_set():
                    if step is not None:
                        self._cond.release()
                        try:
                            step()
                        finally:
                            self._cond.acquire()
                    self._cond.wait(0.01)
            finally:
                timer.cancel()
            assert self.items, "nothing arrived"
            return self.items[-1]


def test_a_disagreement_is_an_event_and_a_diagnostic(crosscheck_suite, probe, monkeypatch):
    from dataclasses import replace

    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

    from mpi_ros.client import EVENTS_QOS
    from mpi_ros.commands import Command
    from mpi_ros.mpi.planning.frames import Listed
    from mpi_ros.mpi.supervisor import motion as motion_module
    from mpi_ros.msg import MotionEvent

    suite = crosscheck_suite
    events = Collector(probe, MotionEvent, "/mpi/events", EVENTS_QOS, lambda m: m.type == "CROSSCHECK")
    diagnostics = Collector(probe, DiagnosticArray, "/diagnostics", 10,
                            lambda m: any(s.name == "mpi/crosscheck" and "1 disagree" in s.message
                                          for s in m.status))
    # wait until the probe's subscriptions are matched by the suite's publishers
    for topic in ("/mpi/events", "/diagnostics"):
        matched = threading.Event()
        while probe.count_publishers(topic) == 0 and not matched.wait(0.01):
            pass

    good, _ = suite.runner.submit(Command("motion_start", 0, request={
        "type": "S_CURVE", "position": [100.0, 0.0],
        "trajectory": [{"velocity": 500.0, "acceleration": 5000.0, "deceleration": 5000.0, "jerk_percent": 50.0}]}))
    assert good.accepted
    assert suite.crosscheck.summary()["agree"] == 2
    suite.runner.step(2000)

    real = motion_module.compile_move

    def wrong(supervisor, motion_type, attrs, params, starts, rate):  # a planner bug
        fast = replace(params, trajectory=[replace(t, acceleration=2 * t.acceleration) for t in params.trajectory])
        move, notes = real(supervisor, motion_type, attrs, fast, starts, rate)
        for plan in move.plans:
            plan.source = Listed(plan.segments, replace(plan.limits, acceleration=plan.limits.acceleration / 2))
        return move, notes

    monkeypatch.setattr(motion_module, "compile_move", wrong)
    reply, _ = suite.runner.submit(Command("motion_start", 0, request={
        "type": "S_CURVE", "position": [0.0, 0.0], "attributes": ["ID"], "id": 7,
        "trajectory": [{"velocity": 500.0, "acceleration": 5000.0, "deceleration": 5000.0, "jerk_percent": 50.0}]}))
    assert reply.accepted
    event = events.wait(step=lambda: suite.runner.step(1))
    assert (event.supervisor, event.axis, event.move_id) == (0, 0, 7)
    assert "DISAGREE" in event.detail
    array = diagnostics.wait(step=lambda: suite.runner.step(20))
    status = next(s for s in array.status if s.name == "mpi/crosscheck")
    assert status.level == DiagnosticStatus.WARN
    values = {kv.key: kv.value for kv in status.values}
    # axis 1 of the second move does not move: nothing to get wrong (AGREE)
    assert values["disagree"] == "1"
    assert values["agree"] == "3"
    assert "DISAGREE" in values["last_disagreement"]


def test_crosscheck_is_off_by_default(ros_context):
    from mpi_ros import config
    from mpi_ros.ros.suite import Suite

    suite = Suite(config.load(), time_scale=None, context=ros_context)
    try:
        assert suite.crosscheck is None
        # the supervisors' trajectory counts and the suite's own entry (mpi/suite), no crosscheck entry
        names = [status.name for provide in suite.controller_node.diagnostic_providers
                 for status in provide(suite.controller)]
        assert names == ["mpi/ms0/joint_trajectory", "mpi/ms1/joint_trajectory", "mpi/suite"]
    finally:
        suite.shutdown()
