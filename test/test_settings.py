"""The settings schema (mpi_ros/settings.py) is the one definition: the file's validation,
the docs' table and the defaults come from it; one reader reads the file and the requests."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from mpi_ros import config, requests, settings
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.params import SAMPLE_RATE_MAX, SAMPLE_RATE_MIN

ROOT = Path(__file__).resolve().parent.parent


def _refusal(overrides: dict) -> str:
    with pytest.raises(config.ConfigError) as error:
        config.load(overrides=overrides)
    return str(error.value)


def _ros(key: str, value) -> dict:
    return {"ros": {key: value}}


# -- the docs ------------------------------------------------------------------------------------

def test_the_docs_table_is_the_schemas():
    """docs/configuration.md holds the table generated from the schema (regenerate it with
    ``python -m mpi_ros.settings --write``)."""
    page = (ROOT / "docs" / "configuration.md").read_text(encoding="utf-8")
    assert settings.with_table(page) == page, "run: python -m mpi_ros.settings --write"
    assert settings.table() in page
    for s in settings.SETTINGS:
        assert s.doc in settings.table()


def test_the_table_command_prints_the_table(capsys):
    assert settings.main(["--table"]) == 0
    assert capsys.readouterr().out == settings.table()


def test_a_page_without_the_markers_is_refused():
    with pytest.raises(ValueError, match="no settings table markers"):
        settings.with_table("# a page\n")


def test_the_readme_names_the_schemas_parameters():
    row = next(line for line in (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
               if line.startswith("| `/mpi/controller` parameters"))
    named = [name.strip(" `") for name in row.split("|")[2].split(",")]
    assert named == list(settings.PARAMETERS)


def test_the_packaged_file_gives_the_schemas_defaults():
    """config/default.yaml writes out (most of) the ros section: each value it gives is the
    schema's default, so the table's defaults are what the suite runs with."""
    data = yaml.safe_load((ROOT / "config" / "default.yaml").read_text(encoding="utf-8"))
    defaults = {s.name: s.default for s in settings.ROS}
    assert data["ros"]
    assert {key: defaults[key] for key in data["ros"]} == data["ros"]
    assert data["supervisor_defaults"]["lost_client_timeout"] == settings.LOST_CLIENT.default
    assert config.load().ros == settings.RosSettings()
    assert config.SupervisorSpec.__dataclass_fields__["lost_client_timeout"].default == settings.LOST_CLIENT.default


# -- the file's validation -----------------------------------------------------------------------

@pytest.mark.parametrize(("key", "value", "text"), [
    ("status_rate", 5000.0, "ros.status_rate: must be a finite number > 0 and <= 1000, got 5000.0"),
    ("status_rate", 0.0, "ros.status_rate: must be a finite number > 0 and <= 1000, got 0.0"),
    ("feedback_rate", -1.0, "ros.feedback_rate: must be a finite number > 0, got -1.0"),
    ("feedback_rate", math.inf, "ros.feedback_rate: expected a finite number, got inf"),
    ("result_timeout", 0.0, "ros.result_timeout: must be a finite number > 0, got 0.0"),
    ("executor_threads", 3, "ros.executor_threads: must be an integer >= 4, got 3"),
    ("executor_threads", 4.0, "ros.executor_threads: expected an integer, got 4.0"),
    ("crosscheck", 1, "ros.crosscheck: expected true or false, got 1"),
    ("discovery", "LAN", "ros.discovery: one of localhost, subnet, system_default, off, got 'LAN'"),
    ("action_server", "stock", "ros.action_server: one of batched, rclpy, got 'stock'"),
    ("namespace", "/cell a", "ros.namespace: expected an absolute ROS namespace"),
    ("robot_description", 3, "ros.robot_description: expected a string, got 3"),
])
def test_a_bad_ros_setting_is_refused_with_its_key_named(key, value, text):
    assert _refusal(_ros(key, value)).startswith(text)


def _ends(s: settings.Setting) -> list[tuple[float, bool]]:
    """(value, allowed) at each end of a setting's range and just beyond it."""
    step = (lambda x, to: math.nextafter(x, to)) if s.kind is float else (lambda x, to: x + (1 if to > x else -1))
    cases = []
    if s.low is not None:
        cases += [(s.low, not s.low_open), (step(s.low, math.inf), True), (step(s.low, -math.inf), False)]
    if s.high is not None:
        cases += [(s.high, not s.high_open), (step(s.high, -math.inf), True), (step(s.high, math.inf), False)]
    return [(s.kind(v), ok) for v, ok in cases]


@pytest.mark.parametrize("setting", [s for s in settings.ROS if s.low is not None or s.high is not None],
                         ids=lambda s: s.key)
def test_every_ros_range_holds_at_its_ends(setting):
    for value, allowed in _ends(setting):
        if allowed:
            assert getattr(config.load(overrides=_ros(setting.name, value)).ros, setting.name) == value
        else:
            assert _refusal(_ros(setting.name, value)).startswith(f"{setting.key}: must be ")


@pytest.mark.parametrize("setting", [s for s in settings.ROS if s.choices], ids=lambda s: s.key)
def test_every_choice_is_taken_and_nothing_else(setting):
    other = {"action_server": {"goal_process": False}}.get(setting.name, {})
    for choice in setting.choices:
        assert getattr(config.load(overrides={"ros": {setting.name: choice, **other}}).ros, setting.name) == choice
    assert _refusal(_ros(setting.name, "nowhere")).startswith(f"{setting.key}: one of ")


def test_the_lost_client_timeout_holds_at_its_end_in_both_places():
    for where, place in (("supervisors[0]", "entry"), ("supervisors[0]", "defaults")):
        def given(value, place=place):
            if place == "defaults":
                return {"supervisor_defaults": {"lost_client_timeout": value}}
            return {"supervisors": [{"number": 0, "axes": [0, 1], "lost_client_timeout": value},
                                    {"number": 1, "axes": [2, 3]}]}
        assert config.load(overrides=given(0.0)).supervisors[0].lost_client_timeout == 0.0
        assert (_refusal(given(-5e-324)) ==
                f"{where}.lost_client_timeout: must be a finite number >= 0, got -5e-324")
        assert _refusal(given(True)) == f"{where}.lost_client_timeout: expected a finite number, got True"


def test_the_validation_follows_the_schema(monkeypatch):
    """Change a setting's range in the schema and the file is validated by the new range."""
    changed = tuple(dataclasses.replace(s, high=50.0) if s.name == "feedback_rate" else s for s in settings.ROS)
    monkeypatch.setattr(config, "ROS", changed)
    assert _refusal(_ros("feedback_rate", 50.5)) == "ros.feedback_rate: must be a finite number > 0 and <= 50, " \
                                                    "got 50.5"
    assert config.load(overrides=_ros("feedback_rate", 50.0)).ros.feedback_rate == 50.0


def test_the_sample_rate_parameter_has_the_controllers_bounds():
    """controller.sample_rate is ControllerConfig's, validated there: the schema takes its
    bounds from the same constants, and the file holds them at both ends."""
    rate = settings.SAMPLE_RATE
    assert (rate.low, rate.high, rate.low_open, rate.high_open) == (SAMPLE_RATE_MIN, SAMPLE_RATE_MAX, False, False)
    for value, allowed in _ends(rate):
        overrides = {"controller": {"sample_rate": value}}
        if allowed:
            assert config.load(overrides=overrides).controller.sample_rate == value
        else:
            assert _refusal(overrides).startswith("controller.sample_rate: must be a finite number")


# -- one reader ----------------------------------------------------------------------------------

def _request_refusal(read, value) -> str:
    with pytest.raises(Refused) as error:
        read(value, "field")
    assert error.value.message == Message.MPIMessagePARAM_INVALID
    return error.value.detail


@pytest.mark.parametrize(("kind", "value"), [
    (int, 3.0), (int, True), (int, "3"), (int, None),
    (bool, 1), (bool, 0), (bool, "true"), (bool, 1.0),
    (float, True), (float, "fast"), (float, [1.0]), (float, 10**400),
    (str, 3), (str, None),
])
def test_the_file_and_the_requests_refuse_the_same_values(kind, value):
    """One rule, two errors: ConfigError naming the key for the file, Refused
    (MPIMessagePARAM_INVALID) naming the field for a request."""
    like = kind()
    with pytest.raises(config.ConfigError, match=r"^key: expected "):
        config.read_value(value, like, "key")
    assert _request_refusal(requests._READ.of(kind), value).startswith("field: ")


@pytest.mark.parametrize(("kind", "value", "read"), [
    (int, 3, 3), (int, np.int64(-2), -2), (bool, True, True), (bool, False, False),
    (float, 7, 7.0), (float, "1e9", 1e9), (float, np.float32(0.5), 0.5), (str, "S_CURVE", "S_CURVE"),
])
def test_the_file_and_the_requests_read_the_same_values_alike(kind, value, read):
    from_file = config.read_value(value, kind(), "key")
    from_request = requests._READ.of(kind)(value, "field")
    assert from_file == from_request == read
    assert type(from_file) is type(from_request) is kind


def test_the_rule_holds_where_requests_and_files_are_read():
    """Through the real readers: a goal's id, a start's final flag, a file's integer and flag."""
    goal = {"type": "S_CURVE", "position": [1.0], "trajectory": [{"velocity": 1.0, "acceleration": 1.0,
                                                                   "deceleration": 1.0}]}
    assert requests.motion_request({**goal, "id": 3}).params.id == 3
    assert _request_refusal(lambda value, _: requests.motion_request({**goal, "id": value}), 3.0) == \
        "id: an integer expected, got 3.0"
    assert _request_refusal(lambda value, _: requests.motion_request({**goal, "final": value}), 1) == \
        "final: true or false expected, got 1"
    assert _request_refusal(lambda value, _: requests.in_position({"position_coarse": value}), 100.0) == \
        "in_position.position_coarse: an integer expected, got 100.0"
    assert _refusal({"axes": {"defaults": {"in_position": {"position_coarse": 100.0}}}}) == \
        "axes[0].in_position.position_coarse: expected an integer, got 100.0"
    assert _refusal({"axes": {"defaults": {"in_position": {"settle_on_stop": 0}}}}) == \
        "axes[0].in_position.settle_on_stop: expected true or false, got 0"
    assert _refusal({"axes": {"count": 4.0}}) == "axes.count: expected an integer, got 4.0"
    assert _refusal({"supervisors": [{"number": 0, "axes": [0, 1.0]}]}) == \
        "supervisors[0].axes[1]: expected an integer, got 1.0"
    # a number may be written as an integer, or as a string PyYAML did not read as a number
    assert requests.motion_config({"normal_feedrate": 1}).normal_feedrate == 1.0
    assert config.load(overrides=_ros("status_rate", "1e2")).ros.status_rate == 100.0
