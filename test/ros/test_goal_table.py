"""GoalTable: the action protocol's goal states, cancel policy, result expiry and status
array, kept without rcl_action (mpi_ros/ros/goal_table.py)."""

from __future__ import annotations

import pytest
from action_msgs.msg import GoalInfo, GoalStatus, GoalStatusArray
from action_msgs.srv import CancelGoal
from hypothesis import given, settings
from hypothesis import strategies as st
from rclpy.serialization import deserialize_message, serialize_message

from mpi_ros.ros import goal_table as gt
from mpi_ros.ros.goal_table import GoalTable

S = 1_000_000_000


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def key(n: int) -> bytes:
    return bytes([n]) * 16


def table(timeout: float = 10.0) -> tuple[GoalTable, FakeClock]:
    clock = FakeClock()
    return GoalTable(timeout, clock), clock


def generated(goals: list[tuple[bytes, int, int]]) -> bytes:
    """The same array built as a message and serialized by rclpy (its padding bytes are
    whatever was in its buffer, ours are zero: compare with ``same``)."""
    array = GoalStatusArray()
    for goal_id, stamp_ns, status in goals:
        info = GoalInfo()
        info.goal_id.uuid = list(goal_id)
        info.stamp.sec, info.stamp.nanosec = divmod(stamp_ns, S)
        array.status_list.append(GoalStatus(goal_info=info, status=status))
    return serialize_message(array)


def same(ours: bytes, theirs: bytes) -> bool:
    """The same CDR: the same length and the same message decoded."""
    return len(ours) == len(theirs) and (deserialize_message(ours, GoalStatusArray)
                                         == deserialize_message(theirs, GoalStatusArray))


# -- states ---------------------------------------------------------------------------------
def test_a_goal_goes_accepted_executing_succeeded():
    goals, _ = table()
    goals.accept(key(1), 5)
    assert goals.status(key(1)) == gt.ACCEPTED
    assert goals.execute(key(1))
    assert goals.status(key(1)) == gt.EXECUTING
    assert not goals.execute(key(1))  # only from ACCEPTED
    assert goals.end(key(1), gt.SUCCEEDED) is not None
    assert goals.status(key(1)) == gt.SUCCEEDED


def test_a_goal_ended_once_keeps_its_first_end():
    goals, _ = table()
    goals.accept(key(1), 5)
    goals.end(key(1), gt.ABORTED)
    assert goals.end(key(1), gt.SUCCEEDED) is None
    assert not goals.cancel(key(1))
    assert not goals.execute(key(1))
    assert goals.status(key(1)) == gt.ABORTED


def test_canceled_needs_an_accepted_cancel_else_aborted():
    goals, _ = table()
    goals.accept(key(1), 5)
    goals.accept(key(2), 5)
    assert goals.cancel(key(2))
    assert goals.status(key(2)) == gt.CANCELING
    goals.end(key(1), gt.CANCELED)
    goals.end(key(2), gt.CANCELED)
    assert goals.status(key(1)) == gt.ABORTED
    assert goals.status(key(2)) == gt.CANCELED


def test_a_reused_goal_id_and_a_non_terminal_end_are_refused():
    goals, _ = table()
    goals.accept(key(1), 5)
    with pytest.raises(ValueError):
        goals.accept(key(1), 6)
    with pytest.raises(ValueError):
        goals.end(key(1), gt.EXECUTING)
    assert key(1) in goals
    assert len(goals) == 1
    assert goals.status(key(9)) == gt.UNKNOWN


# -- results expire ---------------------------------------------------------------------------
def two_ended(apart: float) -> tuple[GoalTable, FakeClock]:
    """Results kept 10 s; goal 1 ends, ``apart`` s later goal 2."""
    goals, clock = table(timeout=10.0)
    goals.accept(key(1), 5)
    goals.accept(key(2), 5)
    goals.end(key(1), gt.SUCCEEDED)
    clock.now += apart
    goals.end(key(2), gt.ABORTED)
    return goals, clock


def test_results_expire_result_timeout_after_their_goal_ended():
    goals, clock = two_ended(4.0)
    clock.now += 5.9
    assert not goals.expire_due()
    assert goals.expire() == []
    clock.now += 0.2  # 10.1 s after the first ended, 6.1 after the second
    assert goals.expire_due()
    assert goals.expire() == [key(1)]
    assert key(1) not in goals
    assert key(2) in goals
    clock.now += 4.0
    assert goals.expire() == [key(2)]
    assert len(goals) == 0
    assert not goals.expire_due()


def test_expiring_until_a_time_keeps_the_results_that_expire_after_it():
    # GoalServer expires in turn with the requests it took: until the time it looked
    goals, clock = two_ended(1.0)
    looked = clock.now + 9.5  # the first had expired then, the second not
    clock.now += 30.0
    assert goals.expire(until=looked) == [key(1)]
    assert goals.get(key(2)) is not None


def test_a_goal_that_has_not_ended_never_expires():
    goals, clock = table(timeout=1.0)
    goals.accept(key(1), 5)
    clock.now += 1e6
    assert goals.expire() == []
    assert key(1) in goals


# -- the cancel policy (action_msgs/srv/CancelGoal) ---------------------------------------------
def cancel_table() -> GoalTable:
    goals, _ = table()
    goals.accept(key(1), 1 * S)
    goals.accept(key(2), 2 * S)
    goals.accept(key(3), 3 * S)
    goals.accept(key(4), 4 * S)
    goals.execute(key(2))
    goals.end(key(3), gt.SUCCEEDED)
    return goals


def named(goals: GoalTable, goal_id: bytes, stamp_ns: int) -> tuple[int, list[bytes]]:
    code, found = goals.to_cancel(goal_id, stamp_ns)
    return code, [goal.key for goal in found]


def test_cancel_one_goal_by_its_id():
    goals = cancel_table()
    assert named(goals, key(2), 0) == (CancelGoal.Response.ERROR_NONE, [key(2)])
    assert named(goals, key(3), 0) == (CancelGoal.Response.ERROR_GOAL_TERMINATED, [])
    assert named(goals, key(9), 0) == (CancelGoal.Response.ERROR_UNKNOWN_GOAL_ID, [])


def test_cancel_every_goal_not_ended():
    assert named(cancel_table(), bytes(16), 0) == (CancelGoal.Response.ERROR_NONE, [key(1), key(2), key(4)])


def test_cancel_the_goals_accepted_at_or_before_a_stamp_and_the_goal_of_an_id():
    goals = cancel_table()
    assert named(goals, bytes(16), 2 * S) == (CancelGoal.Response.ERROR_NONE, [key(1), key(2)])
    assert named(goals, key(4), 1 * S) == (CancelGoal.Response.ERROR_NONE, [key(1), key(4)])
    assert named(goals, bytes(16), 1) == (CancelGoal.Response.ERROR_NONE, [])


def test_naming_goals_to_cancel_changes_no_state():
    goals = cancel_table()
    goals.to_cancel(bytes(16), 0)
    assert [goals.status(key(n)) for n in (1, 2, 3, 4)] == [gt.ACCEPTED, gt.EXECUTING, gt.SUCCEEDED, gt.ACCEPTED]


# -- the status array ---------------------------------------------------------------------------
def test_an_empty_status_array_is_rclpys():
    goals, _ = table()
    assert goals.status_array() == generated([])


def test_the_status_array_is_rclpys_in_the_order_accepted():
    goals, _ = table()
    goals.accept(key(3), 7 * S + 5)
    goals.accept(key(1), 8 * S + 999_999_999)
    goals.accept(key(2), 9 * S)
    goals.execute(key(1))
    goals.cancel(key(2))
    goals.end(key(3), gt.SUCCEEDED)
    expected = [(key(3), 7 * S + 5, gt.SUCCEEDED), (key(1), 8 * S + 999_999_999, gt.EXECUTING),
                (key(2), 9 * S, gt.CANCELING)]
    assert same(goals.status_array(), generated(expected))
    goals.end(key(1), gt.ABORTED)  # a change keeps the goal's place
    expected[1] = (key(1), 8 * S + 999_999_999, gt.ABORTED)
    assert same(goals.status_array(), generated(expected))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.binary(min_size=16, max_size=16), st.integers(0, 2**31 * S - 1),
                          st.sampled_from(["accepted", "executing", "canceling", "succeeded", "aborted"])),
                max_size=12, unique_by=lambda goal: goal[0]))
def test_any_status_array_decodes_to_the_goals_kept(spec):
    goals, _ = table()
    steps = {"accepted": [], "executing": [goals.execute], "canceling": [goals.cancel],
             "succeeded": [lambda k: goals.end(k, gt.SUCCEEDED)], "aborted": [lambda k: goals.end(k, gt.ABORTED)]}
    for goal_id, stamp_ns, state in spec:
        goals.accept(goal_id, stamp_ns)
        for step in steps[state]:
            step(goal_id)
    data = goals.status_array()
    decoded = deserialize_message(data, GoalStatusArray)
    assert [(bytes(s.goal_info.goal_id.uuid), s.goal_info.stamp.sec * S + s.goal_info.stamp.nanosec, s.status)
            for s in decoded.status_list] == [(g, t, goals.status(g)) for g, t, _ in spec]
    assert same(data, generated([(g, t, goals.status(g)) for g, t, _ in spec]))
