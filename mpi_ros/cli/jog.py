"""The console's jog: the arrow keys move ONE selected axis of a supervisor, at a set speed.

How one axis of a multi-axis supervisor is jogged alone (docs/console.md, "Jog"): a VELOCITY
move with one trajectory per axis (MPI 000, MPIMotionVelocity; one per axis is allowed for a
VELOCITY move, docs/decisions.md), the selected axis at +-speed and every other axis at 0. The
jog starts only from IDLE: from MOVING or STOPPING another move owns the axes, and a start from
STOPPED would drop the operator's paused move. The other arrow, or another axis, modifies the
jog (mpiMotionModify). When the key stops repeating, the jog is STOPped; once STOPPED, RESET
drops the jog's remaining profile, so RESUME cannot restart an axis with no key held.

The ROS calls run in one worker thread, in the order the keys asked for them: a key never waits
for the network, and a STOP is never overtaken by the start it ends.
"""

from __future__ import annotations

import collections
import queue
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

# A terminal reports no key release, only repeats: about every 0.03-0.1 s, but the first one
# comes only after the keyboard's repeat delay (0.25 to 1 s; 0.5-0.66 s by default on X11 and macOS).
JOG_FIRST = 0.8  # s after a press without a first repeat before the jog stops (a tap jogs this long)
JOG_RELEASE = 0.35  # s without a further repeat before the jog stops


@dataclass(frozen=True, slots=True)
class JogTarget:
    """What a held arrow asks for: supervisor ``supervisor``'s axis at index ``axis`` (in the
    supervisor's axis list), direction ``sign``; ``number`` is the axis's own number, for the log."""

    supervisor: int
    axis: int
    number: int
    sign: int

    def __post_init__(self) -> None:
        if self.sign not in (-1, 1) or self.axis < 0:
            raise ValueError(f"a jog needs sign -1 or 1 and an axis index >= 0, not {self.sign}, {self.axis}")

    def name(self, speed: float) -> str:
        return f"ms{self.supervisor} axis{self.number} {'+' if self.sign > 0 else '-'}{speed:g} counts/s"


def jog_goal(axes: int, target: JogTarget, speed: float, acceleration: float) -> dict[str, Any]:
    """The VELOCITY goal that moves the target axis alone: one trajectory per axis, the others at 0."""
    velocities = [0.0] * axes
    velocities[target.axis] = target.sign * speed
    # deceleration is ignored by VELOCITY (MPI 000, MPIMotionVelocity); given so the goal reads the same as a move's
    return {"type": "VELOCITY", "trajectory": [{"velocity": v, "acceleration": acceleration,
                                                "deceleration": acceleration} for v in velocities]}


def busy(state_name: str, move_id: int) -> str | None:
    """Why a supervisor in ``state_name`` cannot start a jog, or None when it can (IDLE)."""
    if state_name == "IDLE":
        return None
    if state_name == "STOPPED":
        return (f"STOPPED with move {move_id} pending: RESUME (u) continues it, RESET (r) drops it; "
                f"a jog would drop it silently")
    if state_name in ("ERROR", "STOPPING_ERROR"):
        return f"in {state_name}: RESET (r) first"
    return f"{state_name} (move {move_id}): STOP it (space) or wait for IDLE"


class Jogger:
    """The jog of the console's clients: ``press`` on each arrow key (or its repeat), ``expire``
    regularly, ``close`` at the end. What it did is in ``said`` (drained by the screen)."""

    def __init__(self, clients: Mapping[int, Any], speed: float, acceleration: float, timeout: float):
        self.clients = clients
        self.speed, self.acceleration, self.timeout = speed, acceleration, timeout
        self.said: collections.deque[str] = collections.deque()  # thread-safe appends and pops
        self.active: JogTarget | None = None  # the jog the keys hold
        self._until = 0.0  # when the active jog stops unless its key repeats
        self._lock = threading.Lock()
        self._moves: dict[int, int] = {}  # supervisor -> move id of its running jog (worker thread only)
        self._work: queue.Queue[Callable[[], None] | None] = queue.Queue()
        self._thread = threading.Thread(target=self._run, name="console-jog", daemon=True)
        self._thread.start()

    # -- the keys' side (the console's thread) ---------------------------------------------------
    def press(self, target: JogTarget, axes: int, now: float) -> None:
        """An arrow for ``target`` (a supervisor of ``axes`` axes) at monotonic time ``now``."""
        with self._lock:
            previous, self.active = self.active, target
            self._until = now + (JOG_RELEASE if previous == target else JOG_FIRST)
        if previous == target:
            return  # a repeat of the key: the jog goes on
        goal = jog_goal(axes, target, self.speed, self.acceleration)
        if previous is not None and previous.supervisor == target.supervisor:
            self._work.put(lambda: self._modify(target, goal))  # the other arrow or another axis
            return
        if previous is not None:  # another supervisor's jog: it stops first
            ended = previous
            self._work.put(lambda: self._stop(ended))
        self._work.put(lambda: self._start(target, goal))

    def expire(self, now: float) -> None:
        """Stop the jog whose key has not repeated in time (JOG_FIRST, then JOG_RELEASE s)."""
        with self._lock:
            if self.active is None or now <= self._until:
                return
            ended, self.active = self.active, None
        self._work.put(lambda: self._stop(ended))

    def close(self) -> None:
        """Stop a running jog and end the worker, waiting for both (the console is exiting)."""
        with self._lock:
            ended, self.active = self.active, None
        if ended is not None:
            self._work.put(lambda: self._stop(ended))
        self._work.put(None)
        # STOP, the wait for STOPPED and RESET: three answers at most
        self._thread.join(3 * self.timeout)

    # -- the worker's side -----------------------------------------------------------------------
    def _run(self) -> None:
        from mpi_ros.errors import NoResponse

        while (job := self._work.get()) is not None:
            try:
                job()
            except NoResponse as exc:  # the suite did not answer: say so, take the next key
                self.said.append(f"jog: {exc}")

    def _start(self, target: JogTarget, goal: dict[str, Any]) -> None:
        client = self.clients[target.supervisor]
        status = client.status(self.timeout)
        refusal = busy(status.state_name, status.move_id)
        if refusal is not None:
            self.said.append(f"jog refused: ms{target.supervisor} is {refusal}")
            return
        self._follow(target, client.start(goal), "jog")

    def _modify(self, target: JogTarget, goal: dict[str, Any]) -> None:
        if target.supervisor not in self._moves:
            return  # its start was refused: nothing to modify
        self._follow(target, self.clients[target.supervisor].modify(goal), "jog now")

    def _follow(self, target: JogTarget, goal: Any, verb: str) -> None:
        """Wait for the goal to run (its first feedback) or end; say which, keep the move id."""
        if goal.wait_started(self.timeout):
            self._moves[target.supervisor] = goal.feedback.move_id
            self.said.append(f"{verb} {target.name(self.speed)}")
            return
        result = goal.wait(self.timeout, raise_on_error=False)
        if result.ok:  # already at velocity: running
            self._moves[target.supervisor] = result.move_id
            self.said.append(f"{verb} {target.name(self.speed)}")
        else:
            self._moves.pop(target.supervisor, None)
            detail = f": {result.detail}" if result.detail else ""
            self.said.append(f"jog refused: {result.message}, state {result.state_name}{detail}")

    def _stop(self, target: JogTarget) -> None:
        """STOP the jog; once STOPPED on the jog's own move, RESET drops what is left of it."""
        move = self._moves.pop(target.supervisor, None)
        if move is None:
            return  # never ran (refused)
        client = self.clients[target.supervisor]
        reply = client.action("STOP", raise_on_error=False)
        if not reply.ok and reply.state_name != "STOPPED":  # e.g. an E_STOP came first: leave it to the operator
            self.said.append(f"jog ms{target.supervisor}: STOP {reply.message}, state {reply.state_name}")
            return
        status = client.wait_for(lambda s: s.sample >= reply.sample and s.state_name != "STOPPING",
                                 self.timeout, "the jog at rest")
        if status.state_name == "STOPPED" and status.move_id == move:
            reset = client.action("RESET", raise_on_error=False)
            status = client.status(self.timeout, newer_than=reset.sample - 1)
        positions = ", ".join(f"axis{a.number} {a.command_position:.1f}" for a in status.axes)
        self.said.append(f"jog ms{target.supervisor} ended: {status.state_name}, {positions}")
