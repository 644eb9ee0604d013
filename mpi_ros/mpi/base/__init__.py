"""The reference's vocabulary and the small values every layer shares: message codes, types
and attribute masks, events, the MPI structs with their validators, the one outcome type,
the feedrate clock, position wrap, the I/O image and master sources, status snapshots.
Imports nothing else of the controller."""
