"""One executor spun in a thread of its own, until told to stop or until it fails.

Why not ``Executor.spin`` in a thread: rclpy's ``spin`` ends only when the context shuts down
or ``Executor.shutdown`` is called, and neither waits for the spinning thread. ``shutdown``
destroys the executor's guard condition while that thread may be between its checks and its
next wait; a context shut down by a signal did not wake every executor of the suite (it hung);
and destroying a node while its executor's thread is in its wait crashed the process (SIGSEGV;
docs/reliability.md, "Stopping").
A Spinner owns its loop: ``stop`` sets a flag, wakes the executor and joins the thread, so the
nodes are destroyed only once nothing waits on them. The wake is a guard condition of the node
with a callback that does nothing: ``Executor.wake`` would not do, since it wakes the executor's
wait but gives ``spin_once`` no work, so ``spin_once`` goes back to waiting without returning.
"""

from __future__ import annotations

import threading
import traceback

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.node import Node

from . import rcl


class Spinner:
    """``Spinner(node, executor).start()`` spins the executor that has ``node``; ``stop(timeout)``
    ends it; ``error`` says why it ended on its own (an exception a callback raised, which the
    executor re-raises), and the node's log has its traceback."""

    def __init__(self, node: Node, executor: Executor):
        self.name = node.get_name()
        self.executor = executor
        self.error: Exception | None = None
        self._logger = node.get_logger()
        self._stopping = False
        # its own group: a callback of the node's default group running long does not hold it back
        self._wake = node.create_guard_condition(_nothing, callback_group=ReentrantCallbackGroup())
        self._thread = threading.Thread(target=self._run, name=f"mpi-ros-{self.name}", daemon=True)

    def start(self) -> None:
        self._thread.start()

    @property
    def ended(self) -> bool:
        """Started and no longer spinning (stopped, failed, or its context shut down)."""
        return self._thread.ident is not None and not self._thread.is_alive()

    def stop(self, timeout: float) -> bool:
        """Stop spinning and wait (up to ``timeout`` s) for the thread; True once it ended."""
        self._stopping = True
        self._wake.trigger()  # kept by the guard condition until a wait takes it: not missed
        return self.join(timeout)

    def join(self, timeout: float) -> bool:
        """Wait (up to ``timeout`` s) for the thread to end; True if it ended or never started."""
        if self._thread.ident is None:
            return True
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def _run(self) -> None:
        try:
            while not self._stopping and self.executor.context.ok():
                self.executor.spin_once()
        except ExternalShutdownException:
            pass  # the context shut down between the check and the wait: nothing left to serve
        except rcl.RCLError as exc:
            # The context shut down between the executor's check and its wait: it cannot make
            # the wait set any more. Anything else is a real error.
            if self.executor.context.ok():
                self._failed(exc)
        except Exception as exc:  # noqa: BLE001 - not swallowed: logged, kept in error, and the suite stops
            self._failed(exc)

    def _failed(self, exc: Exception) -> None:
        self.error = exc
        self._logger.error(f"its executor stopped on an error:\n{traceback.format_exc().rstrip()}")


def _nothing() -> None:
    """The wake's callback: running it is what makes ``spin_once`` return."""
