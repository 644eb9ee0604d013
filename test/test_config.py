"""The suite configuration: defaults from config/default.yaml, clear errors for bad files."""

from __future__ import annotations

import re

import pytest

from mpi_ros import config, requests
from mpi_ros.commands import Command, apply
from mpi_ros.mpi.base.types import MPIState


def test_default_config_builds_the_documented_controller():
    cfg = config.load()
    # README.md, "Configuration": 4 axes, 2 supervisors, ms0 on axes 0 and 1, ms1 on 2 and 3.
    assert cfg.axis_count == 4
    assert [(s.number, s.axes) for s in cfg.supervisors] == [(0, [0, 1]), (1, [2, 3])]
    ctl = cfg.build_controller()
    assert ctl.rate == 2000.0
    assert ctl.config.frame_buffer_size == 128
    assert [ms.mapped for ms in ctl.supervisors] == [[0, 1], [2, 3]]
    assert all(ms.state is MPIState.IDLE for ms in ctl.supervisors)
    ms0 = ctl.supervisor(0)
    assert (ms0.config.decel_time.stop, ms0.config.decel_time.e_stop) == (0.5, 0.05)
    assert cfg.ros.status_rate == 100.0
    assert cfg.ros.namespace == "/mpi"


@pytest.mark.parametrize(
    ("data", "where"),
    [
        ({"supervisors": [{"axes": [7]}]}, "supervisors[0].axes[0]"),
        ({"supervisors": [{"axes": []}]}, "supervisors[0].axes"),
        ({"supervisors": [{"number": 0, "axes": [0]}, {"number": 0, "axes": [1]}]}, "supervisors[1].number"),
        ({"axes": {"count": 0}}, "axes.count"),
        ({"axes": {"defaults": {"plant": {"damping": -1.0}}}}, "axes[0].plant.damping"),
        ({"axes": {"defaults": {"plant": {"bandwidth": 3.0}}}}, "axes[0].plant.bandwidth"),
        ({"controller": {"sample_rate": 0.0}}, "controller.sample_rate"),
        ({"controller": {"sample_rate": "fast"}}, "controller.sample_rate"),
        ({"ros": {"status_rate": 5000.0}}, "ros.status_rate"),
        ({"ros": {"namespace": "mpi"}}, "ros.namespace"),
        ({"supervisor_defaults": {"config": {"decel_time_stop": 0.0}}, "supervisors": [{"axes": [0]}]},
         "supervisors[0].config.decel_time_stop"),
        ({"supervisors": [{"axes": [0], "event_notify": ["BOGUS"]}]}, "supervisors[0].event_notify"),
        ({"bogus": 1}, "bogus"),
    ],
)
def test_bad_configuration_names_the_key(data, where):
    with pytest.raises(config.ConfigError) as error:
        config.parse(data)
    assert str(error.value).startswith(where)


def test_load_reports_unreadable_and_invalid_yaml(tmp_path):
    with pytest.raises(config.ConfigError, match="cannot read"):
        config.load(tmp_path / "missing.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("axes: [1, 2\n")
    with pytest.raises(config.ConfigError, match="not valid YAML"):
        config.load(broken)


def test_per_axis_overrides(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("axes:\n  count: 2\n  overrides:\n    1:\n      in_position: {settling_time: 0.2}\n"
                    "supervisors:\n  - {number: 0, axes: [0, 1]}\n")
    cfg = config.load(path)
    assert [ip.settling_time for ip in cfg.in_position] == [0.01, 0.2]


# ------------------------------------------------------------------ ranges: one validator per struct ----
@pytest.mark.parametrize(
    ("data", "where"),
    [
        # issue 9: "blend_limit: 5.0 with decel_time_stop: 2.0 starts with the defaults"
        ({"supervisor_defaults": {"config": {"blend_limit": 5.0, "decel_time_stop": 2.0}}},
         "supervisors[0].config.blend_limit"),
        ({"supervisor_defaults": {"config": {"normal_feedrate": 1e308}}}, "supervisors[0].config.normal_feedrate"),
        ({"supervisor_defaults": {"config": {"normal_feedrate": 1e-300}}}, "supervisors[0].config.normal_feedrate"),
        ({"supervisor_defaults": {"config": {"user_label": "x" * 17}}}, "supervisors[0].config.user_label"),
        ({"axes": {"defaults": {"in_position": {"settling_time": 1e308}}}}, "axes[0].in_position.settling_time"),
        ({"axes": {"overrides": {2: {"in_position": {"position_fine": 0.0}}}}}, "axes[2].in_position.position_fine"),
        ({"axes": {"defaults": {"in_position": {"position_fine": 0.5}}}}, "axes[0].in_position.position_fine"),
        ({"axes": {"defaults": {"plant": {"damping": 1.5}}}}, "axes[0].plant.damping"),
        ({"axes": {"count": 100_000}}, "axes.count"),
        ({"controller": {"sample_rate": 1e9}}, "controller.sample_rate"),
        ({"controller": {"frame_buffer_size": 10**9}}, "controller.frame_buffer_size"),
        ({"axes": {"overrides": {2: {"frame_buffer_size": 8}}}}, "axes[2].frame_buffer_size"),
        ({"axes": {"defaults": {"frame_buffer_size": "big"}}}, "axes[0].frame_buffer_size"),
        ({"controller": {"axis_frame_buffer_sizes": {0: 256}}}, "controller.axis_frame_buffer_sizes"),
        # MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: one size on a supervisor's axes
        ({"axes": {"overrides": {1: {"frame_buffer_size": 256}}}, "supervisors": [{"number": 0, "axes": [0, 1]}]},
         "supervisors[0].axes"),
    ],
)
def test_values_the_controller_cannot_hold_name_the_key(data, where):
    # the struct validators (MPI 000 MPIMotionConfig/MEIMotionConfig, 002 MPIAxisInPosition, ...):
    # the file is refused with the key named, never started with some other value
    with pytest.raises(config.ConfigError) as error:
        config.parse(data)
    assert str(error.value).startswith(where + ":")


def test_per_axis_frame_buffer_sizes_reach_the_controller():
    # MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "The axis frame buffer sizes are configured" per axis;
    # the controller's frame_buffer_size stays the default of every other axis
    cfg = config.parse({"controller": {"frame_buffer_size": 64},
                        "axes": {"overrides": {2: {"frame_buffer_size": 512}, 3: {"frame_buffer_size": 512}}},
                        "supervisors": [{"number": 0, "axes": [0, 1]}, {"number": 1, "axes": [2, 3]}]})
    ctl = cfg.build_controller()
    assert [ctl.config.frame_buffer_size_of(n) for n in range(4)] == [64, 64, 512, 512]
    assert [s.size for s in ctl.supervisor(1).frame_buffer_status()[1]] == [512, 512]
    cfg.supervisors[0].axes = [1, 2]  # past the loader: the controller answers it
    with pytest.raises(config.ConfigError, match=r"supervisors\[0\]\.axes: .*AXIS_FRAME_COUNT"):
        cfg.build_controller()


def test_configured_values_reach_the_controller():
    cfg = config.parse({"supervisor_defaults": {"config": {"blend_limit": 0.5, "decel_time_stop": 2.0,
                                                           "normal_feedrate": 0.25}},
                        "axes": {"overrides": {1: {"in_position": {"settling_time": 0.2}}}}})
    ctl = cfg.build_controller()
    ms = ctl.supervisor(0)
    assert (ms.config.blend_limit, ms.config.decel_time.stop, ms.config.normal_feedrate) == (0.5, 2.0, 0.25)
    assert [a.in_position.settling_time for a in ctl.axes] == [0.01, 0.2, 0.01, 0.01]


@pytest.mark.parametrize(
    ("spoil", "where"),
    [
        (lambda c: setattr(c.supervisors[1].config, "blend_limit", 5.0), "supervisors[1].config.blend_limit"),
        (lambda c: setattr(c.supervisors[0].config, "normal_feedrate", 1e308), "supervisors[0].config.normal_feedrate"),
        (lambda c: setattr(c.in_position[3], "settling_time", 1e308), "axes[3].in_position.settling_time"),
        (lambda c: setattr(c.plant[0], "encoder_resolution", 40.0), "axes[0].in_position.position_fine"),
        (lambda c: setattr(c.plant[1], "damping", 3.0), "axes[1].plant.damping"),
        (lambda c: setattr(c.controller, "io_words", 0), "controller.io_words"),
        (lambda c: setattr(c.supervisors[0], "axes", [0, 9]), "supervisors[0].axes"),
        (lambda c: setattr(c.supervisors[1], "number", 0), "supervisors[1].number"),
    ],
)
def test_build_controller_never_drops_a_refused_value(spoil, where):
    # issue 9: build_controller ignored the Message of config_set. Every call that builds the
    # controller must succeed, or the suite stops with the key named.
    cfg = config.load()
    spoil(cfg)
    with pytest.raises(config.ConfigError) as error:
        cfg.build_controller()
    assert str(error.value).startswith(where)


@pytest.mark.parametrize(("key", "values"), [
    ("normal_feedrate", [1.0, 1e-3, 1e3, 9.9e-4, 1000.1, 0.0, 1e308]),
    ("blend_limit", [-1.0, 1.0, 1.0001, -2.0]),
    ("decel_time_stop", [1e-6, 21474.0, 0.0, 1e9]),
    ("pause_feedrate", [0.0, 0.5, 1e-300, -1.0]),
])
def test_yaml_service_and_controller_agree_on_motion_config(key, values):
    # one MotionConfig validator: the YAML loader, /mpi/ms<n>/config_set (commands.apply) and
    # mpiMotionConfigSet accept and refuse the same values
    for value in values:
        try:
            config.parse({"supervisor_defaults": {"config": {key: value}}})
            by_yaml = True
        except config.ConfigError:
            by_yaml = False
        ctl = config.load().build_controller()
        request = {**requests.motion_config_to_dict(ctl.supervisor(0).config_get()[1]), key: value}
        by_service = apply(ctl, Command("config_set", 0, request={"config": request})).accepted
        assert by_yaml is by_service, (key, value)


@pytest.mark.parametrize(("key", "values"), [
    ("settling_time", [0.0, 21474.0, 1e308, -1.0]),
    ("position_fine", [0.51, 1e14, 0.5, 0.0]),
    ("velocity", [1e-3, 3e38, 0.0, 1e39]),
    ("position_coarse", [0, 2**31 - 1, -1, 2**31]),
])
def test_yaml_service_and_controller_agree_on_in_position(key, values):
    # one AxisInPosition validator (MPI 002 MPIAxisInPosition): YAML, /mpi/axis<k>/config_set
    for value in values:
        try:
            config.parse({"axes": {"defaults": {"in_position": {key: value}}}})
            by_yaml = True
        except config.ConfigError:
            by_yaml = False
        ctl = config.load().build_controller()
        by_service = apply(ctl, Command("axis_config_set", axis=0, request={"in_position": {key: value}})).accepted
        assert by_yaml is by_service, (key, value)



def test_axis_master_and_secondary_feedback_from_yaml():
    # MPI 002, MPIAxisConfig.master / masterCorrection per axis; the secondary feedback input of motor n
    # (docs/cams.md)
    from mpi_ros.mpi import AxisMaster, AxisMasterType, SecondaryFeedback

    cfg = config.parse({"axes": {"overrides": {
        1: {"master": {"type": "address", "address": 5, "correction": 3}},
        2: {"secondary_feedback": {"position": 10.0, "velocity": 250.0}}}}})
    ctl = cfg.build_controller()
    assert ctl.axes[1].master == AxisMaster(AxisMasterType.ADDRESS, 0, 5, 3)
    assert ctl.axes[0].master == AxisMaster()
    assert ctl.secondary.get(2) == (0, SecondaryFeedback(10.0, 250.0))


@pytest.mark.parametrize(("override", "words"), [
    ({"master": {"type": "SOMEWHERE"}}, "axes[1].master.type"),
    ({"master": {"type": "AXIS_ACTUAL_POSITION", "number": "zero"}}, "axes[1].master.number"),
    ({"master": {"correction": -5}}, "axes[1].master.correction"),
    ({"master": {"type": "ADDRESS", "address": 64}}, "axes[1].master.address"),
    ({"secondary_feedback": {"velocity": 1e13}}, "axes[1].secondary_feedback.velocity"),
])
def test_a_bad_axis_master_names_its_key(override, words):
    with pytest.raises(config.ConfigError, match=re.escape(words)):
        config.parse({"axes": {"overrides": {1: override}}}).build_controller()
