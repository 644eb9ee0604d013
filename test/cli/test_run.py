"""`mpi-ros run`'s process set-up (mpi_ros/cli/run.py)."""

from __future__ import annotations

import platform
import subprocess
import sys
from pathlib import Path

import pytest

# In a fresh process (an allocator no one has used for large blocks yet): is an 8 MB block
# mapped on its own (returned to the system when freed), before and after one was freed?
# glibc marks such a chunk IS_MMAPPED (bit 1 of the size word just before the pointer).
_PROBE = """
import ctypes, sys
from mpi_ros.cli.run import release_large_buffers
if sys.argv[1] == "pinned":
    assert release_large_buffers()
libc = ctypes.CDLL("libc.so.6")
libc.malloc.restype = ctypes.c_void_p
libc.free.argtypes = [ctypes.c_void_p]
def mapped():
    block = libc.malloc(8 << 20)
    own = bool(ctypes.c_size_t.from_address(block - ctypes.sizeof(ctypes.c_size_t)).value & 2)
    libc.free(block)
    return own
print(mapped(), mapped())
"""


def probe(mode: str) -> str:
    done = subprocess.run([sys.executable, "-c", _PROBE, mode], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's allocator only: nothing to pin elsewhere")
def test_large_buffers_go_back_to_the_system_once_the_threshold_is_pinned():
    # glibc raises its mmap threshold when the first large block is freed: the next one comes
    # from the heap and stays there (the refused-goal memory growth, docs/hostile-input.md)
    assert probe("default") == "True False"
    assert probe("pinned") == "True True"


_CRASH = """
import faulthandler, sys, threading
from mpi_ros.cli.run import report_crashes
assert report_crashes(sys.stderr)
def clock_thread(): threading.Event().wait()
threading.Thread(target=clock_thread, name="clock", daemon=True).start()
faulthandler._sigsegv()
"""


def test_a_crash_in_c_code_leaves_every_threads_stack_in_the_log():
    # the middleware crashing at shutdown once ended the suite with SIGSEGV and no word of where
    done = subprocess.run([sys.executable, "-c", _CRASH], capture_output=True, text=True, timeout=60)
    assert done.returncode == -11, done.stderr
    assert "Fatal Python error: Segmentation fault" in done.stderr
    assert "clock_thread" in done.stderr  # not only the crashing thread's stack


def test_crash_reports_are_left_alone_without_a_file_descriptor():
    import faulthandler
    import io

    from mpi_ros.cli.run import report_crashes

    before = faulthandler.is_enabled()
    assert report_crashes(io.StringIO()) is False  # stderr captured in-process, as run() in tests
    assert faulthandler.is_enabled() == before


# -- the suite's DDS announcements (config/fastdds_discovery.xml) ------------------------------------
def test_the_suite_announces_itself_often_unless_a_profile_or_middleware_was_chosen(tmp_path):
    from mpi_ros.cli.run import announce_often

    environ: dict[str, str] = {}
    chosen = announce_often(environ)
    assert chosen is not None
    assert environ["FASTRTPS_DEFAULT_PROFILES_FILE"] == chosen
    assert "<leaseAnnouncement><sec>0</sec><nanosec>100000000</nanosec></leaseAnnouncement>" in Path(chosen).read_text()
    own = {"FASTDDS_DEFAULT_PROFILES_FILE": str(tmp_path / "mine.xml")}
    assert announce_often(own) is None
    assert "FASTRTPS_DEFAULT_PROFILES_FILE" not in own
    cyclone = {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}
    assert announce_often(cyclone) is None
    assert cyclone == {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}
