"""mpi_ros/graph_names.py: the suite's names, types and QoS are the ROS contract's, and are
spelled nowhere else in the package."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from mpi_ros import graph_names as gn

PACKAGE = Path(__file__).resolve().parents[1] / "mpi_ros"

# The ROS contract (docs/decisions.md, "The ROS contract"), written out by hand: full name
# in the default namespace, for supervisor 0 and axis 1, -> interface type.
CONTRACT = {
    "/mpi/ms0/motion_start": "mpi_ros/action/MotionStart",
    "/mpi/ms0/motion_modify": "mpi_ros/action/MotionModify",
    "/mpi/ms0/action": "mpi_ros/srv/MotionAction",
    "/mpi/ms0/stop": "std_srvs/srv/Trigger",
    "/mpi/ms0/e_stop": "std_srvs/srv/Trigger",
    "/mpi/ms0/abort": "std_srvs/srv/Trigger",
    "/mpi/ms0/reset": "std_srvs/srv/Trigger",
    "/mpi/ms0/resume": "std_srvs/srv/Trigger",
    "/mpi/ms0/status": "mpi_ros/msg/MotionStatus",
    "/mpi/axis1/status": "mpi_ros/msg/AxisStatus",
    "/mpi/events": "mpi_ros/msg/MotionEvent",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
    # "further services ... under /mpi/ms<n>/... or /mpi/axis<k>/..."
    "/mpi/ms0/config_get": "mpi_ros/srv/MotionConfigGet",
    "/mpi/ms0/params_set": "mpi_ros/srv/MotionParamsSet",
    "/mpi/ms0/axis_list_get": "mpi_ros/srv/AxisListGet",
    "/mpi/ms0/frame_buffer_status": "mpi_ros/srv/FrameBufferStatusGet",
    "/mpi/ms0/event_notify_set": "mpi_ros/srv/EventNotifySet",
    "/mpi/axis1/config_get": "mpi_ros/srv/AxisConfigGet",
    "/mpi/axis1/position_set": "mpi_ros/srv/AxisPositionSet",
    "/mpi/gate_set": "mpi_ros/srv/GateSet",
    "/clock": "rosgraph_msgs/msg/Clock",
    "/mpi/commands": "mpi_ros/msg/Command",
    "/mpi/configuration": "mpi_ros/msg/SuiteConfiguration",
    # issue 34: amplifier enable, axis events, meiMotionParamsValidate, Axis objects, the flash
    "/mpi/axis1/amp_enable_set": "mpi_ros/srv/AmpEnableSet",
    "/mpi/axis1/event_notify_get": "mpi_ros/srv/EventNotifyGet",
    "/mpi/axis1/event_reset": "mpi_ros/srv/EventReset",
    "/mpi/ms0/params_validate": "mpi_ros/srv/MotionParamsValidate",
    "/mpi/axis_create": "mpi_ros/srv/AxisCreate",
    "/mpi/axis_delete": "mpi_ros/srv/AxisDelete",
    "/mpi/axis_validate": "mpi_ros/srv/AxisValidate",
    "/mpi/ms0/flash_config_set": "mpi_ros/srv/MotionFlashConfigSet",
    "/mpi/axis1/flash_config_get": "mpi_ros/srv/AxisFlashConfigGet",
}


def test_the_names_are_the_contracts():
    table = gn.suite_endpoints(gn.DEFAULT_NAMESPACE, [0], [1])
    assert {name: table[name].type for name in CONTRACT} == CONTRACT
    assert {e.kind for name, e in table.items() if "motion_" in name} == {gn.Kind.ACTION}


def test_a_suite_in_another_namespace_keeps_its_names_apart():
    table = gn.suite_endpoints("/cell_a", [1], [3])
    assert gn.joint_states("/cell_a") == "/cell_a/joint_states"
    assert "/cell_a/ms1/motion_start" in table
    assert "/cell_a/axis3/status" in table
    shared = sorted(name for name in table if not name.startswith("/cell_a/"))
    assert shared == ["/clock", "/diagnostics"]  # shared by design: statuses are named by namespace


def test_every_endpoint_is_listed_once():
    assert len(set(gn.ENDPOINTS)) == len(gn.ENDPOINTS)
    numbered = (gn.Owner.SUPERVISOR, gn.Owner.AXIS)
    names = [e.name("/mpi", 0 if e.owner in numbered else None) for e in gn.ENDPOINTS]
    assert len(set(names)) == len(names)
    assert gn.axis_status_number("/mpi", "/mpi/axis12/status") == 12
    assert gn.axis_status_number("/mpi", "/mpi/ms1/status") is None


def test_a_number_is_required_exactly_where_the_owner_has_one():
    with pytest.raises(ValueError, match="needs number"):
        gn.MOTION_STATUS.name("/mpi")
    with pytest.raises(ValueError, match="takes no number"):
        gn.EVENTS.name("/mpi", 0)


def test_bad_profiles_and_endpoints_are_refused():
    with pytest.raises(ValueError, match="depth"):
        gn.Qos(0)
    with pytest.raises(ValueError, match="depth"):
        gn.Qos(True)
    with pytest.raises(ValueError, match="pkg/srv/Type"):
        gn.Endpoint(gn.Kind.SERVICE, gn.Owner.SUITE, "x", "mpi_ros/msg/X", gn.SERVICE_QOS)
    with pytest.raises(ValueError, match="relative name"):
        gn.Endpoint(gn.Kind.TOPIC, gn.Owner.SUITE, "/x", "mpi_ros/msg/X", gn.SERVICE_QOS)


def test_the_rclpy_profiles_equal_the_plain_data():
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy, qos_profile_action_status_default

    from mpi_ros.qos import profile

    clock = profile(gn.CLOCK.qos)
    assert (clock.depth, clock.reliability, clock.durability) == (1, ReliabilityPolicy.BEST_EFFORT,
                                                                   DurabilityPolicy.VOLATILE)
    commands = profile(gn.COMMANDS.qos)
    assert (commands.depth, commands.durability) == (1000, DurabilityPolicy.TRANSIENT_LOCAL)
    assert profile(gn.ACTION_STATUS_QOS) == qos_profile_action_status_default
    assert profile(gn.Qos(1000)) is profile(gn.ACTION_SERVICE_QOS)  # the goal front checks identity


# -- no name or QoS spelled elsewhere -------------------------------------------------------------------
# A path ending in an endpoint's leaf, a supervisor or axis prefix, an action's internals, an
# interface type or the default namespace.
_LEAVES = "|".join(sorted({re.escape(e.leaf) for e in gn.ENDPOINTS}))
_STRAY = re.compile(rf"/({_LEAVES})$|/(ms|axis)\{{\}}|_action/|^\w+/(msg|srv|action)/\w+$|^/mpi(/|$)")
_EXEMPT = {PACKAGE / "graph_names.py", PACKAGE / "qos.py"}
# (file, literal) pairs that match the pattern for another reason, each with why: none today.
_ALLOWED: dict[tuple[str, str], str] = {}
_ROS_CALLS = {"create_publisher", "create_subscription", "create_service", "create_client", "ActionClient",
              "ActionServer"}


def _sources() -> list[Path]:
    return [p for p in sorted(PACKAGE.rglob("*.py")) if "mpi" not in p.relative_to(PACKAGE).parts[:1]
            and p not in _EXEMPT]


def _texts(tree: ast.AST) -> list[tuple[int, str]]:
    """Every string literal outside docstrings (an f-string with ``{}`` for its values)."""
    skip: set[int] = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) and isinstance(body[0].value,
                                                                                            ast.Constant):
            skip.add(id(body[0].value))
        if isinstance(node, ast.JoinedStr):
            skip.update(id(v) for v in node.values)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            found.append((node.lineno, "".join(v.value if isinstance(v, ast.Constant) else "{}"
                                               for v in node.values)))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip:
            found.append((node.lineno, node.value))
    return found


def test_no_endpoint_name_or_type_is_spelled_outside_graph_names():
    strays = []
    for path in _sources():
        relative = path.relative_to(PACKAGE).as_posix()
        for line, text in _texts(ast.parse(path.read_text())):
            if _STRAY.search(text) and (relative, text) not in _ALLOWED:
                strays.append(f"mpi_ros/{relative}:{line}: {text!r}")
    assert strays == []


def _call_name(node: ast.Call) -> str:
    return node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")


def test_endpoints_are_created_from_graph_names_and_qos_from_its_profiles():
    """No literal name or QoS depth in a call that creates an endpoint, and rclpy's QoS
    classes are used in mpi_ros/qos.py alone."""
    strays = []
    for path in _sources():
        relative = path.relative_to(PACKAGE).as_posix()
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == "rclpy.qos":
                # a type hint may name QoSProfile; no policy or profile may be taken from rclpy
                strays += [f"{relative}:{node.lineno}: rclpy.qos.{a.name}" for a in node.names
                           if a.name != "QoSProfile"]
            if not isinstance(node, ast.Call):
                continue
            name = _call_name(node)
            if name == "QoSProfile":
                strays.append(f"{relative}:{node.lineno}: QoSProfile(...)")
            if name in _ROS_CALLS:
                literal = [a for a in [*node.args, *(k.value for k in node.keywords)]
                           if isinstance(a, ast.JoinedStr) or (isinstance(a, ast.Constant)
                                                               and isinstance(a.value, (str, int)))]
                strays += [f"{relative}:{node.lineno}: {name}(... {ast.unparse(a)} ...)" for a in literal]
    assert strays == []
