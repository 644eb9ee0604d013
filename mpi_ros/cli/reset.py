"""RESET a supervisor: leave ERROR (or drop a STOPPED move) and go to IDLE.

  mpi-ros reset
  mpi-ros reset --supervisor 1

While MOVING or STOPPING it is refused with that state's message (exit status 1).
"""

from .actions import verb

add_arguments, run = verb("RESET")
