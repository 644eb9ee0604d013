"""Hosts of a plant network on one Linux machine: network namespaces joined by veth links to
a switch (a bridge in a namespace of its own), for test_cell_netns.py and bench/bench_cell.py.

    with Plant(["a", "b", "c"]) as plant:
        plant.popen("a", [...])            # a process on host a (ip netns exec)
        plant.link("a", up=False)          # cut host a's link at the switch; up=True restores it

Every name carries a tag unique to the process (namespaces and links are global to the
machine, other runs may be on it); addresses (10.77.0.0/24) exist only inside the
namespaces. Everything created is removed on exit, whatever happened. Needs root (or
CAP_NET_ADMIN and CAP_SYS_ADMIN): ``refused()`` says why a machine does not allow it.
"""

from __future__ import annotations

import os
import queue
import shutil
import subprocess
import threading
from pathlib import Path

SUBNET = "10.77.0"


def _ip(*args: str, netns: str | None = None) -> None:
    command = ["ip", *(["netns", "exec", netns, "ip"] if netns else []), *args]
    done = subprocess.run(command, capture_output=True, text=True, timeout=30)
    if done.returncode != 0:
        raise OSError(f"{' '.join(command)}: {done.stderr.strip() or done.returncode}")


def refused() -> str | None:
    """Why network namespaces cannot be made here (None: they can), the machine's own words."""
    if shutil.which("ip") is None:
        return "the ip command (iproute2) is not installed"
    probe = f"mpiros{os.getpid()}probe"
    try:
        _ip("netns", "add", probe)
    except OSError as exc:
        return f"network namespaces are refused here: {exc}"
    try:
        _ip("link", "add", "br0", "type", "bridge", netns=probe)
    except OSError as exc:
        return f"bridges are refused here: {exc}"
    finally:
        subprocess.run(["ip", "netns", "del", probe], capture_output=True, timeout=30)
    return None


class Plant:
    def __init__(self, hosts: list[str]):
        self.tag = f"mr{os.getpid() % 100000}"
        self.hosts = hosts
        self.switch = f"{self.tag}sw"
        self.made: list[str] = []
        self.processes: list[Process] = []

    def netns(self, host: str) -> str:
        return f"{self.tag}{host}"

    def address(self, host: str) -> str:
        return f"{SUBNET}.{self.hosts.index(host) + 1}"

    def _port(self, host: str) -> str:
        return f"{self.tag}{host}s"  # the switch's end of the host's link

    def __enter__(self) -> Plant:
        try:
            self._add(self.switch)
            _ip("link", "add", "br0", "type", "bridge", netns=self.switch)
            _ip("link", "set", "br0", "up", netns=self.switch)
            for host in self.hosts:
                self._host(host)
        except BaseException:
            self.close()
            raise
        return self

    def _add(self, netns: str) -> None:
        _ip("netns", "add", netns)
        self.made.append(netns)

    def _host(self, host: str) -> None:
        netns, nic, port = self.netns(host), f"{self.tag}{host}", self._port(host)
        self._add(netns)
        _ip("link", "add", nic, "type", "veth", "peer", "name", port)
        _ip("link", "set", nic, "netns", netns)  # (both ends leave the machine's own namespace)
        _ip("link", "set", port, "netns", self.switch)
        _ip("link", "set", port, "master", "br0", netns=self.switch)
        _ip("link", "set", port, "up", netns=self.switch)
        _ip("link", "set", "lo", "up", netns=netns)
        _ip("addr", "add", f"{self.address(host)}/24", "dev", nic, netns=netns)
        _ip("link", "set", nic, "up", netns=netns)
        # DDS discovery multicasts (239.255.0.1): without a route for it sending fails
        _ip("route", "add", "224.0.0.0/4", "dev", nic, netns=netns)

    def link(self, host: str, up: bool) -> None:
        """Cut (or restore) the host's link at the switch, as a pulled cable would."""
        _ip("link", "set", self._port(host), "up" if up else "down", netns=self.switch)

    def popen(self, host: str, command: list[str], env: dict, log: Path) -> Process:
        process = Process(["ip", "netns", "exec", self.netns(host), *command], env, log)
        self.processes.append(process)
        return process

    def close(self) -> None:
        for process in self.processes:
            process.kill()
        for netns in reversed(self.made):  # deleting a namespace deletes its links (and their peers)
            subprocess.run(["ip", "netns", "del", netns], capture_output=True, timeout=30)
        self.made.clear()

    def __exit__(self, *exc) -> None:
        self.close()


class Process:
    """A process whose stdout lines are kept (and queued) and whose stderr goes to a file."""

    def __init__(self, command: list[str], env: dict, log: Path):
        self.log = log
        self._err = open(log, "w")  # noqa: SIM115 - closed in kill()
        self.popen = subprocess.Popen(command, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=self._err, text=True)
        self.lines: queue.Queue = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def expect(self, predicate, timeout: float) -> str:
        """The next stdout line for which ``predicate`` holds (AssertionError after ``timeout`` s)."""
        while True:
            try:
                line = self.lines.get(timeout=timeout)
            except queue.Empty:
                raise AssertionError(f"no such line within {timeout} s; stderr: {self.stderr()[-2000:]}") from None
            if line is None:
                raise AssertionError(f"the process ended (rc {self.popen.wait()}); stderr: {self.stderr()[-2000:]}")
            if predicate(line):
                return line

    def expect_all(self, wanted: set[str], timeout: float) -> None:
        """Until every line of ``wanted`` has come, in any order."""
        missing = set(wanted)
        while missing:
            missing.discard(self.expect(lambda line: line in missing, timeout))

    def send(self, line: str) -> None:
        assert self.popen.stdin is not None
        self.popen.stdin.write(line + "\n")
        self.popen.stdin.flush()

    def stderr(self) -> str:
        self._err.flush()
        return self.log.read_text(errors="replace")

    def wait_in_log(self, text: str, timeout: float) -> None:
        """Until ``text`` shows in stderr (polled: it is a file)."""
        done = threading.Event()
        for _ in range(int(timeout / 0.05)):
            if text in self.stderr():
                return
            done.wait(0.05)
        raise AssertionError(f"{text!r} not in the log within {timeout} s: {self.stderr()[-2000:]}")

    def interrupt(self, timeout: float) -> int:
        """Ctrl-C (to ``ip netns exec``, which passes it on) and the exit status."""
        self.popen.send_signal(2)
        return self.popen.wait(timeout=timeout)

    def kill(self) -> None:
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(timeout=10)
        self._err.close()
