"""How moves ended, kept by the controller (mpi_ros/mpi/move_log.py), and when a goal that
follows a move is over (Controller.move_ends)."""

from __future__ import annotations

from mpi_ros.mpi import Controller, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import MoveEnd, Outcome
from mpi_ros.mpi.move_log import ENDS_PER_MOVE, MoveLog

OK = Outcome(Message.MPIMessageOK, "motion done")


def end(serial: int, sample: int, supervisor: int = 0) -> MoveEnd:
    return MoveEnd(serial, OK, sample, supervisor=supervisor)


def test_ends_are_kept_by_serial_and_the_moves_ended_longest_ago_go_first():
    log = MoveLog(kept=2)
    for e in (end(1, 10), end(2, 20), end(1, 30), end(3, 40)):
        log.record(e)
    assert len(log) == 2
    assert log.ends(2) == ()
    assert [e.sample for e in log.ends(1)] == [10, 30]
    assert [e.sample for e in log.ends(3)] == [40]
    assert [(e.serial, e.sample) for e in log.recent()] == [(1, 10), (2, 20), (1, 30), (3, 40)]


def test_ends_read_are_kept_for_kept_read_moves_and_ends_not_read_yet_for_kept():
    # A stream ended at once ends all its unreached chunks together (one serial each): the
    # goals that follow them read their ends at the next review, however many there are.
    log = MoveLog(kept=100, kept_read=3)
    for serial in range(1, 51):
        log.record(end(serial, 500))
    assert len(log) == 50
    assert all(log.ends(serial) for serial in range(1, 51))
    log.mark_read()
    assert len(log) == 3
    assert [s for s in range(1, 51) if log.ends(s)] == [48, 49, 50]
    log.record(end(51, 600))  # a move read long ago goes for it; the new one stays until read
    assert [s for s in range(1, 52) if log.ends(s)] == [49, 50, 51]
    for serial in range(52, 200):
        log.record(end(serial, 700))
    assert len(log) == 100
    assert log.ends(99) == ()
    assert log.ends(100)
    log.mark_read()
    assert [s for s in range(1, 200) if log.ends(s)] == [197, 198, 199]
    assert MoveLog(kept=2, kept_read=5)._kept_read == 2  # never more read than kept at all


def test_a_move_modified_for_hours_keeps_only_its_latest_ends():
    # A move modified again and again keeps its serial and ends at every DONE: at 8 ends a
    # second its list would grow for as long as the suite runs (issue 14's soak found it).
    log = MoveLog(ends_per_move=4)
    for sample in range(0, 1000, 10):
        log.record(end(7, sample))
    assert [e.sample for e in log.ends(7)] == [960, 970, 980, 990]
    assert log.since(7, 975).sample == 980
    assert log.since(7, 991) is None
    one = MoveLog(ends_per_move=1)
    for sample in (10, 20):
        one.record(end(7, sample))
    assert [e.sample for e in one.ends(7)] == [20]
    assert MoveLog().ends(7) == ()
    assert MoveLog()._ends_per_move == ENDS_PER_MOVE


def test_since_is_the_first_end_at_or_after_the_goals_sample():
    log = MoveLog()
    log.record(end(5, 100))  # a VELOCITY move at +200 counts/s
    log.record(end(5, 400))  # modified at sample 300 to -300 counts/s: its own end
    assert log.since(5, 100).sample == 100  # recorded at the sample the goal took effect: its own
    assert log.since(5, 101).sample == 400
    assert log.since(5, 300).sample == 400
    assert log.since(5, 401) is None
    assert log.since(6, 0) is None


def test_recent_is_bounded_and_filtered_by_supervisor():
    log = MoveLog()
    for k in range(3000):
        log.record(end(k, k, supervisor=k % 2))
    assert len(log.recent()) == 1024
    assert log.recent()[-1].serial == 2999
    assert {e.supervisor for e in log.recent(1)} == {1}


def test_a_goal_is_over_at_its_moves_end_or_when_the_supervisor_says_so():
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0]).ok
    assert ms.action(MPIAction.MAP).ok
    slow = MotionParams(position=[100_000.0], trajectory=[Trajectory(1000.0, 10_000.0, 10_000.0)])
    assert ms.start(MPIMotionType.TRAPEZOIDAL, params=slow).ok
    serial, since = ctl.current_serial(0), ctl.effective_sample
    ctl.step(200)
    assert ctl.move_end(0, serial, since) is None  # still moving toward its target
    assert ms.action(MPIAction.STOP).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 20_000, chunk=10)
    stopped = ctl.move_end(0, serial, since)
    assert stopped.message is Message.MPIMotionMessageSTOPPED
    assert "STOP" in stopped.detail
    assert ms.action(MPIAction.RESET).ok  # drops the move: its end is recorded
    (dropped,) = ctl.move_log.ends(serial)
    assert dropped.message is Message.MPIMotionMessageSTOPPED
    assert dropped.supervisor == 0
    assert ctl.move_ends(0, [(serial, since), (serial, ctl.sample + 1)]) == [
        dropped, MoveEnd(serial, Outcome(Message.MPIMotionMessageIDLE, "the move is no longer on the supervisor"),
                         ctl.sample)]
    assert ctl.move_end(3, 99, 0).message is Message.MPIMotionMessageMOTION_INVALID  # no such supervisor


def test_each_controller_numbers_its_own_moves():
    numbered = []
    for _ in range(2):
        ctl = Controller()
        _, ms = ctl.create_motion(0)
        assert ms.axis_list_set([0]).ok
        assert ms.action(MPIAction.MAP).ok
        for target in (1000.0, 2000.0):
            assert ms.start(MPIMotionType.TRAPEZOIDAL, params=MotionParams(
                position=[target], trajectory=[Trajectory(1e5, 1e6, 1e6)])).ok
            numbered.append(ctl.current_serial(0))
            assert ctl.run_until(lambda c: c.supervisor(0).state is MPIState.IDLE, 20_000, chunk=10)
    assert numbered == [1, 2, 1, 2]
