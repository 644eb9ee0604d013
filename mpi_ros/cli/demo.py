"""Bring the suite up, take a narrated tour of it, record it, and leave the bag and plots.

  mpi-ros demo                              real time (about 20 s), into ./mpi-ros-demo-<date-time>/
  mpi-ros demo --output tour --time-scale 4

The tour, on supervisor 0 (axes 0 and 1): an S-curve move; a jog modified in flight
into a move to a target; STOP and RESUME; E_STOP, a move refused in ERROR, and RESET; a
path move (PVT) through three points; back home. Each step prints the `mpi-ros` command that does the same against a
running suite, then the controller's answer. While it runs, `mpi-ros status` in another
shell shows the axes move.

The demo starts the suite as `mpi-ros run --record BAG` would (a process of its own, its
log in suite.log) and drives it over ROS like any client; it will not start beside a
suite already running under the namespace (--namespace /demo runs it beside one). At the
end it stops the suite and prints where it left the bag (replay it with `mpi-ros replay
BAG`) and the PNG plots: the whole recording (`mpi-ros plot BAG`) and the first move's
profile against ruckig's (`mpi-ros plot --type S_CURVE ...`).

Exit status: 0 the whole tour ran; 1 the controller refused a step of it; 2 usage,
start-up or connection problem (e.g. a suite already runs under the namespace).
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO, TypedDict

from .console import DEFAULT_NAMESPACE, OK, REFUSED, USAGE, UsageError, fail, positions

# s to let an already running suite show itself on the graph: DDS discovery between processes
# on one host takes up to about 3 s here (a missed first announcement waits for the next).
EXISTING_SUITE_WAIT = 4.0
STARTUP_WAIT = 30.0  # s for the suite's process to come up on the graph
STOP_WAIT = 30.0  # s for the suite's process to stop and write the bag
WAIT = 60.0  # s of wall time any one step may take (at time scale 1 the longest takes ~3 s)


class _Move(TypedDict):
    """A point-to-point move's values (a plain dict at run time)."""

    position: list[float]
    velocity: float
    acceleration: float
    jerk_percent: float


# The first move: its profile is also plotted against ruckig's.
S_CURVE: _Move = {"position": [4000.0, 2000.0], "velocity": 2000.0, "acceleration": 10000.0, "jerk_percent": 50.0}
# A PVT path (it starts where the axes are): three points, positions interleaved by axis, one time per point.
PATH = {"type": "PVT", "position": [1000.0, 1000.0, 2500.0, 500.0, 3000.0, 0.0],
        "point_velocity": [1200.0, 600.0, 1000.0, -800.0, 0.0, 0.0], "time": [1.0, 1.0, 1.0]}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--output", "-o", metavar="DIR",
                        help="directory for the bag, plots and suite log (default ./mpi-ros-demo-<date-time>; "
                             "must not exist or be empty)")
    parser.add_argument("--time-scale", type=float, default=1.0, metavar="X",
                        help="1 real time (default), larger faster; the tour needs X > 0")
    parser.add_argument("--config", help="suite configuration (YAML); default: config/default.yaml")
    parser.add_argument("--namespace", default=DEFAULT_NAMESPACE, metavar="NS",
                        help="the suite's namespace (default /mpi; another one if a suite already runs there)")


def _output(args: argparse.Namespace) -> Path:
    out = Path(args.output or f"mpi-ros-demo-{time.strftime('%Y%m%d-%H%M%S')}")
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise UsageError(f"{out} exists and is not an empty directory: pass --output DIR")
    return out


def _terminate(_signum, _frame) -> None:
    raise KeyboardInterrupt  # SIGTERM stops the demo as Ctrl-C does: the suite stopped, the bag finished


def run(args: argparse.Namespace) -> int:
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        return _run(args)
    finally:
        signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace) -> int:
    from mpi_ros import config as suite_config

    if not args.time_scale > 0:
        return fail(args, "--time-scale must be > 0: the tour follows its moves as they run")
    namespace = "/" + args.namespace.strip("/")
    try:
        out = _output(args)
        base = suite_config.load(args.config)
        cfg = suite_config.load(args.config, {"ros": {"namespace": namespace}})
    except (UsageError, suite_config.ConfigError) as exc:
        return fail(args, str(exc))
    if not any(spec.number == 0 and spec.axes for spec in cfg.supervisors):
        return fail(args, f"{cfg.source}: the tour needs supervisor 0 with axes")
    status = _run_suite(args, cfg, out, namespace != base.ros.namespace)
    if status != OK:
        return status
    return _plots(args, out)


# -- the suite, in a process of its own ---------------------------------------------------------------
class SuiteProcess:
    """``mpi-ros run --record BAG`` as a child process; ``stop()`` ends it as Ctrl-C does."""

    def __init__(self, args: argparse.Namespace, cfg, out: Path, write_config: bool):
        import mpi_ros

        command = [sys.executable, "-m", "mpi_ros.cli", "run", "--time-scale", repr(args.time_scale),
                   "--record", str(out / "bag")]
        if write_config:  # another namespace than the file's: the child reads the merged file
            import yaml

            config = out / "suite.yaml"
            config.write_text(yaml.safe_dump(cfg.raw, sort_keys=False), encoding="utf-8")
            command += ["--config", str(config)]
        elif args.config:
            command += ["--config", str(Path(args.config).resolve())]
        command += getattr(args, "ros_args", [])
        # The child runs the same mpi_ros as this process (the source tree too).
        env = dict(os.environ)
        package_root = str(Path(mpi_ros.__file__).resolve().parents[1])
        env["PYTHONPATH"] = os.pathsep.join(p for p in (package_root, env.get("PYTHONPATH", "")) if p)
        self.log_path = out / "suite.log"
        self._log = open(self.log_path, "w", encoding="utf-8")  # noqa: SIM115 - closed in stop()
        # A session of its own: Ctrl-C in the terminal reaches the demo, which stops the suite
        # itself, in order (the recording is finished when the process ends).
        self.process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=self._log,
                                        stderr=subprocess.STDOUT, env=env, start_new_session=True,
                                        preexec_fn=_child_setup())

    def running(self) -> bool:
        return self.process.poll() is None

    def log_tail(self, lines: int = 15) -> str:
        self._log.flush()
        text = self.log_path.read_text(encoding="utf-8", errors="replace").splitlines()
        return "\n".join(text[-lines:])

    def stop(self) -> int | None:
        """SIGINT (the suite's clean shutdown, which finishes the bag); its exit status."""
        try:
            if self.running():
                self.process.send_signal(signal.SIGINT)
                try:
                    self.process.wait(STOP_WAIT)
                except subprocess.TimeoutExpired:
                    self.process.kill()
                    self.process.wait(STOP_WAIT)
            return self.process.returncode
        finally:
            self._log.close()


def _child_setup() -> Callable[[], None]:
    """What the suite's process does before it starts: take SIGINT (the demo stops it with
    one, and a demo started in the background passes SIGINT on ignored), and on Linux end
    when the demo does, however the demo ends."""
    try:
        import ctypes

        prctl = ctypes.CDLL(None, use_errno=True).prctl  # loaded here: nothing is imported after the fork
    except (OSError, AttributeError):
        prctl = None

    def setup() -> None:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        if prctl is not None:
            prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG: SIGTERM (a clean stop for the suite) when the demo ends

    return setup


def _wait_up(client: Any, suite: SuiteProcess) -> None:
    """Until supervisor 0 answers; UsageError (with the suite's log) if the process ends first."""
    from mpi_ros.errors import NoResponse

    deadline = time.monotonic() + STARTUP_WAIT
    pause = threading.Event()  # never set: an interruptible wait between looks
    while time.monotonic() < deadline:
        if not suite.running():
            raise UsageError(f"the suite did not start (exit status {suite.process.returncode}); "
                             f"its log, {suite.log_path}:\n{suite.log_tail()}")
        try:
            client.wait_for_suite(0.5, 0)
        except NoResponse:
            pause.wait(0.05)
            continue
        if client.wait_for_server(STARTUP_WAIT):
            return
    raise UsageError(f"the suite did not come up within {STARTUP_WAIT:g} s; its log, {suite.log_path}:\n"
                     f"{suite.log_tail()}")


def _run_suite(args: argparse.Namespace, cfg, out: Path, write_config: bool) -> int:
    """The suite, recorded, with the tour driven through the client; the exit status."""
    import rclpy

    from mpi_ros.client import MotionClient, Watcher
    from mpi_ros.errors import MpiError, NoResponse, NoSuchSupervisor, SuiteNotFound

    namespace = cfg.ros.namespace
    context = rclpy.Context()
    try:
        rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])], context=context)
    except RuntimeError as exc:
        return fail(args, f"invalid ROS arguments: {str(exc).split(', at ')[0]}")
    suite: SuiteProcess | None = None
    status = OK
    try:
        with Watcher(namespace, context=context, node_name="mpi_ros_demo_check") as watcher:
            try:
                found = watcher.wait_for_suite(EXISTING_SUITE_WAIT)
            except SuiteNotFound:
                found = []  # the namespace is free: what we want
        if found:
            return fail(args, f"a suite already runs under {namespace} on ROS_DOMAIN_ID "
                              f"{context.get_domain_id()} (ms{', ms'.join(map(str, found))}): stop it, or run the "
                              f"demo under another namespace (--namespace /demo)")
        out.mkdir(parents=True, exist_ok=True)
        suite = SuiteProcess(args, cfg, out, write_config)
        with MotionClient(0, namespace, context=context, timeout=WAIT, node_name="mpi_ros_demo") as client:
            _wait_up(client, suite)
            print(f"suite up under {namespace} on ROS_DOMAIN_ID {context.get_domain_id()} "
                  f"(process {suite.process.pid}, log {suite.log_path}), time scale {args.time_scale:g}, "
                  f"recording to {out / 'bag'}", flush=True)
            tour(Tour(client, sys.stdout, sys.stdout.isatty(), cfg.controller.sample_rate))
    except MpiError as exc:
        print(f"the tour was refused: {exc}", file=sys.stderr)
        status = REFUSED
    except (NoResponse, NoSuchSupervisor, UsageError) as exc:
        status = fail(args, str(exc))
    except KeyboardInterrupt:
        print("interrupted: stopping the suite", file=sys.stderr)
        status = 130
    finally:
        if suite is not None:
            code = suite.stop()
            if code != 0 and status == OK:
                status = fail(args, f"the suite ended with exit status {code}; its log, {suite.log_path}:\n"
                                    f"{suite.log_tail()}")
        context.try_shutdown()
    return status


def _plots(args: argparse.Namespace, out: Path) -> int:
    from mpi_ros.crosscheck.request import ProfileRequest
    from mpi_ros.plot.bag import plot_bag
    from mpi_ros.plot.profile import plot_profile

    bag = out / "bag"
    # The first move is a vector move: its S-curve runs along the path, math.hypot(*position) long.
    request = ProfileRequest.from_mapping({"type": "S_CURVE", "distance": math.hypot(*S_CURVE["position"]),
                                           "velocity": S_CURVE["velocity"], "acceleration": S_CURVE["acceleration"],
                                           "jerk_percent": S_CURVE["jerk_percent"]})
    try:
        tour_png = plot_bag(bag, out / "tour.png")
        profile_png, _check = plot_profile(request, out / "s_curve_vs_ruckig.png")
    except (OSError, ValueError) as exc:
        return fail(args, f"plotting failed: {exc}", USAGE)
    print(f"\nbag:   {bag}   (replay it: mpi-ros replay {bag})")
    print(f"plots: {tour_png}   (the whole recording, as mpi-ros plot {bag})")
    print(f"       {profile_png}   (move 1 along its path, against ruckig's profile)")
    return OK


# -- the tour -----------------------------------------------------------------------------------------
@dataclass
class Tour:
    client: Any  # MotionClient of ms0
    out: TextIO
    tty: bool
    sample_rate: float = 2000.0  # Hz: the controller's
    number: int = 0

    def step(self, title: str, command: str) -> None:
        self.number += 1
        print(f"\n{self.number}. {title}\n   $ {command}", file=self.out, flush=True)

    def say(self, text: str) -> None:
        print(f"   {text}", file=self.out, flush=True)

    def follow(self, goal: Any, expect_ok: bool = True) -> Any:
        """The goal to its end (a progress bar on a terminal), its result narrated.

        With ``expect_ok``, any other message than MPIMessageOK ends the tour (raised).
        """
        from mpi_ros.errors import raise_for

        from .goals import ProgressView, follow

        result = follow(goal, ProgressView(self.out, self.tty, plain=False))
        detail = f": {result.detail}" if result.detail else ""
        self.say(f"{result.message} (code {result.code}) {result.outcome}{detail}, state {result.state_name}, "
                 f"at {positions(result.actual_position)}")
        if expect_ok:
            raise_for(result.message, result.detail, result)
        return result

    def until(self, predicate: Callable[[Any], bool], what: str) -> Any:
        return self.client.wait_for(predicate, WAIT, what)

    def action(self, name: str) -> Any:
        """An mpiMotionAction, narrated; a refusal ends the tour (raised)."""
        from mpi_ros.errors import raise_for

        reply = self.client.action(name, raise_on_error=False)
        self.say(f"{name}: {reply.message} (code {reply.code}), state {reply.state_name}")
        raise_for(reply.message, f"{name} in {reply.state_name}", reply)
        return reply


def _goal(position: list[float], velocity: float, acceleration: float, jerk_percent: float = 50.0,
          motion_type: str = "S_CURVE") -> dict[str, Any]:
    return {"type": motion_type, "position": position,
            "trajectory": [{"velocity": velocity, "acceleration": acceleration, "deceleration": acceleration,
                            "jerk_percent": jerk_percent}]}


def tour(t: Tour) -> None:
    """Every step in order."""
    s_curve_move(t)
    modify_in_flight(t)
    stop_resume_e_stop_reset(t)
    path_move(t)
    home(t)


def s_curve_move(t: Tour) -> None:
    p, v, a, j = S_CURVE["position"], S_CURVE["velocity"], S_CURVE["acceleration"], S_CURVE["jerk_percent"]
    t.step("An S-curve move of ms0's two axes (0 and 1) with 50 % jerk: the axes arrive together",
           f"mpi-ros move --type S_CURVE --position {p[0]:g} {p[1]:g} --velocity {v:g} --acceleration {a:g} "
           f"--deceleration {a:g} "
           f"--jerk-percent {j:g}")
    t.follow(t.client.start(_goal(p, v, a, j)))


# The in-flight steps act on jogs (VELOCITY moves), which run until something ends them:
# what the tour narrates happens however slow the machine is or fast the time scale.
JOG = {"acceleration": 5000.0, "deceleration": 5000.0}


def _jog(velocity: float) -> dict[str, Any]:
    return {"type": "VELOCITY", "trajectory": [{"velocity": velocity, **JOG}]}


def modify_in_flight(t: Tour) -> None:
    t.step("A jog, modified in flight into an S-curve move to a target",
           "mpi-ros move --type VELOCITY -v -1000 -a 5000      # returns once at velocity\n"
           "   $ mpi-ros modify --type S_CURVE --position 1000 -1000 -v 2000 -a 10000 -d 10000 -j 50")
    t.follow(t.client.start(_jog(-1000.0)))
    t.follow(t.client.modify(_goal([1000.0, -1000.0], 2000.0, 10000.0)))


def stop_resume_e_stop_reset(t: Tour) -> None:
    t.step("STOP a jog: it decelerates over decelTime.stop to STOPPED, the rest of the move kept",
           "mpi-ros move --type VELOCITY -v 1500 -a 5000; mpi-ros stop")
    t.follow(t.client.start(_jog(1500.0)))
    reply = t.action("STOP")
    status = t.client.wait_for_state("STOPPED", WAIT, newer_than=reply.sample)
    t.say(f"STOPPED at {positions(a.command_position for a in status.axes)}")

    t.step("RESUME: the same move picks up where it stopped", "mpi-ros resume")
    reply = t.action("RESUME")
    ramp = int(0.5 * t.sample_rate)  # half a second of controller time: back at full speed
    status = t.until(lambda s: s.state_name == "MOVING" and s.sample > reply.sample + ramp, "moving again")
    t.say(f"MOVING again, at {positions(a.command_position for a in status.axes)}, "
          f"{positions(a.command_velocity for a in status.axes)} counts/s")

    t.step("E_STOP at full speed: a fast stop (decelTime.eStop), then ERROR", "mpi-ros e-stop")
    reply = t.action("E_STOP")
    status = t.client.wait_for_state("ERROR", WAIT, newer_than=reply.sample)
    t.say(f"ERROR at {positions(a.actual_position for a in status.axes)}: every move is refused until a RESET")

    t.step("A move in ERROR is refused, with the spec's message", "mpi-ros move --position 0 0 -v 1000 -a 5000 -d 5000")
    refused = t.client.start(_goal([0.0, 0.0], 1000.0, 5000.0)).wait(WAIT, raise_on_error=False)
    t.say(f"{refused.message} (code {refused.code}) {refused.outcome}: {refused.detail}")

    t.step("RESET leaves ERROR", "mpi-ros reset")
    t.action("RESET")


def path_move(t: Tour) -> None:
    t.step("A path: PVT through three points (position, velocity and time of each)",
           "mpi-ros move --goal \"{type: PVT, position: [1000, 1000, 2500, 500, 3000, 0], "
           "point_velocity: [1200, 600, 1000, -800, 0, 0], time: [1, 1, 1]}\"")
    result = t.client.start(PATH).wait(WAIT, raise_on_error=False)
    t.say(f"{result.message} (code {result.code}) {result.outcome}, state {result.state_name}, "
          f"at {positions(result.actual_position)}")
    from mpi_ros.errors import raise_for

    raise_for(result.message, result.detail, result)


def home(t: Tour) -> None:
    t.step("Back home", "mpi-ros move --position 0 0 -v 4000 -a 20000 -d 20000 -j 50")
    t.follow(t.client.start(_goal([0.0, 0.0], 4000.0, 20000.0)))
