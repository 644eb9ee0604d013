"""Run the node suite on the built-in simulated controller.

  mpi-ros run [--config FILE] [--time-scale X] [--record BAG] [--ros-args ...]
  ros2 run mpi_ros suite [the same options]         (on a full ROS install; launch uses it too)

X = 1 runs in real time (the default), larger is faster, 0 as fast as possible. Stop it
with Ctrl-C: goals end, the nodes are destroyed and the controller stops. Then, from
another shell: `mpi-ros status`, `mpi-ros move ...` (see `mpi-ros --help`); or, instead
of run, `mpi-ros demo` for a narrated, recorded tour.
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", help="suite configuration (YAML); default: the installed config/default.yaml")
    parser.add_argument("--time-scale", type=float, default=1.0,
                        help="1 real time, larger is faster, 0 as fast as possible (default 1)")
    parser.add_argument("--record", metavar="BAG", help="record the run to this bag directory (see mpi-ros record)")


def run(args) -> int:
    from mpi_ros import config as suite_config

    # The name the user started: `mpi-ros run`, `mpi-ros record` or `mpi_ros suite` (ros2 run, launch).
    prog = getattr(args, "_prog", "mpi-ros run")
    if args.time_scale < 0:
        print(f"{prog}: --time-scale must be >= 0", file=sys.stderr)
        return 2

    import rclpy

    from mpi_ros.ros import parameters
    from mpi_ros.ros.suite import Suite

    # rclpy's own SIGINT/SIGTERM handling shuts the context down and wakes the executor.
    rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])])
    try:
        cfg, time_scale = parameters.resolve(None, args.config, args.time_scale)
    except suite_config.ConfigError as exc:
        print(f"{prog}: invalid configuration: {exc}", file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    suite = Suite(cfg, time_scale=time_scale)
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
             f"{cfg.controller.sample_rate:g} Hz, time scale {time_scale:g}, config {cfg.source}")
    suite.start(spin_in_thread=False)
    try:
        suite.spin()
    except KeyboardInterrupt:
        pass
    finally:
        suite.shutdown()
        if recorder is not None:
            recorder.close()
            print(f"recorded to {args.record}", file=sys.stderr)
        rclpy.try_shutdown()
    print("mpi_ros suite stopped", file=sys.stderr)
    return 0
