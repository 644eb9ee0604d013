"""Motion log (meiMotionLogOpen / meiMotionLogPrint / meiMotionLogClose).

Logs every sample while open, up to ``max_entries`` (the buffer's size): sample, the
supervisor's state, and per axis command and actual position and command velocity.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, Outcome


@dataclass(slots=True)
class MotionLog:
    max_entries: int
    samples: list[np.ndarray] = field(default_factory=list)
    states: list[str] = field(default_factory=list)
    columns: list[np.ndarray] = field(default_factory=list)  # per chunk: (n, 3 * axes)
    count: int = 0

    @property
    def full(self) -> bool:
        return self.count >= self.max_entries

    def record(self, samples: np.ndarray, state: str,
               per_axis: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> None:
        room = self.max_entries - self.count
        if room <= 0 or len(samples) == 0:
            return
        n = min(room, len(samples))
        cols = [c[:n] for triple in per_axis for c in triple]
        self.samples.append(samples[:n])
        self.states.append(state)
        self.columns.append(np.column_stack(cols) if cols else np.zeros((n, 0)))
        self.count += n

    def write(self, filename: str, axes: list[int]) -> Outcome:
        header = ["sample", "state"]
        for a in axes:
            header += [f"axis{a}_command", f"axis{a}_actual", f"axis{a}_velocity"]
        try:
            with open(filename, "w", encoding="utf-8") as out:
                out.write(",".join(header) + "\n")
                for samples, state, cols in zip(self.samples, self.states, self.columns, strict=True):
                    for i, sample in enumerate(samples):
                        values = ",".join(repr(float(x)) for x in cols[i])
                        out.write(f"{int(sample)},{state}" + (f",{values}" if values else "") + "\n")
        except OSError as exc:
            return Outcome(Message.MPIMessageFILE_OPEN_ERROR, f"filename: cannot write {filename!r}: {exc.strerror}")
        return VALID
