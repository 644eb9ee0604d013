"""Motion log (mpi_ros/mpi/supervisor/log.py): meiMotionLogOpen / meiMotionLogPrint / meiMotionLogClose."""

from __future__ import annotations

import csv

import numpy as np

from mpi_ros.mpi import Controller, MPIMotionType, MPIState
from mpi_ros.mpi.base.messages import Message

T = MPIMotionType


def test_log_records_every_sample_up_to_max_entries(ctl, ms, params):
    # MPI 000, meiMotionLogOpen "meiMotionLogOpen allocates a memory buffer for motion logging"; MPI 000,
    # meiMotionLogOpen, maxEntries maxEntries "The maximum number of log entries"
    assert ms.log_open(500).ok
    ms.start(T.TRAPEZOIDAL, params=params((300.0, 100.0)))
    commands = []
    for _ in range(700):
        ctl.step(1)
        commands.append((ctl.axes[0].cmd_p, ctl.axes[1].cmd_p))
    log = ms.log
    samples = np.concatenate(log.samples)
    assert log.count == 500
    assert log.full
    assert list(samples) == list(range(1, 501))
    columns = np.concatenate(log.columns)
    assert [tuple(row) for row in columns[:, [0, 3]]] == commands[:500]


def test_log_is_the_same_in_any_batches(params):
    # docs/decisions.md, "Samples, commands and replay": whole samples; batching changes nothing
    def logged(batch):
        ctl = Controller()
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        ms.log_open(1500)
        ms.start(T.S_CURVE, params=params((300.0, 100.0), jerk_percent=50.0))
        for _ in range(1500 // batch):
            ctl.step(batch)
        assert ms.log.count == 1500
        return np.concatenate(ms.log.columns), [s for chunk in ms.log.samples for s in chunk]

    one, samples = logged(1)
    big, _ = logged(1500)
    assert np.array_equal(one, big)
    assert samples == list(range(1, 1501))


def test_log_print_writes_the_buffer(tmp_path, ctl, ms, params):
    # MPI 000, meiMotionLogPrint "meiMotionLogPrint reads the motion log buffer entries and writes the data into a
    # file specified by the fileName"
    ms.log_open(100)
    ms.start(T.TRAPEZOIDAL, params=params((300.0, 100.0)))
    ctl.step(100)
    path = tmp_path / "motion.csv"
    assert ms.log_print(str(path)).ok
    rows = list(csv.reader(path.open()))
    assert rows[0] == ["sample", "state", "axis0_command", "axis0_actual", "axis0_velocity",
                       "axis1_command", "axis1_actual", "axis1_velocity"]
    assert len(rows) == 101
    assert rows[-1][0] == "100"
    assert rows[-1][1] == MPIState.MOVING.name
    assert float(rows[-1][2]) == ctl.axes[0].command_position


def test_log_print_to_a_bad_path(tmp_path, ms):
    # MPI 000, meiMotionLogPrint, filename "*filename a pointer to a file name string" (a file that cannot be opened)
    ms.log_open(10)
    refused = ms.log_print(str(tmp_path / "no" / "such" / "dir" / "x.csv"))
    assert refused.message is Message.MPIMessageFILE_OPEN_ERROR
    assert refused.detail.startswith("filename: cannot write ")  # the file, and the system's reason


def test_log_close_frees_the_buffer(ctl, ms, params):
    # MPI 000, meiMotionLogClose "meiMotionLogClose frees the memory buffer for motion logging"
    ms.log_open(10)
    assert ms.log_close().ok
    assert ms.log is None
    assert ms.log_print("/tmp/unused.csv").message is Message.MPIMessageHANDLE_INVALID  # nothing to print
    ctl.step(10)


def test_log_open_needs_entries(ms):
    # MPI 000, meiMotionLogOpen, maxEntries maxEntries "determines the log buffer memory size"
    assert ms.log_open(0).message is Message.MPIMessagePARAM_INVALID
    assert ms.log is None
