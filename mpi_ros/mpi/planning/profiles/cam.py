"""A cam table: the slave's position as a function of the master's travel along the table.

MPI 000, MPIMotionCam: ``masterDistance`` is the distance the master moves in each segment,
``slavePosition`` the distance each slave moves in it, and for CAM_CUBIC ``gearRatio`` the
first derivative of the slave position with respect to the master position at each of the
transitions between the segments, "the initial gear ratio is assumed to be zero". CAM_LINEAR
interpolates linearly between the segment ends, CAM_CUBIC with the cubic (Hermite) segment
that meets the positions and the gear ratios at both ends, so position and gear ratio are
continuous at every transition.

A table is evaluated at a travel ``u`` along it (master counts from its start, in the
direction of the table): before the start the slave waits at the start; past the end it
rests at the end, or with a repeat (MPIMotionAttrREPEAT, ``repeatFrom``) the segments from
``repeat_from`` on run again and again, each cycle adding the distance they move. Cycles are
counted from ``u`` itself, never accumulated, so the thousandth cycle is where the first was,
plus exactly 999 times that distance. All of it is numpy over arrays of ``u``: every sample of
a stretch at once, each value computed by the same operations whatever the batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt


@dataclass(frozen=True, slots=True)
class CamTable:
    """One slave axis' cam. ``knots``: the travel at the segment ends, 0 = X_0 < X_1 < .. < X_N
    (cumulative |masterDistance|); ``slave``: the slave's offset there, S_0 = 0 .. S_N
    (cumulative slavePosition); ``ratios``: CAM_CUBIC's gear ratio dS/du there (G_0 = 0),
    None for CAM_LINEAR; ``repeat_from``: the first repeated segment, None without REPEAT."""

    knots: npt.NDArray[np.float64]
    slave: npt.NDArray[np.float64]
    ratios: npt.NDArray[np.float64] | None
    repeat_from: int | None

    @classmethod
    def build(cls, distances: list[float], slave_distances: list[float], ratios: list[float] | None,
              repeat_from: int | None) -> CamTable:
        """From the segments: master distances (> 0, along the table), slave distances, and for a
        cubic cam the gear ratio at the end of each segment."""
        knots = np.cumsum(np.concatenate(([0.0], np.asarray(distances, dtype=float))))
        slave = np.cumsum(np.concatenate(([0.0], np.asarray(slave_distances, dtype=float))))
        gear = None if ratios is None else np.concatenate(([0.0], np.asarray(ratios, dtype=float)))
        return cls(knots, slave, gear, repeat_from)

    @property
    def length(self) -> float:
        """The master travel of the whole table (the run-in and one cycle)."""
        return float(self.knots[-1])

    @property
    def end(self) -> float | None:
        """The travel at which the cam is complete (None: a repeating cam never is)."""
        return None if self.repeat_from is not None else self.length

    @property
    def frames(self) -> int:
        """Frames the table occupies in each slave axis' buffer: one per segment, and the final
        frame every move loads (frames.AxisPlan.frame_count)."""
        return len(self.knots)

    def wrap(self, u: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(travel within the table, completed repeat cycles) at travels ``u`` (>= 0)."""
        if self.repeat_from is None:
            return np.minimum(u, self.length), np.zeros_like(u)
        first, end = float(self.knots[self.repeat_from]), self.length
        period = end - first
        cycles = np.maximum(np.ceil((u - end) / period), 0.0)
        # (clipped: rounding of cycles * period must not leave the repeated part)
        return np.where(cycles > 0.0, np.minimum(np.maximum(u - cycles * period, first), end), u), cycles

    def position(self, u: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The slave's offset from its start at travels ``u`` (before the start: 0)."""
        w, cycles = self.wrap(np.maximum(u, 0.0))
        i, tau, h = self._segment(w)
        s0, s1 = self.slave[i], self.slave[i + 1]
        inside: npt.NDArray[np.float64]
        if self.ratios is None:
            inside = s0 + (s1 - s0) * tau
        else:
            g0, g1 = self.ratios[i], self.ratios[i + 1]
            tau2 = tau * tau
            inside = s0 + (s1 - s0) * (tau2 * (3.0 - 2.0 * tau)) + h * (g0 * (tau * (1.0 - tau) ** 2)
                                                                        + g1 * (tau2 * (tau - 1.0)))
        # Exactly on the knot at a segment's end (the end of the table is the move's target).
        inside = np.where(w >= self.knots[i + 1], s1, inside)
        if self.repeat_from is None:
            return inside
        rise: float = self.slave[-1] - self.slave[self.repeat_from]  # (the slave's rise per cycle)
        return inside + cycles * rise

    def ratio(self, u: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The gear ratio dS/du at travels ``u`` (before the start and past a non-repeating end: 0)."""
        w, _ = self.wrap(np.maximum(u, 0.0))
        i, tau, h = self._segment(w)
        s0, s1 = self.slave[i], self.slave[i + 1]
        if self.ratios is None:
            slope = (s1 - s0) / h
        else:
            g0, g1 = self.ratios[i], self.ratios[i + 1]
            slope = ((s1 - s0) * 6.0 * tau * (1.0 - tau) / h + g0 * (1.0 - tau) * (1.0 - 3.0 * tau)
                     + g1 * tau * (3.0 * tau - 2.0))
        outside = (u < 0.0) | ((u >= self.length) if self.repeat_from is None else False)
        return np.where(outside, 0.0, slope)

    def _segment(
        self, w: npt.NDArray[np.float64],
    ) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(segment index, fraction 0..1 into it, its length) at travels ``w`` within the table."""
        last = len(self.knots) - 2
        i = np.minimum(np.maximum(np.searchsorted(self.knots, w, side="right") - 1, 0), last)
        h = self.knots[i + 1] - self.knots[i]
        return i, (w - self.knots[i]) / h, h
