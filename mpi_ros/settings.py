"""The suite's settings, declared once: type, default, range or choices, a one-line doc.

Each setting of the ``ros`` section of the configuration file (config/default.yaml), a
supervisor's ``lost_client_timeout`` and each ROS parameter of the controller node is a
:class:`Setting`. From them come:

- the validation of those keys in the file (config.py: a bad value stops the start with its
  key named, ``ros.status_rate: must be a finite number > 0 and <= 1000, got 5000.0``);
- the parameters' descriptors, which ``ros2 param describe`` shows (ros/parameters.py);
- the table of docs/configuration.md: ``python -m mpi_ros.settings --table`` prints it,
  ``--write`` puts it into that page (test/test_settings.py checks the page is current).

The ``ros`` settings are RosSettings' fields, each declared with :func:`setting`, so the
dataclass and its schema are one definition. The structs' settings (controller, axes,
supervisors' config) keep their validators in mpi_ros/mpi/base/params.py; the one of them
that is also a parameter, controller.sample_rate, is declared here with its validator's bounds.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from mpi_ros.graph_names import DEFAULT_NAMESPACE, joint_states
from mpi_ros.mpi.base.params import SAMPLE_RATE_MAX, SAMPLE_RATE_MIN, ControllerConfig, shown

_SETTING = "mpi_ros.setting"  # the key of a field's schema in its dataclass metadata


@dataclass(frozen=True, slots=True)
class Setting:
    """One setting: where it is set, its type, default, what values it allows, what it does."""

    key: str  # its place in the file ("ros.status_rate"); for one not in the file, its parameter's name
    kind: type  # float, int, bool or str
    default: Any
    doc: str  # one line: what it does
    unit: str = ""
    low: float | None = None  # the range's ends (None: unbounded); a float's value must also be finite
    high: float | None = None
    low_open: bool = False  # the end itself is excluded (> low)
    high_open: bool = False
    choices: tuple[str, ...] = ()
    form: Callable[[Any], str | None] | None = None  # a rule beyond range and choices: why a value breaks it
    form_doc: str = ""  # that rule in words (the docs' "allowed" column)
    parameter: bool = False  # also a read-only ROS parameter of <ns>/controller, named as the key's last part
    in_file: bool = True  # False: set by a parameter or a command-line option only

    @property
    def name(self) -> str:
        """The key's last part: the field's and the ROS parameter's name."""
        return self.key.rsplit(".", 1)[-1]

    def refusal(self, value: Any) -> str | None:
        """Why ``value`` (already read as ``kind``) is not allowed, or None if it is."""
        if self.choices and value not in self.choices:
            return f"one of {', '.join(self.choices)}, got {shown(value)}"
        if not self._within(value):
            noun = "a finite number" if self.kind is float else "an integer"
            return f"must be {noun} {self.bounds()}, got {shown(value)}"
        return self.form(value) if self.form is not None else None

    def _within(self, value: Any) -> bool:
        if self.low is None and self.high is None:
            return True
        if self.kind is float and not math.isfinite(value):
            return False
        above = self.low is None or (value > self.low if self.low_open else value >= self.low)
        below = self.high is None or (value < self.high if self.high_open else value <= self.high)
        return above and below

    def bounds(self) -> str:
        """The range in words ("> 0 and <= 1000"); empty if unbounded."""
        ends = []
        if self.low is not None:
            ends.append(f"{'>' if self.low_open else '>='} {self.low:g}")
        if self.high is not None:
            ends.append(f"{'<' if self.high_open else '<='} {self.high:g}")
        return " and ".join(ends)

    def allowed(self) -> str:
        """Every rule on its values, in words (empty: any value of its type)."""
        if self.choices:
            return "one of " + ", ".join(f"`{c}`" for c in self.choices)
        return "; ".join(filter(None, (self.bounds(), self.form_doc)))


def setting(default: Any, doc: str, **rules: Any) -> Any:
    """A dataclass field with its default and schema (the keyword arguments of Setting but
    key, kind and default, which the field gives)."""
    return field(default=default, metadata={_SETTING: {"doc": doc, **rules}})


def schema(cls: type, section: str) -> tuple[Setting, ...]:
    """The settings of dataclass ``cls``, whose fields were declared with :func:`setting`,
    as keys of ``section``."""
    return tuple(Setting(f"{section}.{f.name}", type(f.default), f.default, **f.metadata[_SETTING])
                 for f in fields(cls))


DISCOVERY_RANGES = ("localhost", "subnet", "system_default", "off")  # ROS_AUTOMATIC_DISCOVERY_RANGE
ACTION_SERVERS = ("batched", "rclpy")
LOST_CLIENT_TIMEOUT = 2.0  # s: the lost-client watchdog's default


def namespace_refusal(namespace: str) -> str | None:
    """Why ``namespace`` is not a ROS namespace (absolute, name parts of letters, digits and
    underscores not starting with a digit: rcl's rules; no trailing slash), or None."""
    parts = namespace.split("/")
    if (not namespace.startswith("/") or namespace == "/" or namespace.endswith("/")
            or not all(p and (p[0].isalpha() or p[0] == "_") and all(c.isalnum() or c == "_" for c in p)
                       and p.isascii() for p in parts[1:])):
        return ("expected an absolute ROS namespace like /mpi or /cell_a (letters, digits, underscores; "
                f"parts not starting with a digit), got {namespace!r}")
    return None


def _rate(default: float, what: str, **rules: Any) -> Any:
    return setting(default, f"how often {what}", unit="Hz", low=0.0, low_open=True, **rules)


@dataclass(slots=True)
class RosSettings:
    """The ``ros`` section of the configuration file."""

    namespace: str = setting(DEFAULT_NAMESPACE, "the suite's namespace: its nodes, topics, services, actions, "
                             "diagnostics and joint names (docs/cell.md)", form=namespace_refusal,
                             form_doc="an absolute ROS namespace (`/mpi`, `/cell_a`)")
    status_rate: float = _rate(100.0, "MotionStatus and AxisStatus are published", high=1000.0, parameter=True)
    feedback_rate: float = _rate(20.0, "a running goal publishes feedback", parameter=True)
    joint_states_rate: float = _rate(100.0, "/joint_states is published", parameter=True)
    diagnostics_rate: float = _rate(1.0, "/diagnostics is published", parameter=True)
    clock_rate: float = _rate(100.0, "/clock is published", parameter=True)
    # The clock thread steps the statuses due within it in one stretch (runner.py); a stretch costs
    # about the same whatever its length, so at 1 kHz status this saves most of the stepping, at a
    # few ms of latency (docs/decisions.md, "Statuses are stepped in stretches").
    publish_period: float = setting(0.005, "how long a status (MotionStatus, AxisStatus, /joint_states, /clock) may "
                                    "wait past its sample before it is published; 0: each as it falls due",
                                    unit="s", low=0.0, high=1.0, parameter=True)
    # ros2_control's update thread does the same; opt-in, since a real-time thread that never slept
    # would hold its core (docs/decisions.md, "The clock thread's priority")
    clock_priority: int = setting(0, "the controller's clock thread runs under SCHED_FIFO at this priority, to keep "
                                  "real time on a loaded machine (needs CAP_SYS_NICE or an rtprio limit; without, "
                                  "the suite says why and runs on); 0: normal scheduling", low=0, high=99,
                                  parameter=True)
    crosscheck: bool = setting(False, "check every started or modified profile against ruckig (docs/profiles.md)",
                               parameter=True)
    # (ros/suite.py)
    executor_threads: int = setting(8, "threads of each node's executor and of the goal loop's pool", low=4)
    clock: bool = setting(True, "publish /clock; in a cell of several suites exactly one should (docs/cell.md)")
    # the suite's default keeps discovery on this host (docs/cell.md, "Exposure")
    discovery: str = setting("localhost", "how far DDS discovery reaches (ROS_AUTOMATIC_DISCOVERY_RANGE; "
                             "`mpi-ros run --discovery` and that variable take precedence)", choices=DISCOVERY_RANGES)
    # rclpy's ActionServer keeps a result 900 s. The action server keeps each goal and publishes
    # the status of all it keeps at every goal's change, so at 100 goals a second 900 s meant
    # 90,000 goals kept and ever larger status messages.
    result_timeout: float = setting(60.0, "how long an ended goal's result is kept for a client that asks late",
                                    unit="s", low=0.0, low_open=True, parameter=True)
    # Taking and answering goal requests in the goal front (ros/goal_front.py) costs the suite's
    # interpreter a few microseconds instead of about 0.2 ms a goal.
    goal_process: bool = setting(False, "the action servers' services in a process of their own, the goal front, "
                                 "for hundreds of goals a second (docs/reliability.md); needs action_server batched")
    # batched: on rclpy's private bindings (ros/rcl.py); rclpy: a goal costs more
    action_server: str = setting("batched", "who speaks the action protocol: the suite's own server (batched) or "
                                 "rclpy's stock ActionServer, for an rclpy other than Jazzy's (docs/reliability.md)",
                                 choices=ACTION_SERVERS)
    # checked against the joints (mpi_ros/description.py)
    robot_description: str = setting("", "a URDF file published on robot_description (in the suite's namespace) "
                                     "instead of the generated one (relative: to the configuration file's folder; "
                                     "docs/joints.md); empty: generated")

    @property
    def joint_states_topic(self) -> str:
        """/joint_states for the default namespace (the contract); <namespace>/joint_states
        for any other, so that suites of a cell neither collide nor interleave there."""
        return joint_states(self.namespace)

    @property
    def joint_prefix(self) -> str:
        """Prefix of every joint name: none for the default namespace, else the namespace
        ("cell_a/axis0"), so joint names stay unique in a cell (one robot description)."""
        return "" if self.namespace == DEFAULT_NAMESPACE else self.namespace.strip("/") + "/"


ROS: tuple[Setting, ...] = schema(RosSettings, "ros")

# The lost-client watchdog (docs/cell.md). On by default (docs/decisions.md): Jazzy's
# `ros2 action send_goal` does not cancel its goal on Ctrl-C.
LOST_CLIENT = Setting("supervisors[n].lost_client_timeout", float, LOST_CLIENT_TIMEOUT,
                      "STOP the supervisor's motion when the client of its running goal has left the graph this "
                      "long; 0: off (docs/cell.md); also in supervisor_defaults", unit="s", low=0.0)

# The controller node's parameters that are not in the ros section (the file's
# controller.sample_rate is ControllerConfig's, validated there with these bounds).
CONFIG = Setting("config", str, "", "the YAML configuration file in effect (default: --config, else "
                 "config/default.yaml)", parameter=True, in_file=False)
TIME_SCALE = Setting("time_scale", float, 1.0, "controller time per wall-clock time: 1 real time, larger faster, "
                     "0 as fast as possible (--time-scale)", low=0.0, parameter=True, in_file=False)
SAMPLE_RATE = Setting("controller.sample_rate", float, ControllerConfig().sample_rate,
                      "the controller's sample rate", unit="Hz", low=SAMPLE_RATE_MIN, high=SAMPLE_RATE_MAX,
                      parameter=True)

SETTINGS: tuple[Setting, ...] = (CONFIG, TIME_SCALE, SAMPLE_RATE, *ROS, LOST_CLIENT)
# The controller node's parameters by name, in the order it declares them.
PARAMETERS: dict[str, Setting] = {s.name: s for s in SETTINGS if s.parameter}

_KINDS = {float: "number", int: "integer", bool: "true/false", str: "string"}


def _default(s: Setting) -> str:
    if s.kind is bool:
        return "true" if s.default else "false"
    if s.kind is str:
        return f"`{s.default}`" if s.default else "empty"
    return f"{s.default:g}"


def table() -> str:
    """The settings as a markdown table (docs/configuration.md)."""
    rows = ["| setting | type | default | allowed | ROS parameter | what it does |",
            "| --- | --- | --- | --- | --- | --- |"]
    for s in SETTINGS:
        kind = _KINDS[s.kind] + (f" ({s.unit})" if s.unit else "")
        parameter = f"`{s.name}`" if s.parameter else ""
        key = f"`{s.key}`" if s.in_file else "(a parameter only)"
        rows.append(f"| {key} | {kind} | {_default(s)} | {s.allowed()} | {parameter} | {s.doc} |")
    return "\n".join(rows) + "\n"


DOCS = Path(__file__).resolve().parent.parent / "docs" / "configuration.md"
BEGIN = "<!-- settings table: generated by `python -m mpi_ros.settings --write`; edit mpi_ros/settings.py -->\n"
END = "<!-- end of the settings table -->\n"


def with_table(page: str) -> str:
    """``page`` with the text between its BEGIN and END markers replaced by :func:`table`."""
    head, begin, rest = page.partition(BEGIN)
    _, end, tail = rest.partition(END)
    if not begin or not end:
        raise ValueError(f"the page has no settings table markers ({BEGIN.strip()} ... {END.strip()})")
    return head + BEGIN + table() + END + tail


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m mpi_ros.settings", description=__doc__.splitlines()[0])
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--table", action="store_true", help="print the settings table (markdown)")
    what.add_argument("--write", action="store_true", help=f"put the table into {DOCS.name}")
    args = parser.parse_args(argv)
    if args.table:
        sys.stdout.write(table())
    else:
        DOCS.write_text(with_table(DOCS.read_text(encoding="utf-8")), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
