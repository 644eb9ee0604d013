"""ROS parameters of the suite: ``--ros-args -p name:=value`` overrides the YAML file.

The controller node (``/<ns>/controller``) takes:

| parameter | overrides |
| --- | --- |
| config | the YAML file (default: --config, else config/default.yaml) |
| time_scale | --time-scale |
| sample_rate | controller.sample_rate |
| status_rate, feedback_rate, joint_states_rate, diagnostics_rate, clock_rate, crosscheck, result_timeout | ros.* |

The namespace: ``--ros-args -r __ns:=/cell_a`` (rcl's remap of every node's namespace)
over ``mpi-ros run --namespace`` over ros.namespace in the YAML; the one in effect is the
suite's namespace everywhere (topics, diagnostics names, joint names, recordings).

They are read once, before the suite is built, and validated with the file (a bad value
stops the start with the key named; ``status_rate:=200`` is taken as 200.0, as a user
means it); the node then shows the values in effect, read only, each with its own
descriptor (type, range, description) for ``ros2 param describe``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, ParameterType
from rclpy.context import Context
from rclpy.node import Node

from .. import config as suite_config

ROS_KEYS = ("status_rate", "feedback_rate", "joint_states_rate", "diagnostics_rate", "clock_rate", "crosscheck",
            "result_timeout")
NODE_NAME = "controller"
_SET_AT_START = "Read only: set at start with --ros-args -p {name}:=VALUE."


@dataclass(frozen=True)
class ParameterSpec:
    """What ``ros2 param describe`` shows for one parameter."""

    name: str
    type: int  # rcl_interfaces ParameterType
    description: str
    low: float | None = None  # inclusive range of a number
    high: float | None = None
    constraints: str = ""

    def descriptor(self) -> ParameterDescriptor:
        descriptor = ParameterDescriptor(name=self.name, type=self.type, read_only=True,
                                         description=self.description,
                                         additional_constraints=" ".join(
                                             filter(None, (self.constraints, _SET_AT_START.format(name=self.name)))))
        if self.low is not None:
            descriptor.floating_point_range = [FloatingPointRange(from_value=self.low, to_value=self.high, step=0.0)]
        return descriptor


def _rate(name: str, what: str, high: float = math.inf, note: str = "") -> ParameterSpec:
    return ParameterSpec(name, ParameterType.PARAMETER_DOUBLE, f"Hz: how often {what} (ros.{name})",
                         0.0, high, note or "Must be > 0.")


SPECS: dict[str, ParameterSpec] = {spec.name: spec for spec in (
    ParameterSpec("config", ParameterType.PARAMETER_STRING, "the suite's YAML configuration file in effect"),
    ParameterSpec("time_scale", ParameterType.PARAMETER_DOUBLE,
                  "controller time per wall-clock time: 1 real time, larger faster, 0 as fast as possible",
                  0.0, math.inf),
    ParameterSpec("sample_rate", ParameterType.PARAMETER_DOUBLE,
                  "Hz: the controller's sample rate (controller.sample_rate)", 0.0, math.inf, "Must be > 0."),
    _rate("status_rate", "MotionStatus and AxisStatus are published", 1000.0, "Must be > 0."),
    _rate("feedback_rate", "a running goal publishes feedback"),
    _rate("joint_states_rate", "/joint_states is published"),
    _rate("diagnostics_rate", "/diagnostics is published"),
    _rate("clock_rate", "/clock is published"),
    ParameterSpec("crosscheck", ParameterType.PARAMETER_BOOL,
                  "check every started or modified profile against ruckig (ros.crosscheck)"),
    ParameterSpec("result_timeout", ParameterType.PARAMETER_DOUBLE,
                  "s: how long an ended goal's result is kept for a client that asks late (ros.result_timeout)",
                  0.0, math.inf, "Must be > 0."),
)}


def _namespace(path: str | None) -> str:
    try:
        return suite_config.load(path).ros.namespace
    except suite_config.ConfigError:
        return "/mpi"


def _typed(name: str, value):
    """The override as its parameter's type (an integer where a number is meant counts)."""
    kind = SPECS[name].type
    if kind == ParameterType.PARAMETER_DOUBLE:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise suite_config.ConfigError(f"{name}: expected a number, got {value!r}")
        return float(value)
    if kind == ParameterType.PARAMETER_BOOL and not isinstance(value, bool):
        raise suite_config.ConfigError(f"{name}: expected true or false, got {value!r}")
    if kind == ParameterType.PARAMETER_STRING and not isinstance(value, str):
        raise suite_config.ConfigError(f"{name}: expected a string, got {value!r}")
    return value


def _read(reader: Node, name: str, default):
    """The value given with -p (or ``default``); any type is accepted here and checked by _typed."""
    loose = ParameterDescriptor(dynamic_typing=True)
    return _typed(name, reader.declare_parameter(name, default, loose).value)


def resolve(context: Context | None, config_path: str | None, time_scale: float,
            namespace: str | None = None) -> tuple[suite_config.SuiteConfig, float]:
    """The configuration and time scale in effect, parameter overrides applied; ``namespace``
    (``--namespace``) replaces ros.namespace, an ``__ns`` remap replaces both."""
    if namespace is not None:
        suite_config.check_namespace(namespace, "--namespace")
    reader = Node(NODE_NAME, namespace=namespace or _namespace(config_path), context=context)
    try:
        path = _read(reader, "config", config_path or "") or None
        time_scale = _read(reader, "time_scale", float(time_scale))
        base = suite_config.load(path)
        overrides: dict = {"ros": {}}
        rate = _read(reader, "sample_rate", base.controller.sample_rate)
        if rate != base.controller.sample_rate:
            overrides["controller"] = {"sample_rate": rate}
        for key in ROS_KEYS:
            value = _read(reader, key, getattr(base.ros, key))
            if value != getattr(base.ros, key):
                overrides["ros"][key] = value
        if reader.get_namespace() != base.ros.namespace:  # --namespace or an __ns remap
            overrides["ros"]["namespace"] = reader.get_namespace()
        cfg = suite_config.parse(suite_config.merge(base.raw, overrides), base.source)
    finally:
        reader.destroy_node()
    if time_scale < 0:
        raise suite_config.ConfigError(f"time_scale: must be >= 0, got {time_scale}")
    return cfg, time_scale


def values(cfg: suite_config.SuiteConfig, time_scale: float) -> dict:
    """Every parameter's value in effect."""
    return {"config": cfg.source, "time_scale": float(time_scale), "sample_rate": cfg.controller.sample_rate,
            **{key: getattr(cfg.ros, key) for key in ROS_KEYS}}


def show(node: Node, cfg: suite_config.SuiteConfig, time_scale: float) -> None:
    """Declare the values in effect on the controller node, read only, each with its own descriptor."""
    for name, value in values(cfg, time_scale).items():
        node.declare_parameter(name, value, SPECS[name].descriptor())
