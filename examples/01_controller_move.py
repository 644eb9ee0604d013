"""01: the simulated controller on its own (no ROS): an S-curve move, stepped by samples.

    .venv/bin/python examples/01_controller_move.py
"""

from mpi_ros.mpi import Controller, MotionAttr, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory

controller = Controller()  # 2 kHz, 4 axes, 2 motion supervisors
message, ms = controller.create_motion(0)  # mpiMotionCreate
ms.axis_list_set([0, 1])  # mpiMotionAxisListSet
ms.action(MPIAction.MAP)  # MEIActionMAP

params = MotionParams(trajectory=[Trajectory(velocity=1000.0, acceleration=10000.0, deceleration=10000.0,
                                             jerk_percent=50.0)], position=[2000.0, 500.0])
print("start:", ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE, params).message.name)  # mpiMotionStart

controller.run_until(lambda c: ms.state is MPIState.IDLE, max_samples=20_000, chunk=100)
status = ms.snapshot()  # mpiMotionStatus
print(f"IDLE at sample {status.sample}: command {[a.command_position for a in status.axes]},"
      f" actual {[a.actual_position for a in status.axes]}")
for event in controller.drain_events():
    print(f"  sample {event.sample:5d}  {event.type_name:<18} axis {event.axis}")
