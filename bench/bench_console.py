"""E_STOP from the console's key to its effect (issue 36 asks a median of at most 20 ms).

A suite of this tree (bench_verbs.start_suite, real time), `mpi-ros console` run headless by
Textual's pilot in this process; per run: the time just before ``pilot.press("e")``, then the
E_STOP's command on /mpi/commands: "effect" is the stamp of the sample it took effect at minus
that time (controller time, which lags the wall clock when the suite falls behind: a lower
bound), "received" when the message reached this process (an upper bound). RESET between runs.

    python -P bench/bench_console.py [--runs 20]
"""

from __future__ import annotations

import argparse
import asyncio
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run with -P: the sibling bench_verbs
from bench_verbs import REPO, Commands, start_suite


async def measure(runs: int) -> list[tuple[float, float]]:
    from mpi_ros.cli.tui import Link, make_app

    args = argparse.Namespace(namespace="/mpi", supervisor=None, timeout=30.0, jog_speed=1000.0,
                              jog_acceleration=10000.0, ros_args=[])
    link = Link(args)
    commands = Commands()
    found: list[tuple[float, float]] = []
    try:
        async with make_app(link, args).run_test(size=(120, 40)) as pilot:
            ms0 = link.clients[0]
            for _ in range(runs):
                after = len(commands.seen)
                start = time.time()
                await pilot.press("e")
                hit = await asyncio.to_thread(commands.wait_for, after, "action", "E_STOP")
                if hit is None:
                    raise RuntimeError("no E_STOP on /mpi/commands")
                found.append((hit[1] - start, hit[0] - start))
                await asyncio.to_thread(ms0.wait_for_state, "ERROR", 30.0)
                reply = await asyncio.to_thread(ms0.reset)
                await asyncio.to_thread(ms0.wait_for_state, "IDLE", 30.0, reply.sample)
    finally:
        commands.close()
        link.close()
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=20)
    args = parser.parse_args()
    import os

    suite = start_suite(REPO)
    try:
        load = os.getloadavg()[0]
        found = asyncio.run(measure(args.runs))
    finally:
        suite.terminate()
        suite.wait(timeout=30)
    effect = [e * 1e3 for e, _ in found]
    received = [r * 1e3 for _, r in found]
    print(f"{len(found)} E_STOPs, 1-minute load average {load:.1f} at the start")
    print()
    print("| | median | max |")
    print("| --- | --- | --- |")
    print(f"| key to effect (stamp of the sample) | {statistics.median(effect):.1f} ms | {max(effect):.1f} ms |")
    print(f"| key to /mpi/commands received | {statistics.median(received):.1f} ms | {max(received):.1f} ms |")


if __name__ == "__main__":
    main()
