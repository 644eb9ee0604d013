"""02: STOP and RESUME continue on the same path; E_STOP needs a RESET (no ROS).

    .venv/bin/python examples/02_stop_resume_e_stop.py
"""

from mpi_ros.mpi import Controller, MotionAttr, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory

controller = Controller()
_, ms = controller.create_motion(0)
ms.axis_list_set([0])
params = MotionParams(trajectory=[Trajectory(2000.0, 20000.0, 20000.0, 30.0)], position=[10_000.0])
ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE, params)
controller.step(1000)
print("STOP:", ms.action(MPIAction.STOP).message.name, "->", ms.state.name)  # decelerates over decelTime.stop
controller.run_until(lambda c: ms.state is MPIState.STOPPED, 5000)
print("STOPPED at", controller.axes[0].command_position)
print("STOP again:", ms.action(MPIAction.STOP).message.name)  # MPIMotionMessageSTOPPED
print("RESUME:", ms.action(MPIAction.RESUME).message.name)  # ramps back and finishes the same profile
controller.run_until(lambda c: ms.state is MPIState.IDLE, 20_000, chunk=100)
print("done at", controller.axes[0].command_position)

ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE, MotionParams(trajectory=[Trajectory(-500.0, 5000.0)]))
controller.step(500)
print("E_STOP:", ms.action(MPIAction.E_STOP).message.name, "->", ms.state.name)  # over decelTime.eStop
controller.run_until(lambda c: ms.state is MPIState.ERROR, 1000)
print("start in ERROR:", ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                                  MotionParams(trajectory=[Trajectory(1.0, 1.0)])).message.name)
print("RESET:", ms.action(MPIAction.RESET).message.name, "->", ms.state.name)
