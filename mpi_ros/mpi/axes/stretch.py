"""Every sample of one stretch of every axis, as (axes, samples) arrays: what axes/trace.py
computes and the status bits (axes/status.py) and the fault monitor read."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from mpi_ros.mpi.axes.scratch import Scratch

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.plant import PlantState


_NO_ROWS = np.zeros(0, dtype=np.int64)
_NO_ROWS.flags.writeable = False


@dataclass(slots=True)
class Stretch:
    """Every sample of one stretch of every axis (raw positions), ``values[axis, i]``."""

    samples: np.ndarray
    t: np.ndarray
    cmd_p: np.ndarray
    cmd_v: np.ndarray
    cmd_a: np.ndarray
    act_p: np.ndarray
    act_v: np.ndarray
    rel: np.ndarray  # profile time into the plan (nan without one)
    values: np.ndarray  # the six above as one (6, axes, samples) block, in bank.VALUES order
    scratch: Scratch
    pieces: np.ndarray = field(default_factory=lambda: _NO_ROWS)  # rows of one piece
    anchors: dict[int, list[PlantState]] = field(default_factory=dict)  # plant anchors of the others

    def __len__(self) -> int:
        return len(self.samples)

    @property
    def shape(self) -> tuple[int, int]:
        return self.cmd_p.shape

    def into(self, name: str, rows: np.ndarray) -> np.ndarray | None:
        """The array ``name`` to compute ``rows`` in directly: all of it when the rows are
        every axis (sorted, as they always are), else None (a temporary, then :meth:`place`)."""
        return getattr(self, name) if len(rows) == self.shape[0] else None

    def place(self, name: str, rows: np.ndarray, values: np.ndarray) -> None:
        """``values`` (rows, or (rows, 1) columns constant over the stretch) into ``name``."""
        array = getattr(self, name)
        if values is not array:
            array[rows] = values

    def temporary(self, name: str, rows: np.ndarray) -> np.ndarray:
        """A scratch (rows, samples) array (never one of the stretch's own)."""
        return self.scratch.take("~" + name, (len(rows), len(self.samples)))

    def target(self, name: str, rows: np.ndarray) -> np.ndarray:
        """Where to compute ``name`` of ``rows``: :meth:`into` it, else a temporary."""
        into = self.into(name, rows)
        return into if into is not None else self.temporary(name, rows)

    def into_if_full(self, name: str, rows: np.ndarray, *operands: np.ndarray) -> np.ndarray | None:
        """:meth:`into`, when ``operands`` broadcast to (rows, samples) (not to columns)."""
        # (every operand is 2-D, so the shapes say it; np.broadcast_shapes makes arrays to find out)
        if all(x.shape[1] == 1 for x in operands):
            return None
        return self.into(name, rows)
