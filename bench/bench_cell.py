"""A cell across a link versus on one host: discovery time, goal round trip, E_STOP round trip
and the status rate each suite holds (docs/cell.md; figures in bench/RESULTS.md).

    sudo -E .venv/bin/python bench/bench_cell.py [--count N]

Builds the test's plant (test/ros/netns.py: hosts a, b, c as network namespaces linked to a
switch, subnet discovery), runs `mpi-ros run` in real time on a (/cell_a) and b (/cell_b), and
the measuring client (test/ros/cell_driver.py bench) once on a itself (one host) and once on
c (across the link), then on c for /cell_b. Needs root (network namespaces). Prints a
markdown table; the ratios are across / one host, measured in the same run.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import os
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DRIVER = REPO / "test" / "ros" / "cell_driver.py"
WAIT = 60.0


def _netns():
    spec = importlib.util.spec_from_file_location("cell_netns", REPO / "test" / "ros" / "netns.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=50, help="goals and E_STOPs per measurement (default 50)")
    args = parser.parse_args(argv)
    netns = _netns()
    refused = netns.refused()
    if refused:
        print(f"bench_cell: {refused}", file=sys.stderr)
        return 2
    env = dict(os.environ, ROS_DOMAIN_ID=str(150 + os.getpid() % 50), ROS_AUTOMATIC_DISCOVERY_RANGE="SUBNET",
               PYTHONPATH=os.pathsep.join(filter(None, (str(REPO), os.environ.get("PYTHONPATH")))))
    runs = {}
    with tempfile.TemporaryDirectory() as tmp, netns.Plant(["a", "b", "c"]) as plant:
        logs = Path(tmp)
        suites = [plant.popen(host, [sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--namespace", ns,
                                     "--discovery", "subnet"], env, logs / f"{host}.log")
                  for host, ns in (("a", "/cell_a"), ("b", "/cell_b"))]
        for suite in suites:  # discovery is timed against running suites
            suite.wait_in_log("mpi_ros suite up", WAIT)
        for label, host, ns in (("one host", "a", "/cell_a"), ("across the link", "c", "/cell_a"),
                                ("across the link", "c", "/cell_b")):
            driver = plant.popen(host, [sys.executable, "-P", str(DRIVER), "bench", ns, str(args.count)], env,
                                 logs / f"driver_{host}_{ns[1:]}.log")
            runs[(label, ns)] = json.loads(driver.expect(lambda line: line.startswith('{"bench"'), WAIT))["bench"]
    print(table(runs, args.count))
    return 0


def table(runs: dict, count: int) -> str:
    local, remote, other = runs[("one host", "/cell_a")], runs[("across the link", "/cell_a")], runs[
        ("across the link", "/cell_b")]
    rows = [("discovery (a new client to its supervisor's servers found), median of 6, s", "discovery_s"),
            ("discovery, max of 6, s", "discovery_s_max"),
            ("goal round trip (sent, applied, accepted), median ms", "goal_ms_median"),
            ("goal round trip, max ms", "goal_ms_max"),
            ("E_STOP round trip (applied at the next sample, answered), median ms", "e_stop_ms_median"),
            ("E_STOP round trip, max ms", "e_stop_ms_max"),
            ("ms0 status received over 5 s, Hz (configured 100)", "status_hz"),
            ("ms0 statuses received in the whole run", "statuses"),
            ("ms0 statuses missed (gaps in their samples)", "statuses_missed")]
    lines = [f"{datetime.date.today()}, `sudo -E .venv/bin/python bench/bench_cell.py --count {count}` "
             "(hosts = network namespaces on one 2-core machine, veth links through a bridge):", "",
             "| figure | /cell_a, client on its host | /cell_a, client across the link | ratio | "
             "/cell_b, across the link |", "| --- | --- | --- | --- | --- |"]
    for label, key in rows:
        ratio = remote[key] / local[key] if local[key] else float("nan")
        lines.append(f"| {label} | {local[key]:g} | {remote[key]:g} | {ratio:.2f} | {other[key]:g} |")
    steps = sorted(set(local["status_steps"]) | set(remote["status_steps"]) | set(other["status_steps"]))
    lines += ["", f"Status sample steps seen (samples between consecutive ms0 statuses; 20 = none missed at "
              f"2000 Hz / 100 Hz): {steps}."]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
