"""The machine's robot description: a URDF generated from the configured joints, or the
user's own URDF checked against them (docs/joints.md, "The robot description").

Generated: a chain from ``<prefix>base_link`` through one link per configured joint, in axis
order (axis k's joint moves link ``<joint>_link`` relative to the link before it). Every joint
origin is at its parent link's origin: the description places the links where the joints
put them, not where a machine's parts sit (a user who wants geometry writes a URDF and
names it in ``ros.robot_description``). Per joint:

- ``<axis>``: the joint's ``axis`` (x, y or z); without one, prismatic joints take x, y, z
  in their order among the prismatic joints (a fourth starts again at x), revolute and
  continuous joints turn about z.
- ``<limit lower upper>`` (revolute and prismatic, where URDF requires them): the axis'
  software limits (docs/faults.md) in the joint's units where they are enabled; a side
  without one gets the end of the controller's 32-bit position range (MPI 000: positions are
  reported in [-2^31, 2^31) counts), the furthest the joint can be reported at. A negative
  counts_per_unit swaps the sides: the lower limit comes from the positive count limit.
- ``<limit velocity>``: the joint's max_velocity; 0 where none is given (the configuration's
  own "none"). ``effort`` is 0: the twin has no force or torque limit (its effort, on
  /joint_states, is the servo's acceleration demand in units/s^2).
- Each joint is preceded by a comment that says where its limits came from.

Axes without a joint block are not in the description (they report counts under ``axis<k>``).
The limits are the configuration's at start: a later ``fault_config_set`` does not change the
published description.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

from mpi_ros import config as suite_config
from mpi_ros.config import ConfigError, SuiteConfig
from mpi_ros.joints import JOINT_AXES, AxisJoint, Joint
from mpi_ros.mpi.base.params import AxisFaultConfig
from mpi_ros.mpi.base.wrap import HALF

_AXIS_VECTORS = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}


def _number(x: float) -> str:
    """Shortest text that reads back as the same double (repr), without a spurious "-0"."""
    return repr(float(x) + 0.0)


def load(path: str | Path | None = None, namespace: str | None = None) -> SuiteConfig:
    """The configuration a suite started with ``--config path --namespace namespace`` runs
    (what ``mpi-ros urdf`` and launch/machine.launch.py describe). ConfigError if bad."""
    config = suite_config.load(path)
    if namespace:
        suite_config.check_namespace(namespace, "--namespace")
        config = suite_config.parse(suite_config.merge(config.raw, {"ros": {"namespace": namespace}}), config.source)
    return config


def base_link(config: SuiteConfig) -> str:
    return f"{config.ros.joint_prefix}base_link"


def link_of(joint_name: str) -> str:
    """The link a joint moves (``joint_name`` with its namespace prefix)."""
    return f"{joint_name}_link"


def joint_axes(joints: Sequence[AxisJoint]) -> dict[str, str]:
    """Every configured joint's axis (x, y or z): its own, else by the rule above."""
    out, prismatic = {}, 0
    for axis_joint in joints:
        joint = axis_joint.joint
        if joint is None:
            continue
        if joint.axis:
            out[axis_joint.name] = joint.axis
        elif joint.type == "prismatic":
            out[axis_joint.name] = JOINT_AXES[prismatic % len(JOINT_AXES)]
            prismatic += 1
        else:
            out[axis_joint.name] = "z"
    return out


def position_limits(joint: Joint, faults: AxisFaultConfig) -> tuple[float, float, str]:
    """(lower, upper, where they came from) in the joint's units."""
    negative = faults.software_limit_negative if faults.software_limit_negative_enabled else -HALF
    positive = faults.software_limit_positive if faults.software_limit_positive_enabled else HALF
    enabled = {"negative": faults.software_limit_negative_enabled, "positive": faults.software_limit_positive_enabled}
    lower, upper = sorted((joint.position(negative), joint.position(positive)))
    if all(enabled.values()):
        source = "the software limits"
    elif any(enabled.values()):
        on = next(side for side, state in enabled.items() if state)
        source = f"the {on} software limit; the other side: the 32-bit position range"
    else:
        source = "no software limit enabled: the 32-bit position range"
    return lower, upper, source


def _axis_faults(config: SuiteConfig, axis: int) -> AxisFaultConfig:
    return config.faults[axis] if config.faults else AxisFaultConfig()


def generate(config: SuiteConfig) -> str:
    """The URDF of the configured joints (see the module's description)."""
    joints = config.axis_joints()
    robot = ET.Element("robot", name=config.ros.namespace.strip("/").replace("/", "_"))
    source = Path(str(config.source))  # absolute: the same text whoever reads the file from where
    shown = source.resolve() if source.is_file() else source
    robot.append(ET.Comment(f" generated by mpi-ros urdf from {shown} (docs/joints.md) "))
    parent = base_link(config)
    ET.SubElement(robot, "link", name=parent)
    axes = joint_axes(joints)
    for axis_joint in joints:
        joint = axis_joint.joint
        if joint is None:
            continue
        child = link_of(axis_joint.name)
        robot.append(ET.Comment(f" {axis_joint.name}: controller axis {axis_joint.axis}, "
                                 f"{_limit_note(config, axis_joint)} "))
        element = ET.SubElement(robot, "joint", name=axis_joint.name, type=joint.type)
        ET.SubElement(element, "parent", link=parent)
        ET.SubElement(element, "child", link=child)
        ET.SubElement(element, "origin", xyz="0 0 0", rpy="0 0 0")
        ET.SubElement(element, "axis", xyz=_AXIS_VECTORS[axes[axis_joint.name]])
        limit = {"effort": "0", "velocity": _number(joint.max_velocity)}
        if joint.type != "continuous":
            lower, upper, _ = position_limits(joint, _axis_faults(config, axis_joint.axis))
            limit = {"lower": _number(lower), "upper": _number(upper), **limit}
        ET.SubElement(element, "limit", limit)
        ET.SubElement(robot, "link", name=child)
        parent = child
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def _limit_note(config: SuiteConfig, axis_joint: AxisJoint) -> str:
    joint = axis_joint.joint
    assert joint is not None
    velocity = "velocity from max_velocity" if joint.max_velocity > 0 else "no max_velocity: velocity 0"
    if joint.type == "continuous":
        return f"continuous (no position limits), {velocity}"
    return f"position limits from {position_limits(joint, _axis_faults(config, axis_joint.axis))[2]}, {velocity}"


def description_path(config: SuiteConfig) -> Path | None:
    """``ros.robot_description`` as a path: relative to the configuration file's folder."""
    given = config.ros.robot_description
    if not given:
        return None
    path = Path(given).expanduser()
    source = Path(str(config.source))
    if not path.is_absolute() and source.is_file():
        path = source.parent / path
    return path


def check(text: str, joints: Sequence[AxisJoint], where: str) -> None:
    """ConfigError unless every configured joint is in the URDF ``text`` with the same type;
    the error names every joint that is missing or of another type."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ConfigError(f"{where}: not a URDF (XML: {exc})") from None
    if root.tag != "robot":
        raise ConfigError(f"{where}: not a URDF (the root element is <{root.tag}>, not <robot>)")
    found = {j.get("name"): j.get("type") for j in root.findall("joint")}
    wanted = [(aj.name, aj.joint.type) for aj in joints if aj.joint is not None]
    missing = [name for name, _ in wanted if name not in found]
    other = [f"{name} ({kind} in the configuration, {found[name]} in the file)"
             for name, kind in wanted if name in found and found[name] != kind]
    problems = ([f"joints of the configuration not in it: {', '.join(missing)}"] if missing else []) + \
               ([f"joints of another type: {', '.join(other)}"] if other else [])
    if problems:
        raise ConfigError(f"{where}: {'; '.join(problems)}")


def robot_description(config: SuiteConfig) -> str:
    """What the suite publishes on <ns>/robot_description: the user's URDF
    (``ros.robot_description``), checked against the joints, or the generated one.
    ConfigError (the key named) if the file cannot be read or does not match."""
    path = description_path(config)
    if path is None:
        return generate(config)
    where = f"ros.robot_description: {path}"
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{where}: cannot read it ({exc})") from None
    check(text, config.axis_joints(), where)
    return text
