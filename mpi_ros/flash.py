"""The twin's flash: mpiMotionFlashConfigGet/Set (MPI 000) and mpiAxisFlashConfigGet/Set (MPI 002).

The flash is a file beside the configuration file (``<name>.flash.yaml`` beside
``<name>.yaml``). FlashConfigSet writes it and changes nothing that runs; the next start loads
it over the configuration (config.load); FlashConfigGet reads it. Its entries are written in
the configuration file's own words (a supervisor's ``config``, an axis' ``in_position`` and
``master``), so the configuration's validators read them, and name them, at the next start.

A write is atomic: the new flash goes to a temporary file in the same directory, is synced,
and replaces the old one by a rename, so a reader (or a crash) sees the old flash or the new
one, never part of one. The file carries the SHA-256 of its contents: a corrupt or partial
flash is refused with its path named, at the start and by Get and Set, and never replaced by
the defaults (docs/configuration.md, "Flash").
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, Outcome
from mpi_ros.mpi.base.params import AxisInPosition, AxisMaster, MotionConfig

FORMAT = "mpi_ros flash 1"
_HEADER = ("# The flash of the mpi_ros twin, written by mpiMotionFlashConfigSet and mpiAxisFlashConfigSet\n"
           "# and loaded over the configuration at the next start. Do not edit: sha256 guards the contents.\n")


class FlashError(ValueError):
    """The flash file cannot be read: corrupt or partial. The message names its path."""


def flash_path(config_path: str | Path) -> Path:
    """The flash of the configuration file ``config_path``: ``<stem>.flash.yaml`` beside it."""
    path = Path(config_path)
    return path.with_name(f"{path.stem}.flash.yaml")


@dataclass(slots=True)
class FlashImage:
    """What the flash holds, in the configuration file's words: supervisor number -> its
    ``config`` mapping, axis number -> {``in_position``, ``master``}."""

    supervisors: dict[int, dict[str, Any]] = field(default_factory=dict)
    axes: dict[int, dict[str, Any]] = field(default_factory=dict)

    def validate(self) -> Outcome:
        """Its shape (the values are the configuration's validators' at the next start)."""
        for name, entries in (("supervisors", self.supervisors), ("axes", self.axes)):
            if not isinstance(entries, dict):
                return Outcome(Message.MPIMessagePARAM_INVALID, f"{name}: expected a mapping")
            for number, entry in entries.items():
                if not isinstance(number, int) or isinstance(number, bool) or number < 0:
                    return Outcome(Message.MPIMessagePARAM_INVALID, f"{name}: {number!r} is not an object number")
                if not isinstance(entry, dict):
                    return Outcome(Message.MPIMessagePARAM_INVALID, f"{name}.{number}: expected a mapping")
        return VALID

    def contents(self) -> dict[str, Any]:
        return {"supervisors": self.supervisors, "axes": self.axes}


def _digest(contents: dict[str, Any]) -> str:
    return hashlib.sha256(json.dumps(contents, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def read(path: Path) -> FlashImage | None:
    """The flash at ``path`` (None if there is none), or FlashError naming it."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise FlashError(f"{path}: cannot read the flash ({exc.strerror})") from exc
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise _corrupt(path, f"not valid YAML: {exc}") from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise _corrupt(path, f"no {FORMAT!r} header")
    contents = data.get("contents")
    if not isinstance(contents, dict) or data.get("sha256") != _digest(contents):
        raise _corrupt(path, "its contents do not match their sha256 (cut short or changed)")
    image = FlashImage(contents.get("supervisors") or {}, contents.get("axes") or {})
    verdict = image.validate()
    if not verdict.ok:
        raise _corrupt(path, verdict.detail)
    return image


def _corrupt(path: Path, why: str) -> FlashError:
    return FlashError(f"{path}: corrupt or partial flash file ({why}); it is not replaced by the defaults: "
                      "restore it, or delete it to start from the configuration alone")


def write(path: Path, image: FlashImage) -> None:
    """Replace the flash at ``path`` by ``image`` atomically (temporary file, fsync, rename)."""
    contents = image.contents()
    text = _HEADER + yaml.safe_dump({"format": FORMAT, "sha256": _digest(contents), "contents": contents},
                                    sort_keys=True)
    fd, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            out.write(text)
            out.flush()
            os.fsync(out.fileno())
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)  # the rename itself survives a power cut
    finally:
        os.close(directory)


def motion_entry(config: MotionConfig) -> dict[str, Any]:
    """A supervisor's MotionConfig as the configuration file writes it (supervisors[i].config)."""
    return {"decel_time_stop": config.decel_time.stop, "decel_time_e_stop": config.decel_time.e_stop,
            "normal_feedrate": config.normal_feedrate, "pause_feedrate": config.pause_feedrate,
            "user_label": config.user_label, "blend_limit": config.blend_limit}


def axis_entry(in_position: AxisInPosition, master: AxisMaster) -> dict[str, Any]:
    """An axis' configuration as the configuration file writes it (axes.overrides.<n>)."""
    return {"in_position": {key: getattr(in_position, key) for key in in_position.__slots__},
            "master": {"type": master.type.name, "number": master.number, "address": master.address,
                       "correction": master.correction}}


class Flash:
    """The flash file of a suite: Get and Set of its entries, one writer at a time."""

    def __init__(self, path: Path):
        self.path = path
        self._lock = threading.Lock()

    def get(self, kind: str, number: int) -> tuple[Outcome, dict[str, Any] | None]:
        """The entry of supervisor or axis ``number`` (``kind``: "supervisors" or "axes"); None
        if the flash holds none (the next start then loads the configuration's)."""
        try:
            image = read(self.path)
        except FlashError as exc:
            return Outcome(Message.MPIMessageFILE_OPEN_ERROR, str(exc)), None
        entries = image.contents()[kind] if image is not None else {}
        return VALID, entries.get(number)

    def set(self, kind: str, number: int, entry: dict[str, Any]) -> Outcome:
        """Write the entry of supervisor or axis ``number``, keeping the others."""
        return self._update(lambda image: image.contents()[kind].__setitem__(number, entry))

    def _update(self, change: Callable[[FlashImage], None]) -> Outcome:
        with self._lock:
            try:
                image = read(self.path) or FlashImage()
            except FlashError as exc:  # never written over: the user decides what it was
                return Outcome(Message.MPIMessageFILE_OPEN_ERROR, str(exc))
            change(image)
            try:
                write(self.path, image)
            except OSError as exc:
                return Outcome(Message.MPIMessageFILE_OPEN_ERROR, f"{self.path}: cannot write the flash ({exc})")
        return VALID


def overlay(data: dict[str, Any], image: FlashImage, path: Path) -> dict[str, Any]:
    """The configuration mapping ``data`` (as loaded from YAML; not changed) with the flash
    ``image`` loaded over it: each supervisor's ``config`` and each axis' overrides. An entry
    for an object the configuration does not have is FlashError."""
    out = dict(data)
    supervisors = [dict(entry) if isinstance(entry, dict) else entry for entry in out.get("supervisors") or []]
    numbers = {entry.get("number", i) if isinstance(entry, dict) else None: i for i, entry in enumerate(supervisors)}
    for number, config in image.supervisors.items():
        if number not in numbers:
            raise FlashError(f"{path}: supervisor {number} is in the flash but not in the configuration")
        entry = supervisors[numbers[number]]
        entry["config"] = {**(entry.get("config") or {}), **config}
    if image.supervisors:
        out["supervisors"] = supervisors
    axes = dict(out.get("axes") or {})
    overrides = dict(axes.get("overrides") or {})
    for number, settings in image.axes.items():
        key = str(number) if str(number) in overrides and number not in overrides else number
        overrides[key] = {**(overrides.get(key) or {}), **settings}
    if image.axes:
        axes["overrides"] = overrides
        out["axes"] = axes
    return out
