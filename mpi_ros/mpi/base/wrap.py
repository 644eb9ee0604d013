"""The controller's 32-bit positions (MPI 000, MPIMotionType, example of the shortest path).

The controller keeps an axis' positions in 32 bits: 2^31 + 10 and 2^31 + 10 - 2^32 are "the
same value" to it. The simulation keeps every position continuous (a double, the MPI's point of
view), so motion runs on smoothly across the wrap; what the controller reports (command,
actual and target positions) is that value brought into [-2^31, 2^31). Moves read their
absolute positions in the turn the axis is in (:func:`turn_offset`). docs/paths.md, "The
controller's 32-bit positions", records the decisions.
"""

from __future__ import annotations

import math

import numpy as np

WRAP = 2.0**32  # the span of the controller's 32-bit position register
HALF = 2.0**31


def wrap_position(x: float) -> float:
    """``x`` as the controller reports it: in [-2^31, 2^31), congruent modulo 2^32. Exact: a
    value already in range is returned as it is, and x - k*2^32 is representable (k*2^32 is
    a multiple of x's unit in the last place whenever x reaches 2^31)."""
    if -HALF <= x < HALF or not math.isfinite(x):
        return x
    r = x - WRAP * math.floor(x / WRAP + 0.5)
    # x / WRAP + 0.5 can round up or down by one turn near the edges: correct it
    if r >= HALF:
        return r - WRAP
    return r + WRAP if r < -HALF else r


def wrap_positions(x: np.ndarray) -> np.ndarray:
    """:func:`wrap_position` of every element (a new array; in-range values untouched)."""
    out = np.array(x, dtype=float, copy=True)
    outside = (out < -HALF) | (out >= HALF)
    if outside.any():
        out[outside] = [wrap_position(v) for v in out[outside].tolist()]
    return out


def turn_offset(x: float) -> float:
    """The multiple of 2^32 that separates ``x`` (continuous) from what the controller reports:
    0.0 within [-2^31, 2^31)."""
    return x - wrap_position(x)
