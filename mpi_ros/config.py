"""The suite's configuration (config/default.yaml): controller, axes, supervisors, ROS.

Validated when loaded: every error names its key (``supervisors[1].axes[0]: axis 7
does not exist (4 axes)``) so a wrong file never starts a half-configured suite. The
``ros`` section and ``lost_client_timeout`` are checked by their declarations in the settings
schema (mpi_ros/settings.py); the other ranges are the structs' own validators
(mpi_ros/mpi/base/params.py), the ones the controller and the services use. Scalars are read
by the requests' reader (mpi_ros/scalars.py: an integer is an int, true is true). Building
the controller checks every call's answer: a value the controller refuses stops the suite
with its key named, it is never dropped. The same configuration builds the controller for
the ROS suite, the CLI tools and replay.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import yaml

from mpi_ros import config_paths, flash
from mpi_ros.joints import AxisJoint, Joint, axis_joints
from mpi_ros.mpi.axes.plant import Plant
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import (
    MAX_COORD_AXES,
    MAX_OBJECTS,
    AxisFaultConfig,
    AxisInPosition,
    AxisMaster,
    ControllerConfig,
    DecelTime,
    MotionConfig,
    PlantConfig,
    SecondaryFeedback,
    check_frame_buffer_size,
    check_settling_reachable,
)
from mpi_ros.mpi.base.types import AxisMasterType, MPIAction
from mpi_ros.mpi.control import Controller
from mpi_ros.scalars import readers
from mpi_ros.settings import (
    ACTION_SERVERS,
    DEFAULT_NAMESPACE,
    DISCOVERY_RANGES,
    LOST_CLIENT,
    LOST_CLIENT_TIMEOUT,
    ROS,
    RosSettings,
    namespace_refusal,
)

__all__ = ["ACTION_SERVERS", "DEFAULT_NAMESPACE", "DISCOVERY_RANGES", "LOST_CLIENT_TIMEOUT", "ConfigError",
           "RosSettings", "SuiteConfig", "SupervisorSpec", "check_namespace", "load", "merge", "parse", "read_value"]


def default_config_path() -> Path:
    """config/default.yaml: installed under share/mpi_ros/config, or in the source tree."""
    return config_file("default.yaml")


def config_file(name: str) -> Path:
    """config/<name>: installed under share/mpi_ros/config, or in the source tree."""
    found = config_paths.find(name)
    if found is not None:
        return found
    raise ConfigError(f"config/{name} not found (looked in " + ", ".join(map(str, config_paths.candidates(name))) + ")")


class ConfigError(ValueError):
    """The configuration is invalid; the message names the key."""


@dataclass(slots=True)
class SupervisorSpec:
    number: int
    axes: list[int]
    config: MotionConfig
    event_notify: MPIEventType
    # The lost-client watchdog (docs/cell.md): STOP this supervisor's motion when the client
    # of a running goal has been gone from the graph this long (s); 0 = off. On by default
    # (docs/decisions.md): Jazzy's `ros2 action send_goal` does not cancel its goal on Ctrl-C.
    lost_client_timeout: float = LOST_CLIENT_TIMEOUT


@dataclass(slots=True)
class SuiteConfig:
    controller: ControllerConfig
    in_position: list[AxisInPosition]
    plant: list[PlantConfig]
    supervisors: list[SupervisorSpec]
    ros: RosSettings = field(default_factory=RosSettings)
    source: str = "<defaults>"
    raw: dict = field(default_factory=dict)  # the validated mapping (recorded in bags for replay)
    faults: list[AxisFaultConfig] = field(default_factory=list)  # per axis (none: the controller's defaults)
    # per axis: the cam master (MPIAxisConfig.master, masterCorrection) and the secondary
    # feedback input of the axis' motor (docs/cams.md); empty: the defaults
    masters: list[AxisMaster] = field(default_factory=list)
    secondary: list[SecondaryFeedback] = field(default_factory=list)
    # per axis: the machine's joint (docs/joints.md); None: ``axis<k>`` in counts
    joints: list[Joint | None] = field(default_factory=list)
    # the flash beside the configuration file (mpi_ros/flash.py); None: no file, no flash
    flash: Path | None = None

    @property
    def axis_count(self) -> int:
        return self.controller.axis_count

    def axis_joints(self) -> list[AxisJoint]:
        """Every axis as /joint_states and the robot description name it."""
        joints = self.joints or [None] * self.axis_count
        return axis_joints(joints, self.ros.joint_prefix)

    def build_controller(self) -> Controller:
        """A controller with the configured axes and supervisors (axis lists mapped). Every
        call must succeed: a refused value raises ConfigError naming its key."""
        _require(self.controller.validate(), "controller.")
        if not len(self.in_position) == len(self.plant) == self.controller.axis_count:
            raise ConfigError(f"axes: {self.controller.axis_count} axes need as many in_position and plant "
                              f"settings, got {len(self.in_position)} and {len(self.plant)}")
        ctl = Controller(self.controller)
        for n, (in_position, plant) in enumerate(zip(self.in_position, self.plant, strict=True)):
            _require(plant.validate(), f"axes[{n}].plant.")
            ctl.axes[n].plant = Plant(plant)  # before the tolerances: they are checked against its encoder
            _accepted(ctl.axis_in_position_set(n, in_position), f"axes[{n}].in_position.")
        for n, master in enumerate(self.masters):
            _accepted(ctl.axis_master_set(n, master), f"axes[{n}].master.")
        for n, feedback in enumerate(self.secondary):
            if feedback == SecondaryFeedback():  # (motor n may not exist: motor_count < axes)
                continue
            _accepted(ctl.secondary_feedback_set(n, feedback), f"axes[{n}].secondary_feedback.")
        for n, faults in enumerate(self.faults):
            _require(ctl.axis_fault_config_set(n, faults), f"axes[{n}].faults.")
        for i, spec in enumerate(self.supervisors):
            self._build_supervisor(ctl, spec, f"supervisors[{i}]")
        return ctl

    @staticmethod
    def _build_supervisor(ctl: Controller, spec: SupervisorSpec, where: str) -> None:
        message, ms = ctl.create_motion(spec.number)
        _accepted(Outcome(message, f"number: cannot create supervisor {spec.number}"), f"{where}.")
        assert ms is not None  # (created: the message was OK)
        # the axes first: mpiMotionConfigSet answers AXIS_COUNT without them (MPI 000)
        _accepted(ms.axis_list_set(spec.axes), f"{where}.axes: ")
        _accepted(ms.config_set(spec.config), f"{where}.config.")
        _accepted(ms.event_notify_set(spec.event_notify), f"{where}.event_notify: ")
        _accepted(ms.action(MPIAction.MAP), f"{where}.axes: ")


def _require(verdict: Outcome, where: str) -> None:
    """Stop on a refusal; ``where`` ends where the field the verdict names is appended."""
    if not verdict.ok:
        raise ConfigError(f"{where}{verdict.detail}")


def _accepted(outcome: Outcome, where: str) -> None:
    """Stop unless the controller accepted a call; ``where`` ends where its detail (which
    names the field first) is appended."""
    if not outcome.ok:
        raise ConfigError(f"{where}{outcome.detail} (the controller answered {outcome.message.name})")


def merge(base: dict, override: dict) -> dict:
    """``base`` with ``override`` merged in, mapping by mapping (neither is changed)."""
    return _merge(base, override)


def _merge(base: dict, override: dict | None) -> dict:
    out = copy.deepcopy(base)
    for key, value in (override or {}).items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


def _unreadable(where: str, expected: str, value: Any) -> ConfigError:
    if expected == "a number":  # a file's number must also be finite (read_value)
        expected = "a finite number"
    return ConfigError(f"{where}: expected {expected}, got {value!r}")


# The file's scalars are read by the rule the requests are read by (mpi_ros/scalars.py).
_READ = readers(_unreadable)


def _dataclass(cls, data: Any, where: str):
    """Build dataclass ``cls`` from a mapping, with clear errors for unknown or bad keys."""
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: expected a mapping, got {type(data).__name__}")
    known = {f.name: f for f in fields(cls)}
    kwargs = {}
    for key, value in data.items():
        if key not in known:
            raise ConfigError(f"{where}.{key}: unknown key (known: {', '.join(sorted(known))})")
        default = getattr(cls(), key)
        kwargs[key] = read_value(value, default, f"{where}.{key}")
    return cls(**kwargs)


def read_value(value: Any, like: Any, where: str) -> Any:
    """``value`` read as a value of ``like``'s type (one of another type: as given), or
    ConfigError naming ``where``. A file's number must also be finite: no setting of the
    suite means NaN or infinity."""
    read = _READ.of(type(like))
    if read is None:
        return value
    value = read(value, where)
    if type(like) is float and not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number, got {value!r}")
    return value


def _controller(raw: dict | None, axis_count: int, supervisor_count: int,
                frame_buffer_sizes: dict[int, int]) -> ControllerConfig:
    raw = dict(raw or {})
    if "axis_frame_buffer_sizes" in raw:
        raise ConfigError("controller.axis_frame_buffer_sizes: unknown key (set axes.overrides.<n>.frame_buffer_size)")
    cfg = _dataclass(ControllerConfig, {**raw, "axis_count": axis_count, "supervisor_count": supervisor_count},
                     "controller")
    cfg.axis_frame_buffer_sizes = dict(frame_buffer_sizes)
    _require(cfg.validate(), "controller.")
    return cfg


@dataclass(slots=True)
class _AxesConfig:
    count: int
    in_position: list[AxisInPosition]
    plant: list[PlantConfig]
    masters: list[AxisMaster]
    secondary: list[SecondaryFeedback]
    faults: list[Any]  # as given (read by _faults once the motors are known)
    joints: list[Joint | None] = field(default_factory=list)
    frame_buffer_sizes: dict[int, int] = field(default_factory=dict)  # axes[n].frame_buffer_size, where given


def _axis_master(raw: Any, where: str) -> AxisMaster:
    """axes[n].master: {type: AXIS_COMMANDED_POSITION, number: 0, address: 0, correction: -1}."""
    if raw is not None and not isinstance(raw, dict):
        raise ConfigError(f"{where}: expected a mapping, got {type(raw).__name__}")
    data = dict(raw or {})
    name = data.pop("type", AxisMaster().type.name)
    kind = AxisMasterType.__members__.get(str(name).strip().upper())
    if kind is None:
        raise ConfigError(f"{where}.type: expected one of {', '.join(AxisMasterType.__members__)}, got {name!r}")
    master = _dataclass(AxisMaster, data, where)
    master.type = kind
    _require(master.validate(), f"{where}.")
    return master


def _axes(raw: dict | None) -> _AxesConfig:
    """The axes' settings; their faults as given (read by :func:`_faults` once the motors are known)."""
    raw = raw or {}
    unknown = set(raw) - {"count", "defaults", "overrides"}
    if unknown:
        raise ConfigError(f"axes.{sorted(unknown)[0]}: unknown key (known: count, defaults, overrides)")
    count = _READ.integer(raw.get("count", 4), "axes.count")
    if not 1 <= count <= MAX_OBJECTS:
        raise ConfigError(f"axes.count: expected an integer from 1 to {MAX_OBJECTS}, got {count!r}")
    defaults = raw.get("defaults") or {}
    overrides = raw.get("overrides") or {}
    if not isinstance(overrides, dict):
        raise ConfigError("axes.overrides: expected a mapping of axis number -> settings")
    out = _AxesConfig(count, [], [], [], [], [])
    for n in range(count):
        merged = _merge(defaults, overrides.get(n, overrides.get(str(n), {})))
        extra = set(merged) - set(_AXIS_KEYS)
        if extra:
            raise ConfigError(f"axes[{n}].{sorted(extra)[0]}: unknown key (known: {', '.join(_AXIS_KEYS)})")
        if "frame_buffer_size" in merged:
            size = merged["frame_buffer_size"]
            _require(check_frame_buffer_size("frame_buffer_size", size), f"axes[{n}].")
            out.frame_buffer_sizes[n] = size
        out.faults.append(merged.get("faults"))
        ip = _dataclass(AxisInPosition, merged.get("in_position"), f"axes[{n}].in_position")
        plant = _dataclass(PlantConfig, merged.get("plant"), f"axes[{n}].plant")
        _require(ip.validate(), f"axes[{n}].in_position.")
        _require(plant.validate(), f"axes[{n}].plant.")
        _require(check_settling_reachable(ip, plant), f"axes[{n}].in_position.")
        secondary = _dataclass(SecondaryFeedback, merged.get("secondary_feedback"), f"axes[{n}].secondary_feedback")
        _require(secondary.validate(), f"axes[{n}].secondary_feedback.")
        out.in_position.append(ip)
        out.plant.append(plant)
        out.masters.append(_axis_master(merged.get("master"), f"axes[{n}].master"))
        out.secondary.append(secondary)
        out.joints.append(_joint(merged.get("joint"), f"axes[{n}].joint"))
    _unique_joint_names(out.joints)
    return out


_AXIS_KEYS = ("faults", "frame_buffer_size", "in_position", "joint", "master", "plant", "secondary_feedback")


def _joint(raw: Any, where: str) -> Joint | None:
    """axes[n].joint: {name, type, counts_per_unit, offset, max_velocity}; absent: none."""
    if raw is None:
        return None
    data = dict(raw) if isinstance(raw, dict) else raw
    if isinstance(data, dict) and "name" not in data:
        raise ConfigError(f"{where}.name: a joint needs a name")
    joint = _dataclass(Joint, data, where)
    _require(joint.validate(), f"{where}.")
    return joint


def _unique_joint_names(joints: list[Joint | None]) -> None:
    """Joint names are unique in the suite, and none is another axis' default name."""
    named = {f"axis{k}": k for k, joint in enumerate(joints) if joint is None}
    for k, joint in enumerate(joints):
        if joint is None:
            continue
        if joint.name in named:
            raise ConfigError(f"axes[{k}].joint.name: {joint.name!r} is already the name of axis {named[joint.name]}")
        named[joint.name] = k


def _faults(raw: Any, number: int, motors: int) -> AxisFaultConfig:
    """An axis' fault limits and actions (docs/faults.md); its encoder fault watches its own
    motor (axis k drives motor k) unless told otherwise, or none if it has no motor."""
    where = f"axes[{number}].faults"
    if raw is None or isinstance(raw, dict):
        raw = {"encoder_fault_motor_number": number if number < motors else -1, **(raw or {})}
    config = _dataclass(AxisFaultConfig, raw, where)
    for key in config.__slots__:
        if key.endswith("_action") and isinstance(getattr(config, key), str):
            setattr(config, key, getattr(config, key).strip().upper())
    _require(config.validate(), f"{where}.")
    return config


def _motion_config(raw: dict, where: str) -> MotionConfig:
    raw = dict(raw or {})
    decel = DecelTime(
        stop=read_value(raw.pop("decel_time_stop", 0.5), 0.5, f"{where}.decel_time_stop"),
        e_stop=read_value(raw.pop("decel_time_e_stop", 0.05), 0.05, f"{where}.decel_time_e_stop"),
    )
    cfg = _dataclass(MotionConfig, raw, where)
    cfg.decel_time = decel
    _require(cfg.validate(), f"{where}.")
    return cfg


def _supervisors(raw: list, defaults: dict | None, axis_count: int) -> list[SupervisorSpec]:
    if not isinstance(raw, list) or not raw:
        raise ConfigError("supervisors: expected a non-empty list")
    defaults = defaults or {}
    specs, seen = [], set()
    for i, entry in enumerate(raw):
        where = f"supervisors[{i}]"
        if not isinstance(entry, dict):
            raise ConfigError(f"{where}: expected a mapping with number and axes")
        extra = set(entry) - set(_SUPERVISOR_KEYS)
        if extra:
            raise ConfigError(f"{where}.{sorted(extra)[0]}: unknown key (known: {', '.join(sorted(_SUPERVISOR_KEYS))})")
        number = _READ.integer(entry.get("number", i), f"{where}.number")
        if not 0 <= number < MAX_OBJECTS:
            raise ConfigError(f"{where}.number: expected an integer from 0 to {MAX_OBJECTS - 1}, got {number!r}")
        if number in seen:
            raise ConfigError(f"{where}.number: supervisor {number} is configured twice")
        seen.add(number)
        axes = entry.get("axes", [])
        if not isinstance(axes, list) or not axes:
            raise ConfigError(f"{where}.axes: expected a non-empty list of axis numbers")
        if len(axes) > MAX_COORD_AXES:
            raise ConfigError(f"{where}.axes: at most {MAX_COORD_AXES} axes (MEIXmpMAX_COORD_AXES)")
        for j, axis in enumerate(axes):
            if not 0 <= _READ.integer(axis, f"{where}.axes[{j}]") < axis_count:
                raise ConfigError(f"{where}.axes[{j}]: axis {axis!r} does not exist ({axis_count} axes)")
        if len(set(axes)) != len(axes):
            raise ConfigError(f"{where}.axes: an axis is listed twice")
        config = _motion_config(_merge(defaults.get("config") or {}, entry.get("config") or {}), f"{where}.config")
        notify_names = entry.get("event_notify", defaults.get("event_notify", ["ALL"]))
        mask = MPIEventType.parse(notify_names) if isinstance(notify_names, list) else None
        if mask is None:
            raise ConfigError(f"{where}.event_notify: expected a list of event type names, got {notify_names!r}")
        timeout = _lost_client_timeout(entry.get("lost_client_timeout", defaults.get("lost_client_timeout",
                                                                                     LOST_CLIENT.default)), where)
        specs.append(SupervisorSpec(number, list(axes), config, mask, timeout))
    return specs


_SUPERVISOR_KEYS = ("number", "axes", "config", "event_notify", "lost_client_timeout")


def _lost_client_timeout(value: Any, where: str) -> float:
    """Seconds, >= 0 (0: the watchdog is off)."""
    where = f"{where}.{LOST_CLIENT.name}"
    timeout = read_value(value, LOST_CLIENT.default, where)
    _check(LOST_CLIENT.refusal(timeout), where)
    return timeout


def _check(refusal: str | None, where: str) -> None:
    if refusal is not None:
        raise ConfigError(f"{where}: {refusal}")


def _ros(raw: dict | None) -> RosSettings:
    """The ros section, each key read and checked as its Setting says (mpi_ros/settings.py)."""
    ros = _dataclass(RosSettings, raw, "ros")
    for key in ROS:
        _check(key.refusal(getattr(ros, key.name)), key.key)
    if ros.goal_process and ros.action_server != "batched":
        raise ConfigError("ros.goal_process: the goal front serves the batched action server only "
                          "(ros.action_server: batched)")
    return ros


def _check_frame_sizes(controller: ControllerConfig, axes: list[int], where: str) -> None:
    """MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "All axes appended to a Motion object must
    have the same frame buffer size" (the controller answers it too; said here with the sizes)."""
    sizes = {n: controller.frame_buffer_size_of(n) for n in axes}
    if len(set(sizes.values())) > 1:
        shown = ", ".join(f"axis {n}: {size}" for n, size in sizes.items())
        raise ConfigError(f"{where}: MPIMotionMessageAXIS_FRAME_COUNT: all axes of a supervisor must have the "
                          f"same frame buffer size ({shown})")


def check_namespace(namespace: str, where: str = "namespace") -> str:
    """``namespace`` if it is a ROS namespace (settings.namespace_refusal), else ConfigError
    naming ``where``."""
    _check(namespace_refusal(namespace), where)
    return namespace


def parse(data: dict, source: str = "<dict>") -> SuiteConfig:
    """Validate a configuration mapping (as loaded from YAML)."""
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: expected a mapping at the top level")
    known = {"controller", "axes", "supervisors", "supervisor_defaults", "ros"}
    extra = set(data) - known
    if extra:
        raise ConfigError(f"{sorted(extra)[0]}: unknown top-level key (known: {', '.join(sorted(known))})")
    axes = _axes(data.get("axes"))
    supervisors = _supervisors(data.get("supervisors", [{"number": 0, "axes": [0]}]),
                               data.get("supervisor_defaults"), axes.count)
    supervisor_count = max(s.number for s in supervisors) + 1
    controller = _controller(data.get("controller"), axes.count, supervisor_count, axes.frame_buffer_sizes)
    for i, spec in enumerate(supervisors):
        _check_frame_sizes(controller, spec.axes, f"supervisors[{i}].axes")
    faults = [_faults(raw, n, controller.motors) for n, raw in enumerate(axes.faults)]
    return SuiteConfig(controller, axes.in_position, axes.plant, supervisors, _ros(data.get("ros")), source,
                       copy.deepcopy(data), faults, masters=axes.masters, secondary=axes.secondary,
                       joints=axes.joints)


def load(path: str | Path | None = None, overrides: dict | None = None) -> SuiteConfig:
    """Load and validate a YAML configuration file (the packaged default if None), with its
    flash (mpi_ros/flash.py) loaded over it and ``overrides`` over both."""
    path = Path(path) if path is not None else default_config_path()
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read ({exc.strerror})") from exc
    try:
        data = yaml.safe_load(text) or {}
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML ({exc})") from exc
    if not isinstance(data, dict):
        return parse(data, str(path))  # (refused: not a mapping)
    loaded = _with_flash(data, path, overrides or {})
    loaded.flash = flash.flash_path(path)
    return loaded


def _with_flash(data: dict, path: Path, overrides: dict) -> SuiteConfig:
    """The configuration with its flash over it. A flash the configuration refuses is named by
    its path: the file alone is parsed first, so an error of its own stays its own."""
    where = flash.flash_path(path)
    try:
        image = flash.read(where)
        if image is None:
            return parse(_merge(data, overrides), str(path))
        flashed = flash.overlay(data, image, where)
    except flash.FlashError as exc:
        raise ConfigError(str(exc)) from exc
    plain = parse(_merge(data, overrides), str(path))
    beyond = sorted(n for n in image.axes if n >= plain.axis_count)
    if beyond:
        raise ConfigError(f"{where}: axis {beyond[0]} is in the flash but not in the configuration "
                          f"({plain.axis_count} axes)")
    try:
        return parse(_merge(flashed, overrides), str(path))
    except ConfigError as exc:
        raise ConfigError(f"{where}: loaded over {path}: {exc}") from exc
