"""Ruckig as an independent judge of the controller's TRAPEZOIDAL, S_CURVE and VELOCITY profiles.

| concept                                                   | module |
| --------------------------------------------------------- | ------ |
| a 1-D request (YAML / key=value) and the controller's plan | request.py |
| request/plan -> ruckig problem; where the models coincide  | mapping.py |
| running ruckig safely; its profile as segments             | solver.py |
| the controller's profile against every limit               | limits.py |
| sampling two profiles against each other                   | sampling.py |
| verdict, reasons, differences, tolerances (the result)     | result.py |
| ``check_plan`` / ``check_request``                          | check.py |
| run-time checking of started/modified moves (no rclpy)     | monitor.py |
| the text table of ``mpi-ros crosscheck``                   | table.py |
| seeded random requests and agreement statistics            | survey.py |

``check_request("{type: S_CURVE, distance: 1000, velocity: 500, acceleration: 5000,
jerk_percent: 50}")`` answers a :class:`CrossCheck` with the verdict AGREE, DIFFER_EXPLAINED
(with the reasons) or DISAGREE (with the problems). ruckig is imported only when a check runs.
"""

from .check import check_plan, check_request
from .request import ProfileRequest, RequestInvalid
from .result import CrossCheck, Reason, StateDifference, Verdict

__all__ = ["CrossCheck", "ProfileRequest", "Reason", "RequestInvalid", "StateDifference", "Verdict",
           "check_plan", "check_request"]
