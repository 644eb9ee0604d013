"""Run the node suite on the built-in simulated controller.

  mpi-ros run [--config FILE] [--time-scale X] [--record BAG] [--namespace NS]
              [--discovery RANGE] [--ros-args ...]
  ros2 run mpi_ros suite [the same options]         (on a full ROS install; launch uses it too)

X = 1 runs in real time (the default), larger is faster, 0 as fast as possible.

Namespace (one suite per controller of a cell): --namespace /cell_a, or ros.namespace in
the YAML, or --ros-args -r __ns:=/cell_a (which wins).

Exposure: the suite keeps DDS discovery on this host unless told otherwise, so nothing on
the plant network can command it by accident. Told otherwise by, first to last:
--discovery subnet (or localhost, system_default, off), ROS_AUTOMATIC_DISCOVERY_RANGE in
the environment, ros.discovery in the YAML (default localhost). ROS_STATIC_PEERS adds named
hosts with any range. DDS security (SROS2) is not available in the PyPI wheels. Stop it
with Ctrl-C (SIGINT) or SIGTERM: goals end with their results, the nodes are destroyed and
the controller stops; a second Ctrl-C ends the process at once. Then, from
another shell: `mpi-ros status`, `mpi-ros move ...` (see `mpi-ros --help`); or, instead
of run, `mpi-ros demo` for a narrated, recorded tour.

One suite per namespace: before it creates its nodes, the suite looks for the namespace's
controller node on the graph for up to 1.5 s (mpi_ros/ros/twin.py); if another suite is there
it says where (namespace, domain, the other process where it can) and exits with status 2.
"""

from __future__ import annotations

import argparse
import ctypes
import faulthandler
import gc
import os
import sys

from . import stop_signals


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", help="suite configuration (YAML); default: the installed config/default.yaml")
    parser.add_argument("--time-scale", type=float, default=1.0,
                        help="1 real time, larger is faster, 0 as fast as possible (default 1)")
    parser.add_argument("--record", metavar="BAG", help="record the run to this bag directory (see mpi-ros record)")
    parser.add_argument("--namespace", metavar="NS", help="the suite's namespace (default: ros.namespace, /mpi)")
    parser.add_argument("--discovery", choices=DISCOVERY_RANGES, type=str.lower,
                        help="how far DDS discovery reaches (default: ROS_AUTOMATIC_DISCOVERY_RANGE if set, "
                             "else ros.discovery, localhost)")


DISCOVERY_RANGES = ("localhost", "subnet", "system_default", "off")  # mpi_ros.settings.DISCOVERY_RANGES
RANGE_VARIABLE = "ROS_AUTOMATIC_DISCOVERY_RANGE"


def announce_often(environ) -> str | None:
    """Point Fast DDS at config/fastdds_discovery.xml (the suite announces itself every 0.1 s,
    so a one-shot verb finds it at once) unless a profile file or another middleware was chosen.
    Returns the file set, or None. Before rclpy.init; the goal front's process inherits it."""
    from mpi_ros import dds_profile

    return dds_profile.use(environ, dds_profile.SUITE)


def discovery_range(flag: str | None, config_path: str | None, environ) -> tuple[str, str]:
    """(ROS_AUTOMATIC_DISCOVERY_RANGE value, where it came from): the flag, the environment,
    ros.discovery of the configuration file (default localhost). Raises ConfigError."""
    from mpi_ros import config as suite_config

    if flag:
        return flag.upper(), "--discovery"
    if environ.get(RANGE_VARIABLE):
        return environ[RANGE_VARIABLE], RANGE_VARIABLE
    return suite_config.load(config_path).ros.discovery.upper(), "ros.discovery"


M_MMAP_THRESHOLD = -3  # glibc's mallopt parameter (malloc.h)
MMAP_THRESHOLD = 128 * 1024  # bytes: glibc's default, kept fixed


GC_THRESHOLDS = (20_000, 20, 10)  # the collector's generations (Python's defaults: 700, 10, 10)


def release_large_buffers() -> bool:
    """Have glibc give every buffer of 128 kB or more back to the system when it is freed.

    glibc raises its mmap threshold to the size of the first large block freed (up to 32 MB);
    from then on such blocks come from the heap of the thread that asks, and freed they stay
    there. A refused request of 1,000,000 values (8 MB, serialized and deserialized on the
    middleware's and the executor's threads) then left its buffers in several per-thread heaps:
    the suite's RSS climbed by about 4 MB per such goal (bench/RESULTS.md, "Refused input and
    memory"). A fixed threshold (setting it turns the adjustment off) returns them at once.
    False where the C library is not glibc (nothing to do there)."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc: its allocator has no such threshold to pin
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD))


def report_crashes(stream) -> bool:
    """Have a crash in C code (SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL) write every thread's
    Python stack to ``stream`` (the suite's log) before the process dies: without it such a
    crash in the middleware ends the suite with no word of where. False when the stream has no
    file descriptor to write to from a signal handler (stderr captured in-process, as in tests
    that call ``run`` directly); nothing is changed then."""
    try:
        stream.fileno()
    except (AttributeError, OSError, ValueError):  # io.UnsupportedOperation is both of the latter
        return False
    faulthandler.enable(stream, all_threads=True)
    return True


def run(args) -> int:
    # The name the user started: `mpi-ros run`, `mpi-ros record` or `mpi_ros suite` (ros2 run, launch).
    prog = getattr(args, "_prog", "mpi-ros run")
    if args.time_scale < 0:
        print(f"{prog}: --time-scale must be >= 0", file=sys.stderr)
        return 2
    # Blocked before anything starts a thread (numpy's OpenBLAS when imported, the middleware in
    # rclpy.init), taken by this thread (stop_signals.py).
    with stop_signals.held() as stops:
        return _serve(args, prog, stops)


def _serve(args, prog: str, stops: stop_signals.StopSignals) -> int:
    """Bring the suite up, serve until a stop signal (or an executor fails), take it down."""
    from mpi_ros import config as suite_config

    try:  # before rclpy.init: the middleware reads it when the context starts
        reach, told_by = discovery_range(getattr(args, "discovery", None), args.config, os.environ)
    except suite_config.ConfigError as exc:
        print(f"{prog}: invalid configuration: {exc}", file=sys.stderr)
        return 2
    os.environ[RANGE_VARIABLE] = reach
    profile = announce_often(os.environ)
    report_crashes(sys.stderr)  # from here on C code runs: the middleware's

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from mpi_ros import description
    from mpi_ros.ros import parameters, twin
    from mpi_ros.ros.rcl import UnsupportedRclpy
    from mpi_ros.ros.suite import Suite

    rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])], signal_handler_options=SignalHandlerOptions.NO)
    try:
        cfg, time_scale = parameters.resolve(None, args.config, args.time_scale, getattr(args, "namespace", None))
        robot_description = description.robot_description(cfg)  # the user's URDF checked against the joints
    except suite_config.ConfigError as exc:
        print(f"{prog}: invalid configuration: {exc}", file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    other = twin.find_suite(rclpy.get_default_context(), cfg.ros.namespace)
    if other is not None and other.origin.gone:  # a killed suite's nodes, until its lease ends
        print(f"{prog}: {other.ghost()}", file=sys.stderr)
    elif other is not None:  # one suite per namespace (docs/cell.md)
        print(f"{prog}: {other.refusal()}", file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    try:
        suite = Suite(cfg, time_scale=time_scale, robot_description=robot_description)
    except UnsupportedRclpy as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    parameters.show(suite.controller_node, cfg, time_scale)
    recorder = None
    if getattr(args, "record", None):
        from mpi_ros.bag.recorder import Recorder

        try:
            recorder = Recorder(suite.runner, args.record, cfg)
        except OSError as exc:
            print(f"{prog}: cannot record: {exc}", file=sys.stderr)
            suite.shutdown()
            rclpy.try_shutdown()
            return 2
    log = suite.controller_node.get_logger()
    log.info(f"mpi_ros suite up: {len(cfg.supervisors)} supervisor(s), {cfg.axis_count} axes, "
             f"{cfg.controller.sample_rate:g} Hz, time scale {time_scale:g}, config {cfg.source}, "
             f"namespace {cfg.ros.namespace}, discovery {reach} ({told_by}"
             + (f", static peers {os.environ['ROS_STATIC_PEERS']}" if os.environ.get("ROS_STATIC_PEERS") else "")
             + ")" + (f", DDS profile {profile}" if profile else ""))
    # What start-up built (rclpy, numpy, the suite) lives as long as the process: frozen, a full
    # collection no longer walks it. Unfrozen, such collections took up to 111 ms during a
    # 100,000-point stream (bench/RESULTS.md), a stall the 128-frame buffer (128 ms of 1 ms
    # points) cannot ride out: the clock then caught up in one batch and the path starved.
    gc.freeze()
    # The young generation collected every 20,000 objects allocated and not freed rather than
    # every 700: the suite's garbage is nearly all freed by reference counting, while its
    # long-lived objects (goals kept for result_timeout, requests waiting) made each young
    # collection promote more and each full one walk them all. At 800 modify goals a second
    # the collector held the interpreter 12.6 s in a minute (23 full collections of ~350 ms,
    # each a stall of the clock); so set, 4.1 s (3 full collections). docs/reliability.md, "The
    # goal path".
    gc.set_threshold(*GC_THRESHOLDS)
    release_large_buffers()
    suite.start()
    received = stops.wait(done=lambda: bool(suite.failed()))
    stops.insist()
    if received is not None:
        log.info(f"{received.name}: stopping (once more to end the process at once)")
    else:
        log.error(f"the executor(s) of {', '.join(s.name for s in suite.failed())} stopped on their own: "
                  f"stopping the suite")
    try:
        clean = suite.shutdown()
    finally:
        if recorder is not None:
            recorder.close()
            print(f"recorded to {args.record}", file=sys.stderr)
        rclpy.try_shutdown()
    print("mpi_ros suite stopped", file=sys.stderr)
    return 0 if received is not None and clean else 1
