"""The twin matched to a machine: fit each axis' servo plant from a recording of command and
actual position, and say how close the twin comes (docs/calibration.md).

recording.py reads a recording (an MCAP bag of this suite's topics, or a CSV) and refuses bad
input; twin.py runs the twin's own plant (mpi_ros.mpi.axes.plant) on the recorded command;
fit.py finds the plant parameters that bring the twin closest; report.py prints and plots.

twin.py and fit.py use scipy, a run-time dependency of these tools only: the suite never imports
this package (the `fit` and `compare` verbs import it when they run).
"""
