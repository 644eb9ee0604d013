"""Cams through ROS (in-process suite, real actions and services): the axis config services with
the master (AxisConfigGet/Set: AxisMaster, master_correction), the motors' secondary feedback
service, a MotionStart goal with the cam fields as `ros2 action send_goal` gives it, and the
Python client's cam(). MPI 000 MPIMotionCam; MPI 002 MPIAxisConfig.master (docs/cams.md).

The controller is stepped by the tests (drive)."""

from __future__ import annotations

import pytest
import yaml

from mpi_ros import errors
from mpi_ros.client import AxisClient, MotionType
from mpi_ros.srv import AxisConfigGet, AxisConfigSet

from .conftest import WAIT

# `ros2 action send_goal /mpi/ms1/motion_start mpi_ros/action/MotionStart "<this>"`: supervisor 1's axes 2
# and 3 follow their master through 3 segments of 1000 master counts, a cubic cam.
CAM_YAML = """
{type: CAM_CUBIC, attributes: [ID], id: 7,
 master_distance: [1000, 1000, 1000],
 slave_position: [500, -200, 500, 0, -700, 100],
 gear_ratio: [0.5, 0, 0.5, 0, 0, 0]}
"""


@pytest.fixture
def axes(suite, ros_context):
    client = AxisClient(context=ros_context, timeout=WAIT, node_name="test_axis_client")
    yield client
    client.close()


def test_axis_config_get_and_set_carry_the_master(suite, axes, probe, service):
    response = service(probe, AxisConfigGet, "/mpi/axis2/config_get", AxisConfigGet.Request())
    # the default master (docs/cams.md) and no correction
    assert (response.master.type, response.master.number, response.master_correction) == (
        "AXIS_COMMANDED_POSITION", 0, -1)
    set_request = AxisConfigSet.Request(in_position=response.in_position, master_correction=1)
    set_request.master.type = "MOTOR_FEEDBACK_SECONDARY"
    set_request.master.number = 3
    answer = service(probe, AxisConfigSet, "/mpi/axis2/config_set", set_request)
    assert answer.message == "MPIMessageOK"
    got = axes.config_get(2)
    assert (got.master.type, got.master.number, got.master_correction) == ("MOTOR_FEEDBACK_SECONDARY", 3, 1)
    assert got.in_position.position_fine == response.in_position.position_fine  # kept as it was sent
    # a master that does not exist: refused with the validator's words, nothing changes
    bad = AxisConfigSet.Request(in_position=response.in_position, master_correction=-1)
    bad.master.type = "AXIS_ACTUAL_POSITION"
    bad.master.number = 99
    answer = service(probe, AxisConfigSet, "/mpi/axis2/config_set", bad)
    assert answer.message == "MPIMessagePARAM_INVALID"
    assert suite.runner.read(lambda ctl: (ctl.axes[2].master.number, ctl.axes[2].master.correction)) == (3, 1)
    with pytest.raises(errors.error_for("MPIMessagePARAM_INVALID")):
        axes.config_set(2, master={"type": "NOT_A_SOURCE"})


def test_cam_goal_from_send_goal_yaml_follows_the_master_to_its_end(suite, client, client1, axes, applied, drive):
    for axis in (2, 3):
        assert axes.config_set(axis, master={"type": "AXIS_COMMANDED_POSITION", "number": 0}).ok
    running = client1.start(yaml.safe_load(CAM_YAML))
    _, _, reply = applied.wait(3)
    assert reply.message.name == "MPIMessageOK"
    client.start({"type": "VELOCITY", "trajectory": [{"velocity": 4000.0, "acceleration": 1e6}]})
    applied.wait(4)
    drive(lambda: running.done, samples=20_000)
    result = running.wait()
    assert result.message == "MPIMessageOK"
    assert result.move_id == 7
    # at the end of the table: the sums of the slave distances
    assert suite.runner.read(lambda ctl: (ctl.axes[2].command_position, ctl.axes[3].command_position)) == (
        300.0, -100.0)


def test_client_cam_follows_a_line_shaft_encoder_and_stops(suite, client1, axes, applied, drive):
    # the secondary feedback input of motor 1 runs like a line shaft; axis 2 follows it with a repeating
    # linear cam (a flying shear's cycle), until STOP
    assert axes.config_set(2, master={"type": "MOTOR_FEEDBACK_SECONDARY", "number": 1}).ok
    assert axes.config_set(3, master={"type": "MOTOR_FEEDBACK_SECONDARY", "number": 1}).ok
    assert axes.secondary_feedback_set(1, 0.0, 2000.0).ok
    running = client1.cam(MotionType.CAM_LINEAR, [200.0, 300.0], [(100.0, 0.0), (-100.0, 0.0)], repeat_from=0,
                          attributes=["NO_BACKTRACK"])
    _, _, reply = applied.wait(4)
    assert reply.message.name == "MPIMessageOK"
    start = suite.runner.ctl.sample
    drive(lambda: suite.runner.ctl.sample >= start + 1250, samples=2000, chunk=50)  # 2500 master counts: 5 cycles
    state, position = suite.runner.read(lambda ctl: (ctl.supervisor(1).state.name, ctl.axes[2].command_position))
    assert state == "MOVING"
    assert 0.0 <= position <= 100.0
    client1.stop()
    drive(lambda: running.done, samples=5000)
    assert running.wait(raise_on_error=False).message == "MPIMotionMessageSTOPPED"
    with pytest.raises(errors.error_for("MPIMessagePARAM_INVALID")):
        axes.secondary_feedback_set(99, 0.0, 1.0)


def test_a_bad_cam_goal_gets_the_spec_message(suite, client1):
    for goal, message in (
        ({"type": "CAM_LINEAR", "master_distance": [100.0], "slave_position": [1.0]}, "MPIMessagePARAM_INVALID"),
        ({"type": "CAM_LINEAR", "attributes": ["NO_BACKTRACK", "NO_BACKTRACK_HOLD"], "master_distance": [100.0],
          "slave_position": [1.0, 1.0]}, "MPIMotionMessageATTRIBUTE_INVALID"),
    ):
        result = client1.start(goal).wait(raise_on_error=False)
        assert result.message == message
