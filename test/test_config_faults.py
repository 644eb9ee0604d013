"""The faults of each axis in the YAML (config.py, docs/faults.md): defaults, per-axis
overrides, the own motor's encoder, and a bad value named by its key."""

from __future__ import annotations

import pytest

from mpi_ros import config


def _faults(overrides: dict):
    return config.parse(config.merge(config.load().raw, overrides)).build_controller().faults


def test_the_default_configuration_watches_nothing_but_each_axis_own_encoder():
    faults = config.load().build_controller().faults
    configs = [axis.config for axis in faults.axes]
    assert [c.encoder_fault_motor_number for c in configs] == [0, 1, 2, 3]
    assert {(c.following_error_limit, c.software_limit_positive_enabled, c.software_limit_negative_enabled)
            for c in configs} == {(0.0, False, False)}
    assert {(c.following_error_action, c.amp_fault_action, c.frame_underflow_action) for c in configs} == {
        ("ABORT", "ABORT", "NONE")}


def test_defaults_and_per_axis_overrides_reach_each_axis():
    defaults = {"faults": {"following_error_limit": 500.0, "following_error_action": "e_stop"}}
    faults = _faults({"axes": {"defaults": defaults,
                               "overrides": {2: {"faults": {"software_limit_negative_enabled": True,
                                                            "software_limit_negative": -100.0,
                                                            "encoder_fault_motor_number": -1}}}}})
    configs = [axis.config for axis in faults.axes]
    assert [c.following_error_limit for c in configs] == [500.0] * 4
    assert {c.following_error_action for c in configs} == {"E_STOP"}  # read in any case
    assert (configs[2].software_limit_negative_enabled, configs[2].software_limit_negative) == (True, -100.0)
    assert [c.encoder_fault_motor_number for c in configs] == [0, 1, -1, 3]


def test_an_axis_without_a_motor_watches_no_encoder():
    faults = _faults({"axes": {"count": 4}, "controller": {"motor_count": 2}})
    assert [axis.config.encoder_fault_motor_number for axis in faults.axes] == [0, 1, -1, -1]


@pytest.mark.parametrize(("faults", "where"), [
    ({"following_error_limit": -5.0}, "axes[0].faults.following_error_limit"),
    ({"software_limit_positive_action": "STOP"}, "axes[0].faults.software_limit_positive_action"),
    ({"overheat": True}, "axes[0].faults.overheat: unknown key"),
    ({"encoder_fault_motor_number": 7}, "axes[0].faults.encoder_fault_motor_number: motor 7 does not exist"),
    ({"amp_fault_action": 3}, "axes[0].faults.amp_fault_action: expected a string"),
])
def test_a_bad_fault_setting_names_its_key(faults, where):
    with pytest.raises(config.ConfigError) as error:
        _faults({"axes": {"defaults": {"faults": faults}}})
    assert str(error.value).startswith(where)
