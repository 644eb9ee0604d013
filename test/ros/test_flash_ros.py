"""The flash through ROS: /mpi/ms<n>/flash_config_get|set (mpiMotionFlashConfigGet/Set, MPI 000)
and /mpi/axis<k>/flash_config_get|set (mpiAxisFlashConfigGet/Set, MPI 002). Set writes the
file beside the configuration and changes nothing that runs; the next start loads it."""

from __future__ import annotations

import shutil

import pytest

from mpi_ros import config, flash
from mpi_ros.srv import (
    AxisFlashConfigGet,
    AxisFlashConfigSet,
    MotionConfigGet,
    MotionFlashConfigGet,
    MotionFlashConfigSet,
)


@pytest.fixture
def suite_config(tmp_path):
    path = tmp_path / "cell.yaml"
    shutil.copy(config.default_config_path(), path)
    return config.load(path)


def test_flash_set_is_what_the_next_start_loads(suite, suite_config, probe, service):
    path = suite_config.flash
    got = service(probe, MotionFlashConfigGet, "/mpi/ms1/flash_config_get", MotionFlashConfigGet.Request())
    assert got.message == "MPIMessageOK"
    assert got.config.normal_feedrate == 1.0  # nothing written yet: the configuration's
    request = MotionFlashConfigSet.Request()
    request.config = got.config
    request.config.normal_feedrate = 0.5
    request.config.decel_time_stop = 0.25
    assert service(probe, MotionFlashConfigSet, "/mpi/ms1/flash_config_set", request).message == "MPIMessageOK"
    got = service(probe, MotionFlashConfigGet, "/mpi/ms1/flash_config_get", MotionFlashConfigGet.Request())
    assert got.config.normal_feedrate == 0.5
    assert got.config.decel_time_stop == 0.25
    running = service(probe, MotionConfigGet, "/mpi/ms1/config_get", MotionConfigGet.Request())
    assert running.config.normal_feedrate == 1.0  # the running configuration is not the flash's

    # a refused value is refused by MotionConfig's validator and not written
    request.config.normal_feedrate = -1.0
    refused = service(probe, MotionFlashConfigSet, "/mpi/ms1/flash_config_set", request)
    assert refused.message == "MPIMessagePARAM_INVALID"
    assert "normal_feedrate" in refused.detail

    axis = service(probe, AxisFlashConfigGet, "/mpi/axis2/flash_config_get", AxisFlashConfigGet.Request())
    axis_request = AxisFlashConfigSet.Request(in_position=axis.in_position, master=axis.master, master_correction=0)
    axis_request.in_position.position_fine = 4.0
    assert service(probe, AxisFlashConfigSet, "/mpi/axis2/flash_config_set", axis_request).message == "MPIMessageOK"
    axis = service(probe, AxisFlashConfigGet, "/mpi/axis2/flash_config_get", AxisFlashConfigGet.Request())
    assert axis.in_position.position_fine == 4.0
    assert axis.master_correction == 0

    following = config.load(path.with_name("cell.yaml")).build_controller()  # the next start
    assert following.supervisor(1).config.normal_feedrate == 0.5
    assert following.supervisor(1).config.decel_time.stop == 0.25
    assert following.axes[2].in_position.position_fine == 4.0
    assert following.axes[2].master.correction == 0

    path.write_text(path.read_text()[:-40])  # cut short
    broken = service(probe, MotionFlashConfigGet, "/mpi/ms1/flash_config_get", MotionFlashConfigGet.Request())
    assert broken.message == "MPIMessageFILE_OPEN_ERROR"
    assert str(path) in broken.detail
    assert flash.flash_path(path.with_name("cell.yaml")) == path
