"""Arrays by name, reused from stretch to stretch (axes/trace.py computes every axis over a
stretch of samples in them)."""

from __future__ import annotations

import math

import numpy as np


class Scratch:
    """Arrays by name, reused from stretch to stretch. A fresh array of a megabyte (32 axes
    x 4096 samples) costs its page faults every time (the allocator hands large blocks
    back to the system), more than the arithmetic done on it. Each is the start of a flat
    buffer, so it is contiguous whatever its shape."""

    def __init__(self) -> None:
        self._buffers: dict[tuple[str, type], np.ndarray] = {}
        self._views: dict[tuple[str, type], tuple[tuple[int, ...], np.ndarray]] = {}

    def take(self, name: str, shape: tuple[int, ...], dtype: type = float) -> np.ndarray:
        """An array of ``shape`` (contents undefined), valid until ``name`` is taken again."""
        key = (name, dtype)
        last = self._views.get(key)
        if last is not None and last[0] == shape:
            return last[1]
        size = math.prod(shape)
        buffer = self._buffers.get(key)
        if buffer is None or len(buffer) < size:
            buffer = self._buffers[key] = np.empty(size, dtype=dtype)
        view = buffer[:size].reshape(shape)
        self._views[key] = (shape, view)
        return view
