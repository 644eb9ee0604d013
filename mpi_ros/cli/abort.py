"""ABORT a supervisor: disable the servos at once (the axes coast), then ERROR until `mpi-ros reset`.

  mpi-ros abort
  mpi-ros abort --supervisor 1

Never refused. After an ABORT, RESET sets the command position to the actual position.
"""

from .actions import verb

add_arguments, run = verb("ABORT")
