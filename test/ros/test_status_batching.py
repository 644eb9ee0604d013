"""Statuses stepped in stretches (ros.publish_period, runner.add_status; issue 35) reach the
topics exactly as statuses stepped one by one: the same messages, byte for byte, on every
status topic, /joint_states and /clock, with a command in between taking effect at the same
sample."""

from __future__ import annotations

import dataclasses
import json
from collections import defaultdict

from mpi_ros import config
from mpi_ros.commands import Command
from mpi_ros.ros import convert

_PUBLISH_ALL = convert.publish_all
EPOCH = 1_795_000_000_000_000_000
GOAL = {"type": "S_CURVE", "position": [2500.0, -400.0],
        "trajectory": [{"velocity": 20000.0, "acceleration": 200000.0, "deceleration": 200000.0,
                        "jerk_percent": 50.0}]}


def _published(ros_context, monkeypatch, publish_period: float) -> tuple[dict[str, list[bytes | str]], list[int]]:
    """Every message the suite published (CDR), by topic, over a scripted run with status and
    joint states at 1 kHz, and the samples its commands took effect at."""
    from mpi_ros.ros.suite import Suite

    raw = config.load().raw
    raw["ros"].update(status_rate=1000.0, joint_states_rate=1000.0, clock_rate=500.0, publish_period=publish_period)
    suite = Suite(config.parse(raw), time_scale=None, context=ros_context, epoch_ns=EPOCH)
    sent: dict[str, list[bytes | str]] = defaultdict(list)

    def record(node, sends):
        sends = list(sends)
        for publisher, msg in sends:
            # messages built in Python (events) as their fields: rclpy's CDR leaves padding bytes unset
            sent[publisher.topic_name].append(msg if isinstance(msg, bytes) else json.dumps(convert.to_dict(msg)))
        _PUBLISH_ALL(node, sends)

    monkeypatch.setattr(convert, "publish_all", record)
    samples = []
    try:
        runner = suite.runner
        runner.step(7)
        samples.append(runner.submit(Command("motion_start", 0, request=GOAL))[1])
        runner.step(33)
        samples.append(runner.submit(Command("motion_start", 1, request=GOAL))[1])
        runner.step(3)
        samples.append(runner.submit(Command("action", 0, request={"action": "E_STOP"}))[1])
        runner.step(400)
    finally:
        suite.shutdown()
    return sent, samples


def test_statuses_stepped_in_stretches_are_published_byte_for_byte_as_one_by_one(ros_context, monkeypatch):
    batched, batched_samples = _published(ros_context, monkeypatch, 0.005)
    single, single_samples = _published(ros_context, monkeypatch, 0.0)
    assert batched_samples == single_samples == [8, 41, 44]
    status_topics = [t for t in single if t.endswith("/status")] + ["/joint_states", "/clock"]
    assert len(status_topics) == 2 + 4 + 2  # ms0, ms1, axis0..3, joint states, clock
    for topic in status_topics:
        assert batched[topic] == single[topic], topic
    assert len(single["/mpi/ms0/status"]) == 443 // 2  # every 2 samples at 2 kHz
    assert len(single["/clock"]) == 443 // 4
    assert batched["/mpi/events"] == single["/mpi/events"]  # in order, the same


def test_the_publish_period_is_a_setting_of_the_ros_section():
    from mpi_ros.settings import PARAMETERS

    assert config.load().ros.publish_period == 0.005
    assert PARAMETERS["publish_period"].high == 1.0
    assert dataclasses.replace(config.load().ros, publish_period=0.0).publish_period == 0.0
