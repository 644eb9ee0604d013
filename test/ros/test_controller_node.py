"""The controller node: axis status, events, joint states, diagnostics, /clock, axis,
gate and I/O services — through real topics and services (in-process)."""

from __future__ import annotations

import threading

from mpi_ros.msg import AxisStatus, MotionEvent

S_CURVE = {"type": "S_CURVE", "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0,
                                               "deceleration": 20000.0, "jerk_percent": 50.0}]}


class Collector:
    """Messages of a topic, with a condition to wait on."""

    def __init__(self, node, msg_type, topic, depth=1000):
        self.messages = []
        self._cond = threading.Condition()
        node.create_subscription(msg_type, topic, self._on, depth)

    def _on(self, msg):
        with self._cond:
            self.messages.append(msg)
            self._cond.notify_all()

    def wait_for(self, predicate, timeout=10.0):
        with self._cond:
            assert self._cond.wait_for(lambda: predicate(self.messages), timeout), "condition not met in time"
            return list(self.messages)


def test_axis_status_is_stamped_with_anchored_controller_time_at_the_status_rate(suite, probe, drive):
    status = Collector(probe, AxisStatus, "/mpi/axis2/status")
    drive(lambda: len(status.messages) >= 5, chunk=20)
    messages = status.messages[:5]
    rate = suite.controller.rate
    every = round(rate / suite.config.ros.status_rate)
    assert [m.sample for m in messages] == list(range(messages[0].sample, messages[0].sample + 5 * every, every))
    for msg in messages:
        assert msg.number == 2
        assert msg.state_name == "IDLE"
        assert msg.state == AxisStatus.STATE_IDLE
        # controller time anchored to the wall clock: epoch + sample / rate
        stamp = msg.header.stamp
        assert stamp.sec * 1_000_000_000 + stamp.nanosec == suite.epoch_ns + round(msg.sample * 1e9 / rate)
        assert msg.header.frame_id == "mpi/axis2"  # the source, named as /diagnostics names it
        assert msg.done
        assert msg.in_fine_position
        assert msg.settled
        assert msg.amp_enabled
        assert msg.supervisor in (-1, 1)


def test_events_arrive_in_order_with_move_ids_and_none_is_lost_in_a_burst(suite, client, probe, applied, drive):
    events = Collector(probe, MotionEvent, "/mpi/events")
    goals = [client.start({**S_CURVE, "position": [100.0 * (i + 1), 0.0], "attributes": ["APPEND", "ID"],
                           "id": i + 1}) for i in range(10)]
    applied.wait(10)
    drive(lambda: all(g.done for g in goals))
    seen = events.wait_for(lambda ms: sum(m.type == "MOTION_DONE" for m in ms) >= 10)
    done = [m for m in seen if m.type == "MOTION_DONE" and m.supervisor == 0]
    # MPI 000, MPIMotionAttrAPPEND APPEND: "Each successful call ... will generate an MPIEventTypeMOTION_DONE"
    assert [m.move_id for m in done] == list(range(1, 11))
    assert [m.sample for m in seen] == sorted(m.sample for m in seen)
    # each header names the event's source: its axis if it names one, else its supervisor
    assert all(m.header.frame_id == (f"mpi/axis{m.axis}" if m.axis >= 0 else f"mpi/ms{m.supervisor}") for m in seen)
    assert {m.header.frame_id for m in done} == {"mpi/ms0"}
    assert any(m.axis >= 0 for m in seen)
    assert all(m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec
               == suite.epoch_ns + round(m.sample * 1e9 / suite.controller.rate) for m in seen)
    controller_events = suite.runner.read(lambda ctl: len(ctl.events))
    assert len(seen) == controller_events  # every event the controller notified reached ROS


def test_joint_states_report_every_axis(suite, probe, drive):
    from sensor_msgs.msg import JointState

    joints = Collector(probe, JointState, "/joint_states")
    drive(lambda: bool(joints.messages))
    msg = joints.messages[0]
    assert list(msg.name) == ["axis0", "axis1", "axis2", "axis3"]
    assert len(msg.position) == 4
    assert len(msg.velocity) == 4
    assert list(msg.effort) == [0.0] * 4  # the servo's effort: at rest, none


def test_diagnostics_go_to_error_on_e_stop(suite, client, probe, applied, drive):
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

    diagnostics = Collector(probe, DiagnosticArray, "/diagnostics")
    drive(lambda: bool(diagnostics.messages), chunk=500)
    names = [s.name for s in diagnostics.messages[0].status]
    assert names == ["mpi/ms0", "mpi/ms1", "mpi/axis0", "mpi/axis1", "mpi/axis2", "mpi/axis3",
                     "mpi/ms0/joint_trajectory", "mpi/ms1/joint_trajectory", "mpi/suite"]
    assert {s.level for s in diagnostics.messages[0].status} == {DiagnosticStatus.OK}
    # what the suite holds, for long runs: no goals at rest; manual clock: never behind; the
    # publications of the batch being stepped (500 samples) queued until it ends, fewer than one a sample
    held = {v.key: v.value for v in diagnostics.messages[0].status[-1].values}
    assert held.pop("clock_scheduling") == "normal"  # ros.clock_priority 0 (test_runner: the others)
    assert held.pop("real_time_factor") == "manual"  # (test_suite and test_pace: a clock that runs)
    held = {key: int(value) for key, value in held.items()}
    assert held.pop("outputs_queued") <= 500
    assert held.pop("python_blocks") > 10_000  # the suite's objects: rclpy, the controller, the interfaces
    assert held == {"samples_behind": 0, **{
        f"ms{n}.{key}": 0 for n in (0, 1) for key in ("goals_tracked", "goals_kept", "requests_unfiled")}}
    client.e_stop()
    drive(lambda: any(s.name == "mpi/ms0" and s.level == DiagnosticStatus.ERROR
                      for m in diagnostics.messages for s in m.status), chunk=500)
    last = diagnostics.messages[-1]
    ms0 = next(s for s in last.status if s.name == "mpi/ms0")
    assert "E_STOP by USER" in ms0.message


def test_clock_follows_the_controller(suite, probe, drive):
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    ticks = []
    probe.create_subscription(Clock, "/clock", ticks.append,
                              QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT))
    drive(lambda: len(ticks) >= 3, chunk=20)
    stamps = [t.clock.sec * 1_000_000_000 + t.clock.nanosec for t in ticks[:3]]
    period = round(1e9 / suite.config.ros.clock_rate)
    assert stamps == sorted(stamps)
    assert stamps[1] - stamps[0] == period
    # the same time base as every stamp: epoch + sample / rate, at whole samples
    assert all((t - suite.epoch_ns) % round(1e9 / suite.controller.rate) == 0 for t in stamps)


def test_axis_services_config_and_positions(suite, client, probe, service, applied, drive):
    from mpi_ros.srv import AxisConfigGet, AxisConfigSet, AxisPositionSet

    config = service(probe, AxisConfigGet, "/mpi/axis0/config_get", AxisConfigGet.Request())
    assert config.message == "MPIMessageOK"
    assert config.in_position.position_fine == 10.0
    request = AxisConfigSet.Request(in_position=config.in_position)
    request.in_position.settling_time = 0.05
    assert service(probe, AxisConfigSet, "/mpi/axis0/config_set", request).message == "MPIMessageOK"
    assert suite.runner.read(lambda ctl: ctl.axes[0].in_position.settling_time) == 0.05

    origin = service(probe, AxisPositionSet, "/mpi/axis0/position_set", AxisPositionSet.Request(which="ORIGIN",
                                                                                               value=100.0))
    assert origin.message == "MPIMessageOK"
    assert suite.runner.read(lambda ctl: ctl.axes[0].command_position) == -100.0

    goal = client.start({**S_CURVE, "position": [5000.0, 0.0]})
    applied.wait(3)
    drive(lambda: suite.runner.ctl.axes[0].cmd_v > 0.0)
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET mpiAxisCommandPositionSet: COMMAND_NOT_SET while the axis is MOVING
    moving = service(probe, AxisPositionSet, "/mpi/axis0/position_set", AxisPositionSet.Request(which="COMMAND",
                                                                                               value=0.0))
    assert moving.message == "MPIAxisMessageCOMMAND_NOT_SET"
    bad = service(probe, AxisPositionSet, "/mpi/axis0/position_set", AxisPositionSet.Request(which="SIDEWAYS"))
    assert bad.message == "MPIMessagePARAM_INVALID"
    drive(lambda: goal.done)


def test_gate_holds_a_move_until_it_opens(suite, client, probe, service, applied, drive):
    from mpi_ros.srv import GateGet, GateSet

    assert service(probe, GateSet, "/mpi/gate_set", GateSet.Request(gate=7, closed=True)).message == "MPIMessageOK"
    assert service(probe, GateGet, "/mpi/gate_get", GateGet.Request(gate=7)).closed
    goal = client.start({**S_CURVE, "position": [300.0, 0.0], "attributes": ["HOLD"],
                         "hold": [{"type": "GATE", "gate": 7}, {"type": "GATE", "gate": 7}]})
    applied.wait(2)
    suite.runner.step(2000)
    # MPI 000, MEIMotionAttrHOLD "the motion will be held until a call to mpiControlGateSet() with closed=FALSE"
    held = suite.runner.read(lambda ctl: (ctl.axes[0].command_position, ctl.supervisor(0).state.name))
    assert held == (0.0, "MOVING")
    service(probe, GateSet, "/mpi/gate_set", GateSet.Request(gate=7, closed=False))
    drive(lambda: goal.done)
    assert list(goal.wait().command_position) == [300.0, 0.0]
    assert service(probe, GateSet, "/mpi/gate_set", GateSet.Request(gate=99)).message == "MPIMessagePARAM_INVALID"


def test_io_services_and_an_input_hold(suite, client, probe, service, applied, drive):
    from mpi_ros.srv import IoGet, IoSet

    goal = client.start({**S_CURVE, "position": [0.0, 200.0], "attributes": ["HOLD"],
                         "hold": [{"type": "INPUT", "address": 3, "mask": 0x4, "pattern": 0x4}] * 2})
    applied.wait(1)
    suite.runner.step(1000)
    assert not goal.done
    assert service(probe, IoSet, "/mpi/io_set", IoSet.Request(space="IO", index=3, value=0x6)).message == "MPIMessageOK"
    assert service(probe, IoGet, "/mpi/io_get", IoGet.Request(space="IO", index=3)).value == 0x6
    drive(lambda: goal.done)
    assert goal.wait().message == "MPIMessageOK"
    refused = service(probe, IoGet, "/mpi/io_get", IoGet.Request(space="TAPE", index=0))
    assert refused.message == "MPIMessagePARAM_INVALID"
