"""The jog's goal and its refusals, without ROS (mpi_ros/cli/jog.py)."""

from __future__ import annotations

import pytest

from mpi_ros.cli.jog import JogTarget, busy, jog_goal


def test_the_jog_goal_moves_the_selected_axis_alone():
    # MPI 000, MPIMotionVelocity: a VELOCITY move with one trajectory per axis, the others at 0
    goal = jog_goal(3, JogTarget(supervisor=1, axis=2, number=7, sign=-1), 1500.0, 8000.0)
    assert goal["type"] == "VELOCITY"
    assert [t["velocity"] for t in goal["trajectory"]] == [0.0, 0.0, -1500.0]
    assert {t["acceleration"] for t in goal["trajectory"]} == {8000.0}


def test_a_target_needs_a_direction_and_an_axis_index():
    with pytest.raises(ValueError, match="sign -1 or 1"):
        JogTarget(0, 0, 0, 0)
    with pytest.raises(ValueError, match="axis index >= 0"):
        JogTarget(0, -1, 0, 1)


@pytest.mark.parametrize(("state", "said"), [
    ("MOVING", "MOVING (move 4): STOP it (space) or wait for IDLE"),
    ("STOPPED", "STOPPED with move 4 pending: RESUME (u) continues it, RESET (r) drops it"),
    ("ERROR", "in ERROR: RESET (r) first"),
])
def test_a_jog_starts_from_idle_only(state, said):
    assert busy("IDLE", 4) is None
    assert said in (busy(state, 4) or "")
