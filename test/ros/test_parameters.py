"""ROS parameters override the YAML configuration at start, validated with it."""

from __future__ import annotations

import pytest
import rclpy

from mpi_ros.config import ConfigError
from mpi_ros.ros import parameters


def context_with(*params: str):
    context = rclpy.Context()
    args = ["test"] + (["--ros-args"] + [x for p in params for x in ("-p", p)] if params else [])
    rclpy.init(args=args, context=context)
    return context


def test_parameters_override_the_file():
    context = context_with("status_rate:=250.0", "time_scale:=3.0", "crosscheck:=true", "sample_rate:=1000.0")
    try:
        cfg, scale = parameters.resolve(context, None, 1.0)
    finally:
        context.try_shutdown()
    assert (cfg.ros.status_rate, cfg.ros.crosscheck, cfg.controller.sample_rate, scale) == (250.0, True, 1000.0, 3.0)
    assert cfg.ros.feedback_rate == 20.0  # not overridden: the file's value


def test_without_parameters_the_file_rules():
    context = context_with()
    try:
        cfg, scale = parameters.resolve(context, None, 2.0)
    finally:
        context.try_shutdown()
    assert (cfg.ros.status_rate, scale) == (100.0, 2.0)


@pytest.mark.parametrize("param, key", [("status_rate:=5000.0", "ros.status_rate"),
                                        ("sample_rate:=-1.0", "controller.sample_rate"),
                                        ("time_scale:=-2.0", "time_scale")])
def test_bad_parameters_stop_the_start_with_the_key_named(param, key):
    context = context_with(param)
    try:
        with pytest.raises(ConfigError) as error:
            parameters.resolve(context, None, 1.0)
    finally:
        context.try_shutdown()
    assert str(error.value).startswith(key)


def test_an_integer_where_a_number_is_meant_counts_and_a_wrong_type_is_named():
    context = context_with("status_rate:=200", "time_scale:=2")
    try:
        cfg, scale = parameters.resolve(context, None, 1.0)
    finally:
        context.try_shutdown()
    assert (cfg.ros.status_rate, scale) == (200.0, 2.0) and isinstance(scale, float)
    context = context_with("crosscheck:=3")
    try:
        with pytest.raises(ConfigError, match=r"^crosscheck: expected true or false, got 3"):
            parameters.resolve(context, None, 1.0)
    finally:
        context.try_shutdown()


def test_each_parameter_has_its_own_descriptor_with_type_range_and_description():
    from rcl_interfaces.msg import ParameterType
    from rclpy.node import Node

    from mpi_ros import config

    context = context_with()
    try:
        node = Node("controller", namespace="/param_test", context=context)
        parameters.show(node, config.load(), 1.0)
        names = sorted(parameters.SPECS)
        descriptors = dict(zip(names, node.describe_parameters(names), strict=True))
        values = {name: node.get_parameter(name).value for name in names}
        node.destroy_node()
    finally:
        context.try_shutdown()
    assert set(names) == {"config", "time_scale", "sample_rate", *parameters.ROS_KEYS}
    assert len({id(d) for d in descriptors.values()}) == len(names)  # not one shared object
    for name, descriptor in descriptors.items():
        assert descriptor.name == name and descriptor.read_only
        assert descriptor.description and f"-p {name}:=VALUE" in descriptor.additional_constraints
    assert descriptors["status_rate"].type == ParameterType.PARAMETER_DOUBLE
    assert (descriptors["status_rate"].floating_point_range[0].from_value,
            descriptors["status_rate"].floating_point_range[0].to_value) == (0.0, 1000.0)
    assert descriptors["crosscheck"].type == ParameterType.PARAMETER_BOOL
    assert descriptors["config"].type == ParameterType.PARAMETER_STRING
    assert "status_rate, boolean" not in descriptors["status_rate"].description
    assert values["sample_rate"] == 2000.0 and values["time_scale"] == 1.0
