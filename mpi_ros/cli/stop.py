"""STOP a supervisor: decelerate over decelTime.stop to STOPPED, the rest of the move kept.

  mpi-ros stop
  mpi-ros stop --supervisor 1

`mpi-ros resume` continues the move, `mpi-ros reset` drops it. STOP while IDLE answers
MPIMotionMessageIDLE, while STOPPED MPIMotionMessageSTOPPED (exit status 1, message printed).
"""

from .actions import verb

add_arguments, run = verb("STOP")
