"""Every mpi_ros interface type imports and survives a CDR round trip with non-default values.

The types are discovered from the .msg/.srv/.action files of the source tree, so a new file is
covered without touching this test; the imports are of the INSTALLED package (the source tree
has no generated code), so a file that was added but not built fails here.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "mpi_ros"

# (subpackage, file suffix, the classes that a type of that kind defines)
KINDS = {
    "msg": (".msg", [()]),
    "srv": (".srv", [("Request",), ("Response",)]),
    "action": (".action", [
        ("Goal",), ("Result",), ("Feedback",),
        # the wire types that carry them
        ("Impl", "SendGoalService", "Request"), ("Impl", "SendGoalService", "Response"),
        ("Impl", "GetResultService", "Request"), ("Impl", "GetResultService", "Response"),
        ("Impl", "FeedbackMessage"),
    ]),
}


def discover():
    cases = []
    for sub, (suffix, parts) in KINDS.items():
        for path in sorted((REPO / sub).glob(f"*{suffix}")):
            for part in parts:
                cases.append((sub, path.stem, part))
    return cases


CASES = discover()


def resolve(sub: str, name: str, part: tuple[str, ...]):
    obj = getattr(importlib.import_module(f"{PACKAGE}.{sub}"), name)
    for attr in part:
        obj = getattr(obj, attr)
    return obj


def _type_class(namespaced):
    module_name = ".".join(namespaced.namespaces)
    module = importlib.import_module(module_name)
    if hasattr(module, namespaced.name):
        return getattr(module, namespaced.name)
    # Types nested in a service or action (MotionStart_Goal, ...) live in the private module
    # of the interface they belong to (mpi_ros.action._motion_start).
    base = namespaced.name.split("_")[0]
    private = "_" + re.sub(r"(?<!^)(?=[A-Z])", "_", base).lower()
    return getattr(importlib.import_module(f"{module_name}.{private}"), namespaced.name)


_INT_RANGES = {
    "int8": (-128, 127), "uint8": (0, 255), "int16": (-32768, 32767), "uint16": (0, 65535),
    "int32": (-2**31, 2**31 - 1), "uint32": (0, 2**32 - 1),
    "int64": (-2**63, 2**63 - 1), "uint64": (0, 2**64 - 1),
}


def value_for(slot_type, seed: int, default=None):
    """A value of the given rosidl type, different from `default` (and from zero/empty)."""
    from rosidl_parser import definition as d

    if isinstance(slot_type, d.BasicType):
        t = slot_type.typename
        if t == "boolean":
            return not bool(default) if default is not None else True
        if t in ("float", "double"):
            value = float(seed) + 0.5          # exact in float32 too
            return value + 1.0 if value == default else value
        if t in _INT_RANGES:
            _lo, hi = _INT_RANGES[t]
            value = 1 + seed % min(hi, 100)
            if value == default:
                value = value + 1 if value < hi else value - 1
            return value
        if t == "octet":
            return bytes([1 + seed % 200])
        if t == "char":
            return 1 + seed % 100
        raise AssertionError(f"unhandled basic type {t}")
    if isinstance(slot_type, (d.UnboundedString, d.BoundedString,
                              d.UnboundedWString, d.BoundedWString)):
        value = f"s{seed}"
        if isinstance(slot_type, (d.BoundedString, d.BoundedWString)):
            value = value[: slot_type.maximum_size]
        return value if value != default else value + "x"
    if isinstance(slot_type, d.NamespacedType):
        return build(_type_class(slot_type), seed)
    if isinstance(slot_type, d.Array):
        return [value_for(slot_type.value_type, seed + i) for i in range(slot_type.size)]
    if isinstance(slot_type, (d.UnboundedSequence, d.BoundedSequence)):
        count = 2
        if isinstance(slot_type, d.BoundedSequence):
            count = min(count, slot_type.maximum_size)
        return [value_for(slot_type.value_type, seed + i) for i in range(count)]
    raise AssertionError(f"unhandled type {slot_type!r}")


def fields(cls) -> list[str]:
    """Field names in declaration order (the order of SLOT_TYPES)."""
    names = list(cls.get_fields_and_field_types())
    assert len(names) == len(cls.SLOT_TYPES)
    return names


def build(cls, seed: int = 1):
    """An instance of cls with every field set to a non-default value."""
    msg = cls()
    for i, (field, slot_type) in enumerate(zip(fields(cls), cls.SLOT_TYPES, strict=True)):
        default = getattr(msg, field)
        scalar_default = default if isinstance(default, (bool, int, float, str)) else None
        setattr(msg, field, value_for(slot_type, seed * 7 + i, scalar_default))
    return msg


def test_interfaces_were_found():
    kinds = {sub for sub, _, _ in CASES}
    assert kinds == {"msg", "srv", "action"}, f"interface files missing under {REPO}"


@pytest.mark.parametrize(("sub", "name", "part"), CASES,
                         ids=[".".join((s, n, *p)) for s, n, p in CASES])
def test_roundtrip(sub, name, part):
    from rclpy.serialization import deserialize_message, serialize_message

    cls = resolve(sub, name, part)
    msg = build(cls)
    default = cls()
    for field in fields(cls):
        assert not _equal(getattr(msg, field), getattr(default, field)), \
            f"{field} still has its default value"
    data = serialize_message(msg)
    assert isinstance(data, bytes)
    assert len(data) > 0
    back = deserialize_message(data, cls)
    assert back == msg
    # (Not comparing bytes of a second serialisation: CDR alignment padding is not zeroed.)
    assert deserialize_message(serialize_message(back), cls) == msg


def _equal(a, b) -> bool:
    try:
        result = a == b
        return bool(result) if not hasattr(result, "all") else bool(result.all())
    except ValueError:
        return False


@pytest.mark.parametrize("name", ["MotionStart", "MotionModify"])
def test_goal_point_defaults(name):
    """The point settings default as the .action file writes them (MPIMotionPoint)."""
    goal = resolve("action", name, ("Goal",))()
    assert goal.final is True
    assert goal.retain is False
    assert goal.empty_count == 5
    assert goal.use_stored_params is False


def test_motion_params_point_defaults():
    from mpi_ros.msg import MotionParams

    params = MotionParams()
    assert (params.final, params.retain, params.empty_count) == (True, False, 5)


def test_float_fields_need_floats():
    """rclpy behaviour the nodes must respect: convert to float at the edge.

    With ROS_PYTHON_CHECK_FIELDS=1 (set by conftest for every test) assigning an int to a
    float64 field raises; without it the assignment is accepted and SILENTLY serialises
    garbage (500 comes back as 5e-324). So every producer of messages converts to float.
    """
    from rclpy.serialization import deserialize_message, serialize_message

    from mpi_ros.msg import Trajectory

    with pytest.raises(AssertionError):
        Trajectory(velocity=500, check_fields=True)
    unchecked = Trajectory(velocity=500, check_fields=False)
    back = deserialize_message(serialize_message(unchecked), Trajectory)
    assert back.velocity != 500.0  # the hazard
    assert Trajectory(velocity=float(500)).velocity == 500.0
