"""The lost-client watchdog of one supervisor (optional; docs/cell.md, "Lost clients").

A client that holds a running goal and vanishes (process killed, link cut) can no longer
cancel it: the move would run to its end with nobody watching. With
``lost_client_timeout: T`` (seconds, per supervisor; 2 by default, 0 is off) the suite
STOPs that supervisor's motion once the goal's client has been gone from the graph for T
seconds, with a CLIENT_LOST event saying which goal and why. It is on by default because
Jazzy's ``ros2 action send_goal`` does not cancel its goal on Ctrl-C (an upstream bug,
fixed in later releases): without it an interrupted send_goal left the axis moving.

A client may leave a goal running on purpose (``mpi-ros move --no-wait``): a node whose
name ends in DETACHED says so, and a goal whose candidate clients are all such nodes is
not watched.

How "the goal's client" is found on the graph: rclpy does not tell an action server who
sent a goal, but every ROS action client (rclpy, rclcpp, the ros2 tool) subscribes to the
action's feedback topic (``<action>/_action/feedback``) when it is created, before it can
send a goal. So the goal's client is one of the feedback topic's subscribers when the goal
arrives; the watchdog keeps their endpoint GIDs and counts the client gone when none of
them is on the graph any more. That never stops a goal whose client may still be there: if
several clients of the same action were present when the goal came, it waits until all of
them have left (the graph cannot tell which one sent it). The graph shows an endpoint gone
as soon as its process closes it, and within the DDS participant lease duration when the
process is killed or its link cut (Fast DDS: 20 s by default; a profile sets it shorter):
the STOP comes T seconds after that. A client that comes back in time (link restored
before lease + T) is seen again and nothing is stopped. A goal whose client was never seen
on the graph at all (killed before the suite discovered its subscription, which a loaded
machine can take tens of milliseconds to do) counts as lost from its arrival once
DISCOVERY_GRACE more has passed: no client that could cancel it was ever there.

When it looks: a look at the graph costs tens to hundreds of microseconds (the whole graph
cache is walked), and the timer would look at every watched topic ten times a second. rclpy
offers no graph-change signal (ros2/rclpy#929), but the node's own publisher on a feedback
topic has a *matched* event (PublisherEventCallbacks), which fires whenever a subscriber of
the topic appears or leaves: a topic whose changes are so signalled (``signalled(topic)``,
then ``changed(topic)`` from the event) is looked at only after a signal, on every tick until
a look SETTLE after it (the event may come just before the graph shows the change), and at
least every REFRESH otherwise (a subscriber that never matches the publisher, such as one of
incompatible QoS, signals nothing). A topic without the signal is looked at on every tick.

The STOP is a command (commands.CLIENT_LOST) through the runner, like any other: it is on
<ns>/commands, in bags, and replays exactly.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from rclpy.callback_groups import CallbackGroup
from rclpy.guard_condition import GuardCondition
from rclpy.node import Node
from rclpy.timer import Timer

PERIOD = 0.1  # s between looks at the graph (shorter for a shorter timeout)
DETACHED = "_detached"  # the end of a client node's name whose goals are left running on purpose
DISCOVERY_GRACE = 1.0  # s a goal's client may take to appear on the graph after its goal
SETTLE = 0.5  # s after a signalled change during which a topic is looked at on every tick
REFRESH = 1.0  # s: the longest a signalled topic goes without a look while its goals are watched


@dataclass(slots=True)
class _Watched:
    key: bytes  # the goal id
    topic: str  # its action's feedback topic
    clients: frozenset  # GIDs of the topic's subscribers when the goal came (its client among them)
    since: float  # monotonic time the goal came
    gone_since: float | None = None  # monotonic time the last of them left the graph


@dataclass(frozen=True, slots=True)
class _Subscribers:
    gids: frozenset  # every subscriber of a feedback topic
    detached: bool  # there are some, and every one is a DETACHED client


def _subscribers(node: Node, topic: str) -> _Subscribers:
    infos = node.get_subscriptions_info_by_topic(topic)
    return _Subscribers(frozenset(bytes(info.endpoint_gid) for info in infos),
                        bool(infos) and all(info.node_name.endswith(DETACHED) for info in infos))


def describe(keys: Iterable[bytes]) -> str:
    """Goal ids as their first 8 hex digits (what logs and the event show)."""
    return ", ".join(key.hex()[:8] for key in keys)


class WatchdogTicker:
    """One timer for every lost-client watchdog of a suite (``add(node, period, check)``),
    ticking only while some watchdog watches a goal (``wake``). Each tick wakes the executor
    of the timer's node, and rclpy rebuilds that node's whole wait set at every wake: a timer
    per supervisor cost about 10 % of a core at 16 supervisors, and one on the controller node
    (hundreds of services at 32 axes) about 5 % ticking with nothing to watch
    (bench/RESULTS.md, "The suite under load"). So the timer goes on the first watchdog's node
    (a supervisor), is cancelled when no goal is watched, and a guard condition wakes its
    executor when it is started again (a wait in progress did not count a cancelled timer).
    It runs at the shortest period asked for: a look sooner than a watchdog needs changes
    nothing it decides."""

    def __init__(self, group: CallbackGroup):
        self._group = group
        self._node: Node | None = None
        self._checks: list[Callable[[], bool]] = []
        self._period: float | None = None
        self._timer: Timer | None = None
        self._wake: GuardCondition | None = None
        self._lock = threading.Lock()
        self._woken = False  # a watchdog began watching since the tick began

    def add(self, node: Node, period: float, check: Callable[[], bool]) -> None:
        """Call ``check()`` at least every ``period`` s while any check answers that it still
        watches a goal, from the first ``wake`` on. Before the executor spins."""
        self._node = self._node or node
        self._checks.append(check)
        if self._wake is None:
            self._wake = self._node.create_guard_condition(_nothing, callback_group=self._group)
        if self._period is None or period < self._period:
            ticking = self._timer is not None and not self._timer.is_canceled()
            if self._timer is not None:
                self._node.destroy_timer(self._timer)
            self._period = period
            self._timer = self._node.create_timer(period, self._tick, callback_group=self._group, autostart=ticking)

    @property
    def period(self) -> float | None:
        return self._period

    @property
    def ticking(self) -> bool:
        return self._timer is not None and not self._timer.is_canceled()

    def wake(self) -> None:
        """A watchdog began watching a goal: tick (from a period on) until none is watched."""
        assert self._timer is not None and self._wake is not None
        with self._lock:
            self._woken = True
            if self._timer.is_canceled():
                self._timer.reset()
                self._wake.trigger()

    def _tick(self) -> None:
        with self._lock:
            self._woken = False
        watching = [check() for check in self._checks]  # every check, each forgets its ended goals
        if not any(watching):
            with self._lock:
                if not self._woken:  # (else a goal came after its watchdog's check)
                    assert self._timer is not None
                    self._timer.cancel()


def _nothing() -> None:
    """The guard condition's callback: the wake itself is what it is for."""


class LostClientWatchdog:
    """``watch(goal id, feedback topic)`` when a goal is accepted; ``running(keys)`` answers
    which of them still run (the goal book); ``on_lost(detail)`` is called (from the timer,
    once per look that finds lost clients) to STOP."""

    def __init__(self, node: Node, timeout: float, running: Callable[[list[bytes]], set[bytes]],
                 on_lost: Callable[[str], None], group: CallbackGroup,
                 clock: Callable[[], float] = time.monotonic, ticker: WatchdogTicker | None = None):
        self.node = node
        self.timeout = timeout
        self._running = running
        self._on_lost = on_lost
        self._clock = clock
        self._goals: dict[bytes, _Watched] = {}
        self._seen: dict[str, tuple[float, _Subscribers]] = {}  # each topic's last look: when, what
        self._changed: dict[str, float] = {}  # signalled topics: the time of their last change
        self._lock = threading.Lock()
        # the suite's one timer (WatchdogTicker) where there is one, else a timer of its own
        self.ticker = ticker or WatchdogTicker(group)
        self.ticker.add(node, min(PERIOD, max(timeout / 4.0, 0.01)), self.check)

    def signalled(self, topic: str) -> None:
        """Every change of ``topic``'s subscribers will be signalled by ``changed(topic)``."""
        with self._lock:
            self._changed.setdefault(topic, -math.inf)

    def changed(self, topic: str) -> None:
        """A subscriber of ``topic`` appeared or left (its publisher's matched event)."""
        now = self._clock()
        with self._lock:
            self._changed[topic] = now

    def watch(self, key: bytes, topic: str) -> None:
        now = self._clock()
        subscribers = _subscribers(self.node, topic)
        with self._lock:
            self._seen[topic] = (now, subscribers)
        if subscribers.detached:
            return  # sent by a client that leaves it running on purpose (only such were there)
        watched = _Watched(key, topic, subscribers.gids, now)
        with self._lock:
            self._goals[key] = watched
        self.ticker.wake()

    def check(self) -> bool:
        """The timer: forget ended goals, time the ones whose client is gone, STOP at T.
        Whether it still watches a goal."""
        with self._lock:
            goals = list(self._goals.values())
        if not goals:
            return False
        still = self._running([w.key for w in goals])
        present: dict[str, _Subscribers] = {}
        now = self._clock()
        lost = []
        for watched in goals:
            if watched.key not in still:
                self._forget(watched.key)
                continue
            if watched.topic not in present:
                present[watched.topic] = self._look(watched.topic, now)
            if not watched.clients and present[watched.topic].detached:  # its client, seen late, is detached
                self._forget(watched.key)
                continue
            if self._gone(watched, present[watched.topic].gids, now):
                lost.append(watched)
                self._forget(watched.key)
        if lost:
            self._on_lost(f"the client of goal {describe(w.key for w in lost)} left the graph: STOP after "
                          f"{self.timeout:g} s without it (lost_client_timeout)")
        return self.watched > 0

    def _look(self, topic: str, now: float) -> _Subscribers:
        """The topic's subscribers: from the graph, or as last seen when nothing changed since."""
        with self._lock:
            seen, changed = self._seen.get(topic), self._changed.get(topic)
        if seen is not None and changed is not None and now - seen[0] < REFRESH and seen[0] > changed + SETTLE:
            return seen[1]
        subscribers = _subscribers(self.node, topic)
        with self._lock:
            self._seen[topic] = (now, subscribers)
        return subscribers

    def _gone(self, watched: _Watched, present: frozenset, now: float) -> bool:
        if not watched.clients:  # its client's subscription was not discovered yet when it came
            watched.clients = present
            # never seen at all: gone since the goal came, once discovery had its time
            return not present and now - watched.since >= self.timeout + DISCOVERY_GRACE
        if watched.clients & present:
            watched.gone_since = None
            return False
        if watched.gone_since is None:
            watched.gone_since = now
        return now - watched.gone_since >= self.timeout

    def _forget(self, key: bytes) -> None:
        with self._lock:
            self._goals.pop(key, None)

    def describe_watched(self) -> list[str]:
        """Each watched goal, its candidate clients and how long they have been gone (logs,
        a failing test's message)."""
        now = self._clock()
        with self._lock:
            goals = list(self._goals.values())
        return [f"goal {describe([w.key])}: {len(w.clients)} candidate client(s), came {now - w.since:.2f} s ago, "
                + ("present" if w.gone_since is None else f"gone for {now - w.gone_since:.2f} s") for w in goals]

    @property
    def watched(self) -> int:
        with self._lock:
            return len(self._goals)
