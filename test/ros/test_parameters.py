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
