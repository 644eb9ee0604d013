"""The fault model (docs/faults.md): the fault monitor that scans each stretch for limits and
trips (monitor.py). It sees the controller through host.FaultHost only."""
