"""The gantry (config/gantry.yaml) on the ROS graph: /joint_states in metres and radians under
x, y, z, c, and the robot description latched on /mpi/robot_description (docs/joints.md)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from .test_controller_node import Collector

GANTRY = Path(__file__).resolve().parents[2] / "config" / "gantry.yaml"
# 0.2 m/s and 2 m/s^2 on X and Y (1e6 counts a metre)
S_CURVE = [{"velocity": 200_000.0, "acceleration": 2e6, "deceleration": 2e6, "jerk_percent": 50.0}]


@pytest.fixture
def suite_config():
    from mpi_ros import config

    return config.load(GANTRY)


def test_joint_states_are_in_metres_and_radians_under_the_joint_names(suite, client, client1, probe, drive):
    from sensor_msgs.msg import JointState

    joints = Collector(probe, JointState, "/joint_states")
    # X to 0.25 m, Y to 0.1 m; Z down by 0.1 m (from 0.3 m), C a quarter turn (2,500 of 10,000 counts)
    xy = client.start({"type": "S_CURVE", "position": [250_000.0, 100_000.0], "trajectory": S_CURVE})
    zc = client1.start({"type": "S_CURVE", "position": [100_000.0, 2_500.0], "trajectory": S_CURVE})
    drive(lambda: xy.done and zc.done)
    assert xy.wait(10.0).message == "MPIMessageOK"
    assert zc.wait(10.0).message == "MPIMessageOK"
    at = suite.controller.sample
    # drive steps 20 samples at a time from 0, and /joint_states is published every 20 (100 Hz): the
    # last one is of this very sample (an earlier one may differ by a count while the servo settles)
    assert at % round(suite.controller.rate / suite.config.ros.joint_states_rate) == 0
    seen = joints.wait_for(lambda ms: bool(ms) and ms[-1].header.stamp.sec * 10**9 + ms[-1].header.stamp.nanosec
                           >= suite.epoch_ns + round(at * 1e9 / suite.controller.rate))
    last = seen[-1]
    assert list(last.name) == ["x", "y", "z", "c"]
    # within the fine in-position window (10 counts: 10 um; on C 10 counts are 6.3 mrad)
    assert last.position[:3] == pytest.approx([0.25, 0.1, 0.2], abs=1e-5)
    assert last.position[3] == pytest.approx(math.pi / 2, abs=10 * 2 * math.pi / 10_000)
    # velocities in m/s: the X-Y vector peaks at the commanded 0.2 m/s (200,000 counts/s); Z moves down
    assert max(math.hypot(m.velocity[0], m.velocity[1]) for m in seen) == pytest.approx(0.2, rel=0.02)
    # (Z's counts go up while it moves down: the joint's velocity is negative, bar the servo's
    # small overshoot as it settles)
    assert min(m.velocity[2] for m in seen) < -0.15
    assert max(m.velocity[2] for m in seen) < 0.01
    # effort: the servo's acceleration demand in m/s^2, of the order of the 2 m/s^2 asked
    assert 1.0 < max(abs(m.effort[0]) for m in seen) < 10.0
    # every value is the axis' counts converted (the controller's own numbers, at that sample)
    counts = suite.runner.read(lambda ctl: [a.actual_position for a in ctl.axes])
    axis_joints = suite.config.axis_joints()
    final = [j.position(c) for j, c in zip(axis_joints, counts, strict=True)]
    assert list(last.position) == pytest.approx(final, abs=1e-9)


def test_the_robot_description_is_latched_for_a_late_subscriber(suite, probe, drive):
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String
    from urdf_parser_py.urdf import URDF

    from mpi_ros import description

    drive(lambda: suite.controller.sample > 200)  # the suite has been up a while: the message is old
    received = Collector(probe, String, "/mpi/robot_description", QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL))
    text = received.wait_for(lambda ms: bool(ms))[0].data
    assert text == description.generate(suite.config) == suite.robot_description
    assert [j.name for j in URDF.from_xml_string(text).joints] == ["x", "y", "z", "c"]
