"""Axis objects through ROS: /mpi/axis_create, /mpi/axis_delete and /mpi/axis_validate
(mpiAxisCreate, mpiAxisDelete, mpiAxisValidate of MPI 002) while the suite runs. A deleted
axis loses its status topic, its services and its /joint_states entry; a created one gets them."""

from __future__ import annotations

import threading

from sensor_msgs.msg import JointState

from mpi_ros.msg import AxisStatus
from mpi_ros.srv import AxisConfigGet, AxisCreate, AxisDelete, AxisListSet, AxisValidate

from .test_controller_node import Collector


def _graph_shows(probe, present: bool, timeout: float = 10.0) -> None:
    """Wait until /mpi/axis3's status publisher and config service are (or are not) on the graph."""
    idle = threading.Event()
    for _ in range(int(timeout / 0.01)):
        services = {name for name, _ in probe.get_service_names_and_types()}
        publishers = probe.count_publishers("/mpi/axis3/status")
        if (publishers == 1 and "/mpi/axis3/config_get" in services) == present and (
                present or (publishers == 0 and not any(name.startswith("/mpi/axis3/") for name in services))):
            return
        idle.wait(0.01)
    raise AssertionError(f"axis 3's endpoints still {'absent' if present else 'present'} after {timeout} s")


def test_axes_deleted_and_created_while_the_suite_runs(suite, probe, service, drive):
    joints = Collector(probe, JointState, "/joint_states")
    status = Collector(probe, AxisStatus, "/mpi/axis3/status")
    drive(lambda: bool(joints.messages) and bool(status.messages))
    assert list(joints.messages[-1].name) == ["axis0", "axis1", "axis2", "axis3"]

    # MPI 002, mpiAxisDelete remarks (objects deleted in reverse order): ms1 lists axis 3
    refused = service(probe, AxisDelete, "/mpi/axis_delete", AxisDelete.Request(number=3))
    assert refused.message == "MPIMessageOBJECT_ON_LIST"
    assert "supervisor 1" in refused.detail
    # MPI 002, MPIAxisMessageAXIS_INVALID: mpiAxisCreate of a number out of range
    assert service(probe, AxisCreate, "/mpi/axis_create", AxisCreate.Request(number=4)).message == (
        "MPIAxisMessageAXIS_INVALID")

    listed = service(probe, AxisListSet, "/mpi/ms1/axis_list_set", AxisListSet.Request(axis_numbers=[2], map=True))
    assert listed.message == "MPIMessageOK"
    assert service(probe, AxisDelete, "/mpi/axis_delete", AxisDelete.Request(number=3)).message == "MPIMessageOK"
    _graph_shows(probe, present=False)
    invalid = service(probe, AxisValidate, "/mpi/axis_validate", AxisValidate.Request(number=3))
    assert invalid.message == "MPIMessageHANDLE_INVALID"  # MPI 002, mpiAxisValidate
    deleted_at = suite.runner.read(lambda ctl: ctl.sample)
    def sample_of(msg) -> int:
        stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        return round((stamp_ns - suite.epoch_ns) * suite.controller.rate / 1e9)

    drive(lambda: sum(sample_of(m) > deleted_at for m in joints.messages) >= 3)
    after = [m for m in joints.messages if sample_of(m) > deleted_at]
    assert all(list(m.name) == ["axis0", "axis1", "axis2"] for m in after)
    assert all(len(m.position) == len(m.velocity) == len(m.effort) == 3 for m in after)
    assert suite.runner.read(lambda ctl: ctl.sample) > deleted_at  # the suite kept running

    created = service(probe, AxisCreate, "/mpi/axis_create", AxisCreate.Request(number=3))
    assert created.message == "MPIMessageOK"
    _graph_shows(probe, present=True)
    assert service(probe, AxisValidate, "/mpi/axis_validate", AxisValidate.Request(number=3)).message == (
        "MPIMessageOK")
    config = service(probe, AxisConfigGet, "/mpi/axis3/config_get", AxisConfigGet.Request())
    assert config.message == "MPIMessageOK"
    seen_status, seen_joints = len(status.messages), len(joints.messages)
    drive(lambda: len(status.messages) > seen_status and len(joints.messages) > seen_joints + 1)
    assert list(joints.messages[-1].name) == ["axis0", "axis1", "axis2", "axis3"]
    assert status.messages[-1].number == 3
    assert not suite.failed()  # no executor stopped on a destroyed endpoint
