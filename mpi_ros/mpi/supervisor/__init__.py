"""A motion supervisor, the Motion object of MPI 000: the facade (motion.py) and its
collaborators, each given the shared state (state.py) and the controller as a SupervisorHost
(host.py): the axis list (axis_list.py), the moves (moves.py, holds.py), the MPI actions
(actions.py), what happens as the controller steps (stepping.py), the motion log (log.py)."""
