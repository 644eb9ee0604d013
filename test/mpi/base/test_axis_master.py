"""MPIAxisMaster.encoderFaultMotorNumber (MPI 002, MPIAxisMaster): "The number of the motor that
is checked for an encoder fault. If this motor detects an encoder fault this axis will abort. A
value of -1 disables this encoder fault function." Set and read in MPIAxisConfig.master, where the
reference puts it; one home (the axis' fault configuration)."""

from __future__ import annotations

import pytest

from mpi_ros.commands import Command, apply
from mpi_ros.mpi import MPIState
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import AxisMaster


def test_the_master_reads_the_motor_the_axis_watches(ctl):
    assert [ctl.axis_master_get(n).encoder_fault_motor_number for n in range(4)] == [0, 1, 2, 3]


def test_set_in_the_master_an_encoder_fault_of_that_motor_aborts_the_axis(ctl, ms, ms1, run_to):
    master = ctl.axis_master_get(2)
    master.encoder_fault_motor_number = 0
    assert ctl.axis_master_set(2, master).ok
    assert ctl.axis_fault_config_get(2)[1].encoder_fault_motor_number == 0  # the one home
    ctl.drain_events()
    assert ctl.axis_fault_inject(0, "ENCODER_FAULT", True).ok
    faulted = [e.axis for e in ctl.drain_events() if e.type is MPIEventType.ENCODER_FAULT]
    assert faulted == [0, 2]
    run_to(ctl, ms1, MPIState.ERROR, chunk=50)
    assert ms1.last_action == "ABORT"


def test_minus_one_disables_it(ctl, ms):
    master = ctl.axis_master_get(0)
    master.encoder_fault_motor_number = -1
    assert ctl.axis_master_set(0, master).ok
    ctl.drain_events()
    assert ctl.axis_fault_inject(0, "ENCODER_FAULT", True).ok
    assert [e for e in ctl.drain_events() if e.type is MPIEventType.ENCODER_FAULT] == []
    assert ms.state is MPIState.IDLE


def test_a_master_without_it_keeps_the_current_motor(ctl):
    assert ctl.axis_master_set(1, AxisMaster()).ok  # (None: keep)
    assert ctl.axis_master_get(1).encoder_fault_motor_number == 1
    assert ctl.axes[1].master.encoder_fault_motor_number is None  # stored once, in the fault configuration


@pytest.mark.parametrize("motor", [4, -3])
def test_a_motor_that_does_not_exist_is_refused_and_changes_nothing(ctl, motor):
    outcome = ctl.axis_master_set(0, AxisMaster(encoder_fault_motor_number=motor))
    assert outcome.message is Message.MPIMessagePARAM_INVALID
    assert ctl.axis_master_get(0).encoder_fault_motor_number == 0


def test_the_axis_config_command_carries_it(ctl):
    # AxisMaster.msg: -2 (its default) keeps the current motor
    reply = apply(ctl, Command("axis_config_set", axis=3, request={"master": {"encoder_fault_motor_number": -1}}))
    assert reply.message.ok
    assert ctl.axis_master_get(3).encoder_fault_motor_number == -1
    keep = Command("axis_config_set", axis=3, request={"master": {"encoder_fault_motor_number": -2}})
    assert apply(ctl, keep).message.ok
    assert ctl.axis_master_get(3).encoder_fault_motor_number == -1
