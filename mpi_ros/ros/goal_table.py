"""The goals one action server keeps, their states and their status array (no rcl_action).

The action protocol's server side keeps every goal it accepted, with its state, until its
result has been kept for ``result_timeout`` after it ended; it publishes the status of every
goal kept whenever one changes, and answers a cancel request by the policy of
action_msgs/srv/CancelGoal. rcl_action does this with an array of C goal handles that it
scans from end to end for every goal accepted (is the id in use?), every goal ended (when
does the next result expire?) and every status published. At 800 goals a second with
results kept 10 s, a server keeps about 1,000-2,000 goals: a goal's acceptance cost 30 us at
1,000 kept and 90 us at 8,000, its end 19 and 145 us, a status array 46 and 565 us, all of
it holding the interpreter (bench/RESULTS.md, "The goals' bookkeeping"). Here each of those
is a dict lookup or a deque append, and the status array is joined from bytes kept per goal.

The states and their changes are the protocol's (action_msgs/msg/GoalStatus; the same
transitions rcl_action allows): ACCEPTED -> EXECUTING; ACCEPTED or EXECUTING -> CANCELING;
EXECUTING or CANCELING -> SUCCEEDED or ABORTED; CANCELING -> CANCELED. ``end`` takes an
ACCEPTED goal through EXECUTING, and turns CANCELED into ABORTED for a goal whose cancel was
not accepted, as GoalServer.finish did with rcl_action.

Not thread safe: GoalServer uses it under its lock.
"""

from __future__ import annotations

import struct
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from action_msgs.msg import GoalStatus
from action_msgs.srv import CancelGoal

ACCEPTED = GoalStatus.STATUS_ACCEPTED
EXECUTING = GoalStatus.STATUS_EXECUTING
CANCELING = GoalStatus.STATUS_CANCELING
SUCCEEDED = GoalStatus.STATUS_SUCCEEDED
CANCELED = GoalStatus.STATUS_CANCELED
ABORTED = GoalStatus.STATUS_ABORTED
UNKNOWN = GoalStatus.STATUS_UNKNOWN
TERMINAL = frozenset((SUCCEEDED, CANCELED, ABORTED))
CANCELABLE = frozenset((ACCEPTED, EXECUTING))

ERROR_NONE = CancelGoal.Response.ERROR_NONE
ERROR_UNKNOWN_GOAL_ID = CancelGoal.Response.ERROR_UNKNOWN_GOAL_ID
ERROR_GOAL_TERMINATED = CancelGoal.Response.ERROR_GOAL_TERMINATED

_NS = 1_000_000_000
_ZERO_ID = bytes(16)
HEADER = b"\x00\x01\x00\x00"  # CDR, little endian (as wire.py)
# A GoalStatus in a GoalStatusArray after the first: the uuid's 16 bytes start 1 past a
# multiple of 4 (the count is 4 bytes, the first element 25), so 3 bytes pad the stamp's sec.
_RECORD = struct.Struct("<16s3xiIb")
_COUNT = struct.Struct("<I")


@dataclass(eq=False, slots=True)
class KeptGoal:
    key: bytes  # the goal id's 16 bytes
    stamp_ns: int  # when it was accepted (the node's clock)
    status: int = ACCEPTED
    response: Any = None  # the GetResult response, once the goal has ended
    waiting: list = field(default_factory=list)  # headers of result requests to answer when it ends


class GoalTable:
    """The goals of one action server, in the order they were accepted."""

    def __init__(self, result_timeout: float, clock: Callable[[], float] = time.monotonic):
        self._goals: dict[bytes, KeptGoal] = {}
        self._records: dict[bytes, bytes] = {}  # each goal's GoalStatus, packed (same order)
        self._expiry: deque[tuple[float, bytes]] = deque()  # (when its result expires, goal), in end order
        self._timeout = result_timeout
        self._clock = clock

    def __len__(self) -> int:
        return len(self._goals)

    def __contains__(self, key: bytes) -> bool:
        return key in self._goals

    def get(self, key: bytes) -> KeptGoal | None:
        return self._goals.get(key)

    def status(self, key: bytes) -> int:
        goal = self._goals.get(key)
        return goal.status if goal is not None else UNKNOWN

    def accept(self, key: bytes, stamp_ns: int) -> KeptGoal:
        if key in self._goals:
            raise ValueError("goal id already in use")
        goal = self._goals[key] = KeptGoal(key, stamp_ns)
        self._record(goal)
        return goal

    def execute(self, key: bytes) -> bool:
        """ACCEPTED -> EXECUTING; False (nothing changed) from any other state."""
        return self._change(key, (ACCEPTED,), EXECUTING)

    def cancel(self, key: bytes) -> bool:
        """ACCEPTED or EXECUTING -> CANCELING; False from any other state."""
        return self._change(key, CANCELABLE, CANCELING)

    def end(self, key: bytes, status: int) -> KeptGoal | None:
        """The goal's terminal state (SUCCEEDED, CANCELED or ABORTED); its result expires
        ``result_timeout`` from now. None for a goal not kept or already ended."""
        if status not in TERMINAL:
            raise ValueError(f"not a terminal status: {status}")
        goal = self._goals.get(key)
        if goal is None or goal.status in TERMINAL:
            return None
        if status == CANCELED and goal.status != CANCELING:
            status = ABORTED  # only a goal whose cancel was accepted ends CANCELED
        goal.status = status
        self._record(goal)
        self._expiry.append((self._clock() + self._timeout, key))
        return goal

    def to_cancel(self, goal_id: bytes, stamp_ns: int) -> tuple[int, list[KeptGoal]]:
        """The goals a cancel request names (action_msgs/srv/CancelGoal's policy), and the
        return code: an id and no stamp, that goal (ERROR_UNKNOWN_GOAL_ID if not kept,
        ERROR_GOAL_TERMINATED if it has ended); otherwise every goal not ended that was
        accepted at or before the stamp (every one for no id and no stamp) and the goal of
        the id, with ERROR_NONE. The goals' states are not changed here."""
        if goal_id != _ZERO_ID and stamp_ns == 0:
            goal = self._goals.get(goal_id)
            if goal is None:
                return ERROR_UNKNOWN_GOAL_ID, []
            if goal.status not in CANCELABLE:
                return ERROR_GOAL_TERMINATED, []
            return ERROR_NONE, [goal]
        until = stamp_ns if stamp_ns != 0 else None  # None: no id and no stamp, every goal
        return ERROR_NONE, [goal for goal in self._goals.values() if goal.status in CANCELABLE
                            and (until is None or goal.stamp_ns <= until or goal.key == goal_id)]

    def expire_due(self) -> bool:
        """Whether a result has expired (``expire`` has something to remove)."""
        return bool(self._expiry) and self._expiry[0][0] <= self._clock()

    def now(self) -> float:
        return self._clock()

    def expire(self, until: float | None = None) -> list[bytes]:
        """Forget the goals whose result had expired by ``until`` (by now if None); their ids."""
        now = self._clock() if until is None else until
        gone = []
        while self._expiry and self._expiry[0][0] <= now:
            _, key = self._expiry.popleft()
            del self._goals[key], self._records[key]
            gone.append(key)
        return gone

    def clear(self) -> None:
        self._goals.clear()
        self._records.clear()
        self._expiry.clear()

    def status_array(self) -> bytes:
        """The CDR of the GoalStatusArray of every goal kept, in the order accepted."""
        records = iter(self._records.values())
        first = next(records, None)
        if first is None:
            return HEADER + _COUNT.pack(0)
        # the first element follows the 4-byte count: its stamp needs no padding
        return b"".join([HEADER, _COUNT.pack(len(self._records)), first[:16], first[19:], *records])

    def _change(self, key: bytes, sources, to: int) -> bool:
        goal = self._goals.get(key)
        if goal is None or goal.status not in sources:
            return False
        goal.status = to
        self._record(goal)
        return True

    def _record(self, goal: KeptGoal) -> None:
        sec, nanosec = divmod(goal.stamp_ns, _NS)
        self._records[goal.key] = _RECORD.pack(goal.key, sec, nanosec, goal.status)
