"""The suite's names on the ROS graph: every topic, service and action, its interface type and its QoS.

This is the one place they are spelled (test/test_graph_names.py greps the package for strays).
The nodes, the recorder, replay, the client, discovery and the console read them from here.
Pure data: no rclpy, so the client, the bag tools and the tests can import it anywhere;
:func:`mpi_ros.ros.qos.profile` turns a :class:`Qos` into rclpy's QoSProfile.

Names follow the ROS contract (docs/decisions.md, "The ROS contract"): supervisor ``n`` is
node ``<ns>/ms<n>``, axis ``k``'s endpoints are under ``<ns>/axis<k>``, the controller's
under ``<ns>``; /joint_states (for the default namespace), /diagnostics and /clock are at the root.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum

DEFAULT_NAMESPACE = "/mpi"
SUPERVISOR_NODE = re.compile(r"ms(\d+)")  # a supervisor's node name within its namespace
CONTROLLER_NODE = "controller"  # the controller node, <ns>/controller


class Reliability(StrEnum):
    RELIABLE = "reliable"
    BEST_EFFORT = "best_effort"


class Durability(StrEnum):
    VOLATILE = "volatile"
    TRANSIENT_LOCAL = "transient_local"  # latched: a late subscriber gets the last `depth` messages


class History(StrEnum):
    KEEP_LAST = "keep_last"
    KEEP_ALL = "keep_all"


@dataclass(frozen=True, slots=True)
class Qos:
    """A QoS profile as plain data (the policies the suite sets; the rest are rmw's defaults)."""

    depth: int
    reliability: Reliability = Reliability.RELIABLE
    durability: Durability = Durability.VOLATILE
    history: History = History.KEEP_LAST

    def __post_init__(self) -> None:
        if isinstance(self.depth, bool) or not isinstance(self.depth, int) or self.depth < 1:
            raise ValueError(f"a QoS depth is a whole number >= 1, got {self.depth!r}")


# -- the profiles ---------------------------------------------------------------------------------
# The status writers keep 1000 samples for their readers: a suite catching up after a stall
# publishes many status points of a topic at once, and a reliable writer keeping fewer drops
# the oldest of a burst before a reader has them (gaps in the soak: with 10, and with 100 in a
# 10-minute soak that fell 2.4 s behind, 235 points of each topic at once). 1000 rides out 10 s
# at 100 Hz, 1 s at 1 kHz. Depth is not part of QoS matching, so readers keep whatever history
# they ask for.
STATUS_QOS = Qos(1000)
STATUS_READER_QOS = Qos(10)  # a client keeps the latest statuses only
# Events come in bursts (6-7 in one sample at the end of a move) and are never dropped: deep and reliable.
EVENTS_QOS = Qos(1000)
COMMAND_HISTORY = 1000
# Applied commands: reliable, deep, and kept for late joiners (a recorder started after the
# first moves still gets them; a subscriber asking for volatile durability is matched too).
COMMANDS_QOS = Qos(COMMAND_HISTORY, durability=Durability.TRANSIENT_LOCAL)
LATCHED_QOS = Qos(1, durability=Durability.TRANSIENT_LOCAL)  # published once (configuration, robot description)
CLOCK_QOS = Qos(1, reliability=Reliability.BEST_EFFORT)
SENSOR_QOS = Qos(10)  # /joint_states and /diagnostics: rclpy's default for a depth of 10
FEEDBACK_QOS = Qos(10)  # rclpy's ActionServer default for its feedback publisher
TRAJECTORY_QOS = Qos(10)  # as joint_trajectory_controller's ~/joint_trajectory subscription
SERVICE_QOS = Qos(10)  # rclpy's default for services (qos_profile_services_default)
# The action servers' services keep deep queues (an E_STOP can end many goals at once); a
# client asks for the same so no result is dropped on its side either.
ACTION_SERVICE_QOS = Qos(1000)
ACTION_STATUS_QOS = Qos(1, durability=Durability.TRANSIENT_LOCAL)  # rcl_action's status topic default
PLAYBACK_QOS = Qos(1000)  # `mpi-ros play` publishes a bag's topics reliably, in bursts


# -- the endpoints ------------------------------------------------------------------------------------
class Kind(StrEnum):
    TOPIC = "topic"
    SERVICE = "service"
    ACTION = "action"


class Owner(StrEnum):
    """Where an endpoint's name lives."""

    SUPERVISOR = "supervisor"  # <ns>/ms<n>/<leaf>
    AXIS = "axis"  # <ns>/axis<k>/<leaf>
    SUITE = "suite"  # <ns>/<leaf> (the controller node's)
    ROOT = "root"  # /<leaf>, shared by every suite of a cell


@dataclass(frozen=True, slots=True)
class Endpoint:
    """One endpoint: its name below its owner, its interface type (``pkg/msg/Type``,
    ``pkg/srv/Type`` or ``pkg/action/Type``) and its QoS (an action's: its services')."""

    kind: Kind
    owner: Owner
    leaf: str
    type: str
    qos: Qos

    def __post_init__(self) -> None:
        folder = {Kind.TOPIC: "msg", Kind.SERVICE: "srv", Kind.ACTION: "action"}[self.kind]
        parts = self.type.split("/")
        if len(parts) != 3 or parts[1] != folder or not self.leaf or self.leaf.startswith("/"):
            raise ValueError(f"{self.leaf!r}: a {self.kind} needs a relative name and a pkg/{folder}/Type, "
                             f"got {self.type!r}")

    def name(self, namespace: str = DEFAULT_NAMESPACE, number: int | None = None) -> str:
        """The full name: ``number`` is the supervisor's or the axis' (by the owner)."""
        numbered = self.owner in (Owner.SUPERVISOR, Owner.AXIS)
        if numbered != (number is not None):
            raise ValueError(f"{self.leaf}: a {self.owner} endpoint {'needs' if numbered else 'takes no'} number")
        if number is not None:
            prefix = supervisor_node if self.owner is Owner.SUPERVISOR else axis_prefix
            return f"{prefix(namespace, number)}/{self.leaf}"
        return f"/{self.leaf}" if self.owner is Owner.ROOT else f"{ns(namespace)}/{self.leaf}"


def ns(namespace: str) -> str:
    """A namespace as the names use it: absolute, no trailing slash (``mpi`` -> ``/mpi``)."""
    return "/" + namespace.strip("/")


def supervisor_node(namespace: str, number: int) -> str:
    """The node of supervisor ``number``: ``<ns>/ms<n>``."""
    return f"{ns(namespace)}/ms{number}"


def axis_prefix(namespace: str, number: int) -> str:
    """Where axis ``number``'s endpoints are: ``<ns>/axis<k>``."""
    return f"{ns(namespace)}/axis{number}"


def _topic(owner: Owner, leaf: str, type_: str, qos: Qos) -> Endpoint:
    return Endpoint(Kind.TOPIC, owner, leaf, type_, qos)


def _service(owner: Owner, leaf: str, type_: str) -> Endpoint:
    return Endpoint(Kind.SERVICE, owner, leaf, type_, SERVICE_QOS)


# topics
MOTION_STATUS = _topic(Owner.SUPERVISOR, "status", "mpi_ros/msg/MotionStatus", STATUS_QOS)
JOINT_TRAJECTORY = _topic(Owner.SUPERVISOR, "joint_trajectory", "trajectory_msgs/msg/JointTrajectory", TRAJECTORY_QOS)
AXIS_STATUS = _topic(Owner.AXIS, "status", "mpi_ros/msg/AxisStatus", STATUS_QOS)
EVENTS = _topic(Owner.SUITE, "events", "mpi_ros/msg/MotionEvent", EVENTS_QOS)
COMMANDS = _topic(Owner.SUITE, "commands", "mpi_ros/msg/Command", COMMANDS_QOS)
CONFIGURATION = _topic(Owner.SUITE, "configuration", "mpi_ros/msg/SuiteConfiguration", LATCHED_QOS)
ROBOT_DESCRIPTION = _topic(Owner.SUITE, "robot_description", "std_msgs/msg/String", LATCHED_QOS)
# /joint_states is at the root for the default namespace only: see joint_states()
JOINT_STATES = _topic(Owner.ROOT, "joint_states", "sensor_msgs/msg/JointState", SENSOR_QOS)
CELL_JOINT_STATES = _topic(Owner.SUITE, "joint_states", "sensor_msgs/msg/JointState", SENSOR_QOS)
DIAGNOSTICS = _topic(Owner.ROOT, "diagnostics", "diagnostic_msgs/msg/DiagnosticArray", SENSOR_QOS)
CLOCK = _topic(Owner.ROOT, "clock", "rosgraph_msgs/msg/Clock", CLOCK_QOS)

# actions
MOTION_START = Endpoint(Kind.ACTION, Owner.SUPERVISOR, "motion_start", "mpi_ros/action/MotionStart",
                        ACTION_SERVICE_QOS)
MOTION_MODIFY = Endpoint(Kind.ACTION, Owner.SUPERVISOR, "motion_modify", "mpi_ros/action/MotionModify",
                         ACTION_SERVICE_QOS)

# a supervisor's services
MOTION_ACTION = _service(Owner.SUPERVISOR, "action", "mpi_ros/srv/MotionAction")
# the MPI actions for any generic ROS tool: service -> the action's name
TRIGGERS = {leaf: (_service(Owner.SUPERVISOR, leaf, "std_srvs/srv/Trigger"), leaf.upper())
            for leaf in ("stop", "e_stop", "abort", "reset", "resume")}
MOTION_CONFIG_GET = _service(Owner.SUPERVISOR, "config_get", "mpi_ros/srv/MotionConfigGet")
MOTION_CONFIG_SET = _service(Owner.SUPERVISOR, "config_set", "mpi_ros/srv/MotionConfigSet")
PARAMS_GET = _service(Owner.SUPERVISOR, "params_get", "mpi_ros/srv/MotionParamsGet")
PARAMS_SET = _service(Owner.SUPERVISOR, "params_set", "mpi_ros/srv/MotionParamsSet")
AXIS_LIST_GET = _service(Owner.SUPERVISOR, "axis_list_get", "mpi_ros/srv/AxisListGet")
AXIS_LIST_SET = _service(Owner.SUPERVISOR, "axis_list_set", "mpi_ros/srv/AxisListSet")
AXIS_LIST_EDIT = _service(Owner.SUPERVISOR, "axis_list_edit", "mpi_ros/srv/AxisListEdit")
POSITION_GET = _service(Owner.SUPERVISOR, "position_get", "mpi_ros/srv/PositionGet")
POSITION_SET = _service(Owner.SUPERVISOR, "position_set", "mpi_ros/srv/PositionSet")
FRAME_BUFFER_STATUS = _service(Owner.SUPERVISOR, "frame_buffer_status", "mpi_ros/srv/FrameBufferStatusGet")
EVENT_NOTIFY_GET = _service(Owner.SUPERVISOR, "event_notify_get", "mpi_ros/srv/EventNotifyGet")
EVENT_NOTIFY_SET = _service(Owner.SUPERVISOR, "event_notify_set", "mpi_ros/srv/EventNotifySet")
EVENT_RESET = _service(Owner.SUPERVISOR, "event_reset", "mpi_ros/srv/EventReset")
PARAMS_VALIDATE = _service(Owner.SUPERVISOR, "params_validate", "mpi_ros/srv/MotionParamsValidate")
# served by the controller node, which owns the flash file (docs/configuration.md, "Flash")
MOTION_FLASH_CONFIG_GET = _service(Owner.SUPERVISOR, "flash_config_get", "mpi_ros/srv/MotionFlashConfigGet")
MOTION_FLASH_CONFIG_SET = _service(Owner.SUPERVISOR, "flash_config_set", "mpi_ros/srv/MotionFlashConfigSet")

# an axis' services (served by the controller node)
AXIS_CONFIG_GET = _service(Owner.AXIS, "config_get", "mpi_ros/srv/AxisConfigGet")
AXIS_CONFIG_SET = _service(Owner.AXIS, "config_set", "mpi_ros/srv/AxisConfigSet")
AXIS_POSITION_SET = _service(Owner.AXIS, "position_set", "mpi_ros/srv/AxisPositionSet")
FAULT_CONFIG_GET = _service(Owner.AXIS, "fault_config_get", "mpi_ros/srv/AxisFaultConfigGet")
FAULT_CONFIG_SET = _service(Owner.AXIS, "fault_config_set", "mpi_ros/srv/AxisFaultConfigSet")
FAULT_INJECT = _service(Owner.AXIS, "fault_inject", "mpi_ros/srv/AxisFaultInject")
AXIS_FLASH_CONFIG_GET = _service(Owner.AXIS, "flash_config_get", "mpi_ros/srv/AxisFlashConfigGet")
AXIS_FLASH_CONFIG_SET = _service(Owner.AXIS, "flash_config_set", "mpi_ros/srv/AxisFlashConfigSet")
AMP_ENABLE_SET = _service(Owner.AXIS, "amp_enable_set", "mpi_ros/srv/AmpEnableSet")
AXIS_EVENT_NOTIFY_GET = _service(Owner.AXIS, "event_notify_get", "mpi_ros/srv/EventNotifyGet")
AXIS_EVENT_NOTIFY_SET = _service(Owner.AXIS, "event_notify_set", "mpi_ros/srv/EventNotifySet")
AXIS_EVENT_RESET = _service(Owner.AXIS, "event_reset", "mpi_ros/srv/EventReset")

# the controller's services (gates, I/O, secondary feedback)
GATE_SET = _service(Owner.SUITE, "gate_set", "mpi_ros/srv/GateSet")
GATE_GET = _service(Owner.SUITE, "gate_get", "mpi_ros/srv/GateGet")
IO_SET = _service(Owner.SUITE, "io_set", "mpi_ros/srv/IoSet")
IO_GET = _service(Owner.SUITE, "io_get", "mpi_ros/srv/IoGet")
MOTOR_FEEDBACK_SECONDARY_SET = _service(Owner.SUITE, "motor_feedback_secondary_set",
                                        "mpi_ros/srv/MotorFeedbackSecondarySet")
# Axis objects (mpiAxisCreate / mpiAxisDelete / mpiAxisValidate: docs/decisions.md, "Axis objects")
AXIS_CREATE = _service(Owner.SUITE, "axis_create", "mpi_ros/srv/AxisCreate")
AXIS_DELETE = _service(Owner.SUITE, "axis_delete", "mpi_ros/srv/AxisDelete")
AXIS_VALIDATE = _service(Owner.SUITE, "axis_validate", "mpi_ros/srv/AxisValidate")

ACTIONS = (MOTION_START, MOTION_MODIFY)
STATUS_TYPES = (MOTION_STATUS.type, AXIS_STATUS.type)


def joint_states(namespace: str) -> str:
    """/joint_states for the default namespace (the contract); <namespace>/joint_states for
    any other, so that suites of a cell neither collide nor interleave there."""
    return JOINT_STATES.name() if ns(namespace) == DEFAULT_NAMESPACE else CELL_JOINT_STATES.name(namespace)


# ROS's action protocol (rcl_action): an action's own services and topics, below its name
ACTION_SERVICES = {"goal": "send_goal", "cancel": "cancel_goal", "result": "get_result"}


def action_service(action_name: str, kind: str) -> str:
    """The service of an action for ``kind`` (goal, cancel or result: ACTION_SERVICES)."""
    return f"{action_name}/_action/{ACTION_SERVICES[kind]}"


def action_feedback(action_name: str) -> str:
    """The feedback topic of an action: its clients subscribe there."""
    return f"{action_name}/_action/feedback"


def action_status(action_name: str) -> str:
    """The goal status topic of an action (GoalStatusArray, latched)."""
    return f"{action_name}/_action/status"


def is_action_internal(name: str) -> bool:
    """Whether ``name`` is one of an action's own topics or services (not the suite's)."""
    return "/_action/" in name


def axis_status_number(namespace: str, topic: str) -> int | None:
    """The axis number of ``topic`` if it is an axis' status topic in ``namespace``, else None."""
    match = re.fullmatch(re.escape(ns(namespace)) + r"/axis(\d+)/" + re.escape(AXIS_STATUS.leaf), topic)
    return int(match.group(1)) if match else None


def suite_endpoints(namespace: str, supervisors: list[int], axes: list[int]) -> dict[str, Endpoint]:
    """Every endpoint a suite with these supervisors and axes puts on the graph, by full name
    (the robot description and /clock included; a suite may leave them out)."""
    table: dict[str, Endpoint] = {}
    for endpoint in ENDPOINTS:
        if endpoint.owner is Owner.SUPERVISOR:
            table.update((endpoint.name(namespace, n), endpoint) for n in supervisors)
        elif endpoint.owner is Owner.AXIS:
            table.update((endpoint.name(namespace, k), endpoint) for k in axes)
        elif endpoint.leaf != JOINT_STATES.leaf:
            table[endpoint.name(namespace)] = endpoint
    table[joint_states(namespace)] = JOINT_STATES
    return table


ENDPOINTS: tuple[Endpoint, ...] = (
    MOTION_STATUS, JOINT_TRAJECTORY, AXIS_STATUS, EVENTS, COMMANDS, CONFIGURATION, ROBOT_DESCRIPTION, JOINT_STATES,
    DIAGNOSTICS, CLOCK, *ACTIONS, MOTION_ACTION, *(service for service, _action in TRIGGERS.values()),
    MOTION_CONFIG_GET, MOTION_CONFIG_SET, PARAMS_GET, PARAMS_SET, AXIS_LIST_GET, AXIS_LIST_SET, AXIS_LIST_EDIT,
    POSITION_GET, POSITION_SET, FRAME_BUFFER_STATUS, EVENT_NOTIFY_GET, EVENT_NOTIFY_SET, EVENT_RESET,
    PARAMS_VALIDATE, MOTION_FLASH_CONFIG_GET, MOTION_FLASH_CONFIG_SET,
    AXIS_CONFIG_GET, AXIS_CONFIG_SET, AXIS_POSITION_SET, FAULT_CONFIG_GET, FAULT_CONFIG_SET, FAULT_INJECT,
    AXIS_FLASH_CONFIG_GET, AXIS_FLASH_CONFIG_SET, AMP_ENABLE_SET, AXIS_EVENT_NOTIFY_GET, AXIS_EVENT_NOTIFY_SET,
    AXIS_EVENT_RESET, GATE_SET, GATE_GET, IO_SET, IO_GET, MOTOR_FEEDBACK_SECONDARY_SET, AXIS_CREATE, AXIS_DELETE,
    AXIS_VALIDATE)
