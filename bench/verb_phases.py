"""Where the time of a one-shot action verb goes, phase by phase (issue 36: at most 1 s from
invocation to effect). Runs what `mpi-ros ACTION` runs (Session, ActionCall, one call) with a
timestamp after each phase, measured from this interpreter's start of user code (so after the
ros_wheels_bootstrapper's re-exec of the interpreter, which a real verb pays as well).

  python -P bench/verb_phases.py --runs 4 RESET     # against a running suite (same ROS_DOMAIN_ID)

Each run is a new process, as a verb is. Prints one line of cumulative milliseconds per run.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

START = time.perf_counter()


def one(action: str, timeout: float) -> str:
    """One verb's phases in this process: 'phase=ms ...' (cumulative)."""
    marks: list[tuple[str, float]] = []

    def mark(what: str) -> None:
        marks.append((what, (time.perf_counter() - START) * 1000.0))

    from mpi_ros.cli.console import Session

    mark("cli")
    import rclpy  # noqa: F401 - timed on its own: the biggest import

    mark("rclpy")
    from mpi_ros.action_call import ActionCall

    mark("messages")
    args = argparse.Namespace(namespace="/mpi", supervisor=0, timeout=timeout, ros_args=[])
    with Session(args) as session:
        mark("init")
        call = session._keep(ActionCall(0, "/mpi", context=session.context, node_name=session.node_name))
        mark("node")
        call.wait_ready(timeout)
        mark("discovered")
        call.call(action, timeout, raise_on_error=False)
        mark("answered")
    mark("closed")
    return " ".join(f"{what}={ms:.0f}" for what, ms in marks)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("action", nargs="?", default="RESET")
    parser.add_argument("--runs", type=int, default=4)
    parser.add_argument("--timeout", type=float, default=10.0)
    parser.add_argument("--one", action="store_true", help=argparse.SUPPRESS)  # a child process: one run
    args = parser.parse_args()
    if args.one:
        print(one(args.action, args.timeout))
        return 0
    for _ in range(args.runs):
        done = subprocess.run([sys.executable, "-P", __file__, "--one", args.action, "--timeout", str(args.timeout)],
                              check=True, capture_output=True, text=True)
        print(done.stdout.strip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
