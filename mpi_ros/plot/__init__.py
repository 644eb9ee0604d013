"""Plots to PNG (matplotlib, Agg backend; imported only when a plot is drawn).

* profile.py — a profile request: the controller's position/velocity/acceleration/jerk with
  ruckig's profile overlaid (``mpi-ros plot``);
* bag.py — a recorded bag over time (``mpi-ros plot BAG``).
"""
