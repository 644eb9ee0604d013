"""ROS parameters of the suite: ``--ros-args -p name:=value`` overrides the YAML file.

The controller node (``/<ns>/controller``) takes the parameters the settings schema declares
(mpi_ros/settings.py, PARAMETERS; the table of docs/configuration.md): ``config`` (the YAML
file), ``time_scale`` (--time-scale), ``sample_rate`` (controller.sample_rate) and the
``ros.*`` rates, ``crosscheck`` and ``result_timeout``.

The namespace: ``--ros-args -r __ns:=/cell_a`` (rcl's remap of every node's namespace)
over ``mpi-ros run --namespace`` over ros.namespace in the YAML; the one in effect is the
suite's namespace everywhere (topics, diagnostics names, joint names, recordings).

They are read once, before the suite is built, each by the file's reader, and validated with
the file (a bad value stops the start with the key named; ``status_rate:=200`` is taken as
200.0, as a user means it); the node then shows the values in effect, read only, each with
the descriptor its Setting makes (type, range, description) for ``ros2 param describe``.
"""

from __future__ import annotations

import math
from typing import Any

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor, ParameterType
from rclpy.context import Context
from rclpy.node import Node

from .. import config as suite_config
from ..graph_names import DEFAULT_NAMESPACE
from ..settings import PARAMETERS, Setting

# the parameters of the ros section, by name
ROS_KEYS = tuple(name for name, s in PARAMETERS.items() if s.key.startswith("ros."))
NODE_NAME = "controller"
_SET_AT_START = "Read only: set at start with --ros-args -p {name}:=VALUE."
_TYPES = {float: ParameterType.PARAMETER_DOUBLE, int: ParameterType.PARAMETER_INTEGER,
          bool: ParameterType.PARAMETER_BOOL, str: ParameterType.PARAMETER_STRING}
_INT64 = (-(2**63), 2**63 - 1)


def descriptor(setting: Setting) -> ParameterDescriptor:
    """What ``ros2 param describe`` shows for a setting's parameter: its type, its range (a
    ROS range includes its ends; an open end is said in the constraints), what it does."""
    where = f" ({setting.key})" if setting.in_file else ""
    unit = f"{setting.unit}: " if setting.unit else ""
    rules = setting.allowed().replace("`", "")
    constraints = " ".join(filter(None, (f"Must be {rules}." if rules else "",
                                         _SET_AT_START.format(name=setting.name))))
    described = ParameterDescriptor(name=setting.name, type=_TYPES[setting.kind], read_only=True,
                                    description=f"{unit}{setting.doc}{where}", additional_constraints=constraints)
    if setting.low is None and setting.high is None:
        return described
    if setting.kind is float:
        low, high = (-math.inf if setting.low is None else setting.low), (math.inf if setting.high is None
                                                                           else setting.high)
        described.floating_point_range = [FloatingPointRange(from_value=low, to_value=high, step=0.0)]
    else:
        low, high = (_INT64[0] if setting.low is None else setting.low), (_INT64[1] if setting.high is None
                                                                          else setting.high)
        described.integer_range = [IntegerRange(from_value=int(low), to_value=int(high), step=0)]
    return described


def _namespace(path: str | None) -> str:
    try:
        return suite_config.load(path).ros.namespace
    except suite_config.ConfigError:
        return DEFAULT_NAMESPACE


def _typed(name: str, value: Any) -> Any:
    """The override read as its parameter's type, by the file's reader (an integer where a
    number is meant counts), or ConfigError naming the parameter."""
    return suite_config.read_value(value, PARAMETERS[name].default, name)


def _read(reader: Node, name: str, default: Any) -> Any:
    """The value given with -p (or ``default``); any type is accepted here and checked by _typed."""
    loose = ParameterDescriptor(dynamic_typing=True)
    return _typed(name, reader.declare_parameter(name, default, loose).value)


def _in_effect(cfg: suite_config.SuiteConfig, setting: Setting) -> Any:
    """A file setting's value in ``cfg`` ("ros.status_rate": cfg.ros.status_rate)."""
    section, name = setting.key.split(".")
    return getattr(getattr(cfg, section), name)


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
        for name, setting in PARAMETERS.items():
            if setting.in_file:
                value = _read(reader, name, _in_effect(base, setting))
                if value != _in_effect(base, setting):
                    overrides.setdefault(setting.key.split(".")[0], {})[name] = value
        if reader.get_namespace() != base.ros.namespace:  # --namespace or an __ns remap
            overrides["ros"]["namespace"] = reader.get_namespace()
        cfg = suite_config.parse(suite_config.merge(base.raw, overrides), base.source)
    finally:
        reader.destroy_node()
    refusal = PARAMETERS["time_scale"].refusal(time_scale)
    if refusal is not None:
        raise suite_config.ConfigError(f"time_scale: {refusal}")
    return cfg, time_scale


def values(cfg: suite_config.SuiteConfig, time_scale: float) -> dict:
    """Every parameter's value in effect."""
    launch = {"config": cfg.source, "time_scale": float(time_scale)}
    return {name: _in_effect(cfg, s) if s.in_file else launch[name] for name, s in PARAMETERS.items()}


def show(node: Node, cfg: suite_config.SuiteConfig, time_scale: float) -> None:
    """Declare the values in effect on the controller node, read only, each with its own descriptor."""
    for name, value in values(cfg, time_scale).items():
        node.declare_parameter(name, value, descriptor(PARAMETERS[name]))
