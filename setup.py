"""The pip route of mpi_ros: ``pip install .`` into a venv that has the ROS 2 Jazzy wheels.

It drives the same CMakeLists.txt as colcon (rosidl_generate_interfaces + the hand-written
Python package), so both routes install the same files:

1. configure (once) and build in ``build/cmake`` with Ninja when installed (requirements/
   runtime.txt pins it) at -O2 (Python users' generators only: MPI_ROS_PYTHON_ONLY in
   CMakeLists.txt; docs/setup.md has the costs) (persistent, so a re-install after a
   Python-only change rebuilds nothing; wiped when the venv, the source directory or the set
   of interface files changes),
   with CMAKE_INSTALL_PREFIX = the venv (sys.prefix), Python3_EXECUTABLE = the venv's python;
2. install with DESTDIR into ``build/stage``, so every path written at install time already
   names the venv;
3. package the staged tree as the wheel: the staged site-packages/mpi_ros (generated
   msg/srv/action + hand-written modules) as the Python package, everything else (lib/,
   include/, share/ament_index, share/mpi_ros, lib/mpi_ros executables) as wheel data, which
   pip installs under the venv prefix, where ros-wheels-bootstrapper's LD_LIBRARY_PATH and
   AMENT_PREFIX_PATH=<venv> find it.

The venv must already hold the ROS wheels of requirements/runtime.txt (scripts/setup.sh does
all of it). Not supported: editable installs (the source folder would shadow the generated
subpackages).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Command, Distribution, setup
from setuptools.command.build import build as _build

import setuptools  # noqa: F401  (makes `distutils` setuptools' copy)
from distutils.command.install_data import install_data as _install_data  # noqa: E402

ROOT = os.path.dirname(os.path.abspath(__file__))
BUILD_DIR = os.path.join(ROOT, "build", "cmake")
STAGE_DIR = os.path.join(ROOT, "build", "stage")
FINGERPRINT = os.path.join(ROOT, "build", "cmake-fingerprint.json")
PACKAGE = "mpi_ros"
# -O2, as the ROS packages of a distribution are built (RelWithDebInfo without -g): CMake's Release
# -O3 costs 10 % more compile time for generated code that mostly copies fields (docs/setup.md).
OPT_FLAGS = "-O2 -DNDEBUG"


def _version() -> str:
    with open(os.path.join(ROOT, PACKAGE, "__init__.py"), encoding="utf-8") as f:
        match = re.search(r'^__version__\s*=\s*"([^"]+)"', f.read(), re.M)
    if not match:
        raise RuntimeError("no __version__ in mpi_ros/__init__.py")
    return match.group(1)


def _log(msg: str) -> None:
    print(f"[mpi_ros setup.py] {msg}", flush=True)


def _clean_env() -> dict[str, str]:
    """The environment for CMake and the generators: the venv's own Python, unconfined.

    pip's build isolation puts its temporary build environment on PYTHONPATH and hides the
    venv's site-packages; the rosidl generators run by CMake need exactly those packages.
    """
    env = dict(os.environ)
    for name in ("PYTHONPATH", "PYTHONNOUSERSITE", "PYTHONHOME", "PYTHONSTARTUP"):
        env.pop(name, None)
    prefix = sys.prefix
    for name in ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH"):
        parts = [p for p in env.get(name, "").split(os.pathsep) if p and p != prefix]
        env[name] = os.pathsep.join([prefix] + parts)
    return env


def _run(cmd: list[str], env: dict[str, str]) -> None:
    _log("$ " + " ".join(cmd))
    subprocess.run(cmd, check=True, env=env)


def _ninja() -> str | None:
    """Ninja (requirements/runtime.txt installs it into the venv), else None: make it is.

    Ninja starts the next compile as soon as a core is free and checks what is up to date
    faster than make's recursive Makefiles (docs/setup.md).
    """
    found = shutil.which("ninja", path=os.pathsep.join(
        [os.path.join(sys.prefix, "bin"), os.environ.get("PATH", "")]))
    return os.path.realpath(found) if found else None


def _python_install_dir() -> str:
    """site-packages relative to the prefix, as ament_cmake_python computes it."""
    purelib = sysconfig.get_path("purelib", vars={"base": sys.prefix, "platbase": sys.prefix})
    return os.path.relpath(purelib, sys.prefix)


def cmake_build_and_stage() -> str:
    """Build with CMake and install into the stage; returns the staged prefix directory."""
    prefix = sys.prefix
    if not os.path.isfile(os.path.join(prefix, "share", "ament_cmake", "cmake",
                                       "ament_cmakeConfig.cmake")):
        raise SystemExit(
            f"mpi_ros: no ament_cmake in {prefix}. Install the ROS 2 wheels into this "
            "environment first: pip install -r requirements/runtime.txt "
            "(scripts/setup.sh does all the set-up).")
    if sys.version_info[:2] != (3, 11):
        raise SystemExit("mpi_ros: the ROS 2 Jazzy wheels need CPython 3.11")
    cmake = shutil.which("cmake")
    if not cmake:
        raise SystemExit("mpi_ros: cmake not found on PATH")
    env = _clean_env()
    # The message wheels' CMake exports name the wheel builder's Python; fix them (idempotent).
    _run([sys.executable, os.path.join(ROOT, "scripts", "fix-ros-wheel-paths.py"),
          "--prefix", prefix, "--quiet"], env)

    # A removed interface file leaves its generated code in the build directory (rosidl does not
    # clean up), so any change in the set of interface files means a clean build.
    interfaces = sorted(
        f"{sub}/{name}"
        for sub, suffix in (("msg", ".msg"), ("srv", ".srv"), ("action", ".action"))
        if os.path.isdir(os.path.join(ROOT, sub))
        for name in os.listdir(os.path.join(ROOT, sub)) if name.endswith(suffix))
    ninja = _ninja()
    fingerprint = {
        "interfaces": interfaces,
        "python_only": True,  # -DMPI_ROS_PYTHON_ONLY=ON below (CMakeLists.txt)
        "generator": ninja or "Unix Makefiles",
        "flags": OPT_FLAGS,
        "source": ROOT,
        "prefix": prefix,
        "python": os.path.realpath(sys.executable),
        "python_version": sys.version,
    }
    old = None
    if os.path.isfile(FINGERPRINT):
        with open(FINGERPRINT, encoding="utf-8") as f:
            try:
                old = json.load(f)
            except ValueError:
                old = None
    if old != fingerprint and os.path.isdir(BUILD_DIR):
        _log(f"environment, source directory or interface files changed: removing {BUILD_DIR}")
        shutil.rmtree(BUILD_DIR)
    if not os.path.isfile(os.path.join(BUILD_DIR, "CMakeCache.txt")):
        os.makedirs(BUILD_DIR, exist_ok=True)
        generator = ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"] if ninja else []
        _run([cmake, "-S", ROOT, "-B", BUILD_DIR, *generator,
              f"-DCMAKE_INSTALL_PREFIX={prefix}",
              f"-DCMAKE_PREFIX_PATH={prefix}",
              f"-DPython3_EXECUTABLE={sys.executable}",
              "-DPython3_FIND_VIRTUALENV=ONLY",
              "-DCMAKE_BUILD_TYPE=Release",
              f"-DCMAKE_C_FLAGS_RELEASE={OPT_FLAGS}",
              f"-DCMAKE_CXX_FLAGS_RELEASE={OPT_FLAGS}",
              "-DBUILD_TESTING=OFF",
              "-DMPI_ROS_PYTHON_ONLY=ON"], env)
        with open(FINGERPRINT, "w", encoding="utf-8") as f:
            json.dump(fingerprint, f, indent=1)
    jobs = str(os.cpu_count() or 1)
    _run([cmake, "--build", BUILD_DIR, "--parallel", jobs], env)
    if os.path.isdir(STAGE_DIR):
        shutil.rmtree(STAGE_DIR)
    install_env = dict(env, DESTDIR=STAGE_DIR)
    _run([cmake, "--install", BUILD_DIR], install_env)
    # DESTDIR + absolute prefix: the staged tree sits at STAGE_DIR/<prefix>.
    return os.path.join(STAGE_DIR, prefix.lstrip(os.sep))


class BinaryDistribution(Distribution):
    """The wheel holds compiled interface libraries: platform-specific, never pure."""

    def has_ext_modules(self) -> bool:
        return True


class build_cmake(Command):
    """Build the interfaces with CMake; put the staged Python package into build_lib."""

    description = "build mpi_ros with CMake (interfaces + Python package)"
    user_options: list = []

    def initialize_options(self) -> None:
        self.build_lib = None

    def finalize_options(self) -> None:
        self.set_undefined_options("build", ("build_lib", "build_lib"))

    def run(self) -> None:
        staged = cmake_build_and_stage()
        self.distribution.staged_prefix = staged
        site = os.path.join(staged, _python_install_dir())
        src = os.path.join(site, PACKAGE)
        if not os.path.isfile(os.path.join(src, "__init__.py")):
            raise SystemExit(f"mpi_ros: CMake did not install {src}")
        for name in os.listdir(site):
            if name != PACKAGE and not name.endswith(".egg-info"):
                _log(f"warning: unexpected {name} in staged site-packages (ignored)")
        dest = os.path.join(self.build_lib, PACKAGE)
        if os.path.isdir(dest):
            shutil.rmtree(dest)  # no stale modules from an earlier build
        shutil.copytree(src, dest, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))


class build(_build):
    sub_commands = [("build_cmake", None)] + _build.sub_commands


class install_data(_install_data):
    """Install everything CMake staged outside site-packages under the prefix (wheel data)."""

    def run(self) -> None:
        staged = getattr(self.distribution, "staged_prefix", None)
        if staged is None:
            self.run_command("build_cmake")
            staged = self.distribution.staged_prefix
        python_dir = os.path.normpath(_python_install_dir())
        data_files = []
        for dirpath, dirnames, filenames in os.walk(staged):
            rel = os.path.relpath(dirpath, staged)
            if rel == python_dir:
                dirnames[:] = []
                continue
            dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
            files = [os.path.join(dirpath, n) for n in sorted(filenames)
                     if not n.endswith(".pyc")]
            if files:
                data_files.append((rel, files))
        self.data_files = data_files
        super().run()


setup(
    name=PACKAGE,
    version=_version(),
    description="ROS 2 node suite for MPI/XMP-style motion controllers, with a simulated controller",
    long_description=open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    if os.path.isfile(os.path.join(ROOT, "README.md")) else "",
    long_description_content_type="text/markdown",
    license="Apache-2.0",
    python_requires="==3.11.*",
    packages=[],  # the package comes from the CMake stage (build_cmake)
    # Non-empty so that install_data runs; replaced by the staged tree in install_data.run.
    data_files=[("share/mpi_ros", ["package.xml"])],
    install_requires=[
        "ros-jazzy-rclpy[fastrtps]>=7.1,<8",
        "ros-jazzy-common-interfaces>=5.3,<6",
        "ros-jazzy-action-msgs>=2.0,<3",
        "ruckig>=0.19,<0.20",
        "mcap>=1.2",
        "mcap-ros2-support>=0.5",
        "numpy>=1.26",
        "PyYAML>=6",
        "matplotlib>=3.8",
        "scipy>=1.11",
    ],
    entry_points={"console_scripts": ["mpi-ros = mpi_ros.cli:main"]},
    distclass=BinaryDistribution,
    cmdclass={"build": build, "build_cmake": build_cmake, "install_data": install_data},
    zip_safe=False,
)
