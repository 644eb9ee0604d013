"""Modify from motion on the running controller: start a random move, let it run a random
number of samples (often mid-ramp, so the axes carry an acceleration), modify it with a
random request, and check every plan of both moves with the run-time monitor.

docs/profiles.md, "Modify: from the current state": a modify of S_CURVE/TRAPEZOIDAL/VELOCITY restarts from the current
position and velocity with zero acceleration; the plans record that start state
(start_velocity, start_acceleration), and vector moves record each axis' share of the
limits (planner.py). Seeded numpy generator: reproducible."""

from __future__ import annotations

from collections import Counter

import numpy as np

from mpi_ros import config as suite_config
from mpi_ros.commands import Command
from mpi_ros.crosscheck import Reason, Verdict
from mpi_ros.crosscheck.monitor import CrosscheckMonitor
from mpi_ros.runner import ControllerRunner

CASES = 300


class Recording(CrosscheckMonitor):
    """The monitor, keeping every result."""

    def __init__(self, ctl):
        super().__init__(ctl)
        self.results = []

    def check_move(self, supervisor, move, sample):
        out = super().check_move(supervisor, move, sample)
        self.results.extend(out)
        return out


def _goal(rng, kind: str, axes: int) -> dict:
    velocity = float(10 ** rng.uniform(2, 4))
    acceleration = float(10 ** rng.uniform(3, 5))
    deceleration = acceleration if rng.random() < 0.5 else float(10 ** rng.uniform(3, 5))
    jerk = 0.0 if kind == "TRAPEZOIDAL" else float(rng.choice([0.0, 100.0, rng.uniform(0, 100)]))
    if kind == "VELOCITY":
        velocity *= float(rng.choice([-1.0, 1.0]))
    goal = {"type": kind, "trajectory": [{"velocity": velocity, "acceleration": acceleration,
                                          "deceleration": deceleration, "jerk_percent": jerk}]}
    if kind != "VELOCITY":
        goal["position"] = [float(rng.uniform(-5000, 5000)) for _ in range(axes)]
        if axes == 2 and rng.random() < 0.3:  # along the current line, or not
            goal["position"][1] = goal["position"][0]
    return goal


def test_modifies_from_motion_agree_or_differ_for_a_stated_reason():
    rng = np.random.default_rng(11)
    base = suite_config.load()
    verdicts, reasons, bad, refused, modifies = Counter(), Counter(), [], 0, 0
    for _ in range(CASES):
        ctl = base.build_controller()
        axes = int(rng.choice([1, 2]))
        ms = ctl.supervisor(0)
        ms.axis_list_set([0, 1][:axes])
        runner = ControllerRunner(ctl, time_scale=None)
        monitor = Recording(ctl)
        results = monitor.results
        runner.on_command(monitor)
        kinds = ["S_CURVE", "TRAPEZOIDAL", "VELOCITY"]
        first = str(rng.choice(kinds))
        reply, _ = runner.submit(Command("motion_start", 0, request=_goal(rng, first, axes)))
        assert reply.accepted, reply
        runner.step(int(rng.integers(1, 400)))
        second = first if first == "VELOCITY" else str(rng.choice(["S_CURVE", "TRAPEZOIDAL"]))
        reply, _ = runner.submit(Command("motion_modify", 0, request=_goal(rng, second, axes)))
        if not reply.accepted:
            refused += 1
            print("refused:", reply.message.name, reply.detail)
            continue
        modifies += 1
        for result in results:
            verdicts[result.verdict] += 1
            reasons.update(result.reasons)
            if result.verdict is Verdict.DISAGREE:
                bad.append(result.detail)
    print(f"live modifies: {modifies} ({refused} refused); plans: { {v.name: n for v, n in verdicts.items()} }; "
          f"reasons: { {r.name: n for r, n in reasons.items()} }")
    assert not bad, bad[:3]
    assert refused <= CASES // 20
    assert modifies >= CASES * 0.9
    assert verdicts[Verdict.AGREE] > 0
    assert verdicts[Verdict.DIFFER_EXPLAINED] > 0
    assert reasons[Reason.ACCELERATION_STEP] > 0
    assert reasons[Reason.START_VELOCITY] > 0
