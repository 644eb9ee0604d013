"""Run-time cross-checking (suite option ``ros.crosscheck: true``): every started or modified
TRAPEZOIDAL, S_CURVE or VELOCITY move is checked against ruckig, axis by axis. No rclpy here.

:class:`CrosscheckMonitor` is a command listener of the
:class:`~mpi_ros.runner.ControllerRunner` (``runner.on_command(monitor)``): it runs under the
runner's lock right after each command, finds the move the start/modify made (the reply's
serial: the supervisor's current move, or the last queued one for an APPEND) and checks each
of its plans. A DISAGREE becomes a ``CROSSCHECK`` event (``controller.emit``: latched on the
supervisor, delivered as the notify mask asks, published on /<ns>/events by the suite) and is
passed to ``on_disagreement`` (the suite logs it); the counts feed the diagnostics.

A check costs well under a millisecond per axis (ruckig solves in microseconds; the
comparison samples both profiles with numpy). A failure inside the cross-check itself is
counted and logged, never raised into the command.
"""

from __future__ import annotations

import logging
import threading
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.control import Controller
from mpi_ros.mpi.planning.frames import Move

from .check import check_plan
from .request import SUPPORTED_TYPES
from .result import CrossCheck, Verdict

_log = logging.getLogger("mpi_ros.crosscheck")
START_OPERATIONS = ("motion_start", "motion_modify")  # mpi_ros.commands.MOTION_START / MOTION_MODIFY


@dataclass(frozen=True, slots=True)
class Disagreement:
    sample: int
    supervisor: int
    move_id: int
    result: CrossCheck


class CrosscheckMonitor:
    def __init__(self, controller: Controller,
                 on_disagreement: Callable[[Disagreement], None] | None = None):
        self.ctl = controller
        self.on_disagreement = on_disagreement
        self.verdicts: Counter = Counter()
        self.errors = 0
        self.last_disagreement: Disagreement | None = None
        self.last_error = ""
        self._lock = threading.Lock()  # the counts are read by the diagnostics outside the runner lock

    # -- the runner listener ----------------------------------------------------------------
    def __call__(self, sample: int, command, reply) -> None:
        self.check_command(command, reply, sample)

    def check_command(self, command, reply, sample: int | None = None) -> list[CrossCheck]:
        """Check the plans of the move ``command`` (a start or modify just applied) made."""
        if command.operation not in START_OPERATIONS or not reply.accepted or not reply.serial:
            return []
        ms = self.ctl.supervisor(command.supervisor)
        if ms is None:
            return []
        move = ms.move(reply.serial)
        if move is None:
            return []
        return self.check_move(ms.number, move, self.ctl.sample if sample is None else sample)

    def check_move(self, supervisor: int, move: Move, sample: int) -> list[CrossCheck]:
        """Check every plan of ``move``; emit a CROSSCHECK event per disagreeing axis."""
        if move.type not in SUPPORTED_TYPES:
            return []
        results = []
        for plan in move.plans:
            try:
                result = check_plan(plan, move.type)
            except Exception as exc:  # noqa: BLE001 - a cross-check fault must not break the command
                _log.exception("crosscheck of supervisor %d axis %d failed", supervisor, plan.axis)
                with self._lock:
                    self.errors += 1
                    self.last_error = f"axis {plan.axis}: {exc!r}"
                continue
            results.append(result)
            with self._lock:
                self.verdicts[result.verdict] += 1
            if result.verdict is Verdict.DISAGREE:
                found = Disagreement(sample, supervisor, move.id, result)
                with self._lock:
                    self.last_disagreement = found
                self.ctl.emit(MPIEventType.CROSSCHECK, supervisor=supervisor, axis=plan.axis,
                              move_id=move.id, element_id=move.element_id, detail=result.detail)
                if self.on_disagreement is not None:
                    self.on_disagreement(found)
        return results

    # -- for diagnostics ----------------------------------------------------------------------
    def summary(self) -> dict:
        """Counts so far and the last disagreement (thread-safe)."""
        with self._lock:
            last = self.last_disagreement
            return {
                "checked": sum(self.verdicts.values()),
                "agree": self.verdicts[Verdict.AGREE],
                "differ_explained": self.verdicts[Verdict.DIFFER_EXPLAINED],
                "disagree": self.verdicts[Verdict.DISAGREE],
                "errors": self.errors,
                "last_disagreement": (f"sample {last.sample}, ms{last.supervisor}: {last.result.detail}"
                                      if last else ""),
                "last_error": self.last_error,
            }
