"""The twin's flash: mpiMotionFlashConfigSet/Get (MPI 000) and mpiAxisFlashConfigSet/Get
(MPI 002). A file beside the configuration file, written atomically, loaded over the
configuration at the next start, and refused (its path named) when corrupt or partial."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from mpi_ros import config, flash
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import AxisInPosition, AxisMaster, DecelTime, MotionConfig


@pytest.fixture
def config_file(tmp_path: Path) -> Path:
    path = tmp_path / "cell.yaml"
    shutil.copy(config.default_config_path(), path)
    return path


def _motion(normal_feedrate: float = 0.5) -> MotionConfig:
    return MotionConfig(decel_time=DecelTime(0.25, 0.02), normal_feedrate=normal_feedrate, blend_limit=0.3)


def test_the_flash_lives_beside_the_configuration(config_file: Path):
    assert flash.flash_path(config_file) == config_file.parent / "cell.flash.yaml"
    assert config.load(config_file).flash == config_file.parent / "cell.flash.yaml"


def test_set_is_loaded_at_the_next_start_over_the_configuration(config_file: Path):
    # MPI 000, mpiMotionFlashConfigSet / MPI 002, mpiAxisFlashConfigSet: written to the flash,
    # which the next start loads; the running configuration is not changed by it
    store = flash.Flash(flash.flash_path(config_file))
    assert store.set("supervisors", 1, flash.motion_entry(_motion())).ok
    in_position = AxisInPosition(position_fine=3.0, position_coarse=30, settling_time=0.02)
    assert store.set("axes", 2, flash.axis_entry(in_position, AxisMaster(number=1, correction=0))).ok
    # MPI 000, mpiMotionFlashConfigGet: reads back what was written
    outcome, entry = store.get("supervisors", 1)
    assert outcome.ok
    assert entry == flash.motion_entry(_motion())
    assert store.get("supervisors", 0) == (outcome, None)  # nothing written for it
    ctl = config.load(config_file).build_controller()
    ms1 = ctl.supervisor(1)
    assert ms1.config.normal_feedrate == 0.5
    assert ms1.config.decel_time.stop == 0.25
    assert ms1.config.blend_limit == 0.3
    assert ctl.supervisor(0).config.normal_feedrate == 1.0  # the configuration's own
    assert ctl.axes[2].in_position.position_fine == 3.0
    assert ctl.axes[2].master.number == 1
    assert ctl.axes[2].master.correction == 0
    assert ctl.axes[1].in_position.position_fine == 10.0


def test_a_write_is_atomic(config_file: Path, monkeypatch):
    path = flash.flash_path(config_file)
    store = flash.Flash(path)
    assert store.set("supervisors", 0, flash.motion_entry(_motion(0.5))).ok
    before = path.read_bytes()

    def power_cut(source, target):
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(os, "replace", power_cut)
    outcome = store.set("supervisors", 0, flash.motion_entry(_motion(0.75)))
    assert outcome.message is Message.MPIMessageFILE_OPEN_ERROR
    assert str(path) in outcome.detail
    assert path.read_bytes() == before  # the old flash, whole
    assert sorted(p.name for p in path.parent.iterdir()) == ["cell.flash.yaml", "cell.yaml"]  # no temporary left
    monkeypatch.undo()
    assert store.set("supervisors", 0, flash.motion_entry(_motion(0.75))).ok
    assert store.get("supervisors", 0)[1]["normal_feedrate"] == 0.75


@pytest.mark.parametrize("damage", ["cut", "edit", "garbage"])
def test_a_corrupt_or_partial_flash_is_refused_with_its_path(config_file: Path, damage: str):
    path = flash.flash_path(config_file)
    store = flash.Flash(path)
    assert store.set("supervisors", 0, flash.motion_entry(_motion())).ok
    assert store.set("axes", 0, flash.axis_entry(AxisInPosition(), AxisMaster())).ok
    text = path.read_text()
    broken = {"cut": text[: len(text) * 2 // 3].rsplit("\n", 1)[0] + "\n",  # cut at a line: still YAML
              "edit": text.replace("normal_feedrate: 0.5", "normal_feedrate: 0.9"),
              "garbage": "\x00\x01: [unclosed"}[damage]
    assert broken != text
    path.write_text(broken)
    with pytest.raises(config.ConfigError, match=str(path)):
        config.load(config_file)  # never the configuration's defaults in its place
    outcome, entry = store.get("supervisors", 0)  # Get answers an error
    assert outcome.message is Message.MPIMessageFILE_OPEN_ERROR
    assert str(path) in outcome.detail
    assert entry is None
    # Set does not write over it either: the user decides what it was
    assert store.set("supervisors", 0, flash.motion_entry(_motion())).message is Message.MPIMessageFILE_OPEN_ERROR
    assert path.read_text() == broken


def test_a_value_the_configuration_refuses_names_the_flash(config_file: Path):
    path = flash.flash_path(config_file)
    flash.write(path, flash.FlashImage(supervisors={0: {"normal_feedrate": -1.0}}))
    with pytest.raises(config.ConfigError, match=f"{path}: loaded over .*normal_feedrate"):
        config.load(config_file)
    flash.write(path, flash.FlashImage(axes={9: {"in_position": {}}}))
    with pytest.raises(config.ConfigError, match=f"{path}: axis 9 is in the flash but not in the configuration"):
        config.load(config_file)
    flash.write(path, flash.FlashImage(supervisors={5: {}}))
    with pytest.raises(config.ConfigError, match=f"{path}: supervisor 5"):
        config.load(config_file)


def test_the_suite_exits_2_naming_a_corrupt_flash(config_file: Path):
    path = flash.flash_path(config_file)
    path.write_text("format: mpi_ros flash 1\nsha256: 0\ncontents: {supervisors: {0: {normal_feedrate: 0.5}}}\n")
    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    done = subprocess.run([sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--config", str(config_file)],
                          capture_output=True, text=True, timeout=120, env=env, check=False)
    assert done.returncode == 2, done.stderr
    assert f"invalid configuration: {path}: corrupt or partial flash file" in done.stderr
