"""The axes: one Axis per MPI 002 axis (axis.py), every axis' state as arrays (bank.py), the
simulated servo and encoder (plant.py), every axis over a stretch of samples at once
(trace.py, into stretch.py's arrays), and the status bits (status.py). Imports base and
planning (the plan an axis runs)."""
