"""convert.to_dict: a message as plain Python values, field for field as its properties read.

to_dict reads a generated class's slots in one go (a per-class plan); the reference here reads
every field through its property and converts by the value's type, independently of the plan.
"""

from __future__ import annotations

import array

import numpy as np
import pytest
from rosidl_parser import definition
from sensor_msgs.msg import NavSatFix

from mpi_ros import msg as mpi_msg
from mpi_ros import srv as mpi_srv
from mpi_ros.action import MotionModify, MotionStart
from mpi_ros.ros import convert

_NUMBER = {"float": 1.5, "double": -2.25, "int8": -3, "uint8": 4, "int16": -5, "uint16": 6, "int32": -7,
           "uint32": 8, "int64": -9, "uint64": 10}


def _value(slot_type, depth: int = 0):
    """A value for a field of ``slot_type`` that differs from its default."""
    if isinstance(slot_type, definition.NamespacedType):
        return _filled(_class(slot_type), depth + 1)
    if isinstance(slot_type, definition.AbstractNestedType):
        one = _value(slot_type.value_type, depth)
        size = slot_type.size if isinstance(slot_type, definition.Array) else 2
        return [one] * size
    if isinstance(slot_type, definition.AbstractGenericString):
        return "text"
    if slot_type.typename == "boolean":
        return True
    if slot_type.typename in ("octet", "char"):
        return b"\x07" if slot_type.typename == "octet" else "c"
    return _NUMBER[slot_type.typename]


def _class(namespaced):
    import importlib

    return getattr(importlib.import_module(".".join(namespaced.namespaces)), namespaced.name)


def _filled(cls, depth: int = 0):
    message = cls()
    for name, slot_type in zip(cls.get_fields_and_field_types(), cls.SLOT_TYPES, strict=True):
        if depth < 3:
            setattr(message, name, _value(slot_type, depth))
    return message


def _reference(value):
    """Plain values by reading properties and looking at each value's type."""
    if hasattr(value, "get_fields_and_field_types"):
        return {name: _reference(getattr(value, name)) for name in value.get_fields_and_field_types()}
    if isinstance(value, (array.array, np.ndarray)):
        return [v.item() if isinstance(v, np.generic) else v for v in value.tolist()]
    if isinstance(value, list):
        return [_reference(v) for v in value]
    return value


MESSAGES = [MotionStart.Goal, MotionModify.Goal, MotionStart.Result, MotionModify.Feedback,
            mpi_msg.AxisStatus, mpi_msg.MotionStatus,
            mpi_msg.MotionParams, mpi_msg.MotionConfig, mpi_msg.AxisFaultConfig, mpi_msg.Command,
            mpi_srv.MotionAction.Request, mpi_srv.MotionParamsSet.Request, NavSatFix]


@pytest.mark.parametrize("cls", MESSAGES, ids=lambda c: c.__name__)
def test_every_field_reads_as_its_property_does(cls):
    message = _filled(cls)
    assert convert.to_dict(message) == _reference(message)


@pytest.mark.parametrize("cls", MESSAGES, ids=lambda c: c.__name__)
def test_defaults_read_as_their_properties_do(cls):
    message = cls()
    assert convert.to_dict(message) == _reference(message)


def test_values_are_python_values_not_arrays():
    goal = convert.fill(MotionModify.Goal(), {"type": "S_CURVE", "position": [1.0, 2.0], "element_id": [3],
                                              "trajectory": [{"velocity": 5.0}], "attributes": ["AUTO_START"]})
    data = convert.to_dict(goal)
    assert type(data["position"]) is list
    assert type(data["position"][0]) is float
    assert type(data["element_id"]) is list
    assert type(data["element_id"][0]) is int
    assert data["trajectory"][0]["velocity"] == 5.0
    assert type(data["trajectory"]) is list
    assert data["attributes"] == ["AUTO_START"]
    fix = NavSatFix()
    assert type(convert.to_dict(fix)["position_covariance"][0]) is float  # a fixed array (numpy)


def test_the_dict_is_the_callers_own():
    """Changing the dict (or its lists) leaves the message as it was."""
    goal = convert.fill(MotionStart.Goal(), {"type": "TRAPEZOIDAL", "position": [1.0], "attributes": ["APPEND"]})
    data = convert.to_dict(goal)
    data["position"].append(9.0)
    data["attributes"].append("DELAY")
    data["type"] = "VELOCITY"
    assert list(goal.position) == [1.0]
    assert goal.attributes == ["APPEND"]
    assert goal.type == "TRAPEZOIDAL"


def test_a_class_that_is_not_generated_is_read_by_its_slots():
    class Stored:  # what a bag reader builds from the definition a bag stores
        __slots__ = ("_hidden", "position", "type")

        def __init__(self):
            self.type = "S_CURVE"
            self.position = array.array("d", [1.0])
            self._hidden = 1

    assert convert.to_dict(Stored()) == {"type": "S_CURVE", "position": [1.0]}


def test_a_header_names_the_most_specific_source_in_the_namespace():
    """frame_id: the axis if one is named, else the supervisor, else the controller, after the
    namespace without its leading slash (as /diagnostics names them; docs/recording.md, "Headers")."""
    assert convert.frame_id("/mpi", axis=0) == "mpi/axis0"
    assert convert.frame_id("/mpi", supervisor=1) == "mpi/ms1"
    assert convert.frame_id("/mpi", supervisor=1, axis=3) == "mpi/axis3"
    assert convert.frame_id("/mpi") == "mpi/controller"
    assert convert.frame_id("/plant/cell_a", 0) == "plant/cell_a/ms0"
    header = convert.header(4001, 2000.0, 7 * 10**9, "mpi/ms0")
    assert (header.stamp.sec, header.stamp.nanosec, header.frame_id) == (9, 500_000, "mpi/ms0")
