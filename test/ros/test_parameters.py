"""ROS parameters override the YAML configuration at start, validated with it."""

from __future__ import annotations

import dataclasses
import math

import pytest
import rclpy

from mpi_ros import settings
from mpi_ros.config import ConfigError
from mpi_ros.ros import parameters


def context_with(*params: str):
    context = rclpy.Context()
    args = ["test"] + (["--ros-args"] + [x for p in params for x in ("-p", p)] if params else [])
    rclpy.init(args=args, context=context)
    return context


def resolved(*params: str, time_scale: float = 1.0):
    """The configuration and time scale the suite starts with under ``params``."""
    context = context_with(*params)
    try:
        return parameters.resolve(context, None, time_scale)
    finally:
        context.try_shutdown()


def refusal(*params: str) -> str:
    """Why the suite refuses to start under ``params`` (the ConfigError's message)."""
    with pytest.raises(ConfigError) as error:
        resolved(*params)
    return str(error.value)


def test_parameters_override_the_file():
    cfg, scale = resolved("status_rate:=250.0", "time_scale:=3.0", "crosscheck:=true", "sample_rate:=1000.0")
    assert (cfg.ros.status_rate, cfg.ros.crosscheck, cfg.controller.sample_rate, scale) == (250.0, True, 1000.0, 3.0)
    assert cfg.ros.feedback_rate == 20.0  # not overridden: the file's value


def test_without_parameters_the_file_rules():
    cfg, scale = resolved(time_scale=2.0)
    assert (cfg.ros.status_rate, scale) == (100.0, 2.0)


@pytest.mark.parametrize(("param", "key"), [("status_rate:=5000.0", "ros.status_rate"),
                                        ("sample_rate:=-1.0", "controller.sample_rate"),
                                        ("time_scale:=-2.0", "time_scale")])
def test_bad_parameters_stop_the_start_with_the_key_named(param, key):
    assert refusal(param).startswith(key)


def test_an_integer_where_a_number_is_meant_counts_and_a_wrong_type_is_named():
    cfg, scale = resolved("status_rate:=200", "time_scale:=2")
    assert (cfg.ros.status_rate, scale) == (200.0, 2.0)
    assert isinstance(scale, float)
    assert refusal("crosscheck:=3").startswith("crosscheck: expected true or false, got 3")


_RCLPY_OWN = ("use_sim_time", "start_type_description_service")  # every rclpy node has these


def _described(cfg=None):
    """The controller node's parameters as ``ros2 param describe`` shows them, with their values."""
    from rclpy.node import Node

    from mpi_ros import config

    context = context_with()
    try:
        node = Node("controller", namespace="/param_test", context=context)
        parameters.show(node, cfg or config.load(), 1.0)
        names = [name for name in node.get_parameters_by_prefix("") if name not in _RCLPY_OWN]
        descriptors = dict(zip(names, node.describe_parameters(names), strict=True))
        values = {name: node.get_parameter(name).value for name in names}
        node.destroy_node()
    finally:
        context.try_shutdown()
    return descriptors, values


def test_each_parameter_has_its_own_descriptor_with_type_range_and_description():
    from rcl_interfaces.msg import ParameterType

    descriptors, values = _described()
    assert set(descriptors) == {"config", "time_scale", "sample_rate", *parameters.ROS_KEYS}
    assert len({id(d) for d in descriptors.values()}) == len(descriptors)  # not one shared object
    for name, descriptor in descriptors.items():
        assert descriptor.name == name
        assert descriptor.read_only
        assert descriptor.description
        assert f"-p {name}:=VALUE" in descriptor.additional_constraints
    assert descriptors["status_rate"].type == ParameterType.PARAMETER_DOUBLE
    assert (descriptors["status_rate"].floating_point_range[0].from_value,
            descriptors["status_rate"].floating_point_range[0].to_value) == (0.0, 1000.0)
    assert "Must be > 0 and <= 1000." in descriptors["status_rate"].additional_constraints
    assert descriptors["crosscheck"].type == ParameterType.PARAMETER_BOOL
    assert descriptors["config"].type == ParameterType.PARAMETER_STRING
    assert descriptors["status_rate"].description == "Hz: how often MotionStatus and AxisStatus are published " \
                                                     "(ros.status_rate)"
    assert values["sample_rate"] == 2000.0
    assert values["time_scale"] == 1.0


def test_the_descriptors_are_the_schemas():
    """Each parameter, its type, range, constraints and description, is its Setting's: a
    change to the schema changes what ``ros2 param describe`` shows."""
    from rcl_interfaces.msg import ParameterType

    from mpi_ros.mpi.base.params import SAMPLE_RATE_MAX, SAMPLE_RATE_MIN

    types = {float: ParameterType.PARAMETER_DOUBLE, bool: ParameterType.PARAMETER_BOOL,
             str: ParameterType.PARAMETER_STRING, int: ParameterType.PARAMETER_INTEGER}
    descriptors, _ = _described()
    assert list(parameters.PARAMETERS) == list(settings.PARAMETERS)
    for name, setting in settings.PARAMETERS.items():
        described = descriptors[name]
        assert described.type == types[setting.kind]
        assert setting.doc in described.description
        ranges = list(described.floating_point_range) + list(described.integer_range)
        if setting.low is None and setting.high is None:
            assert not ranges
            continue
        assert (ranges[0].from_value, ranges[0].to_value) == (setting.low, setting.high or math.inf)
        assert f"Must be {setting.bounds()}." in described.additional_constraints
    assert (descriptors["sample_rate"].floating_point_range[0].from_value,
            descriptors["sample_rate"].floating_point_range[0].to_value) == (SAMPLE_RATE_MIN, SAMPLE_RATE_MAX)


def test_a_schema_change_shows_in_the_descriptor(monkeypatch):
    changed = dataclasses.replace(settings.PARAMETERS["feedback_rate"], high=50.0, doc="a changed doc")
    monkeypatch.setitem(parameters.PARAMETERS, "feedback_rate", changed)
    descriptors, _ = _described()
    described = descriptors["feedback_rate"]
    assert described.floating_point_range[0].to_value == 50.0
    assert "a changed doc" in described.description
    assert "<= 50" in described.additional_constraints


@pytest.mark.parametrize(("param", "text"), [
    ("crosscheck:=1", "crosscheck: expected true or false, got 1"),  # the one reader: 1 is not true
    ("feedback_rate:=fast", "feedback_rate: expected a finite number, got 'fast'"),
    ("config:=3", "config: expected a string, got 3"),
    ("time_scale:=inf", "time_scale: expected a finite number, got inf"),
    ("result_timeout:=0.0", "ros.result_timeout: must be a finite number > 0, got 0.0"),
])
def test_a_parameter_is_read_as_the_file_is(param, text):
    assert refusal(param) == text
