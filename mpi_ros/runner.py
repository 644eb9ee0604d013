"""Runs the controller on its own clock thread and serialises access to it.

Python cannot sleep 500 us reliably, so the thread wakes every few milliseconds and
steps, in one batch, the samples that wall time x scale says are due: it
wakes as the next periodic stop (a status, say) becomes due and steps to it, not past it
(see ``_clock_target``). A command first catches the controller up to the sample that is
due now and is then applied, so it takes effect within one sample of arriving. One lock
guards the controller; work that talks to ROS (publishing) runs after the lock is
released, in order: on the clock thread while it runs (a command wakes it), else by the
caller. Change hooks (``on_change``) run under the lock after every step batch and every
command, so whoever follows the controller (the goals of the nodes) is told without
a thread of its own waiting on it.

Status publications (``add_status``) read only the controller's snapshots at their own
sample, so they need not stop the stepping: the runner steps through several of their
samples in one stretch (Controller.step_snapshots, which answers the snapshots of each, equal
to stepping there) and calls each callback with its sample's snapshots, in sample order. How
long a status may wait for the stretch that carries it is ``publish_period`` (the setting
ros.publish_period; 0: each ends a stretch as it falls due). Periodic work that reads the live
controller (``add_periodic``: feedback, diagnostics) still ends a stretch at its stop, while
it has something to do (``wanted``: feedback only while goals are tracked).

Modes: ``time_scale`` 1 = real time, >1 faster, 0 = as fast as possible, None = manual
(nothing runs by itself; ``step`` advances, as tests and replay do).
"""

from __future__ import annotations

import heapq
import itertools
import logging
import os
import threading
import time
from collections import deque
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field

from mpi_ros.mpi.base.events import Event
from mpi_ros.mpi.control import Controller
from mpi_ros.mpi.snapshots import Snapshots

from .commands import Command, Reply, apply

_log = logging.getLogger("mpi_ros.runner")
FAST_BATCH = 2000  # samples per batch when running as fast as possible
_WAKE_MARGIN = 0.0002  # s the clock thread wakes after a periodic stop is due
CATCH_UP = 10  # wake periods the clock thread steps at most before it publishes (when behind)

Output = Callable[[], None]  # work to do outside the lock (e.g. publish)
Answer = tuple[Reply, int] | Exception  # a command's reply and sample, or what it raised


@dataclass(eq=False, slots=True)
class _Batch:
    """Commands applied together (submit_all), and what came of them."""

    commands: list[Command]
    then: Callable[[Controller, list[Answer]], None] | None
    answers: list[Answer] = field(default_factory=list)
    error: Exception | None = None  # what ``then`` raised
    done: threading.Event = field(default_factory=threading.Event)

    def result(self) -> list[Answer]:
        if self.error is not None:
            raise self.error
        return self.answers


@dataclass(frozen=True, slots=True)
class AtSample:
    """What a status callback reads: its sample and, if it asked for them, every
    supervisor's and axis' snapshot there (Controller.motion_snapshots at that sample)."""

    sample: int
    snapshots: Snapshots | None

    def taken(self) -> Snapshots:
        """The snapshots (for a callback added with ``snapshots``: always there)."""
        if self.snapshots is None:
            raise ValueError(f"the status at sample {self.sample} was collected without its snapshots")
        return self.snapshots


LiveCallback = Callable[[Controller], Output | None]
StatusCallback = Callable[[Controller, AtSample], Output | None]


@dataclass(eq=False, slots=True)
class _Periodic:
    every: int
    next_sample: int
    live: LiveCallback | None = None  # reads the controller now: its stop ends a stretch
    status: StatusCallback | None = None  # reads its sample's snapshots: may wait in a stretch
    snapshots: bool = False  # the status callback reads the snapshots (not only the sample)
    wanted: Callable[[], bool] | None = None  # (live) whether it has anything to do now; None: always
    idle: bool = False  # wanted answered False before the last stretch: its stops since then passed


@dataclass(order=True, slots=True)
class _Scheduled:
    """A command to apply when the controller reaches ``sample`` (schedule)."""

    sample: int
    seq: int
    command: Command = field(compare=False)
    tag: Hashable = field(compare=False)
    answered: Callable[[Answer], Output | None] | None = field(compare=False, default=None)


class ControllerRunner:
    def __init__(self, controller: Controller, time_scale: float | None = 1.0, wake_period: float = 0.01,
                 publish_period: float = 0.0, priority: int = 0, clock: Callable[[], float] = time.monotonic):
        if time_scale is not None and time_scale < 0:
            raise ValueError("time_scale must be >= 0 (0: as fast as possible) or None (manual)")
        if not publish_period >= 0:
            raise ValueError(f"publish_period must be >= 0 s, got {publish_period!r}")
        if not 0 <= priority <= 99:
            raise ValueError(f"priority must be a SCHED_FIFO priority (1 to 99) or 0 (normal scheduling), "
                             f"got {priority!r}")
        self.ctl = controller
        self.publish_period = publish_period
        self.priority = priority
        self.scheduling = "normal"  # what the clock thread runs under (/diagnostics), once it runs
        self.priority_refused = False  # it runs without the priority asked for
        self.time_scale = time_scale
        self.clock = clock  # wall time, s (monotonic): what the controller keeps to
        self.wake_period = wake_period
        self.lock = threading.RLock()
        self.changed = threading.Condition(self.lock)
        self._periodic: list[_Periodic] = []
        self._command_listeners: list[Callable[[int, Command, Reply], None]] = []
        self._change_hooks: list[Callable[[Controller], Output | None]] = []
        self._event_listeners: list[Callable[[Event], None]] = []
        self._outputs: deque[Output] = deque()
        self._mailbox: deque[_Batch] = deque()  # command batches for the clock thread (submit_all)
        self._flush_lock = threading.Lock()
        self._wake = threading.Event()  # the clock thread: flush now
        self._thread: threading.Thread | None = None
        self._running = threading.Event()
        self._anchor_wall = 0.0
        self._anchor_sample = 0
        self._scheduled: list[_Scheduled] = []  # a heap: commands waiting for their sample
        self._seq = itertools.count()
        controller.listeners.append(self._on_event)

    # -- configuration ---------------------------------------------------------------
    def add_periodic(self, rate_hz: float, callback: LiveCallback, wanted: Callable[[], bool] | None = None) -> None:
        """Call ``callback(controller)`` (under the lock) every 1/rate_hz of controller time,
        at exact samples; what it returns is run after the lock is released.

        ``wanted()`` (under the lock, before each stretch) tells whether the callback has
        anything to do: while it answers False, its stops pass without it, so they neither
        call it nor end a stretch (each stretch costs the controller a fixed amount; the
        feedback of a supervisor without goals cut the stepping 20 times a second for
        nothing). A stop is kept, or passed, as the stretch that reaches it begins; a command
        that makes it wanted is applied between stretches, so it counts from the next."""
        self._add(rate_hz, _Periodic(0, 0, live=callback, wanted=wanted))

    def add_status(self, rate_hz: float, callback: StatusCallback, snapshots: bool = True) -> None:
        """Call ``callback(controller, at)`` (under the lock) every 1/rate_hz of controller
        time, for exact samples: ``at`` holds the sample and (``snapshots``) the snapshots
        there. The controller may be past that sample by then (at most ``publish_period``):
        the callback reads ``at``, and of the controller only what no step changes (its
        rate, its axes' list). What it returns is run after the lock is released."""
        self._add(rate_hz, _Periodic(0, 0, status=callback, snapshots=snapshots))

    def _add(self, rate_hz: float, periodic: _Periodic) -> None:
        periodic.every = max(1, round(self.ctl.rate / rate_hz))
        with self.lock:
            periodic.next_sample = (self.ctl.sample // periodic.every + 1) * periodic.every
            self._periodic.append(periodic)

    def _hold(self) -> int:
        """Samples a status may wait past its sample: publish_period, rounded down to a
        whole number of the fastest status' periods (a wait that gathers no further status
        would only delay it)."""
        everies = [p.every for p in self._periodic if p.status is not None]
        if not everies:
            return 0
        fastest = min(everies)
        return int(self.publish_period * self.ctl.rate + 1e-9) // fastest * fastest

    def _active(self) -> list[_Periodic]:
        """Lock held: the periodic work that has anything to do now (``add_periodic``'s
        wanted), in the order it was added. One that had nothing to do until now resumes at
        its first stop after the current sample: the stops it passed had nothing to do."""
        active = []
        sample = self.ctl.sample
        for periodic in self._periodic:
            if periodic.wanted is not None:
                if not periodic.wanted():
                    periodic.idle = True
                    continue
                if periodic.idle:
                    periodic.idle = False
                    periodic.next_sample = (sample // periodic.every + 1) * periodic.every
            active.append(periodic)
        return active

    def _deadline(self, periodic: _Periodic, hold: int) -> int:
        """The sample by which ``periodic``'s next stop must have been stepped to."""
        return periodic.next_sample + (hold if periodic.status is not None else 0)

    def on_command(self, listener: Callable[[int, Command, Reply], None]) -> None:
        """``listener(sample, command, reply)`` for every command applied (under the lock)."""
        self._command_listeners.append(listener)

    def on_change(self, hook: Callable[[Controller], Output | None]) -> None:
        """Call ``hook(controller)`` (under the lock) after every step batch and every command
        (the moves that ended are in the controller's move log then; after the hooks the
        runner marks them read, Controller.ends_read); what it returns is run after the lock is
        released, in order with the other deferred work."""
        self._change_hooks.append(hook)

    def on_event(self, listener: Callable[[Event], None]) -> None:
        """``listener(event)`` for every notified event (outside the lock, in order)."""
        self._event_listeners.append(listener)

    # -- the clock thread ---------------------------------------------------------------
    def start(self) -> None:
        if self.time_scale is None or self._thread is not None:
            return
        with self.lock:
            self._anchor_wall = self.clock()
            self._anchor_sample = self.ctl.sample
        self._running.set()
        self._thread = threading.Thread(target=self._loop, name="mpi-controller-clock", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._running.clear()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None
        self._flush()

    @property
    def running(self) -> bool:
        return self._thread is not None and self._running.is_set()

    def _loop(self) -> None:
        self._take_priority()
        hold = self._hold()
        scale = max(self.time_scale or 1.0, 1e-9)
        # it waits for the first stop due (a status: its sample + hold), but catches up in pieces
        # of the fastest periodic's period: a piece of CATCH_UP waits would publish CATCH_UP x
        # (hold / period) statuses a topic at once, more than a slow reliable reader's queue holds
        fastest = min((p.every for p in self._periodic), default=10**9) / self.ctl.rate
        period = min(self.wake_period, max(fastest, hold / self.ctl.rate) / scale)
        piece = min(self.wake_period, fastest / scale)
        while self._running.is_set():
            try:
                # Commands step the controller to their sample too (submit catches up), so
                # under a flood of commands the lock may stay taken for long: then the clock
                # thread publishes what they collected instead of waiting its turn, so status
                # keeps flowing and the queue of publications cannot grow without bound.
                served: list[_Batch] = []
                if self.lock.acquire(timeout=period):
                    try:
                        if self.running:
                            served = self._take_mailbox()
                            self._apply(served)
                            self._advance_to(self._clock_target(self.due_sample(), piece))
                    finally:
                        self.lock.release()
                        for batch in served:
                            batch.done.set()
                self._flush()
            except Exception:  # noqa: BLE001 - the clock must keep running; the error is logged
                _log.exception("controller clock: a step or its output failed")
            if self.time_scale:
                self._wake.wait(self._until_next_stop(period))
                self._wake.clear()

    def _take_priority(self) -> None:
        """The clock thread (the caller) under SCHED_FIFO at ``priority``, if asked (0: not).
        On a loaded machine a normal thread gets its fair share of a core, which at 8 axes
        with status at 1 kHz is less than the stepping needs: the controller falls behind
        real time. Refused (no CAP_SYS_NICE, no rtprio limit), it says why and runs on at
        normal scheduling, as ros2_control's update thread does."""
        if not self.priority:
            return
        asked = f"SCHED_FIFO {self.priority}"
        if not self.time_scale:  # as fast as possible: it never sleeps, so it would hold its core
            self.scheduling, self.priority_refused = f"normal: {asked} not taken, as fast as possible", True
            _log.warning("controller clock: %s not taken: running as fast as possible, the clock thread never "
                         "sleeps", asked)
            return
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(self.priority))  # (0: this thread)
        except OSError as exc:
            self.scheduling, self.priority_refused = f"normal: {asked} refused ({exc.strerror})", True
            _log.warning("controller clock: %s refused (%s), so the clock thread runs at normal scheduling; "
                         "allow it with an rtprio limit (limits.conf) or CAP_SYS_NICE", asked, exc.strerror)
            return
        self.scheduling = asked

    def _clock_target(self, due: int, period: float) -> int:
        """Where the clock thread steps to next.

        The last periodic stop that is due, if it is less than a wake period behind ``due``,
        else ``due``: every stretch stepped costs the controller a fixed amount whatever its
        length (bench/RESULTS.md: about 0.25 ms at 32 axes), and the samples past the last stop are read by
        nobody until the next one, so stepping them now would double the stretches.
        Commands still catch up to ``due`` first (submit): they take effect at the sample
        due, and nothing waits more than a wake period.

        Behind by more than CATCH_UP wake periods (an overloaded machine), it catches up in
        pieces of that size and publishes between them: caught up in one batch, the topics
        would fall silent, and the work held for after it grow, for as long as it lasts."""
        active = self._active()
        if not active or not self.time_scale:
            return due
        wake = period * self.time_scale * self.ctl.rate  # samples per wake
        limit = min(due, self.ctl.sample + max(1, int(CATCH_UP * wake)))
        last = max(p.next_sample + p.every * ((limit - p.next_sample) // p.every) for p in active)
        return last if limit - last < wake else limit

    def _until_next_stop(self, period: float) -> float:
        """Seconds until the next periodic stop is due (at most ``period``): the clock thread
        wakes as it becomes due, steps to it and publishes at once."""
        scale = self.time_scale
        # (unlocked: as idle as the last stretch found it; what a command made wanted since, the
        # command's wake brings in)
        active = [p for p in self._periodic if not p.idle]
        if not active or self._anchor_wall is None or not scale:  # manual or as fast as possible
            return period
        hold = self._hold()
        ahead = min(self._deadline(p, hold) for p in active) - self._anchor_sample
        due_at = self._anchor_wall + ahead / (scale * self.ctl.rate)
        # a little late rather than early: early, the sample due would still be the one before
        return min(period, max(0.0, due_at - self.clock() + _WAKE_MARGIN))

    def backlog(self) -> int:
        """Outputs (publications) collected and not yet published."""
        return len(self._outputs)

    def due_sample(self) -> int:
        """The sample the controller should be at now."""
        if self.time_scale is None:
            return self.ctl.sample
        if self.time_scale == 0:
            return self.ctl.sample + FAST_BATCH
        elapsed = self.clock() - self._anchor_wall
        return max(self.ctl.sample, self._anchor_sample + int(elapsed * self.time_scale * self.ctl.rate))

    @property
    def started(self) -> tuple[float, int] | None:
        """(wall time, sample) when the clock thread started keeping the controller to the wall
        clock; None before, and in manual mode."""
        return (self._anchor_wall, self._anchor_sample) if self._thread is not None else None

    def samples_behind(self) -> int:
        """How many samples the controller is behind its clock: 0 unless the clock thread
        keeps it to the wall clock (manual, as fast as possible, not started)."""
        if not self.time_scale or not self.running:
            return 0
        return self.due_sample() - self.ctl.sample

    def _catch_up(self) -> None:
        if self.running:
            self._advance_to(self.due_sample())

    # -- stepping ---------------------------------------------------------------------
    def step(self, samples: int) -> None:
        """Advance ``samples`` samples now (manual mode, replay, tests)."""
        with self.lock:
            self._advance_to(self.ctl.sample + samples)
        self._flush()

    def _advance_to(self, target: int) -> None:
        ctl = self.ctl
        if ctl.sample >= target:
            return
        hold = self._hold()
        while ctl.sample < target:
            self._apply_scheduled()
            active = self._active()
            self._skip_passed(active)
            end = min([target] + [self._deadline(p, hold) for p in active]
                      + [entry.sample for entry in self._scheduled[:1]])
            stops = self._stops(end, active)
            wanted = [sample for sample, due in stops.items() if any(p.snapshots for p in due)]
            taken = ctl.step_snapshots(end - ctl.sample, wanted) if end > ctl.sample else {}
            for sample, due in stops.items():
                self._call(due, sample, taken.get(sample))
        self._apply_scheduled()
        self._changed()

    def _stops(self, end: int, active: list[_Periodic]) -> dict[int, list[_Periodic]]:
        """The stops of the ``active`` periodic work up to ``end``, in sample order, each with
        its due callbacks in the order they were added; every one's next stop moved past
        ``end``."""
        stops: dict[int, list[_Periodic]] = {}
        for periodic in active:
            while periodic.next_sample <= end:
                stops.setdefault(periodic.next_sample, []).append(periodic)
                periodic.next_sample += periodic.every
        order = {id(p): i for i, p in enumerate(self._periodic)}
        return {sample: sorted(stops[sample], key=lambda p: order[id(p)]) for sample in sorted(stops)}

    def _skip_passed(self, active: list[_Periodic]) -> None:
        """Periodic stops the controller has passed without the runner (stepped directly):
        each such callback of the ``active`` work runs once, now, and its next stop is the
        first one ahead."""
        ctl = self.ctl
        passed = [p for p in active if p.next_sample <= ctl.sample]
        if not passed:
            return
        for periodic in passed:
            periodic.next_sample += periodic.every * ((ctl.sample - periodic.next_sample) // periodic.every + 1)
        wanted = any(p.snapshots for p in passed)
        self._call(passed, ctl.sample, ctl.motion_snapshots() if wanted else None)

    def _call(self, due: list[_Periodic], sample: int, snapshots: Snapshots | None) -> None:
        """Lock held: the callbacks due at ``sample``; their outputs queued."""
        at = AtSample(sample, snapshots)
        for periodic in due:
            if periodic.status is not None:
                output = periodic.status(self.ctl, at)
            else:
                assert periodic.live is not None and sample == self.ctl.sample  # live stops end stretches
                output = periodic.live(self.ctl)
            if output is not None:
                self._outputs.append(output)

    # -- commands at a given sample ----------------------------------------------------------
    def schedule(self, sample: int, command: Command, tag: Hashable = None,
                 answered: Callable[[Answer], Output | None] | None = None) -> None:
        """Apply ``command`` when the controller is at ``sample`` (it takes effect from that
        sample's time on and is recorded with the next, as every command); one already due is
        applied as the controller next steps. ``answered(answer)`` is called under the lock
        with its reply and sample; what it returns runs after the lock. Stepping stops at the
        sample however the samples are batched, so a scheduled command is never late, and a
        recording of it replays exactly."""
        with self.lock:
            heapq.heappush(self._scheduled, _Scheduled(sample, next(self._seq), command, tag, answered))
        self._wake.set()

    def unschedule(self, drop: Callable[[int, Hashable], bool]) -> int:
        """Drop the scheduled commands for which ``drop(sample, tag)`` holds; how many."""
        with self.lock:
            kept = [entry for entry in self._scheduled if not drop(entry.sample, entry.tag)]
            dropped = len(self._scheduled) - len(kept)
            heapq.heapify(kept)
            self._scheduled = kept
        return dropped

    def scheduled(self) -> int:
        """Commands waiting for their sample."""
        return len(self._scheduled)

    def _apply_scheduled(self) -> None:
        """Lock held: the scheduled commands due at the controller's sample, in order."""
        while self._scheduled and self._scheduled[0].sample <= self.ctl.sample:
            entry = heapq.heappop(self._scheduled)
            answer = self._apply_one(entry.command, self.ctl.effective_sample)
            if entry.answered is not None:
                output = entry.answered(answer)
                if output is not None:
                    self._outputs.append(output)

    def _changed(self) -> None:
        """After a step batch or a command (under the lock): hooks, waiters."""
        read = True
        for hook in self._change_hooks:
            try:
                output = hook(self.ctl)
            except Exception:  # noqa: BLE001 - the step or command is done; a hook must not undo
                # that for its caller (an E_STOP service, the clock thread): log it and go on
                _log.exception("controller runner: a change hook failed")
                read = False  # (it may not have read the ends it follows: they stay)
                continue
            if output is not None:
                self._outputs.append(output)
        if read:
            self.ctl.ends_read()  # the goals' reviews are hooks: they have read every end so far
        self.changed.notify_all()

    # -- access -------------------------------------------------------------------------
    def submit(self, command: Command) -> tuple[Reply, int]:
        """Apply a command now, in the caller's thread (a service: STOP, E_STOP, a setting),
        at the sample due; returns the reply and the sample it took effect at."""
        batch = _Batch([command], None)
        self._serve([batch])
        answer = batch.result()[0]
        if isinstance(answer, Exception):
            raise answer
        return answer

    def submit_all(self, commands: list[Command],
                   then: Callable[[Controller, list[Answer]], None] | None = None) -> list[Answer]:
        """Apply commands in order, at one sample, and return each one's reply and sample, or
        the exception its command raised (an internal error: the others are still applied).
        ``then(controller, answers)`` runs under the same hold of the lock, before the change
        hooks (the goals of the commands are filed there, so the review that follows sees them).

        While the clock thread runs, the batch goes to it (a mailbox) and this waits for its
        answers: the clock thread takes every batch waiting, from every supervisor, catches the
        controller up once and applies them all. Each caller catching up for itself would
        step the controller in fragments of a sample or two, each costing what a whole
        stretch costs, and under a stream of goals the callers kept the lock from the clock
        thread (measured: 400 ms waits for the lock, 58 ms holds, the clock falling behind)."""
        batch = _Batch(commands, then)
        if not self.running or threading.current_thread() is self._thread:
            self._serve([batch])
            return batch.result()
        self._mailbox.append(batch)
        self._wake.set()
        while not batch.done.wait(self.wake_period * 10):
            if not self.running:  # stopped meanwhile: whatever it did not take is served here
                self._serve(self._take_mailbox())
        return batch.result()

    def _serve(self, batches: list[_Batch]) -> None:
        """Apply the batches now, in the caller's thread."""
        with self.lock:
            self._apply(batches)
        for batch in batches:
            batch.done.set()
        self._deferred()

    def _take_mailbox(self) -> list[_Batch]:
        batches = []
        while self._mailbox:
            try:
                batches.append(self._mailbox.popleft())
            except IndexError:
                break
        return batches

    def _apply(self, batches: list[_Batch]) -> None:
        """Lock held: catch up, apply every batch at the sample due, then the change hooks."""
        if not batches:
            return
        self._catch_up()
        sample = self.ctl.effective_sample
        for batch in batches:
            batch.answers = [self._apply_one(command, sample) for command in batch.commands]
            if batch.then is not None:
                try:
                    batch.then(self.ctl, batch.answers)
                except Exception as exc:  # noqa: BLE001 - not swallowed: raised to the batch's caller
                    batch.error = exc
        self._changed()

    def _apply_one(self, command: Command, sample: int) -> Answer:
        try:
            reply = apply(self.ctl, command)
        except Exception as exc:  # noqa: BLE001 - not swallowed: handed to the caller with the others' replies
            return exc
        for listener in self._command_listeners:
            listener(sample, command, reply)
        return reply, sample

    def update(self, change: Callable[[Controller], Output | None]) -> None:
        """Run ``change(controller)`` under the lock (bookkeeping around the controller, not
        motion: commands go through ``submit``); what it returns is run after the lock is
        released, in order with the other deferred work."""
        with self.lock:
            output = change(self.ctl)
            if output is not None:
                self._outputs.append(output)
        self._deferred()

    def read(self, reader: Callable[[Controller], object]):
        """Run ``reader(controller)`` under the lock (queries; must not change anything)."""
        with self.lock:
            return reader(self.ctl)

    def wait(self, predicate: Callable[[Controller], bool], timeout: float) -> bool:
        """Wait (up to ``timeout`` s) until ``predicate(controller)`` holds."""
        with self.changed:
            return self.changed.wait_for(lambda: predicate(self.ctl), timeout)

    # -- events and deferred work ----------------------------------------------------------
    def _on_event(self, event: Event) -> None:
        if self._event_listeners:
            def notify(e: Event = event) -> None:
                for listener in self._event_listeners:
                    listener(e)

            self._outputs.append(notify)

    def _deferred(self) -> None:
        """After a command or an update, the lock released: its deferred work runs now, on
        the clock thread if it runs. A caller (an E_STOP service) thus answers at once, and
        never first publishes what others left (feedback of hundreds of goals, say)."""
        if self.running:
            self._wake.set()
        else:
            self._flush()

    def _flush(self) -> None:
        with self._flush_lock:
            while self._outputs:
                try:
                    output = self._outputs.popleft()
                except IndexError:
                    break
                output()
