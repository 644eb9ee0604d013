"""JointTrajectory on <ns>/ms<n>/joint_trajectory, through ROS (an rclpy publisher, as
`ros2 topic pub --once` sends it), with config/gantry.yaml (ms0 = x, y in metres): the gantry
moves through the points along MPI 000's PVT equations (Streaming Point Motion Type
Calculations, PVT Moves: the cubic Hermite between points), checked in SI units from the
status topic; each refusal moves nothing and is counted on /diagnostics; a stamp in the
future starts the path then. The controller is stepped by the tests."""

from __future__ import annotations

import threading

import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from scipy.interpolate import CubicHermiteSpline

from mpi_ros.client import STATUS_QOS
from mpi_ros.commands import Command, Operation

from .conftest import WAIT
from .test_paths_ros import Topic

RATE = 2000.0  # config/gantry.yaml: controller.sample_rate
TOPIC = "/mpi/ms0/joint_trajectory"
POINTS = [([0.10, 0.05], [0.20, 0.0], 0.5), ([0.25, 0.20], [0.10, 0.3], 1.0), ([0.30, 0.30], [0.0, 0.0], 1.6)]


@pytest.fixture
def suite_config():
    from mpi_ros import config

    return config.load("config/gantry.yaml", {"ros": {"diagnostics_rate": 10.0}})


def message(names, points, stamp_ns: int = 0):
    from builtin_interfaces.msg import Duration, Time
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

    msg = JointTrajectory()
    msg.header.stamp = Time(sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000)
    msg.joint_names = list(names)
    for positions, velocities, t in points:
        seconds = int(t)
        msg.points.append(JointTrajectoryPoint(positions=[float(p) for p in positions],
                                               velocities=[float(v) for v in velocities],
                                               time_from_start=Duration(sec=seconds,
                                                                        nanosec=round((t - seconds) * 1e9))))
    return msg


@pytest.fixture
def publish(probe, suite):
    from trajectory_msgs.msg import JointTrajectory

    publisher = probe.create_publisher(JointTrajectory, TOPIC,
                                       QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
    pause = threading.Event()
    for _ in range(int(WAIT / 0.01)):
        if publisher.get_subscription_count() > 0:
            break
        pause.wait(0.01)
    feed = suite.supervisor_nodes[0].trajectories

    def send(msg) -> None:
        """Publish and wait until the suite has taken it (received, refused or scheduled)."""
        before = feed.snapshot().received
        publisher.publish(msg)
        for _ in range(int(WAIT / 0.005)):
            if feed.snapshot().received > before:
                return
            pause.wait(0.005)
        raise AssertionError("the trajectory did not arrive")

    return send


def si(suite, status) -> list[float]:
    joints = suite.config.axis_joints()
    return [joints[a.number].position(a.command_position) for a in status.axes]


def test_a_published_pvt_trajectory_moves_ms0_through_its_points(suite, probe, publish, applied, drive):
    from mpi_ros.msg import MotionStatus

    statuses = Topic(probe, MotionStatus, "/mpi/ms0/status", STATUS_QOS)
    statuses.matched()
    publish(message(["y", "x"], [(p[::-1], v[::-1], t) for p, v, t in POINTS]))
    suite.runner.step(1)
    sample, command, reply = applied.wait(1)
    assert command.operation == "joint_trajectory", reply.detail
    assert reply.message.name == "MPIMessageOK", reply.detail
    begin = sample - 1  # the path runs from this sample's time on (recorded with the next)
    drive(lambda: suite.runner.ctl.sample > begin + 1.7 * RATE)
    end = statuses.wait_for(lambda m: m.sample >= begin + 1.7 * RATE, "a status after the path")
    assert si(suite, end) == pytest.approx([0.30, 0.30], abs=1e-12)
    knots = [0.0] + [t for _, _, t in POINTS]
    expected = [CubicHermiteSpline(knots, [0.0] + [p[i] for p, _, _ in POINTS], [0.0] + [v[i] for _, v, _ in POINTS])
                for i in range(2)]
    checked = 0
    for status in list(statuses.messages):
        elapsed = (status.sample - begin) / RATE
        if 0.0 <= elapsed <= 1.6:
            assert si(suite, status) == pytest.approx([float(e(elapsed)) for e in expected], abs=1e-9), elapsed
            checked += 1
    assert checked >= 150  # 100 Hz over 1.6 s


def test_a_future_stamp_starts_the_path_then(suite, publish, applied):
    start = suite.runner.ctl.sample + 2000  # one second of controller time ahead
    stamp = suite.epoch_ns + round(start / RATE * 1e9)
    publish(message(["x", "y"], [([0.1, 0.0], [], 0.5)], stamp))
    suite.runner.step(start - 1 - suite.runner.ctl.sample)  # one sample short of the stamp
    assert suite.runner.read(lambda ctl: ctl.supervisor(0).state.name) == "IDLE"
    assert not applied.commands
    suite.runner.step(10)
    sample, command, reply = applied.wait(1)
    assert (sample, command.operation, reply.message.name) == (start + 1, "joint_trajectory", "MPIMessageOK")


def test_each_refusal_moves_nothing_and_is_counted_on_diagnostics(suite, probe, publish, applied):
    from diagnostic_msgs.msg import DiagnosticArray

    diagnostics = Topic(probe, DiagnosticArray, "/diagnostics", 10)
    diagnostics.matched()
    ok = [([0.1, 0.0], [], 0.5)]
    publish(message(["x", "q"], ok))  # an unknown joint
    publish(message(["x"], [([0.1], [], 0.5)]))  # only some of the joints
    publish(message(["x", "y"], [([0.1, 0.0], [], 0.5), ([0.2, 0.0], [], 0.5)]))  # times that do not increase
    publish(message(["x", "y"], [([float("nan"), 0.0], [], 0.5)]))  # NaN
    publish(message(["x", "y"], [([0.4, 0.0], [], 0.5)]))  # 0.8 m/s, over x's max_velocity 0.5 m/s
    suite.runner.step(100)
    suite.runner.submit(Command(Operation.ACTION, 0, request={"action": "E_STOP"}))
    suite.runner.step(100)
    publish(message(["x", "y"], ok))  # the supervisor is in ERROR
    suite.runner.step(400)
    positions = suite.runner.read(lambda ctl: [ctl.axis_snapshot(n).command_position for n in (0, 1)])
    assert positions == [0.0, 0.0]
    # Refused as they arrived: nothing reached the controller. The speed from where the path
    # starts, and the ERROR, are the controller's answers to the first chunk (recorded).
    commands = [(c.operation, r.message.name) for _, c, r in applied.commands]
    assert commands == [("joint_trajectory", "MPIMessagePARAM_INVALID"), ("action", "MPIMessageOK"),
                        ("joint_trajectory", "MPIMotionMessageERROR")]
    counts = suite.supervisor_nodes[0].trajectories.snapshot()
    assert counts.received == 6
    assert counts.accepted == 0
    assert dict(counts.refused) == {"MPIMessagePARAM_INVALID": 3, "MPIMotionMessagePATH_ERROR": 1,
                                    "MEIMotionMessageBAD_PATH_DATA": 1, "MPIMotionMessageERROR": 1}

    def counted(msg) -> bool:
        status = next((s for s in msg.status if s.name == "mpi/ms0/joint_trajectory"), None)
        return status is not None and {v.key: v.value for v in status.values}.get("refused") == "6"

    suite.runner.step(400)
    found = diagnostics.wait_for(counted, "/diagnostics counting 6 refusals")
    status = next(s for s in found.status if s.name == "mpi/ms0/joint_trajectory")
    values = {v.key: v.value for v in status.values}
    assert values["refused_MPIMotionMessagePATH_ERROR"] == "1"
    assert values["accepted"] == "0"
    assert "supervisor is ERROR" in values["last_refusal"]
