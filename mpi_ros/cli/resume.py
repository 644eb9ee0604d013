"""RESUME a STOPPED supervisor: ramp back up and finish the same move.

  mpi-ros resume
  mpi-ros resume --supervisor 1

Only from STOPPED; otherwise the state's message (MPIMotionMessageIDLE, ...), exit status 1.
"""

from .actions import verb

add_arguments, run = verb("RESUME")
