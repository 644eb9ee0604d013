"""The lost-client watchdog (docs/cell.md, "Lost clients"; mpi_ros/ros/watchdog.py): on by
default (2 s; docs/decisions.md: Jazzy's `ros2 action send_goal` does not cancel its goal on
Ctrl-C), 0 turns it off; a goal whose client leaves the graph has its motion STOPped, with a
Operation.CLIENT_LOST event, through a recorded command."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import pytest

from mpi_ros import config
from mpi_ros.commands import Command, Operation, apply
from mpi_ros.mpi.base.types import MPIState

from .conftest import WAIT

LEASE_PROFILE = Path(__file__).resolve().parents[2] / "config" / "fastdds_short_lease.xml"
# this tree's default configuration (an installed copy, which config.load() prefers, may be older)
DEFAULTS = Path(__file__).resolve().parents[2] / "config" / "default.yaml"
TIMEOUT = config.LOST_CLIENT_TIMEOUT  # s: ms1's lost_client_timeout here, the default
LEASE = 2.0  # s: the killed client's DDS lease (config/fastdds_short_lease.xml)
# s more a loaded machine may take to see the killed client leave the graph (the middleware's
# lease check and graph update; 2.5 s in all here, over 12 s seen once in a loaded full run)
LOADED = 30.0

DOOMED = Path(__file__).with_name("doomed_client.py")  # a client process killed mid-goal
FEEDBACK = "/mpi/ms1/motion_start/_action/feedback"  # where the doomed client subscribes


@pytest.fixture
def suite_config():
    # ms1 keeps the default; ms0 turns the watchdog off
    return config.load(DEFAULTS, overrides={"supervisors": [{"number": 0, "axes": [0, 1], "lost_client_timeout": 0},
                                                            {"number": 1, "axes": [2, 3]}]})


def test_the_watchdog_is_on_at_2_s_by_default_and_validated(tmp_path):
    assert TIMEOUT == 2.0
    cfg = config.load(DEFAULTS)
    assert [spec.lost_client_timeout for spec in cfg.supervisors] == [2.0, 2.0]
    unsaid = tmp_path / "unsaid.yaml"  # a configuration that does not name it
    unsaid.write_text("".join(line for line in DEFAULTS.read_text().splitlines(keepends=True)
                              if "lost_client_timeout" not in line))
    assert [spec.lost_client_timeout for spec in config.load(unsaid).supervisors] == [2.0, 2.0]
    off = config.load(DEFAULTS, overrides={"supervisor_defaults": {"lost_client_timeout": 0}})
    assert [spec.lost_client_timeout for spec in off.supervisors] == [0.0, 0.0]
    for bad in (-1.0, "soon", float("inf"), True):
        with pytest.raises(config.ConfigError, match=r"supervisors\[0\]\.lost_client_timeout"):
            config.load(overrides={"supervisors": [{"number": 0, "axes": [0], "lost_client_timeout": bad}]})


def _no_inherited_sigint() -> None:
    # a process started from a background job inherits an ignored SIGINT: the client must die of it
    signal.signal(signal.SIGINT, signal.SIG_DFL)


class Events:
    """The controller's events and applied commands, as the suite's hooks see them."""

    def __init__(self, runner):
        self.events: list = []
        self.commands: list = []
        self._cond = threading.Condition()
        runner.on_event(self._add(self.events))
        runner.on_command(lambda sample, command, reply: self._add(self.commands)((sample, command, reply)))

    def _add(self, into: list):
        def add(item) -> None:
            with self._cond:
                into.append(item)
                self._cond.notify_all()
        return add

    def wait_command(self, operation: str, timeout: float, why: Callable[[], str] = str):
        with self._cond:
            assert self._cond.wait_for(lambda: any(c.operation == operation for _, c, _ in self.commands), timeout), (
                f"no {operation} command within {timeout} s; {why()}")
            return next(entry for entry in self.commands if entry[1].operation == operation)


@pytest.mark.parametrize("kill", [signal.SIGINT, signal.SIGKILL], ids=["SIGINT", "SIGKILL"])
def test_a_killed_client_has_its_motion_stopped_with_an_event(suite, drive, tmp_path, kill):
    """SIGINT is Ctrl-C on a client that does not cancel its goal then, as Jazzy's ros2
    action send_goal; SIGKILL leaves nothing the client could do. Either way the motion is
    STOPPED lost_client_timeout after the client has left the graph (at once for SIGINT, its
    DDS lease for SIGKILL)."""
    seen = Events(suite.runner)
    env = dict(os.environ, FASTRTPS_DEFAULT_PROFILES_FILE=str(LEASE_PROFILE))
    doomed = subprocess.Popen([sys.executable, "-P", str(DOOMED), "1", "500000.0"], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=tmp_path, env=env,
                              preexec_fn=_no_inherited_sigint)
    watchdog = suite.supervisor_nodes[1].watchdog
    assert suite.supervisor_nodes[0].watchdog is None  # lost_client_timeout: 0 is off
    try:
        assert doomed.stdout.readline().strip() == "sent"
        seen.wait_command("motion_start", WAIT)
        drive(lambda: suite.runner.ctl.axes[2].cmd_v > 500.0)
        assert watchdog.watched == 1
    finally:
        killed_at = time.monotonic()
        doomed.send_signal(kill)
        ended = doomed.wait(timeout=10)
    # SIGINT: rclpy's handler shuts the client's context down and KeyboardInterrupt ends it
    # (an exit status 1, or an abort in the middleware's teardown, -6, seen here)
    assert ended == -signal.SIGKILL if kill is signal.SIGKILL else ended != 0
    sample, command, reply = seen.wait_command(
        Operation.CLIENT_LOST, LEASE + TIMEOUT + LOADED,
        lambda: f"watched: {watchdog.describe_watched()}; subscribers of the feedback topic: "
                + ", ".join(f"{info.node_namespace}/{info.node_name}"
                            for info in suite.supervisor_nodes[1].get_subscriptions_info_by_topic(FEEDBACK)))
    took = time.monotonic() - killed_at
    assert TIMEOUT <= took < LEASE + TIMEOUT + LOADED
    # the client did not cancel (no STOP action of its own): the watchdog stopped the motion
    assert [c.operation for _, c, _ in seen.commands] == ["motion_start", Operation.CLIENT_LOST]
    assert command.supervisor == 1
    assert reply.message.name == "MPIMessageOK"
    assert reply.state is MPIState.STOPPING
    lost = [e for e in seen.events if e.type_name == "CLIENT_LOST"]
    assert len(lost) == 1
    assert lost[0].supervisor == 1
    assert "left the graph" in lost[0].detail
    after = [e.type_name for e in seen.events[seen.events.index(lost[0]):] if e.supervisor == 1]
    assert after[:2] == ["CLIENT_LOST", "STOP"]
    assert lost[0].sample == sample - 1
    drive(lambda: suite.runner.read(lambda ctl: ctl.supervisor(1).state is MPIState.STOPPED))
    assert suite.runner.read(lambda ctl: ctl.supervisor(0).state) is MPIState.IDLE  # the other one untouched
    assert watchdog.watched == 0  # the goal ended (STOPPED): nothing left to watch


def test_a_client_lost_command_replays_as_recorded():
    """The watchdog's STOP is data: applied again to a fresh controller it gives the same
    answer and the same event (what `mpi-ros replay` relies on)."""
    answers = []
    for _ in range(2):
        ctl = config.load().build_controller()
        events: list = []
        ctl.listeners.append(events.append)
        apply(ctl, Command("motion_start", 0, request={
            "type": "TRAPEZOIDAL", "position": [100000.0, 0.0],
            "trajectory": [{"velocity": 1000.0, "acceleration": 10000.0, "deceleration": 10000.0}]}))
        ctl.step(100)
        lost = {"detail": "the client of goal 0123abcd left the graph"}
        reply = apply(ctl, Command(Operation.CLIENT_LOST, 0, request=lost))
        answers.append((reply.message, reply.state, [(e.sample, e.type_name, e.detail) for e in events]))
    assert answers[0] == answers[1]
    assert answers[0][0].name == "MPIMessageOK"
    assert answers[0][1] is MPIState.STOPPING
    refused = apply(config.load().build_controller(), Command(Operation.CLIENT_LOST, 0, request={"detail": 5}))
    assert refused.message.name == "MPIMessagePARAM_INVALID"


class FakeGraph:
    """A node's graph queries and timer, for the watchdog's logic without DDS."""

    def __init__(self):
        self.subscribers: dict[str, list[bytes]] = {}
        self.names: dict[bytes, str] = {}  # node names by GID ("client" when not given)
        self.woken = 0  # guard condition triggers (the ticker waking its executor)

    def get_subscriptions_info_by_topic(self, topic):
        return [SimpleNamespace(endpoint_gid=list(gid), node_name=self.names.get(gid, "client"))
                for gid in self.subscribers.get(topic, [])]

    def create_timer(self, period, callback, callback_group=None, autostart=True):
        return FakeTimer(period, callback, not autostart)

    def create_guard_condition(self, callback, callback_group=None):
        return SimpleNamespace(trigger=lambda: setattr(self, "woken", self.woken + 1))


@dataclass
class FakeTimer:
    period: float
    callback: Callable[[], None]
    canceled: bool

    def is_canceled(self) -> bool:
        return self.canceled

    def cancel(self) -> None:
        self.canceled = True

    def reset(self) -> None:
        self.canceled = False


def test_the_watchdog_times_the_clients_absence_and_forgives_a_return():
    from mpi_ros.ros.watchdog import LostClientWatchdog

    graph, now, lost, running = FakeGraph(), [0.0], [], {b"g" * 16}
    topic = "/mpi/ms0/motion_start/_action/feedback"
    graph.subscribers[topic] = [b"A" * 16, b"B" * 16]
    watchdog = LostClientWatchdog(graph, 1.0, lambda keys: running & set(keys), lost.append, None,
                                  clock=lambda: now[0])
    assert watchdog.ticker.period == 0.1
    watchdog.watch(b"g" * 16, topic)
    graph.subscribers[topic] = [b"B" * 16]  # one of the two candidates remains: maybe the sender
    now[0] = 5.0
    watchdog.check()
    assert not lost
    graph.subscribers[topic] = [b"C" * 16]  # both gone; a newcomer is not the goal's client
    watchdog.check()
    now[0] = 5.9
    watchdog.check()
    assert not lost
    graph.subscribers[topic] = [b"B" * 16]  # back in time (a link restored): forgiven
    now[0] = 6.5
    watchdog.check()
    graph.subscribers[topic] = []
    now[0] = 7.0
    watchdog.check()
    now[0] = 7.99
    watchdog.check()
    assert not lost
    now[0] = 8.0
    watchdog.check()
    assert len(lost) == 1
    assert "67676767" in lost[0]
    assert "1 s" in lost[0]
    assert watchdog.watched == 0
    watchdog.watch(b"h" * 16, topic)  # a goal that ended is forgotten, never stopped
    now[0] = 20.0
    watchdog.check()
    assert watchdog.watched == 0
    assert len(lost) == 1


def test_a_goal_whose_client_was_never_seen_is_stopped_after_the_discovery_grace():
    """A client killed right after its goal, before the suite discovered its subscription,
    never shows on the graph: its goal counts as lost from its arrival, once discovery had
    DISCOVERY_GRACE to show the client."""
    from mpi_ros.ros.watchdog import DISCOVERY_GRACE, LostClientWatchdog

    graph, now, lost = FakeGraph(), [10.0], []
    topic = "/mpi/ms0/motion_start/_action/feedback"
    watchdog = LostClientWatchdog(graph, 0.5, lambda keys: set(keys), lost.append, None, clock=lambda: now[0])
    watchdog.watch(b"g" * 16, topic)
    now[0] = 10.0 + 0.5 + DISCOVERY_GRACE - 0.01
    watchdog.check()
    assert not lost
    assert "came 1.49 s ago" in watchdog.describe_watched()[0]
    now[0] = 10.0 + 0.5 + DISCOVERY_GRACE
    watchdog.check()
    assert len(lost) == 1
    assert watchdog.watched == 0
    watchdog.watch(b"h" * 16, topic)  # seen late (discovery lagged): watched as usual from then on
    graph.subscribers[topic] = [b"A" * 16]
    now[0] = 30.0
    watchdog.check()
    assert len(lost) == 1
    assert watchdog.watched == 1


def test_a_goal_whose_clients_are_all_detached_is_not_watched():
    """`mpi-ros move --no-wait` leaves its goal running on purpose: its node's name ends in
    DETACHED, and a goal whose candidate clients are all such nodes is never stopped; with
    any other candidate among them it is watched as usual."""
    from mpi_ros.ros.watchdog import DETACHED, LostClientWatchdog

    graph, now, lost = FakeGraph(), [0.0], []
    topic = "/mpi/ms0/motion_start/_action/feedback"
    graph.subscribers[topic] = [b"D" * 16]
    graph.names[b"D" * 16] = f"mpi_ros_cli_123{DETACHED}"
    watchdog = LostClientWatchdog(graph, 0.5, lambda keys: set(keys), lost.append, None, clock=lambda: now[0])
    watchdog.watch(b"g" * 16, topic)
    assert watchdog.watched == 0
    graph.subscribers[topic] = [b"D" * 16, b"A" * 16]  # a ros2 tool beside it: which one sent it?
    watchdog.watch(b"h" * 16, topic)
    assert watchdog.watched == 1
    graph.subscribers[topic] = []
    watchdog.check()
    now[0] = 0.5
    watchdog.check()
    assert len(lost) == 1
    assert "68686868" in lost[0]
    graph.subscribers[topic] = []  # a detached client seen only after its goal: forgotten then
    watchdog.watch(b"i" * 16, topic)
    graph.subscribers[topic] = [b"D" * 16]
    watchdog.check()
    assert watchdog.watched == 0
    assert len(lost) == 1


def test_the_watchdogs_of_a_suite_share_one_timer_at_the_shortest_period():
    """One timer for every supervisor's watchdog (WatchdogTicker): a timer each woke every
    supervisor's executor ten times a second (bench/RESULTS.md). Each tick runs every check."""
    from mpi_ros.ros.watchdog import LostClientWatchdog, WatchdogTicker

    graph, lost = FakeGraph(), []
    timers = []
    graph.create_timer = lambda period, callback, callback_group=None, autostart=True: timers.append(
        FakeTimer(period, callback, not autostart)) or timers[-1]
    graph.destroy_timer = timers.remove
    ticker = WatchdogTicker(None)
    running = {b"a" * 16, b"b" * 16}
    slow = LostClientWatchdog(graph, 2.0, lambda keys: running & set(keys), lost.append, None,
                              clock=lambda: 10.0, ticker=ticker)
    fast = LostClientWatchdog(graph, 0.2, lambda keys: running & set(keys), lost.append, None,
                              clock=lambda: 10.0, ticker=ticker)
    assert [t.period for t in timers] == [0.05]  # one timer, at the shorter period: 0.2 / 4
    assert ticker.period == 0.05
    topics = {b"a" * 16: "/mpi/ms0/motion_start/_action/feedback", b"b" * 16: "/mpi/ms1/motion_start/_action/feedback"}
    for key, topic in topics.items():
        graph.subscribers[topic] = [key]
    slow.watch(b"a" * 16, topics[b"a" * 16])
    fast.watch(b"b" * 16, topics[b"b" * 16])
    running.clear()  # both goals ended: one tick has each watchdog forget its own
    timers[0].callback()
    assert slow.watched == fast.watched == 0
    assert not lost


def test_a_signalled_topic_is_looked_at_only_after_a_change_or_a_refresh():
    """A topic whose subscribers' changes are signalled (the feedback publisher's matched event)
    is looked at on the graph after a signal, on every tick until a look SETTLE after it (the
    event may precede the graph), and every REFRESH otherwise; the decisions are the same."""
    from mpi_ros.ros.watchdog import REFRESH, SETTLE, LostClientWatchdog

    graph, now, lost = FakeGraph(), [0.0], []
    looks = []
    query = graph.get_subscriptions_info_by_topic
    graph.get_subscriptions_info_by_topic = lambda topic: looks.append(now[0]) or query(topic)
    topic = "/mpi/ms0/motion_start/_action/feedback"
    graph.subscribers[topic] = [b"A" * 16]
    watchdog = LostClientWatchdog(graph, 1.0, lambda keys: set(keys), lost.append, None, clock=lambda: now[0])
    watchdog.signalled(topic)
    watchdog.watch(b"g" * 16, topic)
    assert looks == [0.0]
    now[0] = 0.1
    watchdog.check()
    assert looks == [0.0]  # nothing changed: the look at the goal's arrival holds
    watchdog.changed(topic)  # the client leaves: its event comes before the graph shows it gone
    watchdog.check()
    assert looks == [0.0, 0.1]
    graph.subscribers[topic] = []
    now[0] = 0.2
    watchdog.check()  # looked at again within SETTLE: now it is gone
    assert looks == [0.0, 0.1, 0.2]
    assert "gone for 0.00 s" in watchdog.describe_watched()[0]
    now[0] = 0.1 + SETTLE + 0.05
    watchdog.check()  # the first look past SETTLE
    now[0] = 0.1 + SETTLE + 0.1
    watchdog.check()
    assert looks == [0.0, 0.1, 0.2, 0.1 + SETTLE + 0.05]
    now[0] = 1.2
    watchdog.check()
    assert len(lost) == 1  # the STOP at T = 1 s after the look that saw it gone, as when looking every tick
    watchdog.watch(b"h" * 16, topic)  # a client was never seen: the same grace, with a look every REFRESH
    count = len(looks)
    now[0] = 1.2 + REFRESH - 0.01
    watchdog.check()
    assert len(looks) == count
    now[0] = 1.2 + REFRESH
    watchdog.check()
    assert len(looks) == count + 1


def test_the_ticker_ticks_only_while_a_goal_is_watched():
    """Every tick wakes the executor of the timer's node, which rebuilds its wait set: with
    no goal watched the timer is cancelled, and a goal watched starts it again and wakes the
    executor (its wait in progress did not count a cancelled timer)."""
    from mpi_ros.ros.watchdog import LostClientWatchdog

    graph, lost, running = FakeGraph(), [], {b"g" * 16}
    topic = "/mpi/ms0/motion_start/_action/feedback"
    graph.subscribers[topic] = [b"A" * 16]
    watchdog = LostClientWatchdog(graph, 1.0, lambda keys: running & set(keys), lost.append, None,
                                  clock=lambda: 0.0)
    ticker = watchdog.ticker
    assert not ticker.ticking
    watchdog.watch(b"g" * 16, topic)
    assert ticker.ticking
    assert graph.woken == 1
    watchdog.watch(b"h" * 16, topic)  # already ticking: no wake needed
    assert graph.woken == 1
    ticker._tick()
    assert ticker.ticking  # "g" still runs
    running.clear()
    ticker._tick()
    assert not ticker.ticking
    assert watchdog.watched == 0
    running.add(b"i" * 16)
    watchdog.watch(b"i" * 16, topic)
    assert ticker.ticking
    assert graph.woken == 2
    assert not lost
