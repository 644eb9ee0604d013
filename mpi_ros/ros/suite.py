"""The node suite: the shared controller, its clock thread, and the nodes, each on an executor of its own.

Why one executor per node: rclpy's executors rebuild their wait set from every entity of
every node they spin, in Python, on every round (rclpy 7.1: about 11 ms for the 378 entities of
a suite of 8 supervisors, against 0.6 ms for the 36 of one supervisor node). A goal takes several
rounds (its request, its result request, the task that finishes it), so with one executor for
the whole suite the goal path was bound by those rounds: about 35 goals a second, with status,
stepping and E_STOP waiting behind them. With an executor per node a request wakes only its own
node's executor, whose round costs what that node has. The goal servers are not on the
executors at all: one GoalLoop waits for all of them (goal_loop.py).
"""

from __future__ import annotations

import sys

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor

from .. import description
from ..config import SuiteConfig
from ..pace import Pace
from ..runner import ControllerRunner
from . import convert, rcl, wire
from .controller_node import ControllerNode
from .goal_front import GoalRelay
from .goal_loop import GoalLoop
from .spinner import Spinner
from .supervisor_node import SupervisorNode
from .watchdog import WatchdogTicker


class Suite:
    """``Suite(config).start()`` brings the graph up; ``shutdown()`` takes it down.

    ``time_scale``: 1 real time, >1 faster, 0 as fast as possible, None manual (the
    caller steps ``suite.runner``; tests do this).

    ``robot_description``: the URDF latched on <ns>/robot_description; default: what
    description.robot_description(config) gives (ConfigError, before any node exists, if the
    user's URDF does not match the joints).

    ``epoch_ns``: the wall-clock time of sample 0 (ns since the Unix epoch); every stamp and
    /clock is ``epoch + sample / rate``. Default: now, when the suite is built (the controller
    starts counting when ``start`` is called, a few milliseconds later). It is published with
    the configuration (latched, <ns>/configuration) and recorded in bags.
    """

    def __init__(self, config: SuiteConfig, time_scale: float | None = 1.0, context: Context | None = None,
                 epoch_ns: int | None = None, robot_description: str | None = None):
        if config.ros.action_server == "batched":
            rcl.check_version()  # before any node: the batched server needs rclpy's private bindings
        self.config = config
        self.robot_description = (description.robot_description(config) if robot_description is None
                                  else robot_description)
        self.controller = config.build_controller()
        self.epoch_ns = convert.anchor(self.controller, epoch_ns)
        self.runner = ControllerRunner(self.controller, time_scale, publish_period=config.ros.publish_period,
                                       priority=config.ros.clock_priority)
        # one Packer for every status topic: a supervisor's status holds its axes' bodies as packed
        # for their own topics, at the same sample (wire.Packer)
        packer = wire.Packer(self.controller.rate, self.epoch_ns, config.ros.namespace)
        self.controller_node = ControllerNode(self.runner, config.ros, config.axis_joints(), self.robot_description,
                                              flash=config.flash, packer=packer, context=context)
        self.goal_loop: GoalLoop | GoalRelay = (
            GoalRelay(config.ros.namespace, config.ros.executor_threads) if config.ros.goal_process
            else GoalLoop(self.controller_node.context, config.ros.executor_threads))
        # one timer for every supervisor's lost-client watchdog, on the first one's node (watchdog.py)
        watchdogs = WatchdogTicker(ReentrantCallbackGroup())
        self.supervisor_nodes = [
            SupervisorNode(self.runner, spec.number, config.ros, self.goal_loop, spec.lost_client_timeout,
                           joints=config.axis_joints(), packer=packer, watchdogs=watchdogs, context=context)
            for spec in config.supervisors
        ]
        self.pace = Pace(self.runner)
        self.configuration = self.controller_node.publish_configuration(config)
        self.crosscheck = self._crosscheck() if config.ros.crosscheck else None
        for node in self.supervisor_nodes:
            self.controller_node.add_diagnostic(node.trajectory_diagnostic)
        self.controller_node.add_diagnostic(lambda ctl: [self.suite_status()])
        self.executors = [_executor(node, config.ros.executor_threads, context) for node in self.nodes]
        self.spinners: list[Spinner] = []

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

    def suite_status(self) -> DiagnosticStatus:
        """/diagnostics "<ns>/suite": whether the controller keeps to the wall clock (pace.py:
        WARN, and a log line when it falls behind and when it is back) and what the suite holds
        (publications queued, goals per supervisor), so a long run shows whether anything
        grows. Runner lock held."""
        pace = self.pace.report()
        factor = pace.real_time_factor
        # Python's allocated blocks: whether the objects grow, apart from the allocators'
        # fragmentation and C's heaps that RSS also counts (cheap: a walk of pymalloc's arenas).
        values: dict[str, object] = {"samples_behind": pace.samples_behind,
                                     "real_time_factor": ("manual" if self.runner.time_scale is None
                                                          else "unknown" if factor is None else f"{factor:.4f}"),
                                     "outputs_queued": self.runner.backlog(),
                                     "python_blocks": sys.getallocatedblocks()}
        for node in self.supervisor_nodes:
            values.update({f"ms{node.number}.{key}": value for key, value in node.held().items()})
        # ros.clock_priority: whether the clock thread got it (WARN: asked for, running without)
        values["clock_scheduling"] = self.runner.scheduling
        message = pace.describe()
        if pace.late and not self.runner.priority:
            message += "; on a loaded machine ros.clock_priority keeps it in time"
        if pace.turned and pace.late:
            self.controller_node.get_logger().warning(f"controller clock {message}")
        elif pace.turned:
            self.controller_node.get_logger().info("controller clock back in real time")
        if self.runner.priority_refused:
            message += f"; clock thread at {self.runner.scheduling}"
        status = DiagnosticStatus(name=f"{self.config.ros.namespace.strip('/')}/suite",
                                  hardware_id="mpi_ros simulated controller", message=message)
        status.level = DiagnosticStatus.WARN if self.runner.priority_refused or pace.late else DiagnosticStatus.OK
        status.values = [KeyValue(key=k, value=str(v)) for k, v in values.items()]
        return status

    @property
    def nodes(self):
        return [self.controller_node, *self.supervisor_nodes]

    def start(self, spin_in_thread: bool = True) -> None:
        """Start the controller clock, the goal loop and (unless told not to) every node's
        executor, each in a thread of its own (spinner.py)."""
        self.runner.start()
        self.goal_loop.start()
        if spin_in_thread:
            pairs = zip(self.nodes, self.executors, strict=True)
            self.spinners = [Spinner(node, executor) for node, executor in pairs]
            for spinner in self.spinners:
                spinner.start()

    def failed(self) -> list[Spinner]:
        """The executors that stopped on their own (an error, or their context shut down)."""
        return [spinner for spinner in self.spinners if spinner.ended]

    def shutdown(self, timeout: float = 5.0) -> bool:
        """Take the suite down in the order that keeps every goal answered and no node destroyed
        while it is waited on: the supervisors end their goals (their results go out while ROS
        still runs), then the clock and the goal loop stop, then the executors (each thread
        joined), and only then are the nodes destroyed. False if an executor did not stop within
        ``timeout`` s: its node is then left to the process' exit rather than destroyed under it."""
        for node in self.supervisor_nodes:
            node.shutdown()
        self.runner.stop()
        self.goal_loop.stop(timeout)
        stuck = {spinner.executor for spinner in self.spinners if not spinner.stop(timeout)}
        for node, executor in zip(self.nodes, self.executors, strict=True):
            if executor in stuck:
                node.get_logger().error(f"its executor did not stop within {timeout:g} s: the node is not destroyed")
                continue
            executor.shutdown(timeout_sec=timeout)
            node.destroy_node()
        return not stuck


def _executor(node, threads: int, context: Context | None) -> MultiThreadedExecutor:
    executor = MultiThreadedExecutor(num_threads=threads, context=context)
    executor.add_node(node)
    return executor


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
