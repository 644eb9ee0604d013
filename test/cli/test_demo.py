"""`mpi-ros demo` end to end: it brings its own suite up, narrates a tour in which every
step really happens (each narrated answer is the controller's), records it, leaves the
bag and the plots, and stops its suite. No other suite runs during this module."""

from __future__ import annotations

import re

import yaml

from .conftest import mpi_ros


def _step(text: str, number: int) -> str:
    """The narration of step ``number``."""
    return text.split(f"\n{number}. ")[1].split(f"\n{number + 1}. ")[0]


def test_demo_tours_records_and_plots(tmp_path):
    out = tmp_path / "tour"
    # Twice real time: at 4x the suite (4 axes, status and recording at 4x their rates) fell
    # 20 s of controller time behind on a 2-core machine where ruckig itself ran at half the
    # speed of another day's, and the tour then overran the timeout.
    proc = mpi_ros("demo", "--output", str(out), "--time-scale", "2", "--namespace", "/demo", timeout=180)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    text = proc.stdout
    assert re.match(r"suite up under /demo on ROS_DOMAIN_ID \d+ \(process \d+, log .*suite.log\), time scale 2, "
                    r"recording to .*bag\n", text)
    assert re.findall(r"^(\d+)\. ", text, re.MULTILINE) == [str(n) for n in range(1, 10)]

    assert _step(text, 1).endswith("MPIMessageOK (code 0) DONE: motion done, state IDLE, at [4000.0, 2000.0]\n")
    jog_and_modify = _step(text, 2)
    assert "MPIMessageOK (code 0) DONE: at velocity, state MOVING" in jog_and_modify
    assert jog_and_modify.endswith("MPIMessageOK (code 0) DONE: motion done, state IDLE, at [1000.0, -1000.0]\n")
    stop = _step(text, 3)
    assert "STOP: MPIMessageOK (code 0), state STOPPING\n   STOPPED at [" in stop
    assert re.search(r"RESUME: MPIMessageOK \(code 0\), state MOVING\n   MOVING again, at \[.*\], "
                     r"\[1500.0, 1500.0\] counts/s", _step(text, 4))
    assert "E_STOP: MPIMessageOK (code 0), state STOPPING_ERROR\n   ERROR at [" in _step(text, 5)
    assert "MPIMotionMessageERROR (code 2315) REFUSED" in _step(text, 6)
    assert "RESET: MPIMessageOK (code 0), state IDLE" in _step(text, 7)
    path = _step(text, 8)
    assert "PVT" in path
    assert "MPIMessageOK (code 0) DONE, state IDLE, at [3000.0, 0.0]" in path
    assert "MPIMessageOK (code 0) DONE: motion done, state IDLE, at [0.0, 0.0]\n\nbag:" in _step(text, 9)

    lines = text.rstrip().splitlines()
    assert lines[-3] == f"bag:   {out / 'bag'}   (replay it: mpi-ros replay {out / 'bag'})"
    for name in ("bag/metadata.yaml", "tour.png", "s_curve_vs_ruckig.png", "suite.log", "suite.yaml"):
        assert (out / name).is_file(), name
    assert str(out / "tour.png") in lines[-2]
    assert str(out / "s_curve_vs_ruckig.png") in lines[-1]
    assert "mpi_ros suite stopped" in (out / "suite.log").read_text()  # stopped cleanly: the bag is whole
    assert yaml.safe_load((out / "suite.yaml").read_text())["ros"]["namespace"] == "/demo"


def test_demo_usage_errors(tmp_path):
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("")
    proc = mpi_ros("demo", "--output", str(tmp_path / "full"))
    assert proc.returncode == 2
    assert proc.stderr.strip() == (f"mpi-ros demo: {tmp_path / 'full'} exists and is not an empty directory: "
                                   "pass --output DIR")
    proc = mpi_ros("demo", "--time-scale", "0")
    assert proc.returncode == 2
    assert "--time-scale must be > 0" in proc.stderr
