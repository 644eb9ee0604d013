"""The suite as users start it: `mpi-ros run` in its own process, driven over DDS with the
Python client; then Ctrl-C stops it cleanly."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

WAIT = 20.0


@pytest.fixture
def suite_process(tmp_path):
    exe = Path(sys.executable).with_name("mpi-ros")
    process = subprocess.Popen([str(exe), "run", "--time-scale", "5"], cwd=tmp_path,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        yield process
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=10)


def test_move_e_stop_reset_across_processes_and_clean_ctrl_c(suite_process, ros_context):
    from mpi_ros import errors
    from mpi_ros.client import MotionClient

    with MotionClient(0, context=ros_context, timeout=WAIT) as ms0:
        assert ms0.wait_for_server(WAIT), "the suite did not come up"
        result = ms0.move([1500.0, -500.0], velocity=5000.0, acceleration=50000.0, deceleration=50000.0,
                          jerk_percent=50.0,
                          timeout=WAIT)
        assert (result.message, result.state_name) == ("MPIMessageOK", "IDLE")
        assert list(result.command_position) == [1500.0, -500.0]

        goal = ms0.start({"type": "VELOCITY", "trajectory": [{"velocity": 800.0, "acceleration": 8000.0}]})
        # a VELOCITY goal succeeds once every axis is at the commanded velocity
        assert goal.wait(WAIT).detail == "at velocity"
        assert ms0.e_stop().state_name == "STOPPING_ERROR"
        status = ms0.wait_for_state("ERROR", WAIT)
        assert (status.last_action, status.action_source) == ("E_STOP", "USER")
        with pytest.raises(errors.MPIMotionMessageERROR):
            ms0.move([0.0, 0.0], velocity=100.0, acceleration=1000.0, deceleration=1000.0)
        assert ms0.reset().state_name == "IDLE"

    suite_process.send_signal(signal.SIGINT)
    _out, err = suite_process.communicate(timeout=WAIT)
    assert suite_process.returncode == 0, err
    assert "Traceback" not in err
    assert "mpi_ros suite stopped" in err


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_stop_signal_ends_the_goal_in_progress_with_its_result(suite_process, ros_context, stop):
    # The suite takes the stop signals itself (mpi_ros/cli/stop_signals.py): ROS still runs
    # while the supervisors end their goals, so the client gets a result, not silence.
    from mpi_ros import errors
    from mpi_ros.client import MotionClient

    with MotionClient(0, context=ros_context, timeout=WAIT) as ms0:
        assert ms0.wait_for_server(WAIT), "the suite did not come up"
        # 1,000,000 counts at 100 counts/s: still moving when the signal comes, however slow the machine
        goal = ms0.start({"type": "S_CURVE", "position": [1e6, 0.0],
                          "trajectory": [{"velocity": 100.0, "acceleration": 1000.0, "deceleration": 1000.0,
                                          "jerk_percent": 50.0}]})
        assert goal.wait_started(WAIT)
        suite_process.send_signal(stop)
        with pytest.raises(errors.MPIMotionMessageSTOPPED) as ended:
            goal.wait(WAIT)
        assert ended.value.detail == "the suite is shutting down"
    _out, err = suite_process.communicate(timeout=WAIT)
    assert suite_process.returncode == 0, err
    assert f"{stop.name}: stopping" in err
    assert "mpi_ros suite stopped" in err
    assert "Traceback" not in err
