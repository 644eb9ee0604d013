"""MCAP recording and exact replay: fixtures replay with zero differences, independent
readers (rosbags, mcap_ros2) read every message of every bag, a bag that lacks what replay
needs is refused saying what, a changed parameter is caught, playback and plots work."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
import yaml

from mpi_ros.bag.reader import BagReader
from mpi_ros.bag.replay import replay

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures"
BAGS = sorted(p for p in (FIXTURES / "bags").iterdir() if p.is_dir())
SCENARIOS = {p.stem for p in (FIXTURES / "scenarios").glob("*.yaml")}


def test_every_scenario_has_a_fixture():
    assert {b.name for b in BAGS} == SCENARIOS == {
        "p2p_modify", "stop_resume", "estop_reset", "append_queue", "sync_end", "two_supervisors", "streamed_path",
        "cams", "faults"}


def test_a_bag_recorded_before_a_type_changed_replays_by_its_own_definitions():
    # Recorded before AxisStatus gained `feedforward` (the installed type's CDR no longer fits
    # it): its messages are read by the definitions the bag stores, and compared field by field.
    bag = FIXTURES / "older" / "p2p_modify_before_feedforward"
    status = next(item for item in BagReader(bag).messages() if item.type == "mpi_ros/msg/MotionStatus")
    assert "feedforward" not in status.schema_text
    report = replay(bag)
    assert report.identical, report.summary()
    assert report.commands == 2
    assert report.statuses > 100


def test_a_bag_recorded_before_the_headers_replays_with_its_stamps_compared():
    # Recorded when statuses, events and commands had a bare `stamp` (docs/recording.md,
    # "Older recordings"): read by the bag's own definitions; the bare stamp is compared with
    # the replayed header's stamp (so a wrong epoch would show), the frame id is not.
    bag = FIXTURES / "older" / "p2p_modify_before_headers"
    reader = BagReader(bag)
    status = next(msg for item, msg in reader.decoded() if item.type == "mpi_ros/msg/AxisStatus")
    assert hasattr(status, "stamp")
    assert not hasattr(status, "header")
    report = replay(bag)
    assert report.identical, report.summary()
    assert report.commands == 2
    assert report.statuses > 100
    assert report.events > 0
    moved = replay(bag, overrides={"controller": {"sample_rate": 1000.0}})  # other stamps at the same samples
    assert not moved.identical
    assert "stamp" in moved.first.field


def test_schemas_are_written_as_rosbag2_writes_them():
    """rosbag2 (rosbag2_cpp's local message definition source): the .msg file as installed,
    then per nested type, depth first, the types one text uses in sorted order, each once:
    a newline, 80 '=', 'MSG: pkg/Type' and that file."""
    from mpi_ros.bag import schema

    separator = "\n" + "=" * 80 + "\n"
    for type_name, nested in {
        "mpi_ros/msg/MotionStatus": ["mpi_ros/AxisStatus", "std_msgs/Header", "builtin_interfaces/Time"],
        "mpi_ros/msg/AxisStatus": ["std_msgs/Header", "builtin_interfaces/Time"],
        "mpi_ros/msg/MotionEvent": ["std_msgs/Header", "builtin_interfaces/Time"],
        "mpi_ros/msg/Command": ["std_msgs/Header", "builtin_interfaces/Time"],
        "sensor_msgs/msg/JointState": ["std_msgs/Header", "builtin_interfaces/Time"],
    }.items():
        first, *sections = schema.ros2msg(type_name).split(separator)
        assert first == schema.msg_text(type_name)  # the file as it is, its last newline included
        assert [s.split("\n", 1)[0] for s in sections] == [f"MSG: {name}" for name in nested]
        assert [s.split("\n", 1)[1] for s in sections] == [schema.msg_text(name) for name in nested]


def test_a_recording_names_each_source_in_its_headers(tmp_path):
    """Statuses, events and commands of a recording carry the header the suite publishes:
    the stamp of their sample and the frame id of their source, in the recorded namespace."""
    from mpi_ros.bag import scenario
    from mpi_ros.ros import convert

    plan = scenario.load(FIXTURES / "scenarios" / "two_supervisors.yaml")
    plan.config = {**plan.config, "ros": {**plan.config["ros"], "namespace": "/cell_a"}}
    bag = scenario.record(plan, tmp_path / "run")
    epoch = int(BagReader(bag).metadata("mpi_ros")["stamp_epoch_ns"])
    seen = set()
    for item, msg in BagReader(bag).decoded():
        if not hasattr(msg, "sample"):
            continue
        rate = 2000.0
        assert convert.time_ns(msg.header.stamp) == epoch + round(msg.sample * 1e9 / rate) == item.log_time
        frame = msg.header.frame_id
        if item.type == "mpi_ros/msg/AxisStatus":
            assert frame == f"cell_a/axis{msg.number}"
        elif item.type == "mpi_ros/msg/MotionStatus":
            assert frame == f"cell_a/ms{msg.number}"
            assert [a.header.frame_id for a in msg.axes] == [f"cell_a/axis{n}" for n in msg.axis_numbers]
        else:
            assert frame == convert.frame_id("/cell_a", msg.supervisor, msg.axis)
        seen.add((item.type, frame.split("/")[1].rstrip("0123456789")))
    assert {("mpi_ros/msg/MotionEvent", "axis"), ("mpi_ros/msg/MotionEvent", "ms"),
            ("mpi_ros/msg/Command", "ms"), ("mpi_ros/msg/Command", "controller")} <= seen  # gate_set: the controller
    assert replay(bag).identical


@pytest.mark.parametrize("bag", BAGS, ids=[b.name for b in BAGS])
def test_fixture_replays_with_zero_differences(bag):
    report = replay(bag)
    assert report.identical, report.summary()
    assert report.commands > 0
    assert report.statuses > 100
    assert report.events > 0


def rosbags_reads_every_message(bag: Path) -> dict[str, int]:
    """Deserialise every message of ``bag`` with rosbags (an independent, strict reader: it
    refuses a message whose length is not its data's) and check that the stored bytes are
    canonical CDR: rosbags serialises what it read back to the very same bytes (exact
    length, zeroed padding). Returns the count per topic."""
    from rosbags.highlevel import AnyReader

    counted: dict[str, int] = {}
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages():
            counted[connection.topic] = counted.get(connection.topic, 0) + 1
            msg = reader.deserialize(raw, connection.msgtype)
            again = reader.typestore.serialize_cdr(msg, connection.msgtype)
            assert bytes(again) == bytes(raw), f"{connection.topic}: not canonical CDR"
            if connection.topic == "/joint_states":
                # a real effort per joint (the servo's), not an empty array
                assert len(msg.effort) == len(msg.name) == len(msg.position) == len(msg.velocity) > 0
    return counted


def mcap_ros2_reads_every_message(bag: Path) -> dict[str, int]:
    """Decode every message with mcap_ros2 (the bag's own schemas, no ROS types)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    counted: dict[str, int] = {}
    with open(BagReader(bag).path, "rb") as stream:
        for _, channel, _, msg in make_reader(stream, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            counted[channel.topic] = counted.get(channel.topic, 0) + 1
            if channel.topic.endswith("/status") and hasattr(msg, "state_name"):
                assert msg.state_name in ("IDLE", "MOVING", "STOPPING", "STOPPED", "STOPPING_ERROR", "ERROR")
    return counted


@pytest.mark.parametrize("bag", BAGS, ids=[b.name for b in BAGS])
def test_rosbags_reads_every_message(bag):
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    claimed = {t["topic_metadata"]["name"]: t["message_count"] for t in info["topics_with_message_count"]}
    counted = rosbags_reads_every_message(bag)
    # count what was read, not what the metadata claims (docs/recording.md, "Reading: count what was read")
    assert counted == claimed == BagReader(bag).counts()
    assert sum(counted.values()) == info["message_count"]
    assert counted["/mpi/commands"] > 0
    assert counted["/joint_states"] > 0
    assert counted["/mpi/configuration"] == 1


@pytest.mark.parametrize("bag", BAGS, ids=[b.name for b in BAGS])
def test_mcap_ros2_decodes_every_message(bag):
    assert mcap_ros2_reads_every_message(bag) == BagReader(bag).counts()


def test_a_fresh_recording_is_read_by_both_readers_and_is_reproducible(tmp_path):
    """Recorded now (not a checked-in file): both readers take every message, and recording
    the same scenario again gives the same bytes (no uninitialised padding)."""
    from mpi_ros.bag import scenario

    plan = scenario.load(FIXTURES / "scenarios" / "estop_reset.yaml")
    first = scenario.record(plan, tmp_path / "a" / "run")
    second = scenario.record(plan, tmp_path / "b" / "run")
    counts = BagReader(first).counts()
    assert rosbags_reads_every_message(first) == counts == mcap_ros2_reads_every_message(first)
    assert (first / "run_0.mcap").read_bytes() == (second / "run_0.mcap").read_bytes()
    assert replay(first).identical


def test_the_writer_stores_canonical_cdr_where_rclpy_pads():
    """Root cause of "CDR message size mismatch for sensor_msgs/msg/JointState" (rosbags):
    rclpy's serialize_message returns the type support's size estimate, which counts
    alignment for empty sequences of doubles; the writer cuts the buffer to the data."""
    from rclpy.serialization import deserialize_message, serialize_message
    from rosbags.typesys import Stores, get_typestore
    from sensor_msgs.msg import JointState

    from mpi_ros.bag import cdr

    store = get_typestore(Stores.ROS2_JAZZY)
    msg = JointState(name=["axis0"], position=[1.0], velocity=[2.0])  # effort empty, as before
    padded = serialize_message(msg)
    with pytest.raises(Exception, match="size mismatch"):
        store.deserialize_cdr(padded, "sensor_msgs/msg/JointState")
    data = cdr.serialize(msg)
    assert len(padded) - len(data) == 4  # one empty float64[]: 4 bytes counted, none written
    read = store.deserialize_cdr(data, "sensor_msgs/msg/JointState")
    assert list(read.position) == [1.0]
    assert list(read.effort) == []
    assert bytes(store.serialize_cdr(read, "sensor_msgs/msg/JointState")) == data
    assert deserialize_message(data, JointState) == msg


def test_replay_names_what_a_bag_lacks(tmp_path):
    """A bag without the configuration or the commands is refused, saying what is missing,
    and `mpi-ros replay` exits 2 with that message (no traceback)."""
    from mpi_ros.bag.reader import BagReader as Reader
    from mpi_ros.bag.replay import MissingInput
    from mpi_ros.bag.writer import BagWriter

    source = FIXTURES / "bags" / "stop_resume"
    cases = {
        "no_commands": lambda topic: topic != "/mpi/commands",
        "no_configuration": lambda topic: topic != "/mpi/configuration",
        "neither": lambda topic: topic not in ("/mpi/commands", "/mpi/configuration"),
    }
    expected = {"no_commands": ["the commands", "/mpi/commands"],
                "no_configuration": ["the configuration", "mpi_ros/msg/SuiteConfiguration"],
                "neither": ["the configuration", "the commands"]}
    exe = Path(sys.executable).with_name("mpi-ros")
    for name, keep in cases.items():
        bag = tmp_path / name
        reader = Reader(source)
        kinds = reader.topics()
        with BagWriter(bag) as writer:  # a graph recording: no 'mpi_ros' metadata
            for topic, kind in kinds.items():
                if keep(topic):
                    writer.add_topic(topic, kind)
            for item in reader.messages():
                if keep(item.topic):
                    writer.write_raw(item.topic, item.type, item.data, item.log_time)
        with pytest.raises(MissingInput) as caught:
            replay(bag)
        for words in expected[name]:
            assert words in str(caught.value), str(caught.value)
        if name == "no_commands":
            assert "configuration" not in str(caught.value)
        result = subprocess.run([str(exe), "replay", str(bag)], capture_output=True, text=True, timeout=60)
        assert result.returncode == 2, result.stderr
        assert "Traceback" not in result.stderr
        assert str(caught.value) in result.stderr
        assert result.stderr.startswith("mpi-ros replay: ")


def test_a_bag_with_the_configuration_topic_but_no_metadata_replays(tmp_path):
    """The latched configuration message is a full substitute for the metadata."""
    from mpi_ros.bag.writer import BagWriter

    source = FIXTURES / "bags" / "p2p_modify"
    reader = BagReader(source)
    bag = tmp_path / "graph"
    with BagWriter(bag) as writer:
        for topic, kind in reader.topics().items():
            writer.add_topic(topic, kind)
        for item in reader.messages():
            writer.write_raw(item.topic, item.type, item.data, item.log_time)
    assert BagReader(bag).metadata("mpi_ros") is None
    report = replay(bag)
    assert report.identical, report.summary()
    assert report.commands == replay(source).commands == 2


def test_a_changed_controller_parameter_is_reported_as_a_divergence():
    report = replay(FIXTURES / "bags" / "p2p_modify",
                    overrides={"axes": {"defaults": {"plant": {"bandwidth_hz": 25.0}}}})
    assert not report.identical
    assert report.first is not None
    # the servo model changed, so the actual position/velocity are where it shows first
    assert "actual" in report.first.field
    assert report.first.difference > 0.0
    assert report.first.sample < 100
    assert report.largest
    command_fields = [f for f in report.largest if f.endswith("command_position")]
    assert not command_fields  # the commanded profile itself is unchanged


def test_a_changed_stop_time_diverges_at_the_stop():
    report = replay(FIXTURES / "bags" / "stop_resume",
                    overrides={"supervisor_defaults": {"config": {"decel_time_stop": 0.4}}})
    assert report.first.sample > 900
    assert "command" in report.first.field


def test_live_run_recorded_with_mpi_ros_run_replays_exactly(tmp_path, ros_context):
    """A real-time run (the clock thread steps in wall-clock batches) replays exactly.

    At 2x, as the demo and killed-recording tests: on a loaded 2-core machine a suite at 4x
    fell behind and an E_STOP service call once waited past the client's timeout."""
    from mpi_ros.client import MotionClient

    bag = tmp_path / "live"
    exe = Path(sys.executable).with_name("mpi-ros")
    process = subprocess.Popen([str(exe), "run", "--time-scale", "2", "--record", str(bag)], cwd=tmp_path,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        with MotionClient(0, context=ros_context, timeout=20.0) as ms0:
            assert ms0.wait_for_server(20.0)
            ms0.move([2000.0, 500.0], velocity=4000.0, acceleration=40000.0, deceleration=40000.0,
                     jerk_percent=50.0, timeout=20.0)
            goal = ms0.start({"type": "S_CURVE", "position": [-30000.0, 0.0],
                              "trajectory": [{"velocity": 3000.0, "acceleration": 30000.0, "deceleration": 30000.0}]})
            ms0.wait_for_state("MOVING", 20.0)
            ms0.stop()
            goal.wait(20.0, raise_on_error=False)
            ms0.resume()
            ms0.e_stop()
            ms0.wait_for_state("ERROR", 20.0)
            ms0.reset()
    finally:
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=30)
    assert process.returncode == 0, err
    report = replay(bag)
    assert report.identical, report.summary()
    assert report.commands == 6
    assert report.statuses > 50
    # independent readers read all of it
    assert rosbags_reads_every_message(bag) == BagReader(bag).counts() == mcap_ros2_reads_every_message(bag)


def test_playback_publishes_every_recorded_event(ros_context, probe):
    from rclpy.node import Node

    from mpi_ros.bag.playback import play
    from mpi_ros.msg import MotionEvent

    bag = FIXTURES / "bags" / "estop_reset"
    expected = BagReader(bag).counts()["/mpi/events"]
    received = []
    done = threading.Event()

    def on_event(msg):
        received.append(msg)
        if len(received) == expected:
            done.set()

    probe.create_subscription(MotionEvent, "/mpi/events", on_event, 1000)
    player = Node("test_player", context=ros_context)
    try:
        sent = play(player, bag, rate=50.0, topics=["/mpi/events"], wait_for_subscribers=1)
    finally:
        player.destroy_node()
    assert sent == expected
    assert done.wait(10.0), f"received {len(received)} of {expected}"
    recorded = [msg.type for _, msg in BagReader(bag).decoded(["/mpi/events"])]
    assert [m.type for m in received] == recorded


def test_playback_of_a_bag_from_before_the_headers_sends_the_installed_types(ros_context, probe):
    """Its bytes are in the older layout: sent as recorded, subscribers of the installed type
    would misread them. Each is rebuilt in the installed type, the bare stamp in the header."""
    from rclpy.node import Node

    from mpi_ros.bag.playback import play
    from mpi_ros.msg import MotionStatus

    bag = FIXTURES / "older" / "p2p_modify_before_headers"
    recorded = [msg for _, msg in BagReader(bag).decoded(["/mpi/ms0/status"])]
    received = []
    done = threading.Event()

    def on_status(msg):
        received.append(msg)
        if len(received) == len(recorded):
            done.set()

    probe.create_subscription(MotionStatus, "/mpi/ms0/status", on_status, 1000)
    player = Node("test_older_player", context=ros_context)
    try:
        assert play(player, bag, rate=50.0, topics=["/mpi/ms0/status"], wait_for_subscribers=1) == len(recorded)
    finally:
        player.destroy_node()
    assert done.wait(10.0), f"received {len(received)} of {len(recorded)}"
    for old, new in zip(recorded, received, strict=True):
        assert (new.header.stamp.sec, new.header.stamp.nanosec) == (old.stamp.sec, old.stamp.nanosec)
        assert new.header.frame_id == ""
        assert new.sample == old.sample
        assert new.state_name == old.state_name
        assert [a.command_position for a in new.axes] == [a.command_position for a in old.axes]
        assert [convert_ns(a.header.stamp) for a in new.axes] == [convert_ns(a.stamp) for a in old.axes]


def convert_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def test_play_takes_the_topic_names_echo_takes_and_refuses_one_the_bag_lacks(capsys):
    from mpi_ros.cli import main
    from mpi_ros.cli.play import resolve_topics

    bag = FIXTURES / "bags" / "estop_reset"
    recorded = BagReader(bag).topics()
    assert resolve_topics(["events", "ms0/status", "joint_states", "/mpi/commands"], "/mpi", recorded) == [
        "/mpi/events", "/mpi/ms0/status", "/joint_states", "/mpi/commands"]
    assert main(["play", str(bag), "--topics", "events", "evnts"]) == 2  # before publishing anything
    err = capsys.readouterr().err
    assert err.startswith("mpi-ros play: no topic /mpi/evnts in the bag: it has /joint_states, /mpi/axis0/status")
    assert main(["play", str(bag), "--topics", "events", "--namespace", "/cell_a"]) == 2
    assert "no topic /cell_a/events in the bag" in capsys.readouterr().err


def test_plot_of_a_bag_writes_a_png(tmp_path):
    from mpi_ros.plot.bag import plot_bag

    out = plot_bag(FIXTURES / "bags" / "two_supervisors", tmp_path / "two.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.stat().st_size > 20_000


def test_plot_reads_the_stamps_of_a_bag_from_before_the_headers():
    from mpi_ros.plot.bag import read_recording

    recording = read_recording(FIXTURES / "older" / "p2p_modify_before_headers")
    assert sorted(recording.axes) == [0, 1, 2, 3]
    assert recording.states
    assert recording.events
    times = list(recording.axes[0]["t"])
    assert 0.0 <= times[0] < 0.1
    assert times == sorted(times)
    assert times[-1] > 1.0
