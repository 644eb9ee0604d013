"""Stopping under a signal: `mpi-ros run` sent SIGINT (or SIGTERM) many times, at chosen moments.

Each run starts `mpi-ros run` (this source tree), sends the signal, and waits up to --patience s
for the process to end. A run still alive then is a hang: its threads' Python stacks are dumped
with py-spy when it is installed, and it is killed. The signal's disposition in the child is the
default (as from a terminal or a Python parent) or, with --ignored, ignored (as a shell script's
background job inherits SIGINT: rclpy's handler then had no KeyboardInterrupt to chain to).

    python -P bench/stop_signals.py --runs 300 --when up       (0 to 0.9 s after "suite up")
    python -P bench/stop_signals.py --runs 40 --when start     (0 to 3 s after the process starts)
    python -P bench/stop_signals.py --runs 100 --when up --ignored

Prints one line per outcome: how many runs ended that way (exit status, a traceback in the log
or not, sent before "suite up" or after), and the logs of the runs that did not exit 0 or 130
go to --keep. docs/reliability.md, "Stopping", and bench/RESULTS.md have the figures.
"""

from __future__ import annotations

import argparse
import collections
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
UP = "suite up"


def _disposition(number: int, ignored: bool):
    return lambda: signal.signal(number, signal.SIG_IGN if ignored else signal.SIG_DFL)


def one_run(index: int, args, rng: random.Random, keep: Path) -> tuple:
    env = dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID=str(args.domain + index % 50))
    exe = Path(sys.executable).with_name("mpi-ros")
    number = signal.Signals[args.signal]
    with tempfile.TemporaryFile("w+") as log:
        process = subprocess.Popen([str(exe), "run"], stdout=log, stderr=subprocess.STDOUT, env=env,
                                   preexec_fn=_disposition(number, args.ignored))
        if args.when == "up":
            deadline = time.monotonic() + 30.0
            while time.monotonic() < deadline and process.poll() is None:
                log.seek(0)
                if UP in log.read():
                    break
                time.sleep(0.05)  # polling a log file: nothing to wait on
            time.sleep(rng.uniform(0.0, 0.9))
        else:
            time.sleep(rng.uniform(0.0, 3.0))
        log.seek(0)
        up = UP in log.read()
        process.send_signal(number)
        try:
            code: int | str = process.wait(timeout=args.patience)
        except subprocess.TimeoutExpired:
            code = "hang"
            if shutil.which("py-spy"):
                dump = subprocess.run(["py-spy", "dump", "--pid", str(process.pid)], capture_output=True, text=True)
                (keep / f"hang-{index}.txt").write_text(dump.stdout + dump.stderr)
            process.kill()
            process.wait()
        log.seek(0)
        text = log.read()
    traceback = "Traceback" in text
    if code not in (0, 130) or traceback:
        (keep / f"run-{index}.log").write_text(text)
    return code, traceback, "after up" if up else "before up"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--when", choices=("up", "start"), default="up")
    parser.add_argument("--signal", choices=("SIGINT", "SIGTERM"), default="SIGINT")
    parser.add_argument("--ignored", action="store_true", help="the child inherits the signal ignored")
    parser.add_argument("--patience", type=float, default=20.0, help="s to wait for the process to end")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--domain", type=int, default=100, help="first ROS_DOMAIN_ID (50 are used in turn)")
    parser.add_argument("--keep", type=Path, default=Path("stop-signals-runs"))
    args = parser.parse_args()
    args.keep.mkdir(parents=True, exist_ok=True)
    rng = random.Random(args.seed)
    outcomes: collections.Counter = collections.Counter()
    started = time.monotonic()
    for index in range(args.runs):
        outcomes[one_run(index, args, rng, args.keep)] += 1
    disposition = "inherited ignored" if args.ignored else "default disposition"
    moment = "0-0.9 s after suite up" if args.when == "up" else "in the first 3 s"
    print(f"{args.runs} runs, {args.signal} ({disposition}) {moment}, {time.monotonic() - started:.0f} s")
    for (code, traceback, up), count in sorted(outcomes.items(), key=str):
        print(f"  {count:4d}  exit {code}, {'traceback' if traceback else 'no traceback'}, sent {up}")
    return 0 if all(code in (0, 130) for code, _, _ in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
