"""mpi_ros/message_dicts.py: one message <-> dict conversion, one rule (unknown fields raise),
for the nodes (ros/convert.py), the client and the console alike."""

from __future__ import annotations

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticStatus

from mpi_ros import client, message_dicts
from mpi_ros.action import MotionStart
from mpi_ros.ros import convert


def test_the_nodes_and_the_client_share_one_conversion():
    assert convert.fill is client.fill is message_dicts.fill
    assert convert.to_dict is client.message_to_dict is message_dicts.to_dict


def test_an_unknown_field_raises_with_the_valid_ones_and_changes_nothing():
    status = DiagnosticStatus(name="kept")
    with pytest.raises(ValueError, match=r"^nmae: no such field in DiagnosticStatus \(fields: level, name, "):
        message_dicts.fill(status, {"nmae": "x"})
    assert status.name == "kept"


def test_numpy_numbers_and_arrays_are_taken_and_bytes_read_as_numbers():
    status = message_dicts.fill(DiagnosticStatus(), {"level": 2, "name": "ms0"})
    assert status.level == b"\x02"
    assert message_dicts.to_dict(status)["level"] == 2  # an octet reads as its number (YAML-friendly)
    assert message_dicts.fill(DiagnosticStatus(), message_dicts.to_dict(status)) == status
    with pytest.raises(ValueError, match=r"^level: expected a byte \(0\.\.255\), got 256"):
        message_dicts.fill(DiagnosticStatus(), {"level": 256})
    goal = message_dicts.fill(MotionStart.Goal(), {"position": np.array([1, 2]), "id": np.int64(4)})
    assert list(goal.position) == [1.0, 2.0]
    assert goal.id == 4


def test_a_nested_message_names_its_path():
    with pytest.raises(ValueError, match=r"^trajectory\[0\]\.nope: no such field in Trajectory"):
        message_dicts.fill(MotionStart.Goal(), {"trajectory": [{"velocity": 1.0, "nope": 1}]})
