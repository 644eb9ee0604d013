"""Electronic cams: CAM_LINEAR and CAM_CUBIC slave axes that follow a master position.

MPI 000, MPIMotionCam and the attributes REPEAT, MASTER_START, NO_BACKTRACK and
NO_BACKTRACK_HOLD; MPI 002, MPIAxisConfig.master and masterCorrection. The slave's command is
a function of the master's position, not of time: each sample the master position (masters.py)
becomes a travel ``x`` along the table (from the master's position at the start, or from
``masterStart``), the backtrack rule turns it into the slave's progress ``u``, and the table
(profiles/cam.py) gives the slave's position at ``u``. Decisions: docs/cams.md.

Progress, per sample k (x_k the master's travel, s_k the feedrate over the normal one):
- before the cam has started (MASTER_START: the master has not reached ``masterStart``;
  x < 0 until then) the slave waits at its start: u = x (the table is flat before 0);
- the reference r follows the master: x itself (the master may reverse and the slave with
  it), the forward travel alone (NO_BACKTRACK: r grows by the master's forward steps, so the
  slave holds while the master goes back and moves as soon as it goes forward again), or
  the furthest point reached (NO_BACKTRACK_HOLD: the slave holds until the master is back
  where it reversed);
- u = r + offset. The offset is the phase a stop lost: at the normal feedrate it does not
  change (u is r plus a constant, one rounding, so no drift however long the cam runs);
  while STOP or E_STOP ramp the feedrate, u grows by s_k times r's step and the offset
  becomes u - r.
- a cam without REPEAT is complete once u reaches the table's end: the slave stays there.
All of it is arrays over a stretch (numpy); a stretch in which the feedrate changes runs the
same recurrence sample by sample. Either way each value is computed by the same operations,
so the result never depends on how the samples were batched.
"""

from __future__ import annotations

from mpi_ros.mpi.base.masters import reads
from mpi_ros.mpi.base.params import AxisMaster, MotionParams
from mpi_ros.mpi.base.types import MotionAttr, MPIMotionType
from mpi_ros.mpi.planning.cam_follow import Backtrack, CamFollow, CamState
from mpi_ros.mpi.planning.families import FAMILIES
from mpi_ros.mpi.planning.frames import AxisPlan, Listed
from mpi_ros.mpi.planning.profiles.cam import CamTable
from mpi_ros.mpi.planning.start import AxisStart


def cam_plans(motion_type: MPIMotionType, attrs: MotionAttr, params: MotionParams, starts: list[AxisStart],
              masters: list[tuple[AxisMaster, float, float]]) -> list[AxisPlan]:
    """The plans of a validated cam (validate._check_cam) for the slave axes ``starts``, each
    with its master, the master's position now and the origins it is read less (its frame).
    Travel 0 is the master's position now, or ``masterStart`` with MASTER_START; the table's
    direction is the sign of the master distances, and a gear ratio (dS/d master position)
    becomes dS/d travel in it."""
    count = len(starts)
    direction = 1.0 if params.master_distance[0] > 0.0 else -1.0
    distances = [abs(float(d)) for d in params.master_distance]
    repeat_from = int(params.repeat_from) if MotionAttr.REPEAT in attrs else None
    cubic = "gear_ratio" in FAMILIES[motion_type].fields  # (MPIMotionCam: the linear cam ignores them)
    plans = []
    for j, (start, (master, now, frame)) in enumerate(zip(starts, masters, strict=True)):
        ratios = [direction * float(g) for g in params.gear_ratio[j::count]] if cubic else None
        table = CamTable.build(distances, [float(s) for s in params.slave_position[j::count]], ratios, repeat_from)
        origin = float(params.master_start) if MotionAttr.MASTER_START in attrs else now
        follow = CamFollow(table, master.copy(), direction, origin, Backtrack.of(attrs), start.position,
                           CamState.at_start((now - origin) * direction), frame)
        plans.append(AxisPlan(axis=start.axis, source=Listed([]), start_position=start.position, target=follow.target,
                              cam=follow))
    return plans


def master_loop(slaves: list[int], masters: list[AxisMaster], running: dict[int, set[int]]) -> str:
    """Why the masters of a cam on ``slaves`` would form a loop ('' if they do not): a slave
    would follow itself, another slave of the cam, or, through the cams running (``running``:
    slave axis -> the axes its master reads), one of them. Each sample a slave follows its
    master's position of the same sample, so the masters must be computed first."""
    for slave, master in zip(slaves, masters, strict=True):
        seen: set[int] = set()
        todo = list(reads(master))
        while todo:
            axis = todo.pop()
            if axis in slaves:
                return f"axis {slave}: its master position reads axis {axis}, a slave of this cam"
            if axis not in seen:
                seen.add(axis)
                todo += running.get(axis, set())
    return ""
