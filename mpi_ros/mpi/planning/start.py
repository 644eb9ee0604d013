"""Where an axis' new profile starts: the input of every plan (planner.py, cams.py)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(slots=True)
class AxisStart:
    """Where an axis' new profile starts: raw position and velocity in profile time."""

    axis: int
    position: float
    velocity: float = 0.0
    origin: float = 0.0
    acceleration: float = 0.0  # used by the jerk types only (they plan from the full state)
