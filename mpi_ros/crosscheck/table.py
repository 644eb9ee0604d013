"""The text table ``mpi-ros crosscheck`` prints: one row per request.

Columns: the request, the controller's and ruckig's durations, their relative difference,
the final-state and largest sampled differences (position, velocity, acceleration; the
sampled ones are compared only where the models coincide), the verdict and its reasons.
Problems (DISAGREE) and mapping notes follow the table, numbered by row.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .request import ProfileRequest
from .result import CrossCheck, Verdict

HEADER = ("#", "request", "controller s", "ruckig s", "|dT|/T", "final dp,dv", "sampled dp,dv,da",
          "verdict", "reasons")


def _num(x: float | None, digits: int = 9) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    return f"{x:.{digits}g}"


def _small(*values: float) -> str:
    return ",".join(f"{v:.1e}" for v in values)


def row(index: int, request: ProfileRequest | None, result: CrossCheck | str) -> tuple[str, ...]:
    label = request.label() if request else "?"  # (a result always has its request)
    if isinstance(result, str):
        return (str(index), label, "-", "-", "-", "-", "-", "REFUSED", result)
    sampled = result.max_difference
    return (
        str(index), label, _num(result.controller_duration), _num(result.ruckig_duration),
        "-" if result.ruckig_duration is None else f"{result.duration_relative:.1e}",
        _small(result.final_difference.position, result.final_difference.velocity),
        _small(sampled.position, sampled.velocity, sampled.acceleration) if result.exact else "(bound)",
        result.verdict.name, ", ".join(r.name for r in result.reasons) or "-",
    )


def format_table(entries: Sequence[tuple[ProfileRequest | None, CrossCheck | str]]) -> str:
    """``entries``: (request, result or the refusal message)."""
    rows: list[tuple[str, ...]] = [HEADER] + [row(i + 1, req, res) for i, (req, res) in enumerate(entries)]
    widths = [max(len(r[c]) for r in rows) for c in range(len(HEADER))]
    lines = []
    for n, r in enumerate(rows):
        lines.append("  ".join(cell.ljust(w) if c in (1, 7, 8) else cell.rjust(w)
                               for c, (cell, w) in enumerate(zip(r, widths, strict=True))).rstrip())
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    footnotes = []
    for i, (_, res) in enumerate(entries):
        if isinstance(res, str):
            continue
        for problem in res.problems:
            footnotes.append(f"  [{i + 1}] problem: {problem}")
        for note in res.notes:
            footnotes.append(f"  [{i + 1}] note: {note}")
    counts = {v: sum(1 for _, r in entries if not isinstance(r, str) and r.verdict is v) for v in Verdict}
    refused = sum(1 for _, r in entries if isinstance(r, str))
    summary = ", ".join(f"{n} {v.name}" for v, n in counts.items()) + (f", {refused} REFUSED" if refused else "")
    return "\n".join(lines + (["", *footnotes] if footnotes else []) + ["", f"{len(entries)} request(s): {summary}"])
