"""Axes as joints (docs/joints.md): one validator for the joint block, conversions between
counts and SI units, the names the graph uses."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from mpi_ros.config import ConfigError, load
from mpi_ros.joints import Joint

GANTRY = Path(__file__).resolve().parents[1] / "config" / "gantry.yaml"


def _with_joint(joint: dict, axis: int = 0):
    return load(overrides={"axes": {"overrides": {axis: {"joint": joint}}}})


def test_axes_without_a_joint_keep_their_names_and_counts():
    joints = load().axis_joints()
    assert [j.name for j in joints] == ["axis0", "axis1", "axis2", "axis3"]
    assert joints[1].position(1234.5) == 1234.5
    assert joints[1].rate(-7.0) == -7.0


def test_the_gantry_names_its_joints_in_si_units():
    joints = load(GANTRY).axis_joints()
    assert [j.name for j in joints] == ["x", "y", "z", "c"]
    assert joints[0].position(250_000.0) == pytest.approx(0.25)
    # Z counts downward from 0.3 m at count 0
    assert joints[2].position(100_000.0) == pytest.approx(0.2)
    assert joints[2].rate(50_000.0) == pytest.approx(-0.05)
    # C: 10,000 counts a turn
    assert joints[3].position(10_000.0) == pytest.approx(2 * math.pi)


def test_a_namespace_prefixes_every_joint_name():
    config = load(GANTRY, overrides={"ros": {"namespace": "/cell_a"}})
    assert [j.name for j in config.axis_joints()] == ["cell_a/x", "cell_a/y", "cell_a/z", "cell_a/c"]


@pytest.mark.parametrize(("joint", "expected"), [
    ({"name": "2x"}, "axes[0].joint.name: expected letters"),
    ({"name": "x", "type": "fixed"}, "axes[0].joint.type: expected one of revolute, prismatic, continuous"),
    ({"name": "x", "counts_per_unit": 0.0}, "axes[0].joint.counts_per_unit: expected a finite, non-zero"),
    ({"name": "x", "counts_per_unit": ".nan"}, "axes[0].joint.counts_per_unit: expected a finite number"),
    ({"name": "x", "max_velocity": -1.0}, "axes[0].joint.max_velocity: expected a finite number >= 0"),
    ({"name": "x", "stiffness": 3.0}, "axes[0].joint.stiffness: unknown key"),
    ({"type": "revolute"}, "axes[0].joint.name: a joint needs a name"),
    ({"name": "axis2"}, "axes[0].joint.name: 'axis2' is already the name of axis 2"),
    ("x", "axes[0].joint: expected a mapping"),
])
def test_a_bad_joint_stops_the_suite_with_its_key_named(joint, expected):
    with pytest.raises(ConfigError, match=expected.replace("[", r"\[").replace("]", r"\]")):
        _with_joint(joint)


def test_two_joints_of_one_name_are_refused():
    with pytest.raises(ConfigError, match=r"axes\[1\]\.joint\.name: 'x' is already the name of axis 0"):
        load(overrides={"axes": {"overrides": {0: {"joint": {"name": "x"}}, 1: {"joint": {"name": "x"}}}}})


def test_conversions_are_inverse_and_a_negative_scale_flips_the_direction():
    joint = Joint(name="q", type="revolute", counts_per_unit=-2000.0, offset=0.5)
    assert joint.validate().ok
    for counts in (-1e6, -3.25, 0.0, 17.0, 4e8):
        assert joint.counts(joint.position(counts)) == pytest.approx(counts, rel=1e-12, abs=1e-9)
    assert joint.position(2000.0) == pytest.approx(-0.5)
    assert joint.counts_rate(joint.rate(123.0)) == pytest.approx(123.0)


def test_joint_states_convert_every_axis_as_its_joint_and_leave_the_others_bit_for_bit():
    from mpi_ros.joints import JointStates

    config = load(overrides={"axes": {"overrides": {1: {"joint": {"name": "q", "type": "revolute",
                                                                   "counts_per_unit": -2000.0, "offset": 0.5}}}}})
    joints = config.axis_joints()
    states = JointStates(joints)
    assert states.names == ("axis0", "q", "axis2", "axis3")
    position, velocity, effort = [-0.0, 1000.0, 3.25, -7.5], [0.0, -400.0, -0.0, 1e300], [-0.0, 8000.0, 2.0, -1.0]
    out = states.convert(position, velocity, effort)
    for k in (0, 2, 3):  # counts as they were, the sign of a zero included
        for converted, given in zip(out, (position, velocity, effort), strict=True):
            assert converted[k] == given[k]
            assert math.copysign(1.0, converted[k]) == math.copysign(1.0, given[k])
    joint = joints[1]
    assert (out[0][1], out[1][1], out[2][1]) == (joint.position(1000.0), joint.rate(-400.0), joint.rate(8000.0))
    assert (out[0][1], out[1][1], out[2][1]) == (0.0, 0.2, -4.0)
    # a suite without joints: the lists themselves, untouched
    plain = JointStates(load().axis_joints())
    assert plain.convert(position, velocity, effort) == (position, velocity, effort)
