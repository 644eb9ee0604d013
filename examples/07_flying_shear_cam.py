"""07: a flying shear: a repeating CAM_CUBIC on axis 1 slaved to axis 0, a line at constant speed (no ROS).

    .venv/bin/python examples/07_flying_shear_cam.py

The line (axis 0) runs at 2000 counts/s. Every 1000 counts of line the shear carriage (axis 1)
speeds up to the line's speed (200 counts of line), cuts while moving with it at a gear ratio
of exactly 1 (200 counts), slows down (300 counts) and returns to its start (300 counts): one
cycle of the cam table, repeated (REPEAT from segment 0) until STOP. The same through ROS:
README.md, "Cams".
"""

from mpi_ros import mpi

RATE = 1000.0
controller = mpi.Controller(mpi.ControllerConfig(sample_rate=RATE, axis_count=2, supervisor_count=2))
_, line = controller.create_motion(0, 0)  # supervisor 0: the line, axis 0
_, shear = controller.create_motion(1, 1)  # supervisor 1: the shear carriage, axis 1
# MPIAxisConfig.master: axis 1 follows axis 0's command position
controller.axis_master_set(1, mpi.AxisMaster(mpi.AxisMasterType.AXIS_COMMANDED_POSITION, number=0))

line.start(mpi.MPIMotionType.VELOCITY, mpi.MotionAttr.NONE,
           mpi.MotionParams(trajectory=[mpi.Trajectory(velocity=2000.0, acceleration=20000.0, deceleration=20000.0)]))
controller.step(200)  # the line is at speed

# MPIMotionCam: master distance and slave distance of each segment, the gear ratio at each segment's end
cam = mpi.MotionParams(master_distance=[200.0, 200.0, 300.0, 300.0],
                   slave_position=[100.0, 200.0, 150.0, -450.0],
                   gear_ratio=[1.0, 1.0, 0.0, 0.0],
                   repeat_from=0)
print("cam start:", shear.start(mpi.MPIMotionType.CAM_CUBIC, mpi.MotionAttr.REPEAT, cam).message.name)
start = controller.sample

worst = 0.0
for cycle in range(5):
    # the cut: from 200 to 400 counts of line into the cycle (100 to 200 samples at 2000 counts/s)
    controller.step(start + 1 + cycle * 500 + 100 - controller.sample)
    for _ in range(99):
        controller.step(1)
        line_axis, shear_axis = controller.axes
        worst = max(worst, abs(shear_axis.cmd_v / line_axis.cmd_v - 1.0))
    print(f"cycle {cycle}: cut done at line {controller.axes[0].command_position:8.1f},"
          f" carriage {controller.axes[1].command_position:6.1f}")
controller.step(start + 5 * 500 - controller.sample)
print(f"synchronized: slave speed / line speed = {1.0 + worst:.6f} during every cut")
print(f"after 5 cycles the carriage is back at {controller.axes[1].command_position:.6f}")

shear.action(mpi.MPIAction.STOP)
controller.run_until(lambda c: shear.state is mpi.MPIState.STOPPED, max_samples=5000, chunk=10)
print(f"STOP: shear {shear.state.name} at {controller.axes[1].command_position:.1f}, line still {line.state.name}")
for event in controller.drain_events():
    if event.supervisor == 1:
        print(f"  sample {event.sample:5d}  {event.type_name:<18} axis {event.axis}")
