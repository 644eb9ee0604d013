"""E_STOP a supervisor: decelerate over decelTime.eStop, then ERROR until `mpi-ros reset`.

  mpi-ros e-stop
  mpi-ros e-stop --supervisor 1

Never refused (safety actions are not): the answer shows the state it leaves, usually
STOPPING_ERROR; moves are refused with MPIMotionMessageERROR until a RESET.
"""

from .actions import verb

add_arguments, run = verb("E_STOP")
