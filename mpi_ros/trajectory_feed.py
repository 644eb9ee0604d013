"""Feeding JointTrajectory commands to a supervisor (ROS-free; the node hands them over).

A trajectory is read and checked as a whole when it arrives (trajectory.py): a refused one
schedules nothing, so it moves nothing. An accepted one is cut into chunks, each a
``joint_trajectory`` command scheduled at the controller sample it is due
(trajectory.feed_samples): the first at the trajectory's start (header.stamp, or now),
the others as the path runs, one chunk ahead. Every chunk goes through the runner's command
path like a goal's command, so /mpi/commands records it with its sample and a replay applies
it at the same sample (docs/trajectories.md).

As joint_trajectory_controller does, a new trajectory replaces the old one from its start
time: chunks of earlier trajectories scheduled at or after it are dropped, and its first
chunk modifies the PT or PVT path in progress. An empty trajectory STOPs now.
"""

from __future__ import annotations

import itertools
import threading
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from mpi_ros.joints import AxisJoint
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome, Refused

from . import trajectory
from .commands import Command, Operation
from .runner import Answer, ControllerRunner, Output

Log = Callable[[str], None]


@dataclass(slots=True)
class FeedCounts:
    """What a supervisor's /diagnostics shows of its trajectories."""

    received: int = 0
    accepted: int = 0
    refused: Counter[str] = field(default_factory=Counter)  # per MPI message name
    interrupted: int = 0  # accepted, then a later chunk refused (a STOP or E_STOP meanwhile)
    last_refusal: str = ""

    @property
    def refused_total(self) -> int:
        return sum(self.refused.values())


class TrajectoryFeed:
    """The JointTrajectory commands of supervisor ``number`` (all axes' joints: ``joints``)."""

    def __init__(self, runner: ControllerRunner, number: int, joints: Sequence[AxisJoint], epoch_ns: int,
                 warn: Log, chunk_points: int = trajectory.CHUNK_POINTS):
        self.runner = runner
        self.number = number
        self.joints = list(joints)
        self.epoch_ns = epoch_ns
        self.warn = warn
        self.chunk_points = chunk_points
        self.counts = FeedCounts()
        self._ids = itertools.count(1)
        self._lock = threading.Lock()  # the counts (read by /diagnostics under the runner lock)

    def receive(self, joint_names: Sequence[str], points: Sequence[tuple[Sequence[float], Sequence[float], float]],
                stamp_ns: int) -> Outcome | None:
        """A trajectory as it arrived: refused (its outcome, logged and counted), or scheduled
        (None). It counts as received once it is one or the other."""
        try:
            return self._receive(joint_names, points, stamp_ns)
        finally:
            with self._lock:
                self.counts.received += 1

    def _receive(self, joint_names: Sequence[str],
                 points: Sequence[tuple[Sequence[float], Sequence[float], float]], stamp_ns: int) -> Outcome | None:
        now, listed, rate = self.runner.read(self._now)
        joints = [self.joints[n] for n in listed]
        try:
            traj = trajectory.read(joint_names, points, joints)
            verdict = traj.validate()
        except Refused as exc:
            traj, verdict = None, exc.outcome
        if not verdict.ok or traj is None:
            self._refused(verdict, "refused")
            return verdict
        serial = next(self._ids)
        if traj.empty:  # JTC: an empty trajectory stops; here the supervisor STOPs now
            self.runner.unschedule(lambda _sample, tag: _is_of(tag, self.number))
            stop = Command(Operation.JOINT_TRAJECTORY, self.number, request={})
            self.runner.schedule(now, stop, (self.number, serial), self._stopped)
            return None
        start = trajectory.start_sample(stamp_ns, self.epoch_ns, rate, now)
        # replaces, from its start on, whatever earlier trajectories were still to feed
        self.runner.unschedule(lambda sample, tag: _is_of(tag, self.number) and sample >= start)
        chunks = traj.chunks(self.chunk_points)
        for k, (chunk, sample) in enumerate(zip(chunks, trajectory.feed_samples(start, chunks, rate), strict=True)):
            self.runner.schedule(sample, Command(Operation.JOINT_TRAJECTORY, self.number, request=chunk.to_request()),
                                 (self.number, serial), self._answered(serial, k))
        return None

    def _now(self, ctl) -> tuple[int, list[int], float]:
        """The controller's sample, this supervisor's axes and the sample rate."""
        ms = ctl.supervisor(self.number)
        return ctl.sample, [] if ms is None else ms.axis_list, ctl.rate

    def _answered(self, serial: int, index: int) -> Callable[[Answer], Output | None]:
        """A chunk's answer (runner lock held): the first one accepts or refuses the
        trajectory; a later one refused interrupts it (its other chunks are dropped)."""

        def answered(answer: Answer) -> Output | None:
            if isinstance(answer, Exception):
                outcome = Outcome(Message.MPIMessagePARAM_INVALID, f"internal error: {answer!r}")
            else:
                outcome = answer[0].outcome
            if outcome.ok:
                if index == 0:
                    with self._lock:
                        self.counts.accepted += 1
                return None
            self.runner.unschedule(lambda _sample, tag: tag == (self.number, serial))
            return lambda: self._refused(outcome, "refused" if index == 0 else f"interrupted at chunk {index}",
                                         interrupted=index > 0)

        return answered

    def _stopped(self, answer: Answer) -> Output | None:
        """An empty trajectory's STOP: nothing to stop (IDLE, STOPPED) is no refusal."""
        if isinstance(answer, Exception) or answer[0].message not in _NOTHING_TO_STOP:
            return self._answered(0, 0)(answer)
        return None

    def _refused(self, outcome: Outcome, what: str, interrupted: bool = False) -> None:
        line = f"joint_trajectory {what}: {outcome.message.name}: {outcome.detail}"
        with self._lock:
            if interrupted:
                self.counts.interrupted += 1
            else:
                self.counts.refused[outcome.message.name] += 1
            self.counts.last_refusal = line
        self.warn(line)

    def snapshot(self) -> FeedCounts:
        with self._lock:
            return FeedCounts(self.counts.received, self.counts.accepted, Counter(self.counts.refused),
                              self.counts.interrupted, self.counts.last_refusal)


_NOTHING_TO_STOP = (Message.MPIMessageOK, Message.MPIMotionMessageIDLE, Message.MPIMotionMessageSTOPPED)


def _is_of(tag: object, number: int) -> bool:
    return isinstance(tag, tuple) and len(tag) == 2 and tag[0] == number
