"""What the faults' checks cost while stepping (docs/faults.md): axis-samples per CPU second.

Three controllers side by side, each case in a fresh process, alternating, best of
``--rounds``: the baseline commit's (``--baseline``, before the faults existed), this tree's
with no fault configured (the default: only the injected faults, nothing checked per sample),
and this tree's with the following error and both software limits checked on every axis (limits
never reached: the cost of watching). Cases are bench_controller.py's 32-axis ones.

    python -P bench/bench_faults.py [--baseline 41a2103] [--rounds 3]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run with -P: the sibling bench_controller
from bench_controller import REPO, baseline_tree

CASES = [(32, 16, "velocity", 20, 20_000), (32, 16, "s-curves", 20, 20_000), (32, 16, "velocity", 4096, 200_000)]
_MEASURE = """
import sys, json
sys.dont_write_bytecode = True
sys.path.insert(0, sys.argv[1]); sys.path.insert(0, sys.argv[2])
import bench_controller as b
case, watched = json.loads(sys.argv[3]), sys.argv[4] == "1"
if watched:
    make = b._controller
    def _controller(axes, supervisors, rate=2000.0):
        from mpi_ros.mpi.base.params import AxisFaultConfig
        ctl = make(axes, supervisors, rate)
        for n in range(axes):
            assert ctl.axis_fault_config_set(n, AxisFaultConfig(
                following_error_limit=1e6, software_limit_positive_enabled=True, software_limit_positive=1e9,
                software_limit_negative_enabled=True, software_limit_negative=-1e9, encoder_fault_motor_number=n)).ok
        return ctl
    b._controller = _controller
print(json.dumps(b.measure(*case)))
"""


def _cpu(source: Path, case: tuple, watched: bool) -> float:
    done = subprocess.run([sys.executable, "-P", "-c", _MEASURE, str(source), str(REPO / "bench"), json.dumps(case),
                           "1" if watched else "0"], check=True, capture_output=True, text=True)
    return json.loads(done.stdout)["cpu"]


def main(baseline: str, rounds: int) -> list[str]:
    rows = [f"| axes | motion | batch | {baseline}: axis-samples per CPU s | no fault configured | "
            "3 checks on every axis |", "| --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as scratch:
        old = baseline_tree(baseline, Path(scratch))
        if old is None:
            raise SystemExit("no git history: the baseline cannot be extracted")
        trees = [(old, False), (REPO, False), (REPO, True)]
        for case in CASES:
            best = [0.0, 0.0, 0.0]
            for _ in range(rounds):  # alternate, so all three see the same load
                for i, (source, watched) in enumerate(trees):
                    best[i] = max(best[i], _cpu(source, case, watched))
            axes, _, motion, batch, _ = case
            rows.append(f"| {axes} | {motion} | {batch} | {best[0]:,.0f} | {best[1]:,.0f} ({best[1] / best[0]:.2f}x) | "
                        f"{best[2]:,.0f} ({best[2] / best[0]:.2f}x) |")
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="41a2103", help="commit to measure side by side (before the faults)")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each case on each tree (best kept)")
    options = parser.parse_args()
    print("\n".join(main(options.baseline, options.rounds)))
