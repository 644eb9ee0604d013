"""`mpi-ros crosscheck` (the table) and `mpi-ros plot` (a profile to PNG; a bag is handed to
mpi_ros.plot.bag)."""

from __future__ import annotations

import sys
import types

import pytest

from mpi_ros.cli import main
from mpi_ros.cli.crosscheck import EXAMPLES
from mpi_ros.mpi.planning.frames import Listed

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_default_set_covers_every_verdict_but_disagree(capsys):
    assert main(["crosscheck"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0].split()[:2] == ["#", "request"]
    assert "verdict" in lines[0]
    assert f"{len(EXAMPLES)} request(s):" in out
    assert "0 DISAGREE" in out
    for word in ("AGREE", "DIFFER_EXPLAINED", "DECELERATION_DIFFERS", "START_VELOCITY", "REVERSAL_ASYMMETRIC",
                 "ACCELERATION_STEP", "jerk from the velocity reached"):
        assert word in out


def test_requests_from_arguments(capsys):
    assert main(["crosscheck", "type=S_CURVE,distance=1000,velocity=500,acceleration=5000,jerk_percent=50",
                 "{type: VELOCITY, velocity: -300, acceleration: 5000, start_velocity: 100}"]) == 0
    out = capsys.readouterr().out
    rows = [line for line in out.splitlines() if line[:1].isdigit() and "request(s)" not in line]
    assert len(rows) == 2
    assert rows[0].startswith("1  S_CURVE x=1000")
    assert " 2.1 " in rows[0]
    assert "AGREE" in rows[0]
    assert rows[1].startswith("2  VELOCITY")
    assert "AGREE" in rows[1]


def test_requests_from_a_yaml_file(tmp_path, capsys):
    path = tmp_path / "requests.yaml"
    path.write_text(
        "requests:\n"
        "  - {type: TRAPEZOIDAL, distance: -1000, velocity: 500, acceleration: 5000, deceleration: 2000}\n"
        "  - {type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, jerk_percent: 100,"
        " start_velocity: 200}\n"
        "  - {type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000, final_velocity: 900}\n")
    assert main(["crosscheck", "--file", str(path)]) == 0
    out = capsys.readouterr().out
    assert "1 AGREE, 1 DIFFER_EXPLAINED, 0 DISAGREE, 1 REFUSED" in out
    assert "MPIMotionMessagePROFILE_ERROR" in out  # a final velocity above the velocity is refused


@pytest.mark.parametrize("argv", [
    ["crosscheck", "type=S_CURVE,distance=1000,speed=3"],
    ["crosscheck", "type=PT,distance=1,velocity=1,acceleration=1"],
    ["crosscheck", "{type: S_CURVE"],
    ["crosscheck", "--file", "/nonexistent/requests.yaml"],
    ["crosscheck", "--random", "0"],
])
def test_bad_input_is_exit_status_2(argv, capsys):
    assert main(argv) == 2
    assert "mpi-ros crosscheck:" in capsys.readouterr().err


def test_a_disagreement_is_exit_status_1(monkeypatch, capsys):
    from dataclasses import replace

    import mpi_ros.crosscheck.request as request_module

    real = request_module.compile_move

    def wrong(supervisor, motion_type, attrs, params, starts, rate):
        fast = replace(params, trajectory=[replace(t, velocity=2 * t.velocity) for t in params.trajectory])
        move, notes = real(supervisor, motion_type, attrs, fast, starts, rate)
        move.plans[0].source = Listed(move.plans[0].segments, params.trajectory[0])
        return move, notes

    monkeypatch.setattr(request_module, "compile_move", wrong)
    assert main(["crosscheck", "type=TRAPEZOIDAL,distance=1000,velocity=500,acceleration=5000"]) == 1
    out = capsys.readouterr().out
    assert "DISAGREE" in out
    assert "problem: segment" in out
    assert "above the velocity 500.0" in out


def test_random_survey_prints_statistics(capsys):
    assert main(["crosscheck", "--random", "40", "--seed", "3"]) == 0
    out = capsys.readouterr().out
    for name in ("TRAPEZOIDAL", "S_CURVE", "VELOCITY", "MODIFY"):
        assert any(line.startswith(name) and " 40 " in line for line in out.splitlines())


def _png_size(path):
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def test_plot_writes_a_png(tmp_path, capsys):
    out = tmp_path / "scurve.png"
    assert main(["plot", "--type", "S_CURVE", "--distance", "1000", "--jerk-percent", "50", "-o", str(out)]) == 0
    assert f"{out}: S_CURVE axis 0: AGREE" in capsys.readouterr().out
    assert _png_size(out) == (1100, 1100)


def test_plot_of_a_request_that_differs(tmp_path, capsys):
    out = tmp_path / "modify.png"
    assert main(["plot", "--request", "type=TRAPEZOIDAL,distance=100,velocity=500,acceleration=5000,"
                 "deceleration=2000,start_velocity=-300", "-o", str(out)]) == 0
    assert "DIFFER_EXPLAINED" in capsys.readouterr().out
    assert out.stat().st_size > 10_000


def test_plot_rejects_a_bad_request(tmp_path, capsys):
    assert main(["plot", "--type", "VELOCITY", "--acceleration", "-1", "-o", str(tmp_path / "x.png")]) == 2
    assert "PARAM_INVALID" in capsys.readouterr().err


def test_plot_bag_dispatch(tmp_path, monkeypatch, capsys):
    calls = []
    fake = types.ModuleType("mpi_ros.plot.bag")
    fake.plot_bag = lambda path, output, axes=None, start=None, end=None: calls.append((path, output, axes)) or output
    monkeypatch.setitem(sys.modules, "mpi_ros.plot.bag", fake)
    bag = tmp_path / "run1"
    bag.mkdir()
    assert main(["plot", str(bag), "--axis", "1"]) == 0
    assert calls == [(str(bag), "run1.png", [1])]
    mcap = tmp_path / "x.mcap"
    mcap.write_bytes(b"")
    assert main(["plot", str(mcap), "-o", str(tmp_path / "y.png")]) == 0
    assert calls[-1] == (str(mcap), str(tmp_path / "y.png"), None)


def test_plot_of_something_that_is_not_a_bag(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "missing.mcap")]) == 2
    assert "not a bag" in capsys.readouterr().err


def test_plot_bag_without_the_bag_module(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "mpi_ros.plot.bag", None)  # as if mpi_ros/plot/bag.py were missing
    assert main(["plot", str(tmp_path)]) == 2
    assert "mpi_ros.plot.bag is missing" in capsys.readouterr().err
