"""The node suite: the shared controller, its clock thread, and the nodes on one executor."""

from __future__ import annotations

import contextlib
import threading

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor

from ..config import SuiteConfig
from ..runner import ControllerRunner
from . import convert
from .controller_node import ControllerNode
from .supervisor_node import SupervisorNode


class Suite:
    """``Suite(config).start()`` brings the graph up; ``shutdown()`` takes it down.

    ``time_scale``: 1 real time, >1 faster, 0 as fast as possible, None manual (the
    caller steps ``suite.runner``; tests do this).

    ``epoch_ns``: the wall-clock time of sample 0 (ns since the Unix epoch); every stamp and
    /clock is ``epoch + sample / rate``. Default: now, when the suite is built (the controller
    starts counting when ``start`` is called, a few milliseconds later). It is published with
    the configuration (latched, <ns>/configuration) and recorded in bags.
    """

    def __init__(self, config: SuiteConfig, time_scale: float | None = 1.0, context: Context | None = None,
                 epoch_ns: int | None = None):
        self.config = config
        self.controller = config.build_controller()
        self.epoch_ns = convert.anchor(self.controller, epoch_ns)
        self.runner = ControllerRunner(self.controller, time_scale)
        self.controller_node = ControllerNode(self.runner, config.ros, context=context)
        self.supervisor_nodes = [
            SupervisorNode(self.runner, spec.number, config.ros, spec.lost_client_timeout, context=context)
            for spec in config.supervisors
        ]
        self.configuration = self.controller_node.publish_configuration(config)
        self.crosscheck = self._crosscheck() if config.ros.crosscheck else None
        self.controller_node.add_diagnostic(lambda ctl: [self._suite_status()])
        self.executor = MultiThreadedExecutor(num_threads=config.ros.executor_threads, context=context)
        for node in self.nodes:
            self.executor.add_node(node)
        self._spin_thread: threading.Thread | None = None

    def _crosscheck(self):
        """ros.crosscheck: every started/modified move is checked against ruckig; a
        disagreement is logged, published as a CROSSCHECK event and in /diagnostics."""
        from ..crosscheck.monitor import CrosscheckMonitor

        log = self.controller_node.get_logger()
        monitor = CrosscheckMonitor(
            self.controller, on_disagreement=lambda found: log.warning(f"crosscheck: {found.result.detail}"))
        self.runner.on_command(monitor)
        name = f"{self.config.ros.namespace.strip('/')}/crosscheck"
        self.controller_node.add_diagnostic(lambda ctl: [_crosscheck_status(name, monitor.summary())])
        return monitor

    def _suite_status(self):
        """/diagnostics "<ns>/suite": how far the controller is behind the wall clock and what
        the suite holds (publications queued, goals per supervisor), so a long run shows
        whether anything grows. Runner lock held."""
        behind = self.runner.due_sample() - self.controller.sample
        values = {"samples_behind": behind, "outputs_queued": self.runner.backlog()}
        for node in self.supervisor_nodes:
            values.update({f"ms{node.number}.{key}": value for key, value in node.held().items()})
        status = DiagnosticStatus(name=f"{self.config.ros.namespace.strip('/')}/suite",
                                  hardware_id="mpi_ros simulated controller",
                                  message=f"{behind} samples behind the wall clock")
        status.level = DiagnosticStatus.OK
        status.values = [KeyValue(key=k, value=str(v)) for k, v in values.items()]
        return status

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

        with contextlib.suppress(ExternalShutdownException):
            self.executor.spin()

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


def _crosscheck_status(name: str, summary: dict):
    from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

    status = DiagnosticStatus()
    status.name = name
    status.hardware_id = "mpi_ros simulated controller"
    bad = summary["disagree"] or summary["errors"]
    level = DiagnosticStatus.WARN if bad else DiagnosticStatus.OK
    status.level = bytes([level]) if isinstance(level, int) else level
    status.message = (f"{summary['checked']} profile(s) checked against ruckig: {summary['agree']} agree, "
                      f"{summary['differ_explained']} differ (explained), {summary['disagree']} disagree"
                      + (f", {summary['errors']} check error(s)" if summary["errors"] else ""))
    status.values = [KeyValue(key=k, value=str(v)) for k, v in summary.items()]
    return status
