"""SIGINT and SIGTERM, taken by the suite's main thread when it is ready for them.

Why not rclpy's signal handlers: they shut the context down from the signal, chain to Python's
handler, and trust every executor to wake and see it. In the suite (an executor per node, each in
a thread) SIGINT soon after start-up could hang it (executors asleep in their wait; 8 of 60 runs
on a busy machine, SIGINT inherited ignored) or crash it (KeyboardInterrupt skipped the join of
the executors' threads and the nodes were destroyed under them; 2 of 60 with the default
disposition). docs/reliability.md, "Stopping"; bench/RESULTS.md, "Stopping under a signal".

So the suite takes the signals itself, synchronously. They are blocked in every thread started
from here on: threads inherit the mask of the thread that starts them, so the block comes before
rclpy starts the middleware's threads. The main thread waits for one with ``sigtimedwait``; no
handler runs in the middle of other code, and nothing is missed. A thread started before the
block (numpy's OpenBLAS starts one when numpy is imported: `mpi-ros run` blocks first) could
still be handed one by the kernel. Python then runs the handler installed here, in the main
thread; it only notes the signal, and ``wait`` reports it too.

A second SIGINT or SIGTERM while the suite is stopping ends the process at once (the default
action): the user or launch insisting.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Callable, Iterator

STOP_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})


class StopSignals:
    """The stop signals, blocked: ``wait`` for one, then ``insist`` lets the next one kill."""

    def __init__(self, signals: frozenset[signal.Signals] = STOP_SIGNALS):
        self.signals = signals
        self.caught: list[signal.Signals] = []  # handed to a thread that does not block them

    def catch(self, number: int, frame: object) -> None:
        """The handler while held: notes the signal for ``wait`` (and raises nothing, so no
        KeyboardInterrupt can surface in the middle of start-up)."""
        self.caught.append(signal.Signals(number))

    def wait(self, done: Callable[[], bool], poll: float = 0.5) -> signal.Signals | None:
        """The signal received, or None once ``done()`` is true (asked every ``poll`` s)."""
        while not self.caught and not done():
            received = signal.sigtimedwait(self.signals, poll)
            # Only a signal of the set counts: CPython 3.11's sigtimedwait, interrupted (EINTR)
            # after its timeout has run out, answers a siginfo it never filled in (its loop
            # breaks to fill_siginfo). A profiler or debugger attaching (ptrace) interrupts it:
            # `py-spy record --native` on the suite ended it with "ValueError: -198506496 is
            # not a valid Signals". Such an answer is a timeout.
            if received is not None and received.si_signo in self.signals:
                return signal.Signals(received.si_signo)
        return self.caught[0] if self.caught else None

    def insist(self) -> None:
        """From now on one more stop signal ends the process (this thread takes it, with the
        default action), rather than waiting blocked until the suite has stopped."""
        for number in self.signals:
            signal.signal(number, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, self.signals)


@contextlib.contextmanager
def held(signals: frozenset[signal.Signals] = STOP_SIGNALS) -> Iterator[StopSignals]:
    """Block ``signals`` in this thread and every thread started inside the block. On the way
    out the signals that arrived and were not taken are dropped, and the mask and handlers are
    restored (so a caller that is not a process of its own, a test, is left as it was)."""
    handlers = {number: signal.getsignal(number) for number in signals}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, signals)
    stops = StopSignals(signals)
    for number in signals:
        signal.signal(number, stops.catch)
    try:
        yield stops
    finally:
        signal.pthread_sigmask(signal.SIG_BLOCK, signals)
        while signal.sigtimedwait(signals, 0) is not None:
            pass
        for number, handler in handlers.items():
            if handler is not None:  # None: installed from C, not ours to put back
                signal.signal(number, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
