"""stop_signals (mpi_ros/cli/stop_signals.py): stop signals blocked, taken by the main thread.

A signal sent to a whole process goes to any thread that does not block it, and pytest's
process has threads of its own (the middleware's, from other tests): the tests that send one
run in a fresh interpreter. They use SIGUSR1 and SIGUSR2, whose default action would end the
process if the module let one through."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap

import pytest

from mpi_ros.cli import stop_signals

SIGNALS = frozenset({signal.SIGUSR1, signal.SIGUSR2})
_HEAD = """\
import os, signal, threading
from mpi_ros.cli import stop_signals
SIGNALS = frozenset({signal.SIGUSR1, signal.SIGUSR2})
"""


def in_fresh_process(body: str) -> str:
    done = subprocess.run([sys.executable, "-c", _HEAD + textwrap.dedent(body)], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_a_signal_sent_to_the_process_is_taken_by_wait_even_from_another_thread():
    assert in_fresh_process("""
        with stop_signals.held(SIGNALS) as stops:
            # a thread started inside the block inherits the mask: the signal waits for wait()
            sender = threading.Thread(target=os.kill, args=(os.getpid(), signal.SIGUSR2))
            sender.start()
            sender.join()
            print(stops.wait(done=lambda: False, poll=10.0).name)
        """) == "SIGUSR2"


def test_a_signal_handed_to_a_thread_started_before_the_block_is_reported_too():
    assert in_fresh_process("""
        # like OpenBLAS's worker: started before the block, it does not block the signals
        early = threading.Thread(target=threading.Event().wait, daemon=True)
        early.start()
        with stop_signals.held(SIGNALS) as stops:
            signal.pthread_kill(early.ident, signal.SIGUSR1)
            print(stops.wait(done=lambda: False, poll=0.05).name)
        """) == "SIGUSR1"


def test_the_mask_and_handlers_are_restored_and_a_signal_not_taken_is_dropped():
    assert in_fresh_process("""
        taken = []
        signal.signal(signal.SIGUSR1, lambda number, frame: taken.append(number))
        before = signal.pthread_sigmask(signal.SIG_BLOCK, [])
        with stop_signals.held(SIGNALS):
            os.kill(os.getpid(), signal.SIGUSR1)  # pending, never waited for
            inside = SIGNALS <= signal.pthread_sigmask(signal.SIG_BLOCK, [])
        restored = signal.pthread_sigmask(signal.SIG_BLOCK, []) == before
        dropped = taken == []  # not delivered to the handler put back
        os.kill(os.getpid(), signal.SIGUSR1)
        print(inside, restored, dropped, taken == [signal.SIGUSR1])  # the handler is back
        """) == "True True True True"


@pytest.fixture
def _handlers_kept():
    handlers = {number: signal.getsignal(number) for number in SIGNALS}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    yield
    for number, handler in handlers.items():
        signal.signal(number, handler)
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)


@pytest.mark.usefixtures("_handlers_kept")
def test_wait_ends_when_done_without_a_signal():
    asked = []

    def done() -> bool:
        asked.append(True)
        return len(asked) == 3

    with stop_signals.held(SIGNALS) as stops:
        assert stops.wait(done=done, poll=0.01) is None
    assert len(asked) == 3


@pytest.mark.usefixtures("_handlers_kept")
def test_after_insist_the_next_signal_has_its_default_action():
    with stop_signals.held(SIGNALS) as stops:
        stops.insist()
        assert signal.getsignal(signal.SIGUSR1) == signal.SIG_DFL
        assert not SIGNALS & signal.pthread_sigmask(signal.SIG_BLOCK, [])


def test_an_answer_of_sigtimedwait_outside_the_set_is_a_timeout_not_a_crash(monkeypatch):
    # CPython 3.11's sigtimedwait, interrupted after its timeout ran out (a profiler attaching
    # by ptrace does it), answers an unfilled siginfo: here the number py-spy's attach gave.
    garbage = signal.struct_siginfo((-198506496, 0, 0, 0, 0, 0, 0))
    answers = iter([garbage, signal.struct_siginfo((0, 0, 0, 0, 0, 0, 0)), None])
    monkeypatch.setattr(signal, "sigtimedwait", lambda signals, timeout: next(answers))
    polls = iter([False, False, False, True])
    stops = stop_signals.StopSignals(SIGNALS)
    assert stops.wait(done=lambda: next(polls), poll=0.01) is None
    assert next(answers, "all asked") == "all asked"
