"""Hostile input through ROS (issue 14): a seeded generator of MotionStart/MotionModify goals
and service requests, and a harness that sends them one at a time to a suite running in this
process and checks every answer.

Used by test/ros/test_hostile_input.py (a few hundred requests, in the normal suite) and by
bench/fuzz.py (10,000, a separate command). Not a test module itself (pytest collects test_*).

What a request may carry: NaN, infinities, huge, tiny, negative and zero values; empty,
short, long and mismatched arrays; names in upper, lower and mixed case, unknown ones,
padded ones, with NUL and non-ASCII characters; every attribute on every motion type (the
path types PT .. BSPLINE2 and FRAME and the path attributes included); and, now and then,
one field made huge: 1,000,000 numbers, 100,000 messages or strings, a string of 100 kB.

What is checked, for every request (``Harness.send``):
- an answer (goal result or service response) within ``bound`` seconds;
- its message is one of the reference's (``Message``) with its code, never the internal
  error (MPIMessageNO_MEMORY, which the command layer answers only for a bug of its own);
- for a goal, the result carries the controller's answer to its command;
- a refused command (any answer but MPIMessageOK / MPIMotionMessageAUTO_START) left the
  controller as it was: supervisor states, positions (command, actual, origin), axis lists,
  configurations, stored parameters, event masks, in-position settings, gates and I/O,
  compared before and after (the suite is stepped by hand: nothing moves in between).
Accepted requests are undone (ABORT, RESET, the configuration restored) before the next.
"""

from __future__ import annotations

import array
import math
import random
import threading
import time
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

NAN, INF = math.nan, math.inf
HUGE_NUMBERS = 1_000_000  # elements of a huge numeric array
HUGE_MESSAGES = 100_000  # elements of a huge array of messages or strings (a million take seconds to build)
HUGE_TEXT = 100_000  # characters of a huge string
AXES = 2  # ms0 has axes 0 and 1 (config/default.yaml)

SPECIAL_FLOATS = (NAN, INF, -INF, 0.0, -0.0, 1e308, -1e308, 5e-324, -5e-324, 1e-300, 2.0**47, -(2.0**47),
                  2.0**47 + 1.0, 2.0**53, 1e12, 1e15, 1e18, 3.5e38, -1.0, 1e-9, 0.5, 1e-4)
SPECIAL_INT32 = (0, 1, -1, 2, 3, 4, 7, 8, 31, 32, 63, 64, 127, 128, 2**15, 2**16, 2**31 - 1, -(2**31))
HOSTILE_NAMES = ("", " ", "BOGUS", "NONE", "INVALID", "\u00e9\u00e8", "S_CURVE\x00", "0", "-1", "\t", "ALL,NONE",
                 "MPIMotionTypeS_CURVE", "\U0001f600")


def _motion_names():
    from mpi_ros.mpi.base.events import MPIEventType
    from mpi_ros.mpi.base.types import HoldType, MotionAttr, MPIAction, MPIMotionType, OutputType

    return {
        "type": [m.name for m in MPIMotionType],
        "attribute": [name for name in MotionAttr.__members__ if name != "NONE"],
        "event": [*MPIEventType.__members__, "ALL", "MOTION", "AXIS"],
        "hold": list(HoldType.__members__),
        "output": list(OutputType.__members__),
        "action": list(MPIAction.__members__),
        "which": ["COMMAND", "ACTUAL", "ORIGIN"],
        "operation": ["APPEND", "INSERT", "REMOVE"],
        "space": ["IO", "MOTOR_GENERAL_IO", "MOTOR_DEDICATED_IO"],
    }


POINT_TO_POINT = ("S_CURVE", "TRAPEZOIDAL", "S_CURVE_JERK")
VELOCITY = ("VELOCITY", "VELOCITY_JERK")
PATHS = ("PT", "PTF", "PVT", "PVTF", "SPLINE", "BESSEL", "BSPLINE", "BSPLINE2")
CAMS = ("CAM_LINEAR", "CAM_CUBIC")
# Goal fields by kind (the MotionParams message has the same ones but the first three).
FLOAT_ARRAYS = ("position", "point_velocity", "time", "feedforward", "delay", "final_velocity", "master_distance",
                "slave_position", "gear_ratio")
INT_FIELDS = ("id", "empty_count", "master_start", "repeat_from", "behavior", "low_count", "expected_axes")


@dataclass
class Request:
    """One request: a goal (kind "start"/"modify", for ms0) or a service request (kind
    "service", ``name`` relative to /mpi); ``state``: the state ms0 is brought to first."""

    kind: str
    name: str
    message: Any
    label: str
    state: str = "IDLE"
    huge: bool = False
    expect: str | None = None  # the message the answer must be (None: any of the reference's)


class Fuzzer:
    """Seeded: the same seed gives the same requests."""

    def __init__(self, seed: int, huge: float = 0.02, clean: bool = False):
        self.rng = random.Random(seed)
        self.huge = 0.0 if clean else huge  # probability that a request carries one huge field
        self.clean = clean  # plausible values only: no special value, no wrong length, no bad name
        self.names = _motion_names()
        if clean:
            for kind in ("hold", "output"):
                self.names[kind] = [n for n in self.names[kind] if n not in ("INVALID", "NONE")]

    # -- values ---------------------------------------------------------------------------
    def real(self, low: float, high: float, bad: float = 0.25) -> float:
        if not self.clean and self.rng.random() < bad:
            return self.rng.choice(SPECIAL_FLOATS)
        return self.rng.uniform(low, high)

    def int32(self, low: int, high: int, bad: float = 0.2) -> int:
        if not self.clean and self.rng.random() < bad:
            return self.rng.choice(SPECIAL_INT32)
        return self.rng.randint(low, high)

    def name(self, kind: str, bad: float = 0.12) -> str:
        if self.clean:
            return self.rng.choice(self.names[kind])
        r = self.rng.random()
        if r < bad:
            return self.rng.choice(HOSTILE_NAMES)
        name = self.rng.choice(self.names[kind])
        r = self.rng.random()
        if r < 0.08:
            return name.lower()
        if r < 0.12:
            return name.capitalize()
        if r < 0.15:
            return f"  {name} "
        return name

    def length(self, usual: int) -> int:
        r = self.rng.random()
        if self.clean or r < 0.7:
            return usual
        return self.rng.choice((0, 1, max(usual - 1, 0), usual + 1, 2 * usual, 3, 9, 33))

    def floats(self, n: int, low: float, high: float, bad: float = 0.08) -> list[float]:
        return [self.real(low, high, bad) for _ in range(n)]

    # -- ROS messages ------------------------------------------------------------------------
    def trajectory(self):
        from mpi_ros.msg import Trajectory

        return Trajectory(velocity=self.real(10.0, 1e5), acceleration=self.real(100.0, 1e6),
                          deceleration=self.real(100.0, 1e6), jerk_percent=self.real(0.0, 100.0),
                          acceleration_jerk=self.real(1e4, 1e9), deceleration_jerk=self.real(1e4, 1e9))

    def hold(self):
        from mpi_ros.msg import Hold

        return Hold(type=self.name("hold"), gate=self.int32(0, 31), number=self.int32(0, 3), address=self.int32(0, 63),
                    mask=self.int32(0, 255), pattern=self.int32(0, 255), position=self.real(-1e4, 1e4),
                    timeout=self.real(0.0, 0.1))

    def output(self, points: int):
        from mpi_ros.msg import Output

        return Output(type=self.name("output"), motor=self.int32(0, 3), address=self.int32(0, 63),
                      on_mask=self.int32(0, 255), off_mask=self.int32(0, 255),
                      point_index=self.int32(0, max(points - 1, 0)))

    def frame(self):
        from mpi_ros.msg import Frame

        return Frame(position=self.real(-1e4, 1e4), velocity=self.real(-1e4, 1e4), acceleration=self.real(-1e5, 1e5),
                     jerk=self.real(-1e6, 1e6), time=self.real(0.0005, 0.05))

    def params_fields(self, motion_type: str, attributes: list[str]) -> dict[str, Any]:  # noqa: C901 - a field each
        """Plausible data for a move of ``motion_type`` (any spelling) with ``attributes``,
        a few of its fields then made hostile."""
        kind = motion_type.strip().upper()
        rng = self.rng
        points = rng.choice((1, 2, 3, 5))
        fields: dict[str, Any] = {}
        if kind in POINT_TO_POINT or kind in VELOCITY or rng.random() < 0.1:
            per_axis = any(a.strip().upper() in ("SYNC_START", "SYNC_END") for a in attributes)
            fields["trajectory"] = [self.trajectory() for _ in range(self.length(AXES if per_axis else 1))]
            fields["position"] = self.floats(self.length(AXES), -1e4, 1e4)
        if kind in PATHS:
            fields["position"] = self.floats(self.length(AXES * points), -1e4, 1e4)
            fields["time"] = self.floats(self.length(points), 0.0005, 0.1)
            if kind in ("PVT", "PVTF") or rng.random() < 0.2:
                fields["point_velocity"] = self.floats(self.length(AXES * points), -1e4, 1e4)
            if kind in ("PTF", "PVTF") or rng.random() < 0.2:
                fields["feedforward"] = self.floats(self.length(AXES * points), -100.0, 100.0)
        if kind == "FRAME":
            fields["frames"] = [self.frame() for _ in range(self.length(AXES * points))]
        if kind in CAMS:
            fields["master_distance"] = self.floats(self.length(points), 1.0, 1e4)
            fields["slave_position"] = self.floats(self.length(AXES * points), -1e4, 1e4)
            fields["gear_ratio"] = self.floats(self.length(AXES * points), -10.0, 10.0)
        names = {a.strip().upper() for a in attributes}
        if "DELAY" in names:
            fields["delay"] = self.floats(self.length(AXES), 0.0, 0.05)
        if "FINAL_VEL" in names:
            fields["final_velocity"] = self.floats(self.length(AXES), -1e3, 1e3)
        if names & {"HOLD", "HOLD_LESS", "HOLD_GREATER"}:
            fields["hold"] = [self.hold() for _ in range(self.length(AXES))]
        if "OUTPUT" in names:
            fields["output"] = [self.output(points) for _ in range(self.length(1))]
        if "ELEMENT_ID" in names:
            fields["element_id"] = [self.int32(0, 100) for _ in range(self.length(rng.choice((1, points))))]
        if "EVENT" in names:
            fields["event_mask"] = [self.name("event") for _ in range(self.length(1))]
        for name, usual in (("id", (0, 1000)), ("empty_count", (-1, 10)), ("low_count", (0, 128)),
                            ("behavior", (0, 0)), ("expected_axes", (AXES, AXES)), ("master_start", (0, 10)),
                            ("repeat_from", (0, 3))):
            if rng.random() < 0.3:
                fields[name] = self.int32(*usual)
        if self.clean:
            return fields
        for name in ("final", "retain"):
            if rng.random() < 0.2:
                fields[name] = rng.random() < 0.5
        for _ in range(rng.choice((0, 0, 1, 1, 2, 3))):
            self._mutate(fields, points)
        return fields

    def _mutate(self, fields: dict[str, Any], points: int) -> None:
        rng = self.rng
        r = rng.random()
        if r < 0.45:  # a special value into a float array
            name = rng.choice(FLOAT_ARRAYS)
            values = list(fields.get(name, [])) or [0.0] * AXES
            values[rng.randrange(len(values))] = rng.choice(SPECIAL_FLOATS)
            fields[name] = values
        elif r < 0.65:  # an array of the wrong length
            name = rng.choice(FLOAT_ARRAYS)
            fields[name] = self.floats(rng.choice((0, 1, 3, 7, 9, 2 * AXES * points + 1)), -1e4, 1e4)
        elif r < 0.8:
            fields[rng.choice(INT_FIELDS)] = rng.choice(SPECIAL_INT32)
        elif r < 0.9:
            fields["trajectory"] = [self.trajectory() for _ in range(rng.choice((0, 1, 2, 3, 9)))]
        else:
            fields["element_id"] = [rng.choice(SPECIAL_INT32) for _ in range(rng.choice((0, 1, points, 9)))]

    def _huge_field(self, fields: dict[str, Any], goal: bool) -> str:
        """Make one field huge; returns its name (for the label)."""
        rng = self.rng
        r = rng.random()
        if r < 0.5:
            name = rng.choice(FLOAT_ARRAYS)
            fields[name] = array.array("d", [rng.choice((0.0, 1.0, NAN, 1e308))]) * HUGE_NUMBERS
        elif r < 0.6:
            fields["element_id"] = array.array("i", [1]) * HUGE_NUMBERS
            name = "element_id"
        elif r < 0.75:
            name = rng.choice(("trajectory", "frames", "hold"))
            one = {"trajectory": self.trajectory, "frames": self.frame, "hold": self.hold}[name]()
            fields[name] = [one] * HUGE_MESSAGES
        elif r < 0.85:
            name = "attributes" if goal else "event_mask"
            fields[name] = ["APPEND"] * HUGE_MESSAGES if goal else ["MOTION_DONE"] * HUGE_MESSAGES
        else:
            name = "type" if goal else "event_mask"
            text = rng.choice(("A", "S_CURVE", "\u00e9")) * HUGE_TEXT
            fields[name] = text[:HUGE_TEXT] if goal else [text[:HUGE_TEXT]]
        return name

    @staticmethod
    def _set(msg, fields: dict[str, Any]):
        for name, value in fields.items():
            setattr(msg, name, value)
        return msg

    def goal(self, kind: str | None = None, motion_type: str | None = None,
             attributes: list[str] | None = None) -> Request:
        from mpi_ros.action import MotionModify, MotionStart

        rng = self.rng
        kind = kind or ("start" if rng.random() < 0.75 else "modify")
        if motion_type is None:
            motion_type = self.name("type") if rng.random() > 0.01 else "A" * 300
        if attributes is None:
            attributes = [self.name("attribute", bad=0.05) for _ in range(rng.choice((0, 0, 1, 1, 1, 2, 3)))]
        fields = self.params_fields(motion_type, attributes)
        fields["type"] = motion_type
        fields["attributes"] = attributes
        if not self.clean and rng.random() < 0.05:
            fields["use_stored_params"] = True
        huge = ""
        if rng.random() < self.huge:
            huge = self._huge_field(fields, goal=True)
        msg = self._set((MotionStart if kind == "start" else MotionModify).Goal(), fields)
        label = f"{kind} {_short(fields['type'])} {_short(fields['attributes'])}" + (f" huge {huge}" if huge else "")
        return Request(kind, f"ms0/motion_{kind}", msg, label, self._state(kind), bool(huge))

    def _state(self, kind: str) -> str:
        if kind == "modify" or self.rng.random() < 0.2:
            return self.rng.choice(("IDLE", "MOVING", "MOVING", "STOPPED", "ERROR"))
        return "IDLE"

    # -- services --------------------------------------------------------------------------
    def service(self) -> Request:  # noqa: C901 - one branch per service of the graph
        from mpi_ros.msg import AxisInPosition, MotionConfig, MotionParams
        from mpi_ros.srv import (
            AxisConfigSet,
            AxisListEdit,
            AxisListSet,
            AxisPositionSet,
            EventNotifySet,
            EventReset,
            GateGet,
            GateSet,
            IoGet,
            IoSet,
            MotionAction,
            MotionConfigSet,
            MotionParamsSet,
            PositionSet,
        )

        rng = self.rng
        choice = rng.choice(SERVICE_WEIGHTS)
        fields: dict[str, Any] = {}
        name, msg = choice, None
        huge = ""
        if choice == "action":
            msg = MotionAction.Request(action=self.name("action"))
        elif choice == "config_set":
            config = MotionConfig(decel_time_stop=self.real(0.01, 1.0), decel_time_e_stop=self.real(0.001, 0.2),
                                  normal_feedrate=self.real(0.1, 2.0), pause_feedrate=self.real(0.0, 0.5),
                                  user_label=rng.choice(("", "cell 1", "x" * 16, "x" * 17, "\u00e9" * 16, "a\x00b")),
                                  axis_numbers=[self.int32(0, 3) for _ in range(self.length(AXES))],
                                  blend_limit=self.real(-1.0, 1.0))
            if rng.random() < self.huge:
                huge = "user_label"
                config.user_label = "L" * HUGE_TEXT
            elif rng.random() < self.huge:
                huge = "axis_numbers"
                config.axis_numbers = array.array("i", [0]) * HUGE_NUMBERS
            msg = MotionConfigSet.Request(config=config)
        elif choice == "params_set":
            motion_type = self.name("type")
            fields = self.params_fields(motion_type, [self.name("attribute") for _ in range(rng.choice((0, 1, 2)))])
            if rng.random() < self.huge:
                huge = self._huge_field(fields, goal=False)
            msg = MotionParamsSet.Request(params=self._set(MotionParams(), fields))
        elif choice == "axis_list_set":
            numbers = rng.choice(([0, 1], [1, 0], [0], [], [0, 1, 2], [4], [-1], [0, 0], [2**31 - 1], list(range(9)),
                                  [self.int32(-2, 5) for _ in range(rng.choice((1, 2, 3)))]))
            if rng.random() < self.huge:
                huge, numbers = "axis_numbers", array.array("i", [0]) * HUGE_NUMBERS
            msg = AxisListSet.Request(axis_numbers=numbers, map=rng.random() < 0.8)
        elif choice == "axis_list_edit":
            msg = AxisListEdit.Request(operation=self.name("operation"), axis=self.int32(-1, 4),
                                       after_axis=self.int32(-1, 4))
        elif choice == "position_set":
            actual = self.floats(self.length(AXES), -1e4, 1e4, bad=0.15)
            command = self.floats(self.length(AXES), -1e4, 1e4, bad=0.15)
            if rng.random() < self.huge:
                huge, actual = "actual", array.array("d", [0.0]) * HUGE_NUMBERS
            msg = PositionSet.Request(actual=actual, command=command)
        elif choice in ("event_notify_set", "event_reset"):
            names = [self.name("event") for _ in range(rng.choice((0, 1, 1, 2, 3)))]
            if rng.random() < self.huge:
                huge, names = "event_types", rng.choice((["MOTION_DONE"] * HUGE_MESSAGES, ["E" * HUGE_TEXT]))
            msg = (EventNotifySet if choice == "event_notify_set" else EventReset).Request(event_types=names)
        elif choice in ("config_get", "params_get", "axis_list_get", "position_get", "frame_buffer_status",
                        "event_notify_get") or choice in TRIGGERS:
            msg = SERVICE_TYPES[choice].Request()
        elif choice == "axis_config_set":
            k = rng.randrange(4)
            name = f"axis{k}/config_set"
            msg = AxisConfigSet.Request(in_position=AxisInPosition(
                position_fine=self.real(0.6, 100.0), position_coarse=self.int32(0, 1000),
                velocity=self.real(1.0, 1e9), settling_time=self.real(0.0, 0.05),
                settle_on_stop=rng.random() < 0.5, settle_on_estop=rng.random() < 0.5,
                settle_on_estop_cmd_eq_act=rng.random() < 0.5))
            # the cam master (MPI 002, MPIAxisMaster): any source, numbers in and out of range
            msg.master.type = rng.choice(("", "AXIS_COMMANDED_POSITION", "AXIS_ACTUAL_POSITION", "ADDRESS",
                                          "MOTOR_FEEDBACK_PRIMARY", "MOTOR_FEEDBACK_SECONDARY", "SIDEWAYS"))
            msg.master.number = self.int32(0, 3, bad=0.3)
            msg.master.address = self.int32(0, 63, bad=0.3)
            msg.master_correction = self.int32(-1, 3, bad=0.3)
        elif choice == "axis_position_set":
            k = rng.randrange(4)
            name = f"axis{k}/position_set"
            which = self.name("which") if rng.random() > self.huge else "C" * HUGE_TEXT
            huge = "which" if len(which) == HUGE_TEXT else ""
            msg = AxisPositionSet.Request(which=which, value=self.real(-1e4, 1e4, bad=0.3))
        elif choice == "axis_config_get":
            name = f"axis{rng.randrange(4)}/config_get"
            msg = SERVICE_TYPES["axis_config_get"].Request()
        elif choice == "gate_set":
            msg = GateSet.Request(gate=self.int32(0, 31, bad=0.3), closed=rng.random() < 0.5)
        elif choice == "gate_get":
            msg = GateGet.Request(gate=self.int32(0, 31, bad=0.3))
        elif choice == "io_set":
            space = self.name("space") if rng.random() > self.huge else "IO" * (HUGE_TEXT // 2)
            huge = "space" if len(space) >= HUGE_TEXT else ""
            msg = IoSet.Request(space=space, index=self.int32(0, 63, bad=0.3), value=self.int32(0, 255),
                                mask=self.int32(-1, 255))
        elif choice == "io_get":
            msg = IoGet.Request(space=self.name("space"), index=self.int32(0, 63, bad=0.3))
        if choice in SUPERVISOR_SERVICES:
            name = f"ms0/{choice}"
        label = f"{name} {_short(_describe(msg))}" + (f" huge {huge}" if huge else "")
        return Request("service", name, msg, label, self._state("service"), bool(huge))

    def request(self) -> Request:
        return self.goal() if self.rng.random() < 0.55 else self.service()

    def matrix(self) -> list[Request]:
        """Every attribute on every motion type (start, from IDLE), with the data the type and
        the attribute read (plausible values with ``clean``)."""
        requests = []
        for motion_type in self.names["type"]:
            if motion_type == "INVALID":
                continue
            for attribute in self.names["attribute"]:
                request = self.goal("start", motion_type, [attribute])
                request.state = "IDLE"
                requests.append(request)
        return requests


TRIGGERS = ("stop", "e_stop", "abort", "reset", "resume")
SUPERVISOR_SERVICES = ("action", "config_set", "params_set", "axis_list_set", "axis_list_edit", "position_set",
                       "event_notify_set", "event_reset", "config_get", "params_get", "axis_list_get", "position_get",
                       "frame_buffer_status", "event_notify_get", *TRIGGERS)
CONTROLLER_SERVICES = ("gate_set", "gate_get", "io_set", "io_get")
# How often each is picked: the setters more than the getters.
SERVICE_WEIGHTS = (("action",) * 4 + ("config_set",) * 4 + ("params_set",) * 5 + ("axis_list_set",) * 3
                   + ("axis_list_edit",) * 3 + ("position_set",) * 4 + ("event_notify_set",) * 2
                   + ("event_reset",) * 2 + ("axis_config_set",) * 4 + ("axis_position_set",) * 4
                   + ("gate_set",) * 2 + ("io_set",) * 3 + ("io_get",) + ("gate_get",) + ("axis_config_get",)
                   + ("config_get", "params_get", "axis_list_get", "position_get", "frame_buffer_status",
                      "event_notify_get") + TRIGGERS)


def _service_types() -> dict[str, type]:
    from std_srvs.srv import Trigger

    from mpi_ros import srv

    types = {"action": srv.MotionAction, "config_set": srv.MotionConfigSet, "params_set": srv.MotionParamsSet,
             "axis_list_set": srv.AxisListSet, "axis_list_edit": srv.AxisListEdit, "position_set": srv.PositionSet,
             "event_notify_set": srv.EventNotifySet, "event_reset": srv.EventReset, "config_get": srv.MotionConfigGet,
             "params_get": srv.MotionParamsGet, "axis_list_get": srv.AxisListGet, "position_get": srv.PositionGet,
             "frame_buffer_status": srv.FrameBufferStatusGet, "event_notify_get": srv.EventNotifyGet,
             "axis_config_set": srv.AxisConfigSet, "axis_config_get": srv.AxisConfigGet,
             "axis_position_set": srv.AxisPositionSet, "gate_set": srv.GateSet, "gate_get": srv.GateGet,
             "io_set": srv.IoSet, "io_get": srv.IoGet}
    types.update({name: Trigger for name in TRIGGERS})
    return types


class _LazyTypes(dict):
    def __missing__(self, key):
        if not self:
            self.update(_service_types())
        if key not in self:
            raise KeyError(key)
        return dict.__getitem__(self, key)


SERVICE_TYPES: dict[str, type] = _LazyTypes()


def _short(value: Any, limit: int = 60) -> str:
    from mpi_ros.mpi.base.params import shown

    text = shown(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _describe(msg) -> dict[str, Any]:
    out = {}
    for name in msg.get_fields_and_field_types():
        value = getattr(msg, name)
        if hasattr(value, "get_fields_and_field_types"):
            value = _describe(value)
        elif hasattr(value, "__len__") and not isinstance(value, str) and len(value) > 4:
            value = f"<{len(value)} values>"
        out[name] = value
    return out


# -- the harness -----------------------------------------------------------------------------
@dataclass
class Outcome:
    request: Request
    message: str
    seconds: float
    refused: bool | None  # None: no command reached the controller (a getter)
    detail: str = ""


@dataclass
class Tally:
    sent: int = 0
    goals: int = 0
    results: int = 0
    services: int = 0
    refused: int = 0
    accepted: int = 0
    huge: int = 0
    slowest: float = 0.0
    slowest_label: str = ""
    messages: Counter = field(default_factory=Counter)
    failures: list[str] = field(default_factory=list)


class Harness:
    """Sends requests to a suite (mpi_ros.ros.suite.Suite, stepped by hand) through ROS."""

    def __init__(self, suite, context, bound: float = 10.0):
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        from mpi_ros.client import MotionClient

        self.suite = suite
        self.runner = suite.runner
        self.bound = bound
        self.tally = Tally()
        self.client = MotionClient(0, context=context, timeout=bound, node_name="hostile_input_ms0")
        assert self.client.wait_for_server(bound), "the suite's ms0 did not come up"
        self.node = Node("hostile_input_probe", context=context)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._executor.spin, daemon=True)
        self._thread.start()
        self._clients: dict[str, Any] = {}
        # The controller's reply to each command (kept: the last one and a count; never the
        # request, which may be huge).
        self._replies = threading.Condition()
        self._count = 0
        self._last_reply = None
        self.runner.on_command(self._on_command)
        self._outstanding: list[tuple[Any, bool]] = []  # (goal, fuzzed) whose result has not come
        self.baseline = self.read(_settings)

    def close(self) -> None:
        self.client.close()
        self._executor.shutdown(timeout_sec=2.0)
        self._thread.join(timeout=2.0)
        self.node.destroy_node()

    def _on_command(self, _sample, _command, reply) -> None:
        with self._replies:
            self._count += 1
            self._last_reply = reply
            self._replies.notify_all()

    @property
    def commands(self) -> int:
        """Commands the controller has applied since the harness was made."""
        with self._replies:
            return self._count

    def read(self, reader):
        return self.runner.read(reader)

    # -- round trips -------------------------------------------------------------------------
    def call(self, name: str, msg, timeout: float | None = None):
        """A service round trip (``name`` relative to /mpi); the response, or AssertionError."""
        cli = self._clients.get(name)
        if cli is None:
            where, _, short = name.rpartition("/")
            srv_type = SERVICE_TYPES["axis_" + short if where.startswith("axis") else short]
            cli = self._clients[name] = self.node.create_client(srv_type, f"/mpi/{name}")
            assert cli.wait_for_service(timeout_sec=self.bound), f"service /mpi/{name} not available"
        future = cli.call_async(msg)
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        assert done.wait(self.bound if timeout is None else timeout), f"no response from /mpi/{name}"
        return future.result()

    def action(self, name: str) -> str:
        from mpi_ros.srv import MotionAction

        return self.call("ms0/action", MotionAction.Request(action=name)).message

    def step_until(self, done, samples: int = 400_000, chunk: int = 200) -> None:
        limit = self.read(lambda ctl: ctl.sample) + samples
        pause = threading.Event()
        while not done():
            assert self.read(lambda ctl: ctl.sample) < limit, "the controller did not get there"
            self.runner.step(chunk)
            pause.wait(0.0005)  # let the executor threads publish and answer

    def ms0_state(self) -> str:
        return self.read(lambda ctl: ctl.supervisor(0).state.name)

    # -- preconditions and clean-up ------------------------------------------------------------
    def bring_to(self, state: str) -> None:
        if state == "IDLE":
            return
        crawl = self.client.start({"type": "S_CURVE", "position": [1e6, -1e6], "trajectory": [
            {"velocity": 100.0, "acceleration": 1000.0, "deceleration": 1000.0, "jerk_percent": 50.0}]})
        self._outstanding.append((crawl, False))
        self.runner.step(20)
        assert self.ms0_state() == "MOVING", self.ms0_state()
        if state == "STOPPED":
            assert self.action("STOP") == "MPIMessageOK"
            self.step_until(lambda: self.ms0_state() == "STOPPED")
        elif state == "ERROR":
            assert self.action("E_STOP") == "MPIMessageOK"
            self.step_until(lambda: self.ms0_state() == "ERROR")

    def restore(self) -> None:
        """Back to IDLE with every goal ended and the settings of the start."""
        from mpi_ros.srv import MotionAction

        pending = any(not goal.done for goal, _ in self._outstanding)
        states = self.read(lambda ctl: [ms.state.name for ms in ctl.supervisors])
        if pending or states != ["IDLE", "IDLE"]:
            for number, state in enumerate(states):
                if state != "IDLE" or (number == 0 and pending):  # ABORT is never refused, IDLE included
                    self.call(f"ms{number}/action", MotionAction.Request(action="ABORT"))
            self.step_until(lambda: all(goal.done for goal, _ in self._outstanding) and self.read(
                lambda ctl: all(ms.state.name in ("IDLE", "ERROR") for ms in ctl.supervisors)))
            for number in (0, 1):
                if self.read(lambda ctl, n=number: ctl.supervisor(n).state.name) == "ERROR":
                    self.call(f"ms{number}/action", MotionAction.Request(action="RESET"))
        for goal, fuzzed in self._outstanding:
            result = goal.wait(self.bound, raise_on_error=False)
            self.tally.results += fuzzed
            self._check_message(result.message, result.code, f"result of an undone goal: {result.detail}")
        self._outstanding.clear()
        self._restore_settings()
        assert self.read(lambda ctl: [ms.state.name for ms in ctl.supervisors]) == ["IDLE", "IDLE"]

    def _restore_settings(self) -> None:
        from mpi_ros.msg import AxisInPosition, MotionConfig
        from mpi_ros.srv import AxisConfigSet, AxisListSet, EventNotifySet, GateSet, MotionConfigSet

        now = self.read(_settings)
        base = self.baseline
        if now["axis_lists"][0] != base["axis_lists"][0] or now["mapped"] != base["mapped"]:
            reply = self.call("ms0/axis_list_set", AxisListSet.Request(axis_numbers=list(base["axis_lists"][0]),
                                                                       map=True))
            assert reply.message == "MPIMessageOK", reply.message
        if now["configs"][0] != base["configs"][0]:
            c = base["config0"]
            reply = self.call("ms0/config_set", MotionConfigSet.Request(config=MotionConfig(
                decel_time_stop=c.decel_time.stop, decel_time_e_stop=c.decel_time.e_stop,
                normal_feedrate=c.normal_feedrate, pause_feedrate=c.pause_feedrate, user_label=c.user_label,
                blend_limit=c.blend_limit)))
            assert reply.message == "MPIMessageOK", reply.message
        if now["notify"][0] != base["notify"][0]:
            reply = self.call("ms0/event_notify_set", EventNotifySet.Request(event_types=base["notify_names0"]))
            assert reply.message == "MPIMessageOK", reply.message
        for k, (cfg, base_cfg) in enumerate(zip(now["in_position"], base["in_position"], strict=True)):
            if cfg != base_cfg:
                p = base["in_position_values"][k]
                reply = self.call(f"axis{k}/config_set", AxisConfigSet.Request(in_position=AxisInPosition(
                    position_fine=float(p.position_fine), position_coarse=int(p.position_coarse),
                    velocity=float(p.velocity), settling_time=float(p.settling_time),
                    settle_on_stop=p.settle_on_stop, settle_on_estop=p.settle_on_estop,
                    settle_on_estop_cmd_eq_act=p.settle_on_estop_cmd_eq_act)))
                assert reply.message == "MPIMessageOK", reply.message
        for gate, closed in enumerate(now["gates"]):
            if closed:
                self.call("gate_set", GateSet.Request(gate=gate, closed=False))
        assert self.read(_settings)["comparable"] == base["comparable"], "the settings were not restored"

    # -- one request -------------------------------------------------------------------------------
    def send(self, request: Request) -> Outcome:
        """Send ``request`` (ms0 first brought to ``request.state``), check its answer, undo it."""
        tally = self.tally
        self.bring_to(request.state)
        before = self.read(fingerprint)
        with self._replies:
            count = self._count
        started = time.monotonic()
        goal = None
        if request.kind in ("start", "modify"):
            goal = (self.client.start if request.kind == "start" else self.client.modify)(request.message)
            reply = self._reply_since(count)
        else:
            response = self.call(request.name, request.message)
            reply = self._reply_since(count, wait=False)
        after = self.read(fingerprint)
        refused = None if reply is None else not reply.accepted
        if goal is not None:
            tally.goals += 1
            if refused:
                result = goal.wait(self.bound, raise_on_error=False)
                tally.results += 1
                message, code, detail = result.message, result.code, result.detail
                if (message, detail) != (reply.message.name, reply.detail):
                    self._fail(request, f"result {message} {detail!r} is not the controller's answer "
                                        f"{reply.message.name} {reply.detail!r}")
            else:
                self._outstanding.append((goal, True))
                message, code, detail = reply.message.name, reply.message.code, reply.detail
        else:
            tally.services += 1
            message = response.message.split(":", 1)[0] if hasattr(response, "success") else response.message
            code = getattr(response, "code", None)
            detail = response.message if hasattr(response, "success") else ""
            if reply is not None and message != reply.message.name:
                self._fail(request, f"response {message} is not the controller's answer {reply.message.name}")
        seconds = time.monotonic() - started
        tally.sent += 1
        tally.huge += request.huge
        tally.messages[message] += 1
        if seconds > tally.slowest:
            tally.slowest, tally.slowest_label = seconds, request.label
        if seconds > self.bound:
            self._fail(request, f"answered after {seconds:.1f} s")
        self._check_message(message, code, request.label)
        if request.expect is not None and message != request.expect:
            self._fail(request, f"answered {message} ({detail}), expected {request.expect}")
        if refused:
            tally.refused += 1
            if after != before:
                self._fail(request, f"refused ({message}: {detail}) but the controller changed: "
                                    f"{_difference(before, after)}")
        elif refused is not None:
            tally.accepted += 1
        self.restore()
        return Outcome(request, message, seconds, refused, detail)

    def _reply_since(self, count: int, wait: bool = True):
        """The controller's reply to the command sent after ``count`` commands (None if the
        request reached no command: a getter)."""
        with self._replies:
            if wait:
                assert self._replies.wait_for(lambda: self._count > count, self.bound), (
                    "no command reached the controller")
            if self._count == count:
                return None
            assert self._count == count + 1, f"{self._count - count} commands for one request"
            return self._last_reply

    def _check_message(self, message: str, code, label: str) -> None:
        from mpi_ros.commands import INTERNAL_ERROR
        from mpi_ros.mpi.base.messages import Message

        known = Message.__members__.get(message)
        if known is None:
            self.tally.failures.append(f"{label}: unknown message {message!r}")
        elif known is INTERNAL_ERROR:
            self.tally.failures.append(f"{label}: internal error")
        elif code is not None and code != known.code:
            self.tally.failures.append(f"{label}: code {code} for {message} ({known.code})")

    def _fail(self, request: Request, why: str) -> None:
        self.tally.failures.append(f"{request.label}: {why}")

    def alive(self) -> None:
        """The suite still serves: a valid move through ROS ends with MPIMessageOK (relative:
        accepted position_set requests may have left the axes anywhere)."""
        goal = self.client.start({"type": "S_CURVE", "attributes": ["RELATIVE"], "position": [100.0, -100.0],
                                  "trajectory": [{"velocity": 20000.0, "acceleration": 400000.0,
                                                  "deceleration": 400000.0, "jerk_percent": 50.0}]})
        self.step_until(lambda: goal.done, samples=200_000, chunk=50)
        result = goal.wait(self.bound, raise_on_error=False)
        assert result.message == "MPIMessageOK", (result.message, result.detail)


def fingerprint(ctl) -> tuple:
    """Everything a refused command must leave as it was (read under the runner's lock)."""
    supervisors = tuple(
        (ms.own_state, ms.state, tuple(ms.axis_list), tuple(ms.mapped), repr(ms.config), repr(ms.stored_params),
         int(ms.notify_mask), int(ms.latched), ms.current.serial if ms.current is not None else None, len(ms.queue))
        for ms in ctl.supervisors)
    axes = tuple((a.cmd_p, a.act_p, a.cmd_v, a.origin, repr(a.in_position), a.amp_enabled) for a in ctl.axes)
    io = (tuple(ctl.io.gates_closed), tuple(tuple(words) for words in ctl.io.words.values()))
    return ctl.sample, supervisors, axes, io


_PARTS = ("sample", "supervisors", "axes", "I/O")


def _difference(before: tuple, after: tuple) -> str:
    return ", ".join(f"{name}: {_short(b, 200)} -> {_short(a, 200)}"
                     for name, b, a in zip(_PARTS, before, after, strict=True) if a != b)


def _settings(ctl) -> dict[str, Any]:
    ms0 = ctl.supervisor(0)
    out = {
        "axis_lists": [tuple(ms.axis_list) for ms in ctl.supervisors],
        "mapped": [tuple(ms.mapped) for ms in ctl.supervisors],
        "configs": [repr(ms.config) for ms in ctl.supervisors],
        "config0": ms0.config.copy(),
        "notify": [int(ms.notify_mask) for ms in ctl.supervisors],
        "notify_names0": ms0.notify_mask.names(),
        "in_position": [repr(a.in_position) for a in ctl.axes],
        "in_position_values": [a.in_position.copy() for a in ctl.axes],
        "gates": list(ctl.io.gates_closed),
    }
    out["comparable"] = (out["axis_lists"], out["mapped"], out["configs"], out["notify"], out["in_position"],
                         out["gates"])
    return out
