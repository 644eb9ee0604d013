"""The whole suite under load, as a user sees it (issue 10).

Separate processes, so that every figure is the suite's and not the GIL of a shared probe:
- the suite: ``mpi-ros run --time-scale 1 --config <generated YAML>`` (this source tree);
- the subscribers, which count the messages of every status topic, /joint_states and
  /clock against the wall clock over a window. By default (``--subscribers rclpy``, issue
  35: "as a user sees it") three plain rclpy subscriber processes, each with a share of the
  topics, the generated message types and rclpy's executor: every message deserialized,
  its stamp read from its header. ``--subscribers raw``: the probe of earlier figures, one
  process that takes the CDR bytes and deserializes nothing.
- the goals: a process that starts a VELOCITY move on every supervisor through its
  MotionStart action (mpi_ros.client.MotionClient, the public client) and says when each
  axis is at its velocity.

This process uses no ROS itself: it starts the others, reads /proc and waits on each of
them with a time limit, so a hang in any of them (Fast DDS once deadlocked here while a
client's participant was destroyed) ends the bench with a message naming it, and every
process it started ends with it, however it ends (PR_SET_PDEATHSIG).

Figures per case:
- real time: controller time (the stamps of /mpi/ms0/status, ``epoch + sample / rate``)
  elapsed over the window / wall time elapsed between the messages' publication (the
  middleware's source timestamps) (target: within 1 %), and by how much the controller's
  lag behind the wall clock varied;
- every topic's rate: messages received in the window (the middleware's reception
  timestamps, so a late probe does not count) / the window's length, against the
  configured rate (target: within 2 %), the worst topic shown, and the messages lost
  (stamps the controller published that never arrived);
- the suite's CPU: utime + stime of its process (/proc/<pid>/stat, every thread) over the
  window, as a share of one core (target for 32 axes: < 40 %), split into the Python
  threads and the DDS threads (by thread name in /proc/<pid>/task);
- the subscribers' (or probe's) own CPU, to judge what they take from the suite on a
  2-core machine.

``--busy N`` runs N busy processes beside every run: the same figures on a loaded machine,
reproducibly (a shared machine's load comes and goes).

Cases: 32 axes in 16 two-axis supervisors with status and joint states at 100 Hz; 8 axes
in 4 two-axis supervisors with status and joint states at 1 kHz, at the default sample
rate (2 kHz) and at 4 kHz (``8x1000@4k``); and, asked for by name, each of them with ``+fifo``
(``8x1000+fifo``, ``32x100+fifo``, ``8x1000@4k+fifo``): the clock thread under SCHED_FIFO
(ros.clock_priority 10), beside the same case without it, idle or with ``--busy``
(``--baseline none`` for a tree without that setting).

The machines are shared and noisy, so each case also runs the suite of a baseline revision
(``--baseline``, extracted with git archive), alternating with this tree, ``--rounds`` times;
the table gives the medians side by side, then every run.

Where the time goes: ``--phases CASE`` runs the case once with the suite's clock thread timed
by phase (its own CPU clock around every step, periodic callback and the publishing each
leaves); ``--profile CASE`` runs it under cProfile (slower: ``--profile-time-scale``).

    python -P bench/bench_suite.py [--seconds 20] [--rounds 2] [--case 32x100] [--baseline REV|none]
                                   [--subscribers rclpy|raw]
    python -P bench/bench_suite.py --phases 8x1000 [--seconds 20]
    python -P bench/bench_suite.py --profile 32x100 [--profile-time-scale 0.25]
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import json
import math
import os
import queue
import random
import shutil
import signal
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

# This source tree, not a stale installed copy (the installed package still supplies the
# generated interfaces: mpi_ros/__init__.py), here and in the suite's process.
REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))  # run with -P: the sibling bench_controller
from bench_controller import compared_trees  # noqa: E402 - after the path it is found on

os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH", "")) if p)
# Its own DDS domain (a pid-based one may be taken by a suite of a concurrent test run).
os.environ.setdefault("ROS_DOMAIN_ID", str(random.Random(os.getpid()).randint(150, 200)))
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")

WAIT = 30.0
BASELINE = "ca83577"  # the suite before issue 10's ROS-layer changes (wire.py, snapshots.py, the clock's stops)
SETTLE = 2.0  # s between the last axis at velocity and the window (discovery, queues drained)
_STAMP = struct.Struct("<iI")  # builtin_interfaces/Time: every topic counted starts with its header's stamp


@dataclass(frozen=True)
class Case:
    name: str
    axes: int
    status_rate: float  # Hz: MotionStatus, AxisStatus and JointState
    sample_rate: float = 2000.0  # Hz: the controller's
    ros: tuple[tuple[str, Any], ...] = ()  # more settings of the ros section (a tree that knows them)

    @property
    def supervisors(self) -> int:
        return self.axes // 2


_PLAIN = (Case("32x100", 32, 100.0), Case("8x1000", 8, 1000.0), Case("8x1000@4k", 8, 1000.0, 4000.0))
# each also with its clock thread under SCHED_FIFO (ros.clock_priority), asked for by name
CASES = {case.name: case for plain in _PLAIN
         for case in (plain, replace(plain, name=f"{plain.name}+fifo", ros=(("clock_priority", 10),)))}
DEFAULT_CASES = [case.name for case in _PLAIN]  # (any tree knows their settings)
SUBSCRIBER_PROCESSES = 3  # --subscribers rclpy: the status topics are shared out among these


def suite_yaml(case: Case, directory: Path, tree: Path = REPO) -> Path:
    """``tree``'s config/default.yaml (the settings that tree knows) with ``case.axes`` axes in
    two-axis supervisors and its rates."""
    raw = yaml.safe_load((tree / "config" / "default.yaml").read_text(encoding="utf-8"))
    raw["axes"]["count"] = case.axes
    raw["supervisors"] = [{"number": n, "axes": [2 * n, 2 * n + 1]} for n in range(case.supervisors)]
    raw["ros"].update(status_rate=case.status_rate, joint_states_rate=case.status_rate, **dict(case.ros))
    raw["controller"]["sample_rate"] = case.sample_rate
    path = directory / f"suite_{case.name}.yaml"
    path.write_text(yaml.safe_dump(raw, sort_keys=False), encoding="utf-8")
    return path


def suite_environment(tree: Path, directory: Path) -> dict[str, str]:
    """The environment of ``tree``'s suite: its source first, and its own Fast DDS profile
    (config/fastdds_discovery.xml, as an installation of that tree would have). The suite
    would take the venv's installed copy, whichever tree runs, and replace a profile it
    finds in a place it looks itself (mpi_ros.dds_profile): a copy in ``directory`` is one of
    the operator's, which it keeps."""
    from mpi_ros import dds_profile

    env = {**os.environ, "PYTHONPATH": str(tree)}
    profile = tree / "config" / dds_profile.SUITE
    if profile.is_file() and not any(os.environ.get(v) for v in dds_profile.PROFILE_VARIABLES):  # else: the operator's
        copy = directory / dds_profile.SUITE
        shutil.copyfile(profile, copy)
        env[dds_profile.PROFILE_VARIABLES[0]] = str(copy)
    return env


# -- /proc ---------------------------------------------------------------------------------------
def _ticks(stat: str) -> int:
    fields = stat.rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])  # utime + stime


def cpu_seconds(pid: int) -> float:
    return _ticks(Path(f"/proc/{pid}/stat").read_text()) / os.sysconf("SC_CLK_TCK")


def thread_cpu(pid: int) -> Counter:
    """CPU seconds per thread name (comm) of a process, every thread summed by name."""
    out: Counter = Counter()
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            stat = (task / "stat").read_text()
        except OSError:
            continue  # the thread ended
        name = stat[stat.index("(") + 1: stat.rindex(")")]
        out[name] += _ticks(stat) / os.sysconf("SC_CLK_TCK")
    return out


def runnable_wait_seconds(pid: int) -> float:
    """Seconds the threads of a process have spent ready to run but waiting for a CPU (the
    scheduler's run-queue delay, /proc/<pid>/task/*/schedstat, second field; threads that
    ended are not counted). Time a process waited for a core is time the machine, not the
    process, was short of."""
    total = 0
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(OSError):  # the thread ended
            total += int((task / "schedstat").read_text().split()[1])
    return total / 1e9


def idle_seconds() -> float:
    """Seconds all the machine's cores have been idle (/proc/stat: idle and iowait)."""
    fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
    return (int(fields[4]) + int(fields[5])) / os.sysconf("SC_CLK_TCK")


def load_average() -> str:
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


# -- the probe -------------------------------------------------------------------------------------
@dataclass
class Topic:
    name: str
    rate: float
    # per message: (sent, received, stamp), ns; sent and received are the middleware's wall-clock
    # times (source and reception timestamps), so the probe's own delays do not count
    messages: list[tuple[int, int, int]] = field(default_factory=list)

    def on_message(self, data: bytes, info: dict) -> None:
        sec, nanosec = _STAMP.unpack_from(data, 4)  # after the 4-byte CDR header
        self.messages.append((info["source_timestamp"], info["received_timestamp"], sec * 1_000_000_000 + nanosec))

    def window(self, start: int, end: int) -> list[tuple[int, int, int]]:
        """The messages received in [start, end) (ns, wall clock)."""
        return [m for m in self.messages if start <= m[1] < end]


@dataclass(frozen=True)
class TopicFigures:
    name: str
    target: float
    measured: float
    lost: int

    @property
    def error(self) -> float:
        return self.measured / self.target - 1.0


def figures(topic: Topic, start: int, end: int) -> TopicFigures:
    window = topic.window(start, end)
    stamps = sorted({stamp for _, _, stamp in window})
    expected = round((stamps[-1] - stamps[0]) * topic.rate / 1e9) + 1 if stamps else 0
    return TopicFigures(topic.name, topic.rate, len(window) * 1e9 / (end - start), expected - len(stamps))


def real_time(topic: Topic, start: int, end: int) -> tuple[float, float]:
    """(controller time elapsed / wall time elapsed between the first and the last message
    sent in the window, the most the controller was behind the wall clock in s: sent - stamp,
    less the least of it)."""
    window = topic.window(start, end)
    if len(window) < 2:
        return math.nan, math.nan  # the suite fell so far behind that nothing came
    (sent0, _, stamp0), (sent1, _, stamp1) = window[0], window[-1]
    lags = [sent - stamp for sent, _, stamp in window]
    return (stamp1 - stamp0) / (sent1 - sent0), (max(lags) - min(lags)) / 1e9


class BenchStalled(RuntimeError):
    """A process of the bench did not answer within its time limit (it was killed)."""


def _die_with_parent() -> None:
    """Run in every child before it executes: the kernel kills it (SIGKILL) when the bench's
    process ends, however that ends (prctl PR_SET_PDEATHSIG), so no suite at real time or
    subscriber outlives a bench that was killed or stopped on a stall."""
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG


@contextlib.contextmanager
def _ended(processes: list[subprocess.Popen]) -> Iterator[None]:
    """Kill ``processes`` (and reap them) when the block ends."""
    try:
        yield
    finally:
        for process in processes:
            process.kill()
            process.wait()


def _child(argv: list[str], **kwargs) -> subprocess.Popen:
    """A process of the bench: it ends when the bench does (_die_with_parent). (A preexec_fn
    is unsafe while other threads hold locks; the bench starts its processes while its only
    other thread, start_moves' reader, is not running.)"""
    return subprocess.Popen(argv, preexec_fn=_die_with_parent, **kwargs)


def _serve(option: str, *args: str) -> list[str]:
    """The command line of this script in one of its child roles (--serve-...)."""
    return [sys.executable, "-P", str(Path(__file__).resolve()), option, *args]


class Probe:
    """A node of its own that counts every topic, raw (the --subscribers raw process).
    rclpy's executor takes one message per subscription and wait, through a task each: too
    slow for 14,000 messages a second on a shared core. Here one thread waits on every
    subscription and takes everything queued at each wake."""

    def __init__(self, context, topics: list[tuple[type, str, Any]]):
        """``topics``: (message type, topic name, what counts its messages: on_message(data, info))."""
        from rclpy.node import Node
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        self.context = context
        self.node = Node("bench_suite_probe", context=context)
        # Deep queues: the probe never drops what arrived (/clock is offered best effort).
        deep = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        clock = QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT)
        self._subscriptions = []
        for msg_type, name, counter in topics:
            qos = clock if name == "/clock" else deep
            subscription = self.node.create_subscription(msg_type, name, lambda _: None, qos, raw=True)
            self._subscriptions.append((subscription, counter))
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._drain, name="bench-probe", daemon=True)
        self.thread.start()

    def _drain(self) -> None:
        from contextlib import ExitStack

        from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

        with ExitStack() as held:  # the handles stay valid while the loop uses them
            for subscription, _ in self._subscriptions:
                held.enter_context(subscription.handle)
            held.enter_context(self.context.handle)
            wait_set = _rclpy.WaitSet(len(self._subscriptions), 0, 0, 0, 0, 0, self.context.handle)
            while not self._stop.is_set():
                wait_set.clear_entities()
                for subscription, _ in self._subscriptions:
                    wait_set.add_subscription(subscription.handle)
                wait_set.wait(100_000_000)  # ns: a stop is seen within 0.1 s
                ready = set(wait_set.get_ready_entities("subscription"))
                for subscription, topic in self._subscriptions:
                    if subscription.handle.pointer in ready:
                        self._take_all(subscription, topic)

    @staticmethod
    def _take_all(subscription, topic: Any) -> None:
        handle = subscription.handle
        while (taken := handle.take_message(subscription.msg_type, True)) is not None:
            topic.on_message(*taken)

    def close(self) -> None:
        self._stop.set()
        self.thread.join(timeout=2.0)
        self.node.destroy_node()


class Subscribers:
    """The processes that count the topics (serve_subscribers). rclpy: plain rclpy subscriber
    processes, what a user's node is: each subscribes to its share of the topics with the
    generated message types, and rclpy's executor deserializes every message and calls back
    with it and its message info (the middleware's source and reception timestamps); the stamp
    is read from the message. raw: one Probe process. Each writes what it counted to a file
    when told to stop."""

    def __init__(self, names: list[str], kind: str, directory: Path):
        self.directory = directory
        processes = SUBSCRIBER_PROCESSES if kind == "rclpy" else 1
        self.shares = [names[i::processes] for i in range(processes)]
        self.procs = [_child(_serve("--serve-subscribers", str(directory / f"subscriber{i}"), "--kind", kind,
                                    "--", *share))
                      for i, share in enumerate(self.shares)]

    @property
    def pids(self) -> list[int]:
        return [proc.pid for proc in self.procs]

    def wait_ready(self) -> None:
        deadline = time.monotonic() + WAIT
        while not all((self.directory / f"subscriber{i}.ready").exists() for i in range(len(self.procs))):
            if any(proc.poll() is not None for proc in self.procs):
                raise RuntimeError("a subscriber process ended before it subscribed")
            if time.monotonic() > deadline:
                raise BenchStalled(f"the subscriber processes did not subscribe within {WAIT:g} s")
            threading.Event().wait(0.05)

    def close(self, topics: dict[str, Topic]) -> None:
        """Stop them and put what each counted into ``topics``; a process that does not stop
        within WAIT is killed (and what it counted is lost: BenchStalled)."""
        for i in range(len(self.procs)):
            (self.directory / f"subscriber{i}.stop").touch()
        stalled = []
        for i, proc in enumerate(self.procs):
            try:
                proc.wait(timeout=WAIT)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
                stalled.append(i)
                continue
            counted = json.loads((self.directory / f"subscriber{i}.json").read_text(encoding="utf-8"))
            for name, messages in counted.items():
                topics[name].messages = [tuple(m) for m in messages]
        if stalled:
            raise BenchStalled(f"subscriber process(es) {stalled} did not stop within {WAIT:g} s (killed)")


def serve_subscribers(out: str, names: list[str], kind: str) -> int:
    """One subscriber process (Subscribers), subscribed to ``names``: <out>.ready once
    subscribed, counts until <out>.stop exists, then writes {topic: [[sent, received, stamp],
    ...]} to <out>.json. rclpy: a node spun by rclpy's executor, a subscription per topic;
    raw: a Probe."""
    import rclpy

    rclpy.init()
    stop = Path(f"{out}.stop")
    if kind == "raw":
        topics = {name: Topic(name, 0.0) for name in names}
        probe = Probe(rclpy.get_default_context(), [(topic_type(name), name, topic) for name, topic in topics.items()])
        Path(f"{out}.ready").touch()
        while not stop.exists():
            threading.Event().wait(0.05)
        probe.close()
        counted = {name: topic.messages for name, topic in topics.items()}
    else:
        counted = _spin_subscriptions(names, Path(f"{out}.ready"), stop)
    Path(f"{out}.json").write_text(json.dumps(counted), encoding="utf-8")
    rclpy.try_shutdown()
    return 0


def _spin_subscriptions(names: list[str], ready: Path, stop: Path) -> dict[str, list[tuple[int, int, int]]]:
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    node = Node(f"bench_suite_subscriber_{os.getpid()}")
    counted: dict[str, list[tuple[int, int, int]]] = {name: [] for name in names}

    def counter(name: str):
        stamp_of = (lambda msg: msg.clock) if name == "/clock" else (lambda msg: msg.header.stamp)
        messages = counted[name]

        def on_message(msg, info) -> None:
            stamp = stamp_of(msg)
            messages.append((info["source_timestamp"], info["received_timestamp"],
                             stamp.sec * 1_000_000_000 + stamp.nanosec))
        return on_message

    for name in names:  # deep queues, as the raw probe's (/clock is offered best effort)
        reliability = ReliabilityPolicy.BEST_EFFORT if name == "/clock" else ReliabilityPolicy.RELIABLE
        node.create_subscription(topic_type(name), name, counter(name), QoSProfile(depth=1000, reliability=reliability))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    ready.touch()
    while not stop.exists():
        executor.spin_once(timeout_sec=0.1)
    node.destroy_node()
    return counted


def case_topics(case: Case) -> dict[str, Topic]:
    """The topics a case counts: every status topic, /joint_states and /clock."""
    rates = ([(f"/mpi/ms{n}/status", case.status_rate) for n in range(case.supervisors)]
             + [(f"/mpi/axis{k}/status", case.status_rate) for k in range(case.axes)]
             + [("/joint_states", case.status_rate), ("/clock", 100.0)])
    return {name: Topic(name, rate) for name, rate in rates}


def topic_type(name: str) -> type:
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import JointState

    from mpi_ros.msg import AxisStatus, MotionStatus

    if name == "/clock":
        return Clock
    if name == "/joint_states":
        return JointState
    return AxisStatus if "/axis" in name else MotionStatus


def start_moves(case: Case) -> int:
    """A VELOCITY move on every supervisor, in a process of its own (serve_moves); returns how
    many goals succeeded within WAIT (a VELOCITY goal succeeds when its axes are at velocity).
    A suite that cannot keep up may answer late: its moves run all the same (a goal's
    command is applied as it is accepted; one whose request is not taken in time does not
    move), and the window shows how far behind.

    The process answers a line per goal; one that says nothing for longer than a goal may
    take (the server's discovery and the goal, WAIT each) has stalled: it is killed and the
    run stops (BenchStalled). A process that answered every goal but does not exit (its ROS
    teardown hung) is killed: its answers stand."""
    proc = _child(_serve("--serve-moves", str(case.supervisors)), stdout=subprocess.PIPE, text=True)
    lines: queue.Queue[str | None] = queue.Queue()

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.put(line)
        lines.put(None)

    threading.Thread(target=read, daemon=True).start()
    at_velocity = 0
    try:
        for n in range(case.supervisors):
            line = lines.get(timeout=2 * WAIT + 5.0)
            if line is None:
                raise RuntimeError(f"the goals' process ended (exit status {proc.wait()}) before ms{n}'s goal")
            at_velocity += json.loads(line)["at_velocity"]
    except queue.Empty:
        proc.kill()
        raise BenchStalled(f"the goals' process (a MotionClient per supervisor) said nothing about ms{n}'s goal "
                           f"for {2 * WAIT + 5.0:g} s (killed)") from None
    finally:
        try:
            proc.wait(timeout=WAIT)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    return at_velocity


def serve_moves(supervisors: int) -> int:
    """The goals' process (start_moves): a line {"at_velocity": 0 or 1} per supervisor, in order.
    Every client shares one DDS participant, which a node of its own keeps from one client's
    close to the next (each client alone would create and destroy a participant)."""
    import rclpy

    from mpi_ros.client import MotionClient
    from mpi_ros.errors import NoResponse

    rclpy.init()
    keeper = rclpy.create_node("bench_suite_goals")
    for n in range(supervisors):
        answered = False
        with MotionClient(n, timeout=WAIT, node_name=f"bench_suite_ms{n}") as client:
            if not client.wait_for_server(WAIT):
                raise RuntimeError(f"/mpi/ms{n} did not come up within {WAIT:g} s")
            try:
                goal = client.start({"type": "VELOCITY",
                                     "trajectory": [{"velocity": 1000.0 + 10.0 * n, "acceleration": 100_000.0}]})
                answered = goal.wait(WAIT).detail == "at velocity"
            except NoResponse:
                pass  # the goal's answer or its result came too late
        print(json.dumps({"at_velocity": int(answered)}), flush=True)
    keeper.destroy_node()
    rclpy.try_shutdown()
    return 0


# -- one case --------------------------------------------------------------------------------------
@dataclass
class Result:
    case: Case
    tree: str  # which source tree the suite ran: "working tree" or the baseline's revision
    at_velocity: int  # goals answered "at velocity" within WAIT (of one per supervisor)
    stopped: str | None  # None: it stopped on Ctrl-C; else what happened
    seconds: float
    real_time: float
    lag: float  # s: how far the controller's lag behind the wall clock varied in the window
    topics: list[TopicFigures]
    suite_cpu: float  # share of one core
    suite_threads: Counter  # CPU share of one core by thread name
    probe_cpu: float
    load_before: str
    load_after: str

    @property
    def worst(self) -> TopicFigures:
        return max(self.topics, key=lambda t: abs(t.error))

    @property
    def cpu_per_controller_second(self) -> float:
        """The suite's CPU per second of controller time: what it takes of a core to do a
        second's work, whether or not it kept real time (a suite starved by other load does
        less work in the window, and its CPU share alone would flatter it)."""
        return self.suite_cpu / self.real_time if self.real_time > 0 else math.nan


def _mark(marks: str | None, what: str) -> None:
    if marks is None:
        return
    Path(f"{marks}.{what}").touch()
    if what == "end":  # the suite writes its table at once: let it before stopping it
        deadline = time.monotonic() + 5.0
        while not Path(f"{marks}.phases.md").exists() and time.monotonic() < deadline:
            threading.Event().wait(0.01)


def _stop(suite: subprocess.Popen) -> str | None:
    """Ctrl-C the suite; None once it stopped, else what happened (a suite far behind real
    time may not stop in time: that is a finding, not an error of the benchmark)."""
    suite.send_signal(signal.SIGINT)
    try:
        suite.wait(timeout=WAIT)
        return None
    except subprocess.TimeoutExpired:
        suite.kill()
        suite.wait()
        return f"did not stop within {WAIT:g} s of Ctrl-C (killed)"


@dataclass
class _Window:
    """What was measured over the window: its ends (ns, wall clock), the CPU of the suite
    (seconds, in all and by thread name) and of the probe, the load before and after."""

    start: int
    end: int
    suite_cpu: float
    suite_threads: Counter
    probe_cpu: float
    load_before: str
    load_after: str


def _window(pid: int, seconds: float, marks: str | None, subscribers: list[int]) -> _Window:
    """``subscribers``: the pids of the subscriber processes, whose CPU counts as the probe's."""
    load_before = load_average()

    def probe_cpu() -> float:
        return time.process_time() + sum(cpu_seconds(p) for p in subscribers)

    cpu0, threads0, probe0 = cpu_seconds(pid), thread_cpu(pid), probe_cpu()
    _mark(marks, "start")
    start = time.time_ns()  # the middleware's timestamps are wall-clock (system) time
    threading.Event().wait(seconds)
    end = time.time_ns()
    _mark(marks, "end")
    cpu1, threads1, probe1 = cpu_seconds(pid), thread_cpu(pid), probe_cpu()
    threads = Counter({name: threads1[name] - threads0.get(name, 0.0) for name in threads1})
    return _Window(start, end, cpu1 - cpu0, threads, probe1 - probe0, load_before, load_average())


def run_case(case: Case, seconds: float, command: list[str] | None = None, marks: str | None = None,
             tree: Path = REPO, label: str = "working tree", subscribers: str = "rclpy") -> Result:
    """One run of ``case``; ``command`` starts the suite (default: mpi-ros run at time scale 1)
    from the source ``tree`` (the installed package supplies the generated interfaces);
    ``marks``: create <marks>.start and <marks>.end when the window begins and ends (serve_phases);
    ``subscribers``: who counts the topics, rclpy subscriber processes or a raw probe
    (Subscribers). Every process it starts is stopped before it returns or raises."""
    with tempfile.TemporaryDirectory(prefix="bench_suite_") as tmp:
        config = suite_yaml(case, Path(tmp), tree)
        argv = command or [sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--time-scale", "1"]
        with open(Path(tmp) / "suite.log", "w") as log:
            suite = _child([*argv, "--config", str(config)], cwd=tmp, stdout=subprocess.DEVNULL,
                           stderr=log, env=suite_environment(tree, Path(tmp)))
        topics = case_topics(case)
        try:
            readers = Subscribers(list(topics), subscribers, Path(tmp))
            try:
                readers.wait_ready()
                at_velocity = start_moves(case)
                threading.Event().wait(SETTLE)
                window = _window(suite.pid, seconds, marks, readers.pids)
            finally:
                readers.close(topics)
        finally:
            stopped = _stop(suite)
        if stopped is None and suite.returncode != 0:
            raise RuntimeError(f"the suite exited with {suite.returncode}:\n{(Path(tmp) / 'suite.log').read_text()}")
    start, end = window.start, window.end
    wall = (end - start) / 1e9
    return Result(case, label, at_velocity, stopped, wall, *real_time(topics["/mpi/ms0/status"], start, end),
                  [figures(topic, start, end) for topic in topics.values()], window.suite_cpu / wall,
                  Counter({name: cpu / wall for name, cpu in window.suite_threads.items()}),
                  window.probe_cpu / wall, window.load_before, window.load_after)


# -- profile -------------------------------------------------------------------------------------
def serve_profiled(out: str, argv: list[str]) -> int:
    """``mpi-ros run <argv>`` in this process, with cProfile on the controller's clock thread
    (stepping, building the messages, publishing) and on the thread that spins the executor;
    on exit each thread's stats go to <out>.<thread>.prof. Only for the profile: cProfile
    slows what it watches, so the figures come from runs without it."""
    import cProfile
    import functools

    from mpi_ros.cli import main as cli_main
    from mpi_ros.ros.spinner import Spinner
    from mpi_ros.runner import ControllerRunner

    def profiled(method, name):
        @functools.wraps(method)
        def wrapper(self, *args, **kwargs):
            profile = cProfile.Profile()
            profile.enable()
            try:
                return method(self, *args, **kwargs)
            finally:
                profile.disable()
                profile.dump_stats(f"{out}.{name(self)}.prof")
        return wrapper

    ControllerRunner._loop = profiled(ControllerRunner._loop, lambda _runner: "clock")
    # One executor thread per node (mpi_ros.ros.spinner): one profile each.
    Spinner._run = profiled(Spinner._run, lambda spinner: f"executor-{spinner.name}")
    return cli_main(["run", *argv])


class _Phases:
    """CPU time of the controller's clock thread by phase, measured with the thread's own CPU
    clock (time.thread_time) around each: an exact split at a few microseconds a call,
    where cProfile's per-call overhead swells the small functions and slows the suite
    until it falls behind."""

    def __init__(self) -> None:
        self.cpu: Counter = Counter()
        self.calls: Counter = Counter()
        self.thread_cpu = 0.0

    def timed(self, name: str, function):
        def wrapper(*args, **kwargs):
            start = time.thread_time()
            try:
                return function(*args, **kwargs)
            finally:
                self.cpu[name] += time.thread_time() - start
                self.calls[name] += 1
        return wrapper

    def producer(self, name: str, callback):
        """A periodic callback or change hook: itself, then the output it returns, each timed."""
        timed = self.timed(name, callback)

        def wrapper(*args):  # (controller) or, a status, (controller, at)
            output = timed(*args)
            return None if output is None else self.timed(f"{name} (output)", output)
        return wrapper

    def table(self, seconds: float) -> list[str]:
        lines = [f"clock thread CPU: {self.thread_cpu / seconds * 100:.1f} % of one core over {seconds:.1f} s",
                 "| phase | share of one core | calls/s | us per call |", "| --- | --- | --- | --- |"]
        for name, cpu in self.cpu.most_common():
            lines.append(f"| {name} | {cpu / seconds * 100:.1f} % | {self.calls[name] / seconds:.0f} "
                         f"| {cpu / self.calls[name] * 1e6:.1f} |")
        return lines


def serve_phases(out: str, argv: list[str]) -> int:
    """``mpi-ros run <argv>`` in this process with its clock thread's CPU split by phase
    (_Phases): the controller's steps, each periodic callback and change hook (under the
    runner's lock) and the output each returns (publishing, after the lock). Counts over
    the probe's window, which it marks with the files <out>.start and <out>.end (a signal
    would wait for the main thread, blocked in the executor's wait); the table goes to
    <out>.phases.md."""
    from mpi_ros.cli import main as cli_main
    from mpi_ros.mpi.control import Controller
    from mpi_ros.runner import ControllerRunner

    phases = _Phases()
    clock_thread: list[int] = []  # the CPU clock of the clock thread

    def named(callback) -> str:
        owner = getattr(callback, "__self__", None)
        return f"{type(owner).__name__}.{callback.__name__}" if owner is not None else callback.__qualname__

    add_periodic, on_change, loop = ControllerRunner.add_periodic, ControllerRunner.on_change, ControllerRunner._loop
    ControllerRunner.add_periodic = lambda self, rate, callback, **wanted: add_periodic(  # (older trees: no wanted)
        self, rate, phases.producer(f"periodic {named(callback)}", callback), **wanted)
    ControllerRunner.on_change = lambda self, hook: on_change(self, phases.producer(f"change hook {named(hook)}", hook))
    Controller.step = phases.timed("Controller.step (the core)", Controller.step)
    if hasattr(ControllerRunner, "add_status"):  # statuses stepped in stretches (issue 35)
        add_status = ControllerRunner.add_status
        ControllerRunner.add_status = lambda self, rate, callback, snapshots=True: add_status(
            self, rate, phases.producer(f"status {named(callback)}", callback), snapshots)
        Controller.step_snapshots = phases.timed("Controller.step_snapshots (the core)", Controller.step_snapshots)

    def clock_loop(self) -> None:
        clock_thread.append(time.pthread_getcpuclockid(threading.get_ident()))
        loop(self)

    ControllerRunner._loop = clock_loop
    threading.Thread(target=_window_watch, args=(phases, clock_thread, out), daemon=True).start()
    return cli_main(["run", *argv])


def _window_watch(phases: _Phases, clock_thread: list[int], out: str) -> None:
    """serve_phases: count from <out>.start to <out>.end, then write the table."""
    pause = threading.Event()
    while not Path(f"{out}.start").exists() or not clock_thread:
        pause.wait(0.01)
    phases.cpu.clear()
    phases.calls.clear()
    wall, cpu = time.monotonic(), time.clock_gettime(clock_thread[0])
    while not Path(f"{out}.end").exists():
        pause.wait(0.01)
    phases.thread_cpu = time.clock_gettime(clock_thread[0]) - cpu
    table = phases.table(time.monotonic() - wall)
    Path(f"{out}.phases.md").write_text("\n".join(table) + "\n", encoding="utf-8")


def profile(case: Case, seconds: float, out: Path, time_scale: float, top: int = 25,
            subscribers: str = "rclpy") -> None:
    """The case with the suite under cProfile (serve_profiled); prints each thread's top
    functions by own time and by cumulative time. ``time_scale`` < 1 gives the profiled
    suite the time the profiler takes (every status round does the same work, fewer of them
    a second), so that it keeps up as the real one does; the figures of that run are
    shown, but only the profile counts."""
    import pstats

    command = [sys.executable, "-P", str(Path(__file__).resolve()), "--serve-profiled", str(out), "--",
               "--time-scale", f"{time_scale:g}"]
    result = run_case(case, seconds, command, subscribers=subscribers)
    print(f"Under cProfile, time scale {time_scale:g} (rates scale with it):")
    print("\n".join(report([result])))
    for path in sorted(out.parent.glob(f"{out.name}.*.prof")):
        stats = pstats.Stats(str(path))
        print(f"\n== {path.name.removeprefix(out.name + '.').removesuffix('.prof')} thread ==")
        stats.sort_stats("tottime").print_stats(top)
        stats.sort_stats("cumulative").print_stats(top)


def phases(case: Case, seconds: float, out: Path, subscribers: str = "rclpy") -> None:
    """The case with the suite's clock thread timed by phase (serve_phases), in real time."""
    for stale in (".start", ".end", ".phases.md"):
        Path(f"{out}{stale}").unlink(missing_ok=True)
    command = [sys.executable, "-P", str(Path(__file__).resolve()), "--serve-phases", str(out), "--",
               "--time-scale", "1"]
    result = run_case(case, seconds, command, marks=str(out), subscribers=subscribers)
    print("\n".join(report([result])))
    print()
    print(Path(f"{out}.phases.md").read_text(encoding="utf-8"))


# -- report ----------------------------------------------------------------------------------------
def _threads(shares: Counter) -> str:
    python = shares.get("python", 0.0) + shares.get("python3", 0.0)
    others = sorted(((share, name) for name, share in shares.items() if name not in ("python", "python3")),
                    reverse=True)
    shown = ", ".join(f"{name} {share * 100:.1f}" for share, name in others if share >= 0.005)
    return f"Python threads {python * 100:.1f} %" + (f"; others: {shown} %" if shown else "")


def rows(result: Result) -> list[str]:
    case = result.case
    worst = result.worst
    lost = sum(t.lost for t in result.topics)
    status = (f"status and joint states at {case.status_rate:g} Hz, sample rate {case.sample_rate / 1000:g} kHz"
              + "".join(f", ros.{key}: {value}" for key, value in case.ros))
    return [
        f"| {case.axes} axes, {case.supervisors} supervisors, {status}, every axis moving "
        f"({len(result.topics)} topics, {result.seconds:.1f} s; load {result.load_before} -> {result.load_after}) "
        f"| {result.tree} "
        f"| {(result.real_time - 1) * 100:+.3f} % (lag varied by {result.lag * 1e3:.1f} ms) "
        f"| worst topic {worst.name} {worst.measured:.2f} Hz "
        f"({worst.error * 100:+.2f} %); {lost} message(s) lost in all"
        + (f"; only {result.at_velocity} of {case.supervisors} goals answered within {WAIT:g} s"
           if result.at_velocity < case.supervisors else "")
        + (f"; {result.stopped}" if result.stopped else "") + " "
        f"| {result.suite_cpu * 100:.1f} % ({_threads(result.suite_threads)}) | {result.probe_cpu * 100:.1f} % |",
    ]


def report(results: list[Result]) -> list[str]:
    lines = ["| case | suite | real time (controller / wall - 1) | every topic's rate (worst) "
             "| suite CPU, share of one core | probe CPU |", "| --- | --- | --- | --- | --- | --- |"]
    for result in results:
        lines += rows(result)
    return lines


def summary(results: list[Result]) -> list[str]:
    """Per case and tree: the median of the runs (the machine is shared: compare side by side)."""
    lines = ["| case | suite | runs | real time, median | worst topic, median | topics within 2 % in every run "
             "| suite CPU, median (range) | suite CPU per controller second, median |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for case in dict.fromkeys(r.case for r in results):
        for tree in dict.fromkeys(r.tree for r in results):
            runs = [r for r in results if r.case == case and r.tree == tree]
            if not runs:
                continue
            cpu = sorted(r.suite_cpu * 100 for r in runs)
            within = all(abs(t.error) <= 0.02 for r in runs for t in r.topics)
            lines.append(f"| {case.name} | {tree} | {len(runs)} | "
                         f"{(statistics.median(r.real_time for r in runs) - 1) * 100:+.3f} % | "
                         f"{statistics.median(r.worst.error for r in runs) * 100:+.2f} % | "
                         f"{'yes' if within else 'no'} | "
                         f"{statistics.median(cpu):.1f} % ({cpu[0]:.1f}-{cpu[-1]:.1f}) | "
                         f"{statistics.median(r.cpu_per_controller_second for r in runs) * 100:.1f} % |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", action="append", choices=sorted(CASES), help="default: every case but the +fifo ones")
    parser.add_argument("--seconds", type=float, default=20.0, help="the measuring window (default 20)")
    parser.add_argument("--rounds", type=int, default=2, help="runs of each case and tree (default 2)")
    parser.add_argument("--subscribers", choices=("rclpy", "raw"), default="rclpy",
                        help=f"who counts the topics: {SUBSCRIBER_PROCESSES} plain rclpy subscriber processes "
                             "(default: what a user's nodes are) or a raw probe in this process")
    parser.add_argument("--baseline", default=BASELINE,
                        help=f"also run the suite of this revision, alternating (default {BASELINE}; 'none': not)")
    parser.add_argument("--busy", type=int, default=0, metavar="N",
                        help="N busy processes (a Python loop each) beside every run: a loaded machine, "
                             "reproducibly (default 0)")
    parser.add_argument("--profile", choices=sorted(CASES), help="run this case with the suite under cProfile")
    parser.add_argument("--phases", choices=sorted(CASES),
                        help="run this case with the clock thread's CPU split by phase (in real time)")
    parser.add_argument("--profile-time-scale", type=float, default=1.0,
                        help="the profiled suite's time scale (default 1; < 1 where the profiler makes it fall behind)")
    parser.add_argument("--profile-out", default=str(Path(tempfile.gettempdir()) / "bench_suite"),
                        help="where the profiles go (<this>.<thread>.prof)")
    parser.add_argument("--serve-profiled", metavar="OUT", help=argparse.SUPPRESS)  # the profiled suite's process
    parser.add_argument("--serve-phases", metavar="OUT", help=argparse.SUPPRESS)  # the timed suite's process
    parser.add_argument("--serve-subscribers", metavar="OUT", help=argparse.SUPPRESS)  # a subscriber process
    parser.add_argument("--kind", choices=("rclpy", "raw"), help=argparse.SUPPRESS)  # ... of this kind
    parser.add_argument("--serve-moves", type=int, metavar="SUPERVISORS", help=argparse.SUPPRESS)  # the goals' process
    parser.add_argument("run_args", nargs="*", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve_profiled:
        sys.exit(serve_profiled(args.serve_profiled, args.run_args))
    if args.serve_subscribers:
        sys.exit(serve_subscribers(args.serve_subscribers, args.run_args, args.kind))
    if args.serve_moves is not None:
        sys.exit(serve_moves(args.serve_moves))
    if args.serve_phases:
        sys.exit(serve_phases(args.serve_phases, args.run_args))
    if args.phases:
        phases(CASES[args.phases], args.seconds, Path(args.profile_out), args.subscribers)
        return
    if args.profile:
        profile(CASES[args.profile], args.seconds, Path(args.profile_out), args.profile_time_scale,
                subscribers=args.subscribers)
        return
    results: list[Result] = []
    stalled: BenchStalled | None = None
    # (each ends with this process: _child)
    busy = [_child([sys.executable, "-c", "while True: pass"]) for _ in range(args.busy)]
    with tempfile.TemporaryDirectory(prefix="bench_suite_baseline_") as tmp, _ended(busy):
        trees = compared_trees(args.baseline, Path(tmp), "working tree")
        runs = [(CASES[name], tree, label) for _ in range(args.rounds) for name in args.case or DEFAULT_CASES
                for tree, label in trees]
        for case, tree, label in runs:
            try:
                results.append(run_case(case, args.seconds, tree=tree, label=label, subscribers=args.subscribers))
            except BenchStalled as exc:  # its processes are stopped: say so, show what was measured, end
                stalled = exc
                print(f"bench_suite: case {case.name} of {label} stalled: {exc}; the bench stops here.", flush=True)
                break
    cases = "".join(f" --case {name}" for name in args.case or ()) + (f" --busy {args.busy}" if args.busy else "")
    print(f"`python -P bench/bench_suite.py --seconds {args.seconds:g} --rounds {args.rounds}{cases} "
          f"--subscribers {args.subscribers} --baseline {args.baseline}` on "
          f"{time.strftime('%Y-%m-%d')}, {os.cpu_count()} cores; the runs alternate between the trees.")
    print()
    print("\n".join(summary(results)))
    print()
    print("\n".join(report(results)))
    if stalled is not None:
        sys.exit(f"bench_suite: stopped after {len(results)} of {len(runs)} runs: {stalled}")


if __name__ == "__main__":
    main()
