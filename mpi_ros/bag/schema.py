"""Message definitions as rosbag2 stores them in MCAP (schema encoding ``ros2msg``).

A schema is the type's .msg text, then for each nested type (depth first, each once, the
types of one text in sorted order, as rosbag2 orders them) a newline, a line of 80 ``=``,
``MSG: pkg/Type`` and that type's .msg text (docs/recording.md, "The MCAP file"). The .msg
files and the RIHS01 type hashes come from the packages' installed share/ folders.
"""

from __future__ import annotations

import importlib
import json
import re
import sys
from functools import cache
from pathlib import Path

PRIMITIVES = {
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
    "int64", "uint64", "string", "wstring",
}
_SEPARATOR = "=" * 80


def _share_dirs(package: str) -> list[Path]:
    dirs = []
    try:
        from ament_index_python.packages import get_package_share_directory

        dirs.append(Path(get_package_share_directory(package)))
    except Exception:  # noqa: BLE001 - no ament index entry: try the prefix below
        pass
    dirs.append(Path(sys.prefix) / "share" / package)
    return dirs


def _find(package: str, name: str, suffix: str) -> Path:
    for share in _share_dirs(package):
        path = share / "msg" / f"{name}{suffix}"
        if path.is_file():
            return path
    raise FileNotFoundError(f"{package}/msg/{name}{suffix} not found in {[str(d) for d in _share_dirs(package)]}")


def split(type_name: str) -> tuple[str, str]:
    """'pkg/msg/Type' or 'pkg/Type' -> ('pkg', 'Type')."""
    parts = type_name.split("/")
    return parts[0], parts[-1]


@cache
def msg_text(type_name: str) -> str:
    package, name = split(type_name)
    return _find(package, name, ".msg").read_text(encoding="utf-8")


def _field_types(text: str, package: str) -> list[str]:
    """Nested message types used by the fields of a .msg text (constants skipped)."""
    found = []
    for raw in text.splitlines():
        words = raw.split("#", 1)[0].split()
        if len(words) < 2:
            continue
        if "=" in words[1] or (len(words) > 2 and words[2].startswith("=")):
            continue  # a constant: TYPE NAME=VALUE
        base = re.sub(r"\[[^\]]*\]$", "", words[0])  # arrays: T[], T[N], T[<=N]
        base = re.sub(r"<=\d+$", "", base)  # bounded strings
        if base in PRIMITIVES:
            continue
        found.append(base if "/" in base else f"{package}/{base}")
    return found


@cache
def ros2msg(type_name: str) -> str:
    """The ros2msg schema text of a type ('pkg/msg/Type'), as rosbag2 writes it (rosbag2_cpp's
    local message definition source): the type's .msg file as it stands; after it, for each
    type that text uses, in sorted order, and not written already: a newline, the line of 80
    ``=``, ``MSG: pkg/Type`` and that type's text, followed in the same way by the types it uses."""
    package, name = split(type_name)
    seen: set[str] = set()

    def text_of(key: str, pkg: str) -> str:
        text = msg_text(key)
        for dep in sorted(set(_field_types(text, pkg))):
            if dep in seen:
                continue
            seen.add(dep)
            text += f"\n{_SEPARATOR}\nMSG: {dep}\n" + text_of(dep, split(dep)[0])
        return text

    return text_of(f"{package}/{name}", package)


@cache
def type_hash(type_name: str) -> str:
    """The RIHS01 type description hash of a type (empty if the package has none)."""
    package, name = split(type_name)
    try:
        data = json.loads(_find(package, name, ".json").read_text(encoding="utf-8"))
    except FileNotFoundError:
        return ""
    for entry in data.get("type_hashes", []):
        if entry.get("type_name") == f"{package}/msg/{name}":
            return entry.get("hash_string", "")
    return ""


def message_class(type_name: str):
    """The generated Python class of 'pkg/msg/Type'."""
    package, name = split(type_name)
    return getattr(importlib.import_module(f"{package}.msg"), name)


def full_name(msg_class) -> str:
    """'pkg/msg/Type' of a generated message class."""
    package = msg_class.__module__.split(".")[0]
    return f"{package}/msg/{msg_class.__name__}"
