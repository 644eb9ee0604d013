"""ROS parameters of the suite: ``--ros-args -p name:=value`` overrides the YAML file.

The controller node (``/<ns>/controller``) takes:

| parameter | overrides |
| --- | --- |
| config | the YAML file (default: --config, else config/default.yaml) |
| time_scale | --time-scale |
| sample_rate | controller.sample_rate |
| status_rate, feedback_rate, joint_states_rate, diagnostics_rate, clock_rate, crosscheck | ros.* |

They are read once, before the suite is built, and validated with the file (a bad value
stops the start with the key named); the node then shows the values in effect, read only.
"""

from __future__ import annotations

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.context import Context
from rclpy.node import Node

from .. import config as suite_config

ROS_KEYS = ("status_rate", "feedback_rate", "joint_states_rate", "diagnostics_rate", "clock_rate", "crosscheck")
NODE_NAME = "controller"


def _namespace(path: str | None) -> str:
    try:
        return suite_config.load(path).ros.namespace
    except suite_config.ConfigError:
        return "/mpi"


def resolve(context: Context | None, config_path: str | None, time_scale: float) -> tuple[suite_config.SuiteConfig, float]:
    """The configuration and time scale in effect, parameter overrides applied."""
    reader = Node(NODE_NAME, namespace=_namespace(config_path), context=context)
    try:
        path = reader.declare_parameter("config", config_path or "").value or None
        time_scale = float(reader.declare_parameter("time_scale", float(time_scale)).value)
        base = suite_config.load(path)
        overrides: dict = {"ros": {}}
        rate = reader.declare_parameter("sample_rate", base.controller.sample_rate).value
        if rate != base.controller.sample_rate:
            overrides["controller"] = {"sample_rate": rate}
        for key in ROS_KEYS:
            value = reader.declare_parameter(key, getattr(base.ros, key)).value
            if value != getattr(base.ros, key):
                overrides["ros"][key] = value
        cfg = suite_config.parse(suite_config.merge(base.raw, overrides), base.source)
    finally:
        reader.destroy_node()
    if time_scale < 0:
        raise suite_config.ConfigError(f"time_scale: must be >= 0, got {time_scale}")
    return cfg, time_scale


def show(node: Node, cfg: suite_config.SuiteConfig, time_scale: float) -> None:
    """Declare the values in effect on the controller node, read only."""
    fixed = ParameterDescriptor(read_only=True, description="in effect; set with --ros-args -p at start")
    node.declare_parameter("config", cfg.source, fixed)
    node.declare_parameter("time_scale", float(time_scale), fixed)
    node.declare_parameter("sample_rate", cfg.controller.sample_rate, fixed)
    for key in ROS_KEYS:
        node.declare_parameter(key, getattr(cfg.ros, key), fixed)
