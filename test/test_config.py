"""The suite configuration: defaults from config/default.yaml, clear errors for bad files."""

from __future__ import annotations

import pytest

from mpi_ros import config
from mpi_ros.mpi.types import MPIState


def test_default_config_builds_the_documented_controller():
    cfg = config.load()
    # DESIGN.md: config/default.yaml: 4 axes, 2 supervisors, ms0 on axes 0 and 1, ms1 on 2 and 3.
    assert cfg.axis_count == 4
    assert [(s.number, s.axes) for s in cfg.supervisors] == [(0, [0, 1]), (1, [2, 3])]
    ctl = cfg.build_controller()
    assert ctl.rate == 2000.0 and ctl.config.frame_buffer_size == 128
    assert [ms.mapped for ms in ctl.supervisors] == [[0, 1], [2, 3]]
    assert all(ms.state is MPIState.IDLE for ms in ctl.supervisors)
    ms0 = ctl.supervisor(0)
    assert (ms0.config.decel_time.stop, ms0.config.decel_time.e_stop) == (0.5, 0.05)
    assert cfg.ros.status_rate == 100.0 and cfg.ros.namespace == "/mpi"


@pytest.mark.parametrize(
    "data, where",
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
