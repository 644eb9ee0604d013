"""The numbered examples that need no running suite must keep working."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


@pytest.mark.parametrize(("name", "expect"), [
    ("01_controller_move.py", "MOTION_DONE"),
    ("02_stop_resume_e_stop.py", "RESET: MPIMessageOK -> IDLE"),
    ("04_record_and_replay.py", "zero differences"),
    ("07_flying_shear_cam.py", "slave speed / line speed = 1.000000 during every cut"),
])
def test_example_runs(name, expect, tmp_path):
    args = [sys.executable, "-P", str(EXAMPLES / name)]
    if name.startswith("04"):
        args.append(str(tmp_path / "bag"))
    done = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert expect in done.stdout
