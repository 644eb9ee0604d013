"""The node suite: the shared controller, its clock thread, and the nodes on one executor."""

from __future__ import annotations

import threading

from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor

from ..config import SuiteConfig
from ..runner import ControllerRunner
from .controller_node import ControllerNode
from .supervisor_node import SupervisorNode


class Suite:
    """``Suite(config).start()`` brings the graph up; ``shutdown()`` takes it down.

    ``time_scale``: 1 real time, >1 faster, 0 as fast as possible, None manual (the
    caller steps ``suite.runner``; tests do this).
    """

    def __init__(self, config: SuiteConfig, time_scale: float | None = 1.0, context: Context | None = None):
        self.config = config
        self.controller = config.build_controller()
        self.runner = ControllerRunner(self.controller, time_scale)
        self.controller_node = ControllerNode(self.runner, config.ros, context=context)
        self.supervisor_nodes = [
            SupervisorNode(self.runner, spec.number, config.ros, context=context) for spec in config.supervisors
        ]
        self.executor = MultiThreadedExecutor(num_threads=config.ros.executor_threads, context=context)
        for node in self.nodes:
            self.executor.add_node(node)
        self._spin_thread: threading.Thread | None = None

    @property
    def nodes(self):
        return [self.controller_node, *self.supervisor_nodes]

    def start(self, spin_in_thread: bool = True) -> None:
        """Start the controller clock and (optionally) spin the executor in a thread."""
        self.runner.start()
        if spin_in_thread:
            self._spin_thread = threading.Thread(target=self.spin, name="mpi-ros-executor", daemon=True)
            self._spin_thread.start()

    def spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            self.executor.spin()
        except ExternalShutdownException:
            pass

    def shutdown(self) -> None:
        """Stop goals, the clock and the executor; destroy the nodes."""
        for node in self.supervisor_nodes:
            node.shutdown()
        self.runner.stop()
        self.executor.shutdown(timeout_sec=5.0)
        if self._spin_thread is not None:
            self._spin_thread.join(timeout=5.0)
        for node in self.nodes:
            node.destroy_node()
