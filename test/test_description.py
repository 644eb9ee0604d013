"""The robot description (docs/joints.md, "The robot description"): the generated URDF read
back with an independent parser (urdf-parser-py), its limits, its chain's forward kinematics
at the twin's joint states, and the check of a user's own URDF."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from urdf_parser_py.urdf import URDF

from mpi_ros import description
from mpi_ros.commands import Command, Operation, apply
from mpi_ros.config import ConfigError, load
from mpi_ros.joints import JointStates
from mpi_ros.mpi.base.wrap import HALF

GANTRY = Path(__file__).resolve().parents[1] / "config" / "gantry.yaml"
S_CURVE = [{"velocity": 200_000.0, "acceleration": 2e6, "deceleration": 2e6, "jerk_percent": 50.0}]


def parsed(config) -> URDF:
    return URDF.from_xml_string(description.generate(config))


def test_the_gantry_is_a_chain_of_its_joints_with_their_types_axes_and_limits():
    robot = parsed(load(GANTRY))
    assert robot.get_root() == "base_link"
    assert robot.get_chain("base_link", "c_link", links=False) == ["x", "y", "z", "c"]
    joints = {j.name: j for j in robot.joints}
    assert {n: j.type for n, j in joints.items()} == {"x": "prismatic", "y": "prismatic", "z": "prismatic",
                                                      "c": "continuous"}
    assert [joints[n].axis for n in "xyzc"] == [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1]]
    # the software limits (counts) in metres: X 0 .. 1e6, Y 0 .. 6e5
    assert (joints["x"].limit.lower, joints["x"].limit.upper, joints["x"].limit.velocity) == (0.0, 1.0, 0.5)
    assert (joints["y"].limit.lower, joints["y"].limit.upper) == (0.0, 0.6)
    # Z counts downward (counts_per_unit -1e6, offset 0.3): the positive count limit (250,000)
    # is the lower limit in metres
    assert joints["z"].limit.lower == pytest.approx(0.05)
    assert joints["z"].limit.upper == 0.3
    assert joints["z"].limit.velocity == 0.2
    assert joints["c"].limit.velocity == pytest.approx(2 * math.pi)
    # a continuous joint has no position limits (the parser reads absent ones as 0: look at the text)
    limit = ET.fromstring(description.generate(load(GANTRY))).find("joint[@name='c']/limit")
    assert limit is not None
    assert "lower" not in limit.attrib
    assert "upper" not in limit.attrib


def test_a_side_without_a_software_limit_is_the_32_bit_range_and_velocity_0_means_none_given():
    config = load(GANTRY, overrides={"axes": {"overrides": {
        0: {"faults": {"software_limit_negative_enabled": False}},
        1: {"faults": {"software_limit_negative_enabled": False, "software_limit_positive_enabled": False},
            "joint": {"name": "y", "type": "prismatic", "counts_per_unit": 1.0e6, "max_velocity": 0.0}}}}})
    text = description.generate(config)
    joints = {j.name: j for j in URDF.from_xml_string(text).joints}
    assert (joints["x"].limit.lower, joints["x"].limit.upper) == (-HALF / 1e6, 1.0)
    assert (joints["y"].limit.lower, joints["y"].limit.upper) == (-HALF / 1e6, HALF / 1e6)
    assert joints["y"].limit.velocity == 0.0
    # and the description says where each limit came from
    assert "x: controller axis 0, position limits from the positive software limit; the other side" in text
    assert "y: controller axis 1, position limits from no software limit enabled" in text
    assert "no max_velocity: velocity 0" in text


def test_a_joint_axis_can_be_chosen_and_revolute_joints_turn_about_z_by_default():
    config = load(overrides={"axes": {"overrides": {
        0: {"joint": {"name": "a", "type": "prismatic", "axis": "z"}},
        1: {"joint": {"name": "b", "type": "prismatic"}},
        2: {"joint": {"name": "r", "type": "revolute"}}}}})
    robot = parsed(config)
    assert [(j.name, j.axis) for j in robot.joints] == [("a", [0, 0, 1]), ("b", [1, 0, 0]), ("r", [0, 0, 1])]
    # axis 3 has no joint: not in the description
    assert [link.name for link in robot.links] == ["base_link", "a_link", "b_link", "r_link"]


def test_a_bad_joint_axis_is_refused_with_its_key():
    with pytest.raises(ConfigError, match=r"axes\[0\]\.joint\.axis: expected one of x, y, z"):
        load(overrides={"axes": {"overrides": {0: {"joint": {"name": "a", "axis": "w"}}}}})


def test_a_namespace_prefixes_every_joint_and_link():
    robot = parsed(load(GANTRY, overrides={"ros": {"namespace": "/cell_a"}}))
    assert robot.name == "cell_a"
    assert robot.get_root() == "cell_a/base_link"
    assert robot.get_chain("cell_a/base_link", "cell_a/c_link", links=False) == \
        ["cell_a/x", "cell_a/y", "cell_a/z", "cell_a/c"]


def test_without_joints_the_description_is_the_base_link_alone():
    robot = parsed(load())
    assert [link.name for link in robot.links] == ["base_link"]
    assert robot.joints == []


# -- forward kinematics over the parsed chain ---------------------------------------------------
def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' formula: the rotation of ``angle`` about the unit vector ``axis``."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    x, y, z = np.eye(3)
    return _rotation(z, yaw) @ _rotation(y, pitch) @ _rotation(x, roll)


def forward_kinematics(robot: URDF, positions: dict[str, float]) -> dict[str, np.ndarray]:
    """Every link's pose (4x4) in the root link, composed joint by joint from the root:
    parent pose x joint origin x the joint's motion along or about its axis (URDF)."""
    poses = {robot.get_root(): np.eye(4)}
    pending = list(robot.joints)
    while pending:
        joint = next(j for j in pending if j.parent in poses)
        pending.remove(joint)
        origin = np.eye(4)
        if joint.origin is not None:
            origin[:3, :3] = _rpy(*joint.origin.rpy)
            origin[:3, 3] = joint.origin.xyz
        axis = np.asarray(joint.axis, dtype=float)
        motion = np.eye(4)
        if joint.type == "prismatic":
            motion[:3, 3] = axis * positions[joint.name]
        elif joint.type in ("revolute", "continuous"):
            motion[:3, :3] = _rotation(axis, positions[joint.name])
        poses[joint.child] = poses[joint.parent] @ origin @ motion
    return poses


def test_forward_kinematics_at_the_twins_joint_states_puts_each_link_where_the_counts_say():
    from mpi_ros.ros import convert

    config = load(GANTRY)
    ctl = config.build_controller()
    # X to 250,000 counts, Y to 100,000; Z down 100,000 counts, C a quarter turn (2,500 counts)
    for number, position in ((0, [250_000.0, 100_000.0]), (1, [100_000.0, 2_500.0])):
        reply = apply(ctl, Command(Operation.MOTION_START, number, request={"type": "S_CURVE", "position": position,
                                                                  "trajectory": S_CURVE}))
        assert reply.accepted, reply
    for samples in (500, 4000):  # on the way, then at rest
        ctl.step(samples)
        state = convert.joint_state(ctl, 0, JointStates(config.axis_joints()))
        counts = [axis.actual_position for axis in ctl.axes]
        poses = forward_kinematics(parsed(config), dict(zip(state.name, state.position, strict=True)))
        x, y, z = counts[0] / 1e6, counts[1] / 1e6, 0.3 - counts[2] / 1e6
        c = counts[3] * 2 * math.pi / 10_000
        assert poses["x_link"][:3, 3] == pytest.approx([x, 0.0, 0.0], abs=1e-12)
        assert poses["y_link"][:3, 3] == pytest.approx([x, y, 0.0], abs=1e-12)
        assert poses["z_link"][:3, 3] == pytest.approx([x, y, z], abs=1e-12)
        assert poses["c_link"][:3, 3] == pytest.approx([x, y, z], abs=1e-12)
        assert poses["c_link"][:3, :3] == pytest.approx(np.array(
            [[math.cos(c), -math.sin(c), 0.0], [math.sin(c), math.cos(c), 0.0], [0.0, 0.0, 1.0]]), abs=1e-12)
        if samples == 500:
            assert 0.0 < counts[0] < 250_000.0
            assert 0.0 < counts[3] < 2_500.0
    assert counts == pytest.approx([250_000.0, 100_000.0, 100_000.0, 2_500.0], abs=10.0)


# -- a user's own URDF --------------------------------------------------------------------------
def _user_urdf(tmp_path: Path, joints: dict[str, str]) -> Path:
    body = "".join(f'<joint name="{name}" type="{kind}"><parent link="l{i}"/><child link="l{i + 1}"/>'
                   f'<limit lower="0" upper="1" effort="1" velocity="1"/></joint>'
                   for i, (name, kind) in enumerate(joints.items()))
    path = tmp_path / "machine.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="m"><link name="l0"/>{body}</robot>', encoding="utf-8")
    return path


def _gantry_with(tmp_path: Path, robot_description: str):
    config = tmp_path / "machine.yaml"
    config.write_text(GANTRY.read_text(encoding="utf-8").replace(
        "ros:\n  namespace: /mpi", f"ros:\n  namespace: /mpi\n  robot_description: {robot_description}"),
        encoding="utf-8")
    return load(config)


def test_a_user_urdf_that_has_every_joint_is_published_as_it_is(tmp_path):
    path = _user_urdf(tmp_path, {"x": "prismatic", "y": "prismatic", "z": "prismatic", "c": "continuous",
                                 "spindle": "continuous"})
    config = _gantry_with(tmp_path, "machine.urdf")  # relative: to the configuration's folder
    assert description.robot_description(config) == path.read_text(encoding="utf-8")


def test_a_user_urdf_without_a_joint_or_of_another_type_stops_the_suite_naming_them(tmp_path):
    _user_urdf(tmp_path, {"x": "prismatic", "z": "revolute", "c": "continuous"})
    config = _gantry_with(tmp_path, "machine.urdf")
    with pytest.raises(ConfigError) as exc:
        description.robot_description(config)
    assert str(exc.value) == (
        f"ros.robot_description: {tmp_path / 'machine.urdf'}: joints of the configuration not in it: y; "
        "joints of another type: z (prismatic in the configuration, revolute in the file)")


@pytest.mark.parametrize(("text", "expected"), [
    ("<robot", "not a URDF (XML: "),
    ("<sdf version='1.6'/>", "not a URDF (the root element is <sdf>, not <robot>)"),
])
def test_a_user_file_that_is_no_urdf_is_refused(tmp_path, text, expected):
    (tmp_path / "machine.urdf").write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError, match=r"ros\.robot_description: .*machine\.urdf: " + expected.replace("(", r"\(")
                       .replace(")", r"\)")):
        description.robot_description(_gantry_with(tmp_path, "machine.urdf"))


def test_a_missing_user_file_is_refused(tmp_path):
    with pytest.raises(ConfigError, match=r"ros\.robot_description: .*nowhere\.urdf: cannot read it"):
        description.robot_description(_gantry_with(tmp_path, "nowhere.urdf"))


# -- mpi-ros urdf -----------------------------------------------------------------------------
def test_the_urdf_command_prints_the_description(capsys):
    from mpi_ros.cli import main

    assert main(["urdf", "--config", str(GANTRY), "--namespace", "/cell_b"]) == 0
    printed = capsys.readouterr().out
    assert printed == description.generate(load(GANTRY, overrides={"ros": {"namespace": "/cell_b"}}))
    assert URDF.from_xml_string(printed).get_root() == "cell_b/base_link"


def test_the_urdf_command_exits_2_on_a_mismatched_user_urdf(tmp_path, capsys):
    from mpi_ros.cli import main

    _user_urdf(tmp_path, {"x": "prismatic"})
    config = _gantry_with(tmp_path, "machine.urdf")
    assert main(["urdf", "--config", config.source]) == 2
    assert capsys.readouterr().err.startswith("mpi-ros urdf: invalid configuration: ros.robot_description: ")
    assert main(["urdf", "--config", config.source, "--generated"]) == 0
    assert capsys.readouterr().out == description.generate(config)


def test_the_suite_refuses_to_start_on_a_mismatched_user_urdf_and_exits_2_naming_the_joints(tmp_path):
    import subprocess
    import sys

    _user_urdf(tmp_path, {"x": "prismatic", "y": "revolute"})
    config = _gantry_with(tmp_path, "machine.urdf")
    proc = subprocess.run([sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--config", config.source],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().endswith(
        f"mpi-ros run: invalid configuration: ros.robot_description: {tmp_path / 'machine.urdf'}: joints of the "
        "configuration not in it: z, c; joints of another type: y (prismatic in the configuration, revolute in "
        "the file)")
