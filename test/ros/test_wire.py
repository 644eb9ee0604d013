"""The status topics are published as CDR packed by mpi_ros/ros/wire.py: the bytes must be
exactly the canonical CDR of the messages convert.py builds from the same snapshots, so that
subscribers, recorders and replay cannot tell the difference."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest
from rclpy.serialization import deserialize_message

from mpi_ros import config
from mpi_ros.bag import cdr
from mpi_ros.mpi import MotionAttr, MotionParams, MPIAction, MPIMotionType, Trajectory
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.msg import AxisStatus, MotionStatus
from mpi_ros.ros import convert, wire

EPOCH = 1_795_000_000_123_456_789


def _controller(axes: int = 6, per: tuple[int, ...] = (1, 2, 3)):
    """Supervisors of 1, 2 and 3 axes: every alignment an AxisStatus can start at in a MotionStatus."""
    raw = config.load().raw
    raw = config.merge(raw, {"axes": {"count": axes}})
    first, supervisors = 0, []
    for n, count in enumerate(per):
        supervisors.append({"number": n, "axes": list(range(first, first + count))})
        first += count
    raw["supervisors"] = supervisors
    return config.parse(raw).build_controller()


def _moving_states(ctl):
    """Snapshots along S-curves, a velocity move and an E_STOP: every state and flag changes."""
    ctl.supervisors[0].start(MPIMotionType.S_CURVE, MotionAttr.NONE, MotionParams(
        trajectory=[Trajectory(4000.0, 40000.0, 40000.0, 50.0)], position=[1234.5]))
    ctl.supervisors[1].start(MPIMotionType.VELOCITY, MotionAttr.NONE, MotionParams(
        trajectory=[Trajectory(-700.0, 9000.0, 9000.0, 0.0)]))
    ctl.supervisors[2].start(MPIMotionType.TRAPEZOIDAL, MotionAttr.NONE, MotionParams(
        trajectory=[Trajectory(3000.0, 30000.0, 30000.0, 0.0)], position=[-100.25, 2e6, 7.0]))
    for step in range(60):
        ctl.step(37)
        if step == 30:
            ctl.supervisors[2].action(MPIAction.E_STOP)
        yield ctl


def _same_message(data: bytes, msg) -> None:
    """``data`` decodes to ``msg``, field for field (json spells NaN alike on both sides)."""
    decoded = deserialize_message(data, type(msg))
    assert json.dumps(convert.to_dict(decoded)) == json.dumps(convert.to_dict(msg))


def test_the_installed_interfaces_have_the_layout_the_encoder_packs():
    assert wire.AVAILABLE


# the headers' frame ids: their lengths move everything after them (every alignment, mod 8)
@pytest.mark.parametrize(("epoch", "namespace"), [(EPOCH, "/mpi"), (0, "/mpi"), (EPOCH, "/plant/cell_a"),
                                                  (EPOCH, "/c"), (EPOCH, "/cell_b7")])
def test_axis_and_motion_status_bytes_equal_the_canonical_cdr_of_convert(epoch, namespace):
    seen_states = set()
    for ctl in _moving_states(_controller()):
        for axis in ctl.axes:
            snap = ctl.axis_snapshot(axis.number)
            msg = convert.axis_status(snap, ctl.rate, epoch, namespace)
            assert wire.axis_status(snap, ctl.rate, epoch, namespace) == cdr.serialize(msg)
            assert msg.header.frame_id == f"{namespace[1:]}/axis{axis.number}"
            seen_states.add(snap.state)
        for ms in ctl.supervisors:
            snap = ms.snapshot()
            msg = convert.motion_status(snap, ctl.rate, epoch, namespace)
            data = wire.motion_status(snap, ctl.rate, epoch, namespace)
            assert data == cdr.serialize(msg)
            _same_message(data, msg)
            assert msg.header.frame_id == f"{namespace[1:]}/ms{ms.number}"
    assert {MPIState.MOVING, MPIState.IDLE, MPIState.STOPPING_ERROR} <= seen_states


def test_edge_values_are_packed_as_convert_sets_them():
    ctl = _controller()
    snap = ctl.axis_snapshot(0)
    snap = dataclasses.replace(snap, feedforward=math.inf)  # a finite value is sent: 0.0
    odd = dataclasses.replace(snap, sample=2**33 + 3, number=31, state=MPIState.STOPPING_ERROR,
                              command_position=math.inf, actual_position=-math.inf, position_error=math.nan,
                              target_position=math.nan, origin=-1e300, command_velocity=-0.0,
                              move_id=-(2**31), element_id=2**31 - 1, frame_count=0, supervisor=-1)
    msg = convert.axis_status(odd, ctl.rate, EPOCH)
    assert wire.axis_status(odd, ctl.rate, EPOCH) == cdr.serialize(msg)
    _same_message(wire.axis_status(odd, ctl.rate, EPOCH), msg)
    motion = dataclasses.replace(ctl.supervisors[2].snapshot(), axes=(odd, snap), axis_numbers=(31, 0),
                                 last_action="E_STOP", action_source="USER", motion_type="S_CURVE_JERK",
                                 moves_pending=-3, feedrate=0.25)
    msg = convert.motion_status(motion, ctl.rate, EPOCH)
    assert wire.motion_status(motion, ctl.rate, EPOCH) == cdr.serialize(msg)
    empty = dataclasses.replace(motion, axes=(), axis_numbers=(), last_action="", action_source="", motion_type="")
    assert wire.motion_status(empty, ctl.rate, EPOCH) == cdr.serialize(convert.motion_status(empty, ctl.rate, EPOCH))


def test_joint_state_bytes_equal_the_canonical_cdr_of_convert_from_the_axes_or_their_snapshots():
    start = _controller()
    names = convert.joint_names(start)
    start.axes[4].origin = 12.5  # positions are reported minus the origin
    for step, ctl in enumerate(_moving_states(start)):
        if step == 40:
            ctl.supervisors[1].action(MPIAction.ABORT)  # amplifier off: no effort
        expected = cdr.serialize(convert.joint_state(ctl, EPOCH))
        direct = convert.joint_values(ctl)
        snapshots = {a.number: ctl.axis_snapshot(a.number) for a in ctl.axes}
        assert convert.joint_values(ctl, snapshots) == direct
        assert wire.joint_state(ctl.sample, ctl.rate, EPOCH, names, *direct) == expected
    assert any(effort == 0.0 for effort in direct[2])
    assert any(effort != 0.0 for effort in direct[2])


@pytest.mark.parametrize("namespace", ["/mpi", "/plant/cell_a", "/c"])
def test_a_packer_packs_each_sample_as_the_functions_do(namespace):
    """wire.Packer keeps a sample's stamp, each source's frame_id and each axis snapshot's
    body: whatever order the statuses are packed in, and when a sample is seen again with
    other snapshots (a command given at it), its bytes are the canonical CDR of each."""
    from mpi_ros.commands import Command, apply

    ctl = _controller()
    packer = wire.Packer(ctl.rate, EPOCH, namespace)
    for step, moving in enumerate(_moving_states(ctl)):
        rounds = [moving.motion_snapshots()]
        if step == 20:  # the same sample, other snapshots (the state changes, the sample does not)
            assert apply(moving, Command("action", 0, -1, {"action": "E_STOP"})).outcome.ok
            rounds.append(moving.motion_snapshots())
            assert rounds[1][0][0].state != rounds[0][0][0].state
        for motions, axes in rounds:
            order = [*motions.values(), *axes] if step % 2 else [*axes, *motions.values()]
            for snap in order:
                if snap in axes:
                    expected = cdr.serialize(convert.axis_status(snap, ctl.rate, EPOCH, namespace))
                    assert packer.axis_status(snap) == expected
                else:
                    expected = cdr.serialize(convert.motion_status(snap, ctl.rate, EPOCH, namespace))
                    assert packer.motion_status(snap) == expected


@pytest.mark.parametrize("namespace", ["/mpi", "/plant/cell_a", "/c", "/cell_b7"])
def test_a_status_sample_and_number_are_read_where_the_fields_reader_finds_them(namespace):
    """Every length of the frame_id mod 8 (the namespaces) moves where the sample lies."""
    from mpi_ros.bag import fields

    readers = {kind: fields.field_reader(kind, ("sample", "number")) for kind in (AxisStatus, MotionStatus)}
    ctl = _controller()
    ctl.step(2**20 + 3)
    motions, axes = ctl.motion_snapshots()
    for snap in axes:
        data = wire.axis_status(snap, ctl.rate, EPOCH, namespace)
        assert wire.sample_and_number(data) == readers[AxisStatus](data) == (ctl.sample, snap.number)
    for snap in motions.values():
        data = wire.motion_status(snap, ctl.rate, EPOCH, namespace)
        assert wire.sample_and_number(data) == readers[MotionStatus](data) == (ctl.sample, snap.number)
    with pytest.raises(ValueError, match="little-endian"):
        wire.sample_and_number(b"\x00\x00" + data[2:])


def test_the_clock_bytes_equal_the_canonical_cdr_of_a_clock_message():
    from rosgraph_msgs.msg import Clock

    for sample in (0, 1, 1999, 2**33 + 7):
        expected = cdr.serialize(Clock(clock=convert.stamp(sample, 2000.0, EPOCH)))
        assert wire.clock(sample, 2000.0, EPOCH) == expected


def test_a_packer_packs_snapshots_with_faults_and_of_other_samples_as_convert():
    """The faults' strings and the state's name are packed once per value; a snapshot of
    another sample than the one kept (inside a MotionStatus, say) is packed, not kept."""
    ctl = _controller()
    packer = wire.Packer(ctl.rate, EPOCH)
    for step, moving in enumerate(_moving_states(ctl)):
        motions, axes = moving.motion_snapshots()
        if step % 7 == 3:
            axes = [*axes[:2], dataclasses.replace(axes[2], sample=axes[2].sample - 5, faults=("AMP_FAULT", "X")),
                    dataclasses.replace(axes[3], faults=("LIMIT_HW_POS",)), *axes[4:]]
            motions = {n: dataclasses.replace(m, axes=tuple(axes[k] for k in m.axis_numbers))
                       for n, m in motions.items()}
        for snap in [*axes, *motions.values(), *axes]:
            make = convert.axis_status if snap in axes else convert.motion_status
            expected = cdr.serialize(make(snap, ctl.rate, EPOCH))
            assert (packer.axis_status(snap) if snap in axes else packer.motion_status(snap)) == expected


def test_publishing_after_the_context_shut_down_publishes_nothing_and_raises_nothing(ros_context):
    import rclpy
    from rosgraph_msgs.msg import Clock

    node = rclpy.create_node("publish_after_shutdown", context=ros_context)
    publisher = node.create_publisher(Clock, "clock_after_shutdown", 1)
    data = wire.clock(5, 2000.0, EPOCH)
    convert.publish_all(node, [(publisher, data)])  # published while the context is up
    ros_context.shutdown()
    convert.publish_all(node, [(publisher, data), (publisher, data)])  # rcl refuses: quietly nothing
    node.destroy_node()
    convert.publish(node, publisher, data)  # the publisher gone with its node: quietly nothing
