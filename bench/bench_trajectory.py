"""A 10,000-point JointTrajectory through ROS, as a user sends it (issue 32, item 3).

Two processes: the suite (``mpi-ros run --time-scale 1 --config config/gantry.yaml``, this
source tree) and this probe, which publishes one trajectory_msgs/JointTrajectory on
/mpi/ms0/joint_trajectory: 10,000 PVT points for x and y, 2 ms apart (20 s; the frame
buffer holds 128 points, so the suite feeds the path chunk by chunk with APPEND,
docs/trajectories.md). It listens to /mpi/events, /mpi/commands and /mpi/ms0/status.

Figures:
- accepted: the first chunk's answer (on /mpi/commands), and the round trip from the publish
  to its arrival here (wall clock: the message to the suite, read, checked, cut in chunks, the
  first applied, recorded and published back);
- streamed: how many chunks (commands) fed the path, every answer, and the events
  FRAMES_LOW, FRAMES_EMPTY and E_STOP (none expected), MOTION_DONE at the end; the end
  position against the last point;
- the suite's CPU (utime + stime of its process, /proc/<pid>/stat) as a share of one core
  while the trajectory runs, beside the same suite idle for as long just before it (side
  by side in one run: the machine is shared).

    python -P bench/bench_trajectory.py [--points 10000] [--dt 0.002]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
WAIT = 30.0


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def trajectory(points: int, dt: float):
    """x from 0 to 0.6 m and y from 0 to 0.3 m and back to rest, along cosines (PVT)."""
    from builtin_interfaces.msg import Duration
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

    msg = JointTrajectory()
    msg.joint_names = ["x", "y"]
    w = math.pi / (points * dt)
    for i in range(points):
        t = (i + 1) * dt
        point = JointTrajectoryPoint()
        point.positions = [0.3 * (1 - math.cos(w * t)), 0.15 * (1 - math.cos(w * t))]
        point.velocities = [0.3 * w * math.sin(w * t), 0.15 * w * math.sin(w * t)]
        seconds = int(t)
        point.time_from_start = Duration(sec=seconds, nanosec=round((t - seconds) * 1e9))
        msg.points.append(point)
    return msg


class Probe:
    def __init__(self, context):
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from trajectory_msgs.msg import JointTrajectory

        from mpi_ros.msg import Command, MotionEvent, MotionStatus

        self.node = Node("bench_trajectory", context=context)
        self.events: Counter = Counter()
        self.commands: list = []
        self.status = None
        self.done = threading.Event()
        reliable = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.node.create_subscription(MotionEvent, "/mpi/events", self._event, reliable)
        self.first_command_ns = 0  # wall clock when the first joint_trajectory command arrived
        self.node.create_subscription(Command, "/mpi/commands", self._command, latched)
        self.node.create_subscription(MotionStatus, "/mpi/ms0/status", self._status, reliable)
        self.publisher = self.node.create_publisher(JointTrajectory, "/mpi/ms0/joint_trajectory",
                                                    QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()

    def _event(self, msg) -> None:
        if msg.supervisor == 0:
            self.events[msg.type] += 1
            if msg.type == "MOTION_DONE":
                self.done.set()

    def _command(self, msg) -> None:
        if msg.operation == "joint_trajectory" and not self.first_command_ns:
            self.first_command_ns = time.time_ns()
        self.commands.append(msg)

    def _status(self, msg) -> None:
        self.status = msg

    def wait_for_suite(self) -> None:
        deadline = time.monotonic() + WAIT
        while self.publisher.get_subscription_count() == 0 or self.status is None:
            if time.monotonic() > deadline:
                raise RuntimeError("the suite's /mpi/ms0/joint_trajectory did not appear")
            threading.Event().wait(0.05)

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=2.0)
        self.node.destroy_node()


def run(points: int, dt: float) -> dict:
    import rclpy

    duration = points * dt
    with tempfile.TemporaryDirectory(prefix="bench_trajectory_") as tmp:
        log = open(Path(tmp) / "suite.log", "w")  # noqa: SIM115 - closed below
        suite = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--time-scale", "1",
                                  "--config", str(REPO / "config" / "gantry.yaml")], cwd=tmp,
                                 stdout=subprocess.DEVNULL, stderr=log, env={**os.environ, "PYTHONPATH": str(REPO)})
        context = rclpy.Context()
        rclpy.init(context=context)
        probe = Probe(context)
        try:
            probe.wait_for_suite()
            msg = trajectory(points, dt)
            cpu0, wall0 = cpu_seconds(suite.pid), time.monotonic()
            threading.Event().wait(duration)  # idle, as long as the trajectory will run
            idle = (cpu_seconds(suite.pid) - cpu0) / (time.monotonic() - wall0)
            cpu0, wall0 = cpu_seconds(suite.pid), time.monotonic()
            sent_ns = time.time_ns()
            probe.publisher.publish(msg)
            finished = probe.done.wait(duration + WAIT)
            moving = (cpu_seconds(suite.pid) - cpu0) / (time.monotonic() - wall0)
            threading.Event().wait(0.5)  # the last commands and events
        finally:
            probe.close()
            context.try_shutdown()
            suite.send_signal(signal.SIGINT)
            suite.wait(timeout=WAIT)
            log.close()
    chunks = [c for c in probe.commands if c.operation == "joint_trajectory"]
    first = chunks[0] if chunks else None
    end = [a.command_position / 1e6 for a in probe.status.axes] if probe.status is not None else []
    last = list(msg.points[-1].positions)
    return {
        "finished": finished, "chunks": len(chunks), "answers": Counter(c.message for c in chunks),
        "first_answer": first.message if first else "none",
        "start_delay_ms": (probe.first_command_ns - sent_ns) / 1e6 if first else math.nan,
        "events": dict(probe.events), "end": end, "last_point": last,
        "end_error_m": max(abs(a - b) for a, b in zip(end, last, strict=True)) if end else math.nan,
        "cpu_idle": idle, "cpu_moving": moving, "duration": duration,
        "chunk_points": max((len(json.loads(c.request).get("time_from_start", [])) for c in chunks), default=0),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=10_000)
    parser.add_argument("--dt", type=float, default=0.002)
    args = parser.parse_args()
    r = run(args.points, args.dt)
    events = r["events"]
    print(f"`python -P bench/bench_trajectory.py --points {args.points} --dt {args.dt}` "
          f"({os.cpu_count()} cores, load {' '.join(Path('/proc/loadavg').read_text().split()[:3])})")
    print()
    print("| figure | value |")
    print("| --- | --- |")
    print(f"| trajectory | {args.points:,} PVT points for x, y, {args.dt * 1e3:g} ms apart ({r['duration']:g} s) |")
    print(f"| first chunk's answer | {r['first_answer']} |")
    print(f"| publish -> first chunk applied and back on /mpi/commands | {r['start_delay_ms']:.0f} ms |")
    print(f"| chunks fed (joint_trajectory commands, up to {r['chunk_points']} points) | {r['chunks']} "
          f"({dict(r['answers'])}) |")
    print(f"| FRAMES_LOW / FRAMES_EMPTY / E_STOP events | {events.get('FRAMES_LOW', 0)} / "
          f"{events.get('FRAMES_EMPTY', 0)} / {events.get('E_STOP', 0)} |")
    print(f"| MOTION_DONE | {'yes' if r['finished'] else 'NO'} ({events.get('MOTION_DONE', 0)}) |")
    print(f"| end position vs the last point | {r['end_error_m']:.2e} m |")
    print(f"| suite CPU, idle (same suite, just before) | {100 * r['cpu_idle']:.1f} % of one core |")
    print(f"| suite CPU, streaming the trajectory | {100 * r['cpu_moving']:.1f} % of one core |")
    print(f"| ratio moving / idle | {r['cpu_moving'] / r['cpu_idle']:.2f} |" if r["cpu_idle"] > 0 else "")
    ok = (r["finished"] and r["first_answer"] == "MPIMessageOK" and not events.get("FRAMES_EMPTY")
          and not events.get("E_STOP") and r["end_error_m"] < 1e-6)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
